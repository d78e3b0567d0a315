//! The CPU twin of the SAH BVH's kernels (`glsl/bvh/`; the tree, its build and its GPU layout:
//! [`crate::accel::bvh`]): the same walks in exactly the same order with the same counts, and the
//! block entry points of `glsl/bvh/entry.comp` ([`entry`]).
//!
//! Traversal (the kernels in `glsl/bvh/traverse.glsl`, and [`BvhTree::traverse`] here, their CPU
//! twin, in exactly the same order with the same counts): stackless. A ray walks the nodes in
//! depth-first order, taking at every inner node first the child on the near side of the split
//! plane (the left unless the ray points down the split axis), and skipping a subtree by its
//! miss link when the ray misses its box or enters it beyond the current limit (the closest
//! hit so far, or the light). This is the ordered, pruned traversal of a stack walk with the
//! order decided by the split axis instead of the entry distances: on llvmpipe a
//! per-invocation stack array costs far more than a texel fetch (docs/design/bvh.md, steps 0
//! and 1).

use std::ops::ControlFlow;

use glam::Vec3;

use crate::accel::bvh::{octant_planes, BvhTree, RayGrid, OCTANTS};
use crate::accel::Accel;
use crate::reference::search::{closest_among, CpuAccelerator, Feeler, Hit};
use crate::scene::Scene;

mod entry;
mod ray;
pub use entry::{BlockEntry, RayBounds};
use ray::{octant, safe_inverse};

impl BvhTree {
    /// The shadow feeler's walk, as intersect2's: whether it is blocked, its triangle tests and
    /// its nodes visited. No hit before the offset counts, so neither do the boxes the feeler
    /// leaves before it.
    pub fn feeler_walk(&self, feeler: &Feeler) -> (bool, u64, u64) {
        let (mut blocked, mut tests) = (false, 0);
        let (ro, rd) = (feeler.ro, feeler.rd);
        let nodes = self.traverse(ro, rd, feeler.offset, feeler.light_distance, |ids| {
            let ids = ids.iter().map(|&i| i as usize);
            blocked = feeler.blocked_among(self.triangles(), ids, &mut tests);
            if blocked {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(feeler.light_distance)
            }
        });
        (blocked, tests, nodes)
    }

    /// Walk the nodes along ro + t·rd for `t_min` ≤ t ≤ `limit`, as `glsl/bvh/traverse.glsl`: every
    /// leaf whose box the ray enters goes to `leaf` (its triangle ids), which returns the new
    /// limit or breaks the walk. Returns the number of nodes visited (boxes tested).
    pub fn traverse(
        &self,
        ro: Vec3,
        rd: Vec3,
        t_min: f32,
        limit: f32,
        leaf: impl FnMut(&[u32]) -> ControlFlow<(), f32>,
    ) -> u64 {
        self.traverse_from(None, ro, rd, t_min, limit, leaf)
    }

    /// [`BvhTree::traverse`] from a block's entry point ([`BvhTree::block_entry`], intersect1's walk):
    /// a ray of the entry's octant walks the entry node's subtree only, others the whole tree.
    pub fn traverse_from(
        &self,
        entry: Option<&BlockEntry>,
        ro: Vec3,
        rd: Vec3,
        t_min: f32,
        mut limit: f32,
        mut leaf: impl FnMut(&[u32]) -> ControlFlow<(), f32>,
    ) -> u64 {
        let inv = safe_inverse(rd);
        let octant = octant(inv);
        let ray = self.grid.ray(ro, inv);
        let (mut node, stop) = entry::walk_range(entry, octant);
        let mut visited = 0u64;
        while node != stop {
            visited += 1;
            let n = &self.nodes[node as usize];
            if self.enter(node as usize, &ray, octant, t_min, limit) {
                if !n.is_leaf() {
                    // the near child first: the right one when the ray points down the axis
                    // (from the ray itself, not Node::near_child, which lays out the records
                    // the kernels walk: the twin checks it)
                    node = n.first as i32 + (inv[n.axis()] < 0.0) as i32;
                    continue;
                }
                let ids = &self.tris[n.first as usize..(n.first + n.count()) as usize];
                match leaf(ids) {
                    ControlFlow::Break(()) => return visited,
                    ControlFlow::Continue(l) => limit = l,
                }
            }
            node = self.links[OCTANTS * node as usize + octant];
        }
        visited
    }

