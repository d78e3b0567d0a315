//! The pipelines — how rays flow through the GPU — behind one [`Renderer`] interface that
//! `render`, `view` and `bench` drive the same way, whatever the design (`crate::design` makes
//! them, one row of its registry per design):
//!
//! | pipeline | source | module | kernels | accelerators |
//! |---|---|---|---|---|
//! | four compute kernels (eye rays → intersect1 → intersect2 → shading) | Müller 2015 | [`mueller2015`] | `glsl/mueller2015/` | `base`, `grid` (thesis, exact), `bvh` ([`crate::accel`]) |
//! | G-buffer + shadow pass + screen-filling quad | Klee 2016 | [`klee2016`] | `glsl/klee2016/` | its N-tree + Cascaded Line Space |
//! | one kernel per pixel (primary ray, BVH walk, Lambert, hard shadow) | Wagner 2018 | [`wagner2018`] | `glsl/wagner2018/` | its BVH in three textures (`--tracer bvh --bvh-variant wagner`) |
//! | fragment programs over a viewport-sized quad, traversal looped until an occlusion query counts no fragment | the streaming tracer | [`stream`] | `glsl/stream/` | its static grid in textures, proximity clouds (`--tracer stream`) |

pub mod klee2016;
pub mod mueller2015;
pub mod ray_kinds;
pub mod stream;
pub mod wagner2018;

pub mod renderer;

pub use renderer::{counter_value, Renderer};
