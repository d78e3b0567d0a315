//! CPU twin of the brute-force accelerator (`accel::brute_force`, `glsl/brute_force/`): every
//! ray against every triangle in id order — Müller 2015, Listings 12 and 15.

use glam::Vec3;

use super::search::{closest_among, CpuAccelerator, Feeler, Hit};
use crate::accel::Accel;
use crate::scene::Scene;

pub struct BruteForce {
    triangles: Vec<[Vec3; 3]>,
}

impl BruteForce {
    pub fn new(triangles: Vec<[Vec3; 3]>) -> BruteForce {
        BruteForce { triangles }
    }
}

impl CpuAccelerator for BruteForce {
    fn closest_hit(&self, ro: Vec3, rd: Vec3, last: i32) -> (Option<Hit>, u64) {
        let (mut best, mut tests) = (None, 0);
        let all = 0..self.triangles.len();
        closest_among(&mut best, &self.triangles, all, (ro, rd, last), &mut tests);
        (best, tests)
    }

    fn occluded(&self, feeler: &Feeler) -> (bool, u64) {
        let mut tests = 0;
        let blocked = feeler.blocked_among(&self.triangles, 0..self.triangles.len(), &mut tests);
        (blocked, tests)
    }
}

/// The base tracer's twin (`design::REGISTRY`).
pub fn twin(scene: &Scene, _: &Accel) -> anyhow::Result<Box<dyn CpuAccelerator>> {
    Ok(Box::new(BruteForce::new(scene.world_triangles())))
}
