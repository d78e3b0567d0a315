//! CPU twin of the thesis grid (`accel::thesis_grid`, `glsl/thesis_grid/`, Müller 2015
//! Listings 17–22): triangles registered along their edges (the build kernel), each ray's
//! non-empty voxels listed by Algorithms 2 and 3 (the traversal kernel), and the intersection
//! kernels walking those lists — the closest-hit walk stopping after the first voxel with a
//! hit, as the thesis does. The fixed-size lists are cut as the kernels cut them; the GPU fills
//! a voxel's list in an order set by its atomics, so the two agree exactly only where no voxel
//! list overflows.

use glam::Vec3;

use super::grid::{clip_to_grid, GridSpace};
use super::search::{closest_among, CpuAccelerator, Feeler, Hit};
use crate::accel::grid_frame::resolution;
use crate::accel::grid_frame::GridMapping;
use crate::accel::thesis_grid::MAX_RESOLUTION;
use crate::accel::Accel;
use crate::scene::Scene;

pub struct ThesisGrid {
    triangles: Vec<[Vec3; 3]>,
    pub space: GridSpace,
    pub mapping: GridMapping,
    /// voxelslist: the triangle ids of every voxel (ascending), at most voxel_array_length.
    pub lists: Vec<Vec<u32>>,
    /// ray_array_length: voxel ids per ray list.
    pub ray_array_length: usize,
    /// Triangle references a full voxel list dropped (`dropped_triangle_refs`).
    pub dropped: u64,
}

impl ThesisGrid {
    pub fn new(
        triangles: Vec<[Vec3; 3]>,
        n: u32,
        mapping: GridMapping,
        voxel_array_length: usize,
        ray_array_length: usize,
    ) -> ThesisGrid {
        let space = GridSpace { n };
        let mut lists = vec![Vec::new(); (n * n * n) as usize];
        let mut dropped = 0;
        for (id, t) in triangles.iter().enumerate() {
            for v in space.thesis_voxels(mapping.triangle(t)) {
                if lists[v].len() < voxel_array_length {
                    lists[v].push(id as u32);
                } else {
                    dropped += 1;
                }
            }
        }
        ThesisGrid {
            triangles,
            space,
            mapping,
            lists,
            ray_array_length,
            dropped,
        }
    }

    /// The traversal kernel (Listing 21): the non-empty voxels the ray passes up to `t_end`,
    /// in traversal order, at most ray_array_length of them.
    pub fn rayslist(&self, ro: Vec3, rd: Vec3, t_end: f32) -> Vec<usize> {
        let (rog, rdg) = (self.mapping.to_grid(ro), rd * self.mapping.scale);
        let (enter, exit) = clip_to_grid(rog, rdg);
        let (t0, t1) = (enter.max(0.0), exit.min(t_end));
        if t0 > t1 {
            return Vec::new();
        }
        let (a, b) = (rog + t0 * rdg, rog + t1 * rdg);
        let s = &self.space;
        s.traverse_connection(a, b, s.clamp(s.get_voxel(a)), s.clamp(s.get_voxel(b)))
            .into_iter()
            .filter_map(|v| s.voxel_id(v))
            .filter(|&id| !self.lists[id].is_empty())
            .take(self.ray_array_length)
            .collect()
    }
}

impl CpuAccelerator for ThesisGrid {
    fn closest_hit(&self, ro: Vec3, rd: Vec3, last: i32) -> (Option<Hit>, u64) {
        let (mut best, mut tests): (Option<Hit>, u64) = (None, 0);
        for voxel in self.rayslist(ro, rd, f32::INFINITY) {
            let ids = self.lists[voxel].iter().map(|&t| t as usize);
            closest_among(&mut best, &self.triangles, ids, (ro, rd, last), &mut tests);
            // Listing 22: a hit in this voxel discards the rest of the list
            if best.is_some() {
                break;
            }
        }
        (best, tests)
    }

    fn occluded(&self, feeler: &Feeler) -> (bool, u64) {
        let mut tests = 0;
        let blocked = self
            .rayslist(feeler.ro, feeler.rd, feeler.light_distance)
            .into_iter()
            .any(|voxel| {
                let ids = self.lists[voxel].iter().map(|&t| t as usize);
                feeler.blocked_among(&self.triangles, ids, &mut tests)
            });
        (blocked, tests)
    }
}

/// The thesis grid's twin (`design::REGISTRY`), with its resolution and list lengths.
pub fn twin(scene: &Scene, o: &Accel) -> anyhow::Result<Box<dyn CpuAccelerator>> {
    let Accel::ThesisGrid(o) = o else {
        anyhow::bail!("the thesis grid's twin made from {o:?}")
    };
    let n = resolution(scene, o.resolution, "thesis", MAX_RESOLUTION)?;
    Ok(Box::new(ThesisGrid::new(
        scene.world_triangles(),
        n,
        GridMapping::of_scene(scene),
        o.voxel_array_length as usize,
        o.ray_array_length.unwrap_or(3 * n) as usize,
    )))
}
