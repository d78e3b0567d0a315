//! The tracer designs. Each module owns its kernels and GPU resources, like the thesis'
//! RTScene and kernel classes (Müller 2015, Fig. 16–18).

pub mod base;
pub mod gpu_scene;
pub mod grid;
pub mod linespace;
pub mod pipeline;

use std::collections::BTreeMap;
use std::sync::Arc;

use anyhow::Result;
use glam::Mat4;
use serde::Serialize;

use crate::gl::{Gl, GlInfo, ShaderSource};
use crate::scene::{Camera, Scene};

/// A tracer design: renders frames of the scene it was made for.
pub trait Tracer {
    /// The `--tracer` name.
    fn name(&self) -> &'static str;
    /// Move object `object` (index in the scene's objects): its model matrix for the next
    /// frames. The transform pass applies it; nothing is uploaded again.
    fn set_model(&mut self, object: usize, model: Mat4);
    /// Render one frame seen from `camera`.
    fn render(&mut self, camera: &Camera) -> Result<Frame>;
    /// The RGBA32F output texture of the last frame (rgb colour, a weight), GL row order, for
    /// showing it through a screen-filling quad (Müller 2015, ch. 3.1.3).
    fn output_texture(&self) -> glow::Texture;
}

/// The `--tracer` choices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TracerKind {
    /// The thesis' base tracer: every ray against every triangle (Müller 2015, ch. 3.1, 4.1).
    Base,
    /// The uniform grid rebuilt every frame (Müller 2015, ch. 3.2, 4.2); see `--grid-variant`.
    Grid,
}

/// Make the tracer `kind` for `scene` on the current context.
pub fn create(
    kind: TracerKind,
    gl: Arc<Gl>,
    info: &GlInfo,
    scene: &Scene,
    shaders: &ShaderSource,
    options: RenderOptions,
) -> Result<Box<dyn Tracer>> {
    Ok(match kind {
        TracerKind::Base => Box::new(base::BaseTracer::new(gl, info, scene, shaders, options)?),
        TracerKind::Grid => Box::new(grid::GridTracer::new(gl, info, scene, shaders, options)?),
    })
}

/// How the shadow flags of intersect2 are stored (Müller 2015, Listing 15 and ch. 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ShadowFlags {
    /// The thesis: one channel of an RGBA32F texture per light, so at most 4 lights.
    Rgba,
    /// The bitwise flags proposed in ch. 5: one bit per light in an RGBA32UI texture, so at
    /// most 128 lights.
    Bits,
}

impl ShadowFlags {
    pub fn max_lights(self) -> usize {
        match self {
            ShadowFlags::Rgba => 4,
            ShadowFlags::Bits => 128,
        }
    }
}

/// The two uniform-grid designs (Müller 2015, ch. 3.2, 4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum GridVariant {
    /// Faithful: triangles registered along their edges into fixed-size voxel lists, per-ray
    /// voxel lists from the traversal kernel (Listings 17–22).
    Thesis,
    /// Exact: triangle/box overlap, compact lists (count, prefix sum, fill), 3D-DDA in the
    /// intersection kernels.
    #[default]
    Exact,
}

/// Options of the grid tracer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GridOptions {
    pub variant: GridVariant,
    /// N of the N³ voxels; `None`: chosen from the triangle count (`--grid auto`).
    pub resolution: Option<u32>,
    /// The thesis variant's fixed list lengths: voxel_array_length (triangle ids per voxel,
    /// Listing 17: 512) and ray_array_length (voxel ids per ray; `None`: 3·N as Listing 17).
    pub voxel_array_length: u32,
    pub ray_array_length: Option<u32>,
}

impl Default for GridOptions {
    fn default() -> Self {
        GridOptions {
            variant: GridVariant::Exact,
            resolution: None,
            voxel_array_length: 512,
            ray_array_length: None,
        }
    }
}

/// `--grid N|auto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridResolution {
    Auto,
    N(u32),
}

impl std::str::FromStr for GridResolution {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(GridResolution::Auto);
        }
        match s.parse::<u32>() {
            Ok(n) if n > 0 => Ok(GridResolution::N(n)),
            _ => Err(format!(
                "`{s}` is neither `auto` nor a positive voxel count per axis"
            )),
        }
    }
}

