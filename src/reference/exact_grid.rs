//! CPU twin of the exact grid (`accel::exact_grid`, `glsl/exact_grid/`): triangles registered
//! in every voxel their triangle/box overlap test accepts, rays walked with a 3D-DDA that ends
//! only at a hit inside the current voxel (`glsl/exact_grid/intersect1.comp`), shadow feelers
//! walked to the first occluder (`intersect2.comp`).

use glam::Vec3;

use super::grid::{GridMapping, GridSpace, Walk};
use super::{closest_among, CpuAccelerator, Feeler, Hit};

pub struct ExactGrid {
    triangles: Vec<[Vec3; 3]>,
    pub space: GridSpace,
    pub mapping: GridMapping,
    /// The triangle ids of every voxel, ascending.
    pub lists: Vec<Vec<u32>>,
}

impl ExactGrid {
    /// The grid of `n`³ voxels over `triangles` (scene space) with `mapping`.
    pub fn new(triangles: Vec<[Vec3; 3]>, n: u32, mapping: GridMapping) -> ExactGrid {
        let space = GridSpace { n };
        let mut lists = vec![Vec::new(); (n * n * n) as usize];
        for (id, t) in triangles.iter().enumerate() {
            for v in space.exact_voxels(mapping.triangle(t)) {
                lists[v].push(id as u32);
            }
        }
        ExactGrid {
            triangles,
            space,
            mapping,
            lists,
        }
    }

    /// Call `visit` with the triangle list of every voxel the ray passes up to `t_end`, in
    /// order, until it returns true; `visit` gets the voxel's exit parameter.
    fn walk(&self, ro: Vec3, rd: Vec3, t_end: f32, mut visit: impl FnMut(&[u32], f32) -> bool) {
        let (rog, rdg) = (self.mapping.to_grid(ro), rd * self.mapping.scale);
        let Some(mut w) = Walk::begin(&self.space, rog, rdg, t_end) else {
            return;
        };
        loop {
            let id = self.space.voxel_id(w.voxel).expect("the walk stays inside");
            if visit(&self.lists[id], w.exit()) || !w.step(&self.space) {
                return;
            }
        }
    }
}

impl CpuAccelerator for ExactGrid {
    fn closest_hit(&self, ro: Vec3, rd: Vec3, last: i32) -> (Option<Hit>, u64) {
        let (mut best, mut tests): (Option<Hit>, u64) = (None, 0);
        self.walk(ro, rd, f32::INFINITY, |list, exit| {
            let ids = list.iter().map(|&t| t as usize);
            closest_among(&mut best, &self.triangles, ids, (ro, rd, last), &mut tests);
            // a hit inside this voxel is the closest
            best.is_some_and(|b| b.t <= exit)
        });
        (best, tests)
    }

    fn occluded(&self, feeler: &Feeler) -> (bool, u64) {
        let (mut blocked, mut tests) = (false, 0);
        self.walk(feeler.ro, feeler.rd, feeler.light_distance, |list, _| {
            let ids = list.iter().map(|&t| t as usize);
            blocked = feeler.blocked_among(&self.triangles, ids, &mut tests);
            blocked
        });
        (blocked, tests)
    }
}