    /// Whether the ray (of `octant`, with the grid factors `ray`) enters node `n`'s box at some
    /// `t_min` ≤ t ≤ `limit` (the slab test of Wagner 2018, Listing 4.5), bit for bit as
    /// `boxEntered` in the kernels: the box on the grid ([`BvhTree::planes`]), each slab's near
    /// plane its low bound, or its high bound where the ray points down the axis (as the records
    /// of [`BvhTree::gpu_words`] store them), its distance q·a + b rounded twice ([`RayGrid::t`]),
    /// and the largest entry and the smallest exit distance taken by integer max and min of the
    /// floats' bits. For t ≥ +0 the order of the bits is the order of the floats; the entry distance is
    /// at least `t_min` ≥ +0, and where an exit distance is negative so is the smallest of the
    /// bits — the box is missed either way (an exit at exactly −0.0 too, a box the ray leaves at
    /// its origin). No distance is NaN: 1/rd is finite ([`safe_inverse`]) and so are a and b.
    fn enter(&self, n: usize, ray: &RayGrid, octant: usize, t_min: f32, limit: f32) -> bool {
        let [near, far] = octant_planes(&self.planes[n], octant);
        let (near, far) = (ray.t(near), ray.t(far));
        let t_near = near.iter().fold(t_min.to_bits() as i32, |m, &t| m.max(t));
        let t_far = far.iter().fold(limit.to_bits() as i32, |m, &t| m.min(t));
        t_near <= t_far
    }
}

impl CpuAccelerator for BvhTree {
    fn closest_hit(&self, ro: Vec3, rd: Vec3, last: i32) -> (Option<Hit>, u64) {
        let (mut best, mut tests): (Option<Hit>, u64) = (None, 0);
        self.traverse(ro, rd, 0.0, f32::INFINITY, |ids| {
            let ids = ids.iter().map(|&i| i as usize);
            closest_among(&mut best, self.triangles(), ids, (ro, rd, last), &mut tests);
            ControlFlow::Continue(best.map_or(f32::INFINITY, |b| b.t))
        });
        (best, tests)
    }

    fn occluded(&self, feeler: &Feeler) -> (bool, u64) {
        let (blocked, tests, _) = self.feeler_walk(feeler);
        (blocked, tests)
    }
}

/// The SAH BVH's twin (`design::REGISTRY`): one tree over the world-space scene, whatever its
/// variant (the fused pass counts as the four kernels; the two levels find the same hits,
/// their counts are the instances' own: `tests/bvh_instances.rs`).
pub fn twin(scene: &Scene, _: &Accel) -> anyhow::Result<Box<dyn CpuAccelerator>> {
    Ok(Box::new(BvhTree::new(scene.world_triangles())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::tree::tests::soup;

    #[test]
    fn traversal_finds_the_brute_force_hits() {
        let tris = soup();
        let bvh = BvhTree::new(tris.clone());
        let brute = super::super::brute_force::BruteForce::new(tris);
        let ro = Vec3::new(-2.0, 5.0, 5.0);
        let (mut hits, mut fewer) = (0, 0);
        for k in 0..400 {
            let a = k as f32 * 0.013;
            let rd = Vec3::new(1.0, (a * 3.1).sin() * 0.5, (a * 1.7).cos() * 0.5).normalize();
            let (b, bt) = bvh.closest_hit(ro, rd, -1);
            let (f, ft) = brute.closest_hit(ro, rd, -1);
            assert_eq!(b.map(|h| (h.id, h.t)), f.map(|h| (h.id, h.t)), "ray {k}");
            hits += b.is_some() as u32;
            fewer += (bt < ft / 10) as u32;
            let feeler = Feeler {
                ro,
                rd,
                light_distance: 6.0,
                offset: 0.0,
                last: -1,
            };
            assert_eq!(
                bvh.occluded(&feeler).0,
                brute.occluded(&feeler).0,
                "feeler {k}"
            );
        }
        assert!(
            hits > 50 && fewer == 400,
            "{hits} hits, {fewer} with few tests"
        );
    }
}
