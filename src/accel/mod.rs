//! The acceleration structures of Müller 2015's four-kernel pipeline, one type each, with a
//! GPU side here and a CPU twin in [`crate::reference`]:
//!
//! | `--tracer` | GPU side | GLSL | CPU twin |
//! |---|---|---|---|
//! | `base` | [`brute_force::BruteForce`] | `glsl/brute_force/` | `reference::brute_force` |
//! | `grid --grid-variant thesis` | [`thesis_grid::ThesisGrid`] | `glsl/thesis_grid/` | `reference::thesis_grid` |
//! | `grid --grid-variant exact` | [`exact_grid::ExactGrid`] | `glsl/exact_grid/` | `reference::exact_grid` |
//! | `bvh` | [`bvh::Bvh`] | `glsl/bvh/` | `reference::bvh` |
//!
//! An accelerator answers the pipeline's two questions — the closest hit of every ray
//! (intersect1) and whether a shadow feeler is blocked (intersect2) — and may rebuild itself
//! every frame from the freshly transformed scene. In the GLSL, its intersect1 kernel defines
//! `closestHit` and its intersect2 kernel `occluded`; the rest of both kernels is the
//! pipeline's (`glsl/common/intersect1_main.glsl`, `intersect2_main.glsl`). The base tracer's
//! intersect1 is written out whole around Listing 12 and calls Listings 13 and 14 in
//! `glsl/common/intersect1_hit.glsl`. The SAH BVH runs a whole pass in one kernel by default
//! through the trait's one optional hook ([`Accelerator::fused_pass`]). Each accelerator is one
//! variant of [`Accel`] with its own options, one [`Entry`] and one row of `design::REGISTRY`,
//! which names its CPU twin (`design::twin`). What the GPU path builds from — boxes ([`aabb`]), the scene-to-grid
//! mapping ([`grid_frame`]), the distance transform ([`proximity`]), the triangle/box test
//! ([`tribox`]) — lives here too, and the twins import it.

pub mod aabb;
pub mod brute_force;
pub mod bvh;
pub mod exact_grid;
pub mod grid_frame;
pub mod interface;
pub mod options;
pub mod proximity;
pub mod thesis_grid;
pub mod tribox;

pub use interface::{
    max_pixel_events, set_camera, Accelerator, BuildContext, Entry, FrameContext, FusedPasses,
    FusedRun, LightTarget, MakeGpu, PassHost, PassRays, PIXELS_PER_INVOCATION,
};
pub use options::{
    auto_resolution, Accel, BvhLevels, BvhOptions, BvhPasses, BvhVariant, ExactGridOptions,
    GridVariant, ThesisGridOptions,
};

impl Accel {
    /// Its entry of the accelerators (and its row's name in `design::REGISTRY`).
    pub fn entry(&self) -> &'static Entry {
        match self {
            Accel::Base => &brute_force::ENTRY,
            Accel::ThesisGrid(_) => &thesis_grid::ENTRY,
            Accel::ExactGrid(_) => &exact_grid::ENTRY,
            Accel::Bvh(_) => &bvh::ENTRY,
        }
    }
}
