//! The soft-shadow renderer's options, below the renderer and its passes, which all read them.

use super::linespace_build::LinespaceBuild;
use crate::scene::shadows::KleeShading;
use crate::scene::ShadowMode;

/// Options of the soft-shadow renderer.
#[derive(Debug, Clone)]
pub struct SoftShadowOptions {
    pub mode: ShadowMode,
    pub samples_u: u32,
    pub samples_v: u32,
    /// N: cells per axis of every N-tree node (10 in the thesis).
    pub ntree_n: u32,
    /// Levels of the N-tree including the root (3 in the thesis).
    pub ntree_depth: u32,
    pub width: u32,
    pub height: u32,
    /// Dispatch the shadow pass in tiles of at most tile×tile pixels (0: one dispatch).
    pub tile: u32,
    /// How the shadow value lights a pixel (ours, or Fig. 7's product).
    pub shading: KleeShading,
    /// Where the line spaces are computed (GPU or CPU).
    pub linespace_build: LinespaceBuild,
}
