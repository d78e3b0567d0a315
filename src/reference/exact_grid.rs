//! CPU twin of the exact grid (`accel::exact_grid`, `glsl/exact_grid/`): triangles registered
//! in every voxel their triangle/box overlap test accepts, rays walked with a 3D-DDA that ends
//! only at a hit inside the current voxel (`glsl/exact_grid/intersect1.comp`), shadow feelers
//! walked to the first occluder (`intersect2.comp`); with proximity clouds
//! (`--proximity-clouds`, `glsl/exact_grid/proximity.comp`) an empty voxel at distance ≥ 2 is
//! left by a jump (`Walk::jump`), as the kernels' stepWalk does.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use glam::Vec3;

use super::grid::{GridSpace, Walk};
use super::proximity::cells_between;
use super::search::{closest_among, CpuAccelerator, Feeler, Hit};
use crate::accel::exact_grid::EXACT_GRID_CLOUD_CAP;
use crate::accel::exact_grid::MAX_RESOLUTION;
use crate::accel::grid_frame::resolution;
use crate::accel::grid_frame::GridMapping;
use crate::accel::proximity::chebyshev_distances;
use crate::accel::Accel;
use crate::scene::Scene;

/// The walks' counts, summed over every ray traced (shared with whoever reads them, as the
/// GPU's counters are): voxels entered (`voxels_visited`), proximity-cloud jumps
/// (`cloud_jumps`) and the voxels they passed over (`empty_cells_skipped`).
#[derive(Debug, Default)]
pub struct WalkTally {
    pub visited: AtomicU64,
    pub jumps: AtomicU64,
    pub skipped: AtomicU64,
}

impl WalkTally {
    /// (visited, jumps, skipped) so far.
    pub fn get(&self) -> (u64, u64, u64) {
        let l = |a: &AtomicU64| a.load(Ordering::Relaxed);
        (l(&self.visited), l(&self.jumps), l(&self.skipped))
    }
}

pub struct ExactGrid {
    triangles: Vec<[Vec3; 3]>,
    pub space: GridSpace,
    pub mapping: GridMapping,
    /// The triangle ids of every voxel, ascending.
    pub lists: Vec<Vec<u32>>,
    /// Proximity-cloud distances per voxel, when the walks jump (`with_proximity`).
    pub proximity: Option<Vec<u32>>,
    pub tally: Arc<WalkTally>,
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
            proximity: None,
            tally: Arc::default(),
        }
    }

    /// The distances of the voxels to the nearest non-empty one, at most
    /// [`EXACT_GRID_CLOUD_CAP`] (`proximity.comp`'s result).
    pub fn distances(&self) -> Vec<u32> {
        let filled: Vec<bool> = self.lists.iter().map(|l| !l.is_empty()).collect();
        let n = self.space.n;
        let d = chebyshev_distances(glam::UVec3::splat(n), &filled);
        d.into_iter().map(|d| d.min(EXACT_GRID_CLOUD_CAP)).collect()
    }

    /// Walk with proximity-cloud jumps.
    pub fn with_proximity(mut self) -> ExactGrid {
        self.proximity = Some(self.distances());
        self
    }

    /// stepWalk with its jump: out of an empty voxel at distance ≥ 2 by a jump, else one
    /// step; false when the walk has ended.
    fn advance(&self, w: &mut Walk, id: usize) -> bool {
        let dist = self.proximity.as_ref().map_or(0, |p| p[id]);
        if w.exit() > w.t_end() {
            return false;
        }
        if self.lists[id].is_empty() && dist >= 2 {
            self.tally.jumps.fetch_add(1, Ordering::Relaxed);
            let from = w.voxel;
            let landed = w.jump(&self.space, dist);
            if landed {
                let skipped = cells_between(from, w.voxel);
                self.tally.skipped.fetch_add(skipped, Ordering::Relaxed);
            }
            return landed;
        }
        w.step(&self.space)
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
            self.tally.visited.fetch_add(1, Ordering::Relaxed);
            if visit(&self.lists[id], w.exit()) || !self.advance(&mut w, id) {
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

/// The exact grid's twin (`design::REGISTRY`), with its resolution and proximity clouds.
pub fn twin(scene: &Scene, o: &Accel) -> anyhow::Result<Box<dyn CpuAccelerator>> {
    let Accel::ExactGrid(o) = o else {
        anyhow::bail!("the exact grid's twin made from {o:?}")
    };
    let n = resolution(scene, o.resolution, "exact", MAX_RESOLUTION)?;
    let g = ExactGrid::new(scene.world_triangles(), n, GridMapping::of_scene(scene));
    Ok(Box::new(match o.proximity_clouds {
        true => g.with_proximity(),
        false => g,
    }))
}
