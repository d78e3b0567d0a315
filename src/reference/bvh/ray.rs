//! A ray's octant and the inverse of its direction, as the kernels compute them
//! (`glsl/bvh/octant.glsl`): below the walk and the blocks' entry points, which both take them.

use glam::Vec3;

/// The ray's octant: bit a set when it points down axis a (by the sign of 1/rd, as the kernels).
pub(super) fn octant(inv: Vec3) -> usize {
    (0..3).map(|a| ((inv[a] < 0.0) as usize) << a).sum()
}

/// 1/rd with zero (and tiny) components replaced by 1e-20, so the slab test never computes
/// 0·∞ (the kernels do the same).
pub(super) fn safe_inverse(rd: Vec3) -> Vec3 {
    safe_divisor(rd).recip()
}

/// The divisors of [`safe_inverse`]: rd with zero (and tiny) components replaced by 1e-20.
pub(super) fn safe_divisor(rd: Vec3) -> Vec3 {
    let s = |d: f32| if d.abs() < 1e-20 { 1e-20 } else { d };
    Vec3::new(s(rd.x), s(rd.y), s(rd.z))
}
