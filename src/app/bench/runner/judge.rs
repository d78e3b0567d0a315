//! What `accel-compare` judges a configuration's first hits by: the CPU reference
//! (`gpgpu_rt::reference`) on the same primary rays — brute force (the base tracer's twin:
//! every ray against every triangle) where that stays within [`BRUTE_FORCE_MAX_TESTS`], else
//! the CPU twin of the SAH BVH (the issue allows Embree there; our twin is tested against the
//! base tracer and Embree in tests/bvh.rs and `tools/embree_peer.py`).

use anyhow::Result;

use super::adapter::Frame;
use gpgpu_rt::accel;
use gpgpu_rt::reference::Reference;
use gpgpu_rt::scene::Scene;

/// Brute force judges a scene while triangles × pixels stays within this (a second or so of CPU
/// time: the judge stays cheap beside the frames it judges).
pub const BRUTE_FORCE_MAX_TESTS: f64 = 2e8;

/// Hit distances this close (relative) count as the same hit: a ray through a shared edge or a
/// vertex may take either triangle.
pub const TIE_T_REL: f32 = 1e-5;

/// The judge's first hits of a scene at one image size (row 0 = top).
pub struct Judge {
    /// "CPU brute force" or "CPU SAH BVH".
    pub name: &'static str,
    ids: Vec<i32>,
    hit_t: Vec<f32>,
}

impl Judge {
    /// The first hits of `scene`'s camera at `width`×`height` on the CPU.
    pub fn of(scene: &Scene, width: u32, height: u32) -> Result<Judge> {
        // first hits only: no lights, no reflection
        let unlit = Scene {
            lights: Vec::new(),
            ..scene.clone()
        };
        let work = scene.triangle_count() as f64 * width as f64 * height as f64;
        let (name, reference) = if work <= BRUTE_FORCE_MAX_TESTS {
            ("CPU brute force", Reference::new(&unlit))
        } else {
            let twin = gpgpu_rt::design::twin(&unlit, &accel::bvh::ENTRY.plain)?;
            ("CPU SAH BVH", Reference::with_accelerator(&unlit, twin))
        };
        let f = reference.render(&scene.camera, width, height, 0);
        Ok(Judge {
            name,
            ids: f.aovs.triangle_id,
            hit_t: f.aovs.hit_t,
        })
    }

    /// The share of the pixels whose first hit agrees with the judge's: the same triangle, or
    /// (a tie on a shared edge) hits at distances within [`TIE_T_REL`]. `None` without first
    /// hits in `frame`.
    pub fn agreement(&self, frame: &Frame) -> Option<f64> {
        let aovs = frame.aovs.as_ref()?;
        if aovs.triangle_id.len() != self.ids.len() {
            return None;
        }
        let same = |i: usize| {
            let (a, b) = (aovs.triangle_id[i], self.ids[i]);
            let (s, t) = (aovs.hit_t[i], self.hit_t[i]);
            a == b || (a >= 0 && b >= 0 && (s - t).abs() <= TIE_T_REL * s.max(t))
        };
        let agree = (0..self.ids.len()).filter(|&i| same(i)).count();
        Some(agree as f64 / self.ids.len().max(1) as f64)
    }
}
