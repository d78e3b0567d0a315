//! What a renderer hands back: the frame's colour, its per-pixel outputs (AOVs) and its
//! statistics. GPU-free, shared by the pipelines, the accelerators, the CPU reference and the
//! output writers.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// Host bytes per pixel of a frame: the colour read back (RGBA32F 16), kept (12) and encoded
/// (8-bit RGB 3, its PNG at most as much again), and the GPU's images of the frame, at most
/// twelve RGBA32F (a software driver's GPU memory is the host's).
const FRAME_PIXEL_BYTES: u64 = 16 + 12 + 3 + 3 + 12 * 16;
/// Host bytes per pixel of the AOVs: four RGBA32F images read back, the arrays kept (ray
/// origin, direction and normal 12 each; hit_t, triangle id and shadow 4 each) and the vectors
/// flattened for the `.npy` encoder (36).
const AOV_PIXEL_BYTES: u64 = 4 * 16 + 48 + 36;

/// Host bytes a `width`×`height` frame takes, rendered, read back and written.
pub fn host_bytes(width: u32, height: u32, aovs: bool) -> u64 {
    let per_pixel = FRAME_PIXEL_BYTES + if aovs { AOV_PIXEL_BYTES } else { 0 };
    width as u64 * height as u64 * per_pixel
}

/// A `width`×`height` frame within the host's memory, checked before any of it is allocated.
pub fn check_host(width: u32, height: u32, aovs: bool) -> Result<(), String> {
    let what = match aovs {
        true => format!("a {width}x{height} frame with its AOVs"),
        false => format!("a {width}x{height} frame"),
    };
    let bytes = host_bytes(width, height, aovs);
    crate::scene::budget::reserve(&what, "--width with --height", bytes)
}

/// Statistics of one frame.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
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
    /// Wall-clock time of the frame on the host, in milliseconds, to after `glFinish`: the whole
    /// frame, the gaps between dispatches that `gpu_ms` leaves out included.
    pub wall_ms: f64,
    /// The work of each kind of rays apart ("primary", "shadow_first_light",
    /// "shadow_other_lights", "reflection"): Müller 2015's and the streaming tracer's pipelines
    /// (see `pipeline::ray_kinds`); empty for the others.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub ray_kinds: BTreeMap<String, RayKindStats>,
}

/// The kinds of rays the pipelines count and time apart: the primary rays' closest hits, the
/// shadow feelers towards the first light and towards the others (every bounce), the closest
/// hits of the reflection rays.
pub const RAY_KINDS: [&str; 4] = [
    "primary",
    "shadow_first_light",
    "shadow_other_lights",
    "reflection",
];

/// The work of one kind of rays in a frame.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct RayKindStats {
    /// GPU time of the kind's dispatches (GL timer queries), in milliseconds.
    pub gpu_ms: f64,
    /// Ray–triangle tests of the kind (of whichever kernels count them).
    pub triangle_tests: u64,
    /// The kind's non-zero counters by the pipeline's names: `rays` (rays traced), the
    /// kernels' triangle tests (`intersect1`, `intersect2`; `closest_tests`, `shadow_tests`),
    /// `voxels_visited`, `nodes_visited`, ...
    pub counts: BTreeMap<String, u64>,
}

impl RayKindStats {
    /// A counter of the kind, 0 where it stayed zero.
    pub fn count(&self, name: &str) -> u64 {
        self.counts.get(name).copied().unwrap_or(0)
    }
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
    /// The fraction of unblocked shadow rays per pixel (1 where no geometry was hit);
    /// `shadow.npy`. Soft shadows (Klee 2016): of the light samples; the ray tracer: of the
    /// point lights' feelers from the first hit (a light behind the surface counts as blocked).
    pub shadow: Option<Vec<f32>>,
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

/// The xyz of every RGBA texel, GL rows flipped to image rows.
pub fn flip_xyz(data: &[[f32; 4]], width: u32, height: u32) -> Vec<[f32; 3]> {
    flip_rows(data, width, height)
        .iter()
        .map(|v| [v[0], v[1], v[2]])
        .collect()
}
