//! The options of Müller 2015's pipeline and the counters its kernels keep: below the ray
//! tracer and its images and records, which all read them.

use serde::Serialize;

use crate::accel::Accel;

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

    /// The texture format of the flags.
    pub fn format(self) -> u32 {
        match self {
            ShadowFlags::Rgba => glow::RGBA32F,
            ShadowFlags::Bits => glow::RGBA32UI,
        }
    }
}

/// Options of Müller 2015's pipeline with one of its accelerators (`design::Design::Mueller2015`).
#[derive(Debug, Clone)]
pub struct RenderOptions {
    /// The accelerator with its own options (`--tracer` and its group).
    pub accel: Accel,
    pub width: u32,
    pub height: u32,
    /// REFL_DEPTH: reflection passes after the primary pass (Fig. 8).
    pub refl_depth: u32,
    /// Dispatches cover at most tile×tile pixels (0: the whole image in one dispatch).
    pub tile: u32,
    pub shadow_flags: ShadowFlags,
    /// Keep the primary rays and first hits for the AOVs.
    pub aovs: bool,
    /// The base tracer's triangles per dispatch (`accel::BuildContext`); `None`: as the GL
    /// implementation needs.
    pub triangles_per_dispatch: Option<u32>,
    /// `--light-samples` U×V: the feelers towards each area light per hit point (ours, after
    /// Klee 2016; the scene's point lights get one each, as Listing 15).
    pub light_samples: (u32, u32),
}

impl RenderOptions {
    /// Müller 2015's pipeline with `accel` at `width`×`height`, `refl_depth` reflection passes,
    /// and the command line's defaults otherwise: tiles of [`crate::limits::defaults::TILE`],
    /// bitwise shadow flags, 4×4 area-light samples, no AOVs.
    pub fn new(accel: Accel, width: u32, height: u32, refl_depth: u32) -> RenderOptions {
        RenderOptions {
            accel,
            width,
            height,
            refl_depth,
            tile: crate::limits::defaults::TILE,
            shadow_flags: ShadowFlags::Bits,
            aovs: false,
            triangles_per_dispatch: None,
            light_samples: crate::limits::defaults::LIGHT_SAMPLES,
        }
    }

    /// Whether a pass runs in the accelerator's fused kernel (the SAH BVH's default).
    pub fn fused(&self) -> bool {
        self.accel.fused()
    }
}

/// Global counter slots, shared with the kernels through `#define COUNTER_*`.
pub const COUNTERS: &[&str] = &[
    "intersect1",
    "intersect2",
    "truncated_rays",
    "voxels_visited",
    "dropped_triangle_refs",
    "ray_list_overflows",
    "nodes_visited",
    // the exact grid's proximity clouds (reported with --proximity-clouds only)
    "cloud_jumps",
    "empty_cells_skipped",
    // rays traced by intersect1 and feelers traced by intersect2 (ours: per ray kind)
    "rays",
];

/// The counters that count ray–triangle tests (the rest count events).
pub const TRIANGLE_TEST_COUNTERS: &[&str] = &["intersect1", "intersect2"];