/// The grid tracer's command-line options (`render`, `view`, `bench`).
#[derive(Debug, Clone, clap::Args)]
pub struct GridArgs {
    /// Grid resolution N (N³ voxels), or `auto`: N = cbrt(triangles / 5), within 4..=64.
    #[arg(long, default_value = "auto", value_name = "N|auto")]
    pub grid: GridResolution,
    /// `thesis`: edge-registered fixed-size lists as Müller 2015; `exact`: overlap test,
    /// compact lists, 3D-DDA.
    #[arg(long, value_enum, default_value = "exact")]
    pub grid_variant: GridVariant,
    /// Thesis variant: triangle ids per voxel list (Listing 17: 512).
    #[arg(long, default_value_t = 512, value_name = "L")]
    pub voxel_array_length: u32,
    /// Thesis variant: voxel ids per ray list (default 3·N, as Listing 17).
    #[arg(long, value_name = "R")]
    pub ray_array_length: Option<u32>,
}

impl GridArgs {
    pub fn options(&self) -> GridOptions {
        GridOptions {
            variant: self.grid_variant,
            resolution: match self.grid {
                GridResolution::Auto => None,
                GridResolution::N(n) => Some(n),
            },
            voxel_array_length: self.voxel_array_length,
            ray_array_length: self.ray_array_length,
        }
    }
}

/// Options of one render.
#[derive(Debug, Clone)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// REFL_DEPTH: reflection passes after the primary pass (Fig. 8).
    pub refl_depth: u32,
    /// Dispatches cover at most tile×tile pixels (0: the whole image in one dispatch).
    pub tile: u32,
    pub shadow_flags: ShadowFlags,
    /// Read back the primary rays and first hits for the AOVs.
    pub aovs: bool,
    /// Grid tracer options (ignored by the base tracer).
    pub grid: GridOptions,
}

/// Global counter slots, shared with the kernels through `#define COUNTER_*`.
pub const COUNTERS: &[&str] = &[
    "intersect1",
    "intersect2",
    "truncated_rays",
    "voxels_visited",
    "dropped_triangle_refs",
    "ray_list_overflows",
];

/// The counters that count ray–triangle tests (the rest count events).
pub const TRIANGLE_TEST_COUNTERS: &[&str] = &["intersect1", "intersect2"];

/// Statistics of one frame.
#[derive(Debug, Clone, Default, Serialize)]
pub struct FrameStats {
    /// Ray–triangle tests per kernel (exact 64-bit counts).
    pub triangle_tests: BTreeMap<String, u64>,
    /// GPU time per kernel in milliseconds (GL timer queries, summed over tiles and passes).
    pub gpu_ms: BTreeMap<String, f64>,
    /// Rays whose loop the GL implementation ended early (llvmpipe's loop limit); a frame
    /// with any is refused by the host.
    pub truncated_rays: u64,
    /// Other exact event counts of the design (grid: voxels_visited, dropped_triangle_refs,
    /// ray_list_overflows, ...).
    pub events: BTreeMap<String, u64>,
    /// Design-specific facts (grid: grid_resolution, grid_bytes, grid_build_ms, ...).
    pub facts: BTreeMap<String, serde_json::Value>,
    /// Wall-clock time of the frame on the host, in milliseconds (includes waiting for the GPU).
    pub wall_ms: f64,
}

impl FrameStats {
    pub fn total_gpu_ms(&self) -> f64 {
        self.gpu_ms.values().sum()
    }
    pub fn total_triangle_tests(&self) -> u64 {
        self.triangle_tests.values().sum()
    }
}

/// Per-pixel outputs beside the colour, row 0 = the top image row.
#[derive(Debug, Clone, Default)]
pub struct Aovs {
    pub ray_origin: Vec<[f32; 3]>,
    pub ray_direction: Vec<[f32; 3]>,
    pub hit_t: Vec<f32>,
    pub triangle_id: Vec<i32>,
    pub normal: Vec<[f32; 3]>,
}

/// A rendered frame: RGBA colour (rgb: colour, a: accumulated weight), row 0 = top.
#[derive(Debug, Clone)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub color: Vec<[f32; 4]>,
    pub aovs: Option<Aovs>,
    pub stats: FrameStats,
}

/// Flip GL row order (row 0 = bottom) to image order (row 0 = top).
pub fn flip_rows<T: Clone>(data: &[T], width: u32, height: u32) -> Vec<T> {
    let w = width as usize;
    (0..height as usize)
        .rev()
        .flat_map(|r| data[r * w..(r + 1) * w].iter().cloned())
        .collect()
}
