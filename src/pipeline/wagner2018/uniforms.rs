//! What the host hands Wagner 2018's kernel (`glsl/wagner2018/raytrace.comp`): its constants,
//! the camera of Listing 4.1, the lighting and the per-vertex surface data. The CPU twin
//! (`reference::wagner2018`) reads the same values.

use glam::Vec3;

use super::bvh::MAX_DEPTH;
use crate::scene::Camera;

/// ε of Listings 4.2 and 4.5 (the thesis gives no value; Möller and Trumbore's paper, its
/// [1], uses 10⁻⁶): a triangle whose determinant is smaller is parallel to the ray, a slab
/// whose direction component is smaller is tested as parallel.
pub const EPSILON: f32 = 1e-6;
/// Iterations of one walk before it stops as truncated: llvmpipe ends an invocation's loops
/// after 65535 iterations in total; two walks of 32000 stay below it.
pub const LOOP_BUDGET: u32 = 32000;
const _: () = assert!(
    2 * LOOP_BUDGET < 65535,
    "two walks must fit llvmpipe's loop limit"
);
/// Entries of the traversal stack: one per level is enough ([`MAX_DEPTH`]).
pub const STACK: usize = MAX_DEPTH as usize;

/// The camera of Listing 4.1 as the host computes it for the kernel: the position, the
/// direction to the upper-left corner of the image, unit vectors to the right and down, and
/// the image's width and height along them (at the distance of `direction`). The thesis does
/// not say where `camera.direction` points; since the listing adds α, β ∈ [0, 1] times the
/// image's extent to it, it must be the corner where both are 0 (our reading, listed in
/// `docs/listings.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WagnerCamera {
    pub position: Vec3,
    pub direction: Vec3,
    pub x_direction: Vec3,
    pub y_direction: Vec3,
    pub x_scale: f32,
    pub y_scale: f32,
}

impl WagnerCamera {
    /// The camera of a scene for a `width`×`height` image (the image plane of `Camera::rays`).
    pub fn new(camera: &Camera, width: u32, height: u32) -> WagnerCamera {
        let r = camera.rays(width, height);
        WagnerCamera {
            position: r.cam_position,
            direction: r.cam_img_offset,
            x_direction: r.cam_width.normalize(),
            y_direction: r.cam_height.normalize(),
            x_scale: r.cam_width.length() * width as f32,
            y_scale: r.cam_height.length() * height as f32,
        }
    }
}

/// The per-vertex normals and colours of the triangles (3 per triangle, world space), as the
/// kernel's textures hold them.
#[derive(Debug, Clone, Copy)]
pub struct Surface<'a> {
    pub normals: &'a [Vec3],
    pub colors: &'a [Vec3],
}

/// The kernel's lighting: one point light, the scene's ambient light and background, and the
/// shadow ray's offset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lighting {
    pub light_position: Vec3,
    pub light_color: Vec3,
    pub ambient: Vec3,
    pub background: Vec3,
    pub shadow_offset: f32,
}
