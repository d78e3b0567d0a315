//! CPU twin of the brute-force accelerator (`accel::brute_force`, `glsl/brute_force/`): every
//! ray against every triangle in id order — Müller 2015, Listings 12 and 15.

use glam::Vec3;

use super::{intersect_triangle, CpuAccelerator, Hit};

pub struct BruteForce {
    triangles: Vec<[Vec3; 3]>,
}

impl BruteForce {
    pub fn new(triangles: Vec<[Vec3; 3]>) -> BruteForce {
        BruteForce { triangles }
    }
}

/// Test triangle `id` against the ray and keep it in `best` if it is closer (equal distances:
/// the lower id), as intersect1's loops do.
pub fn closer_hit(best: &mut Option<Hit>, tri: &[Vec3; 3], id: usize, ro: Vec3, rd: Vec3) {
    if let Some((t, u, v)) = intersect_triangle(ro, rd, tri[0], tri[1], tri[2]) {
        if best.is_none_or(|b| t < b.t || (t == b.t && id < b.id)) {
            *best = Some(Hit { t, id, u, v });
        }
    }
}

/// Whether triangle `tri` occludes the shadow feeler: offset < t < light_distance.
pub fn occludes(tri: &[Vec3; 3], ro: Vec3, rd: Vec3, light_distance: f32, offset: f32) -> bool {
    intersect_triangle(ro, rd, tri[0], tri[1], tri[2])
        .is_some_and(|(t, _, _)| t > offset && t < light_distance)
}

impl CpuAccelerator for BruteForce {
    fn closest_hit(&self, ro: Vec3, rd: Vec3, last: i32) -> (Option<Hit>, u64) {
        let mut best = None;
        let mut tests = 0;
        for (i, t) in self.triangles.iter().enumerate() {
            if i as i32 != last {
                tests += 1;
                closer_hit(&mut best, t, i, ro, rd);
            }
        }
        (best, tests)
    }

    fn occluded(
        &self,
        ro: Vec3,
        rd: Vec3,
        light_distance: f32,
        offset: f32,
        last: i32,
    ) -> (bool, u64) {
        let mut tests = 0;
        for (i, t) in self.triangles.iter().enumerate() {
            if i as i32 != last {
                tests += 1;
                if occludes(t, ro, rd, light_distance, offset) {
                    return (true, tests);
                }
            }
        }
        (false, tests)
    }
}
