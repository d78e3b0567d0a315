//! Entry points per block of rays — ours, not in Wagner 2018: the idea of Reshetov, Soupikov
//! and Hurley's multi-level ray tracing (MLRTA, SIGGRAPH 2005), which starts a beam's rays
//! below the root, at the deepest node whose siblings on the way down the beam misses. The
//! CPU twin of `glsl/bvh/entry.comp`, bit for bit.
//!
//! A block is the 8×8 pixels of one work group of intersect1 ([`BLOCK`]). Its active rays,
//! where they share one octant, are bounded per axis by the smallest and largest origin
//! coordinate and 1/direction ([`RayBounds`]; a block whose rays point up and down an axis has
//! no entry). From the root of that octant's walk the search goes down while the bounds can
//! enter only one child of the node ([`RayBounds::may_enter`]): every ray of the bounds misses
//! the other child's box, so its walk would visit that subtree's root, skip it and find nothing
//! there. Where both children may be entered (or at a leaf) the search stops: the block's rays
//! walk that node's subtree only — its records from the node on, up to its miss link — and the
//! hits are those of a walk from the root, as each ray's own tests would have skipped every box
//! the search left out. Only the nodes visited are fewer. (A walk checks the entry's octant
//! against its ray's, as the kernel does; a ray of another octant walks from its root.)

use glam::Vec3;

use super::ray::{octant, safe_divisor};
use crate::accel::bvh::{octant_planes, BvhTree, BLOCK, END, GRID_STEPS, OCTANTS};

/// The rays of a block (all of one octant), bounded per axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayBounds {
    pub octant: usize,
    pub inv_lo: Vec3,
    pub inv_hi: Vec3,
    pub ro_lo: Vec3,
    pub ro_hi: Vec3,
}

impl RayBounds {
    /// The bounds of the rays (origin, direction); `None` without a ray, or if they point up
    /// and down one axis (more than one octant). As the kernel: per axis the smallest and
    /// largest divisor of `safe_inverse`, whose inverses bound the rays' 1/rd exactly (1/x
    /// falls on either side of 0, and rounding keeps the order).
    pub fn of(rays: impl IntoIterator<Item = (Vec3, Vec3)>) -> Option<RayBounds> {
        let (mut d_lo, mut d_hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let (mut ro_lo, mut ro_hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for (ro, rd) in rays {
            let d = safe_divisor(rd);
            (d_lo, d_hi) = (d_lo.min(d), d_hi.max(d));
            (ro_lo, ro_hi) = (ro_lo.min(ro), ro_hi.max(ro));
        }
        let one_octant = (d_lo * d_hi.signum()).cmpge(Vec3::ZERO).all();
        (d_lo.x <= d_hi.x && one_octant).then(|| RayBounds {
            octant: octant(d_lo),
            inv_lo: d_hi.recip(),
            inv_hi: d_lo.recip(),
            ro_lo,
            ro_hi,
        })
    }

    /// May a ray of the bounds enter the box of `planes` (from t = 0 on)? `false` only where,
    /// bounding each slab's entry and exit distances over the bounds' origins and directions
    /// by interval products and widening them by a margin, the latest entry comes after the
    /// earliest exit (or the exit before 0).
    ///
    /// The margin, per axis, in world units: 4 grid steps and 2^-18 of the magnitudes of the
    /// grid's extent, its origin and the rays' origins, in distance at the bounds' largest
    /// |1/d|. A ray's own test (`boxEntered`, [`RayGrid::t`](crate::accel::bvh::RayGrid::t)) and these bounds
    /// each err by a few roundings of those magnitudes (about 2^-22 of them), so a box refused
    /// here is refused by the test of every ray of the bounds too; and being more than a step
    /// away from the box, no ray hits a triangle in it (the boxes hold their triangles).
    pub fn may_enter(&self, bvh: &BvhTree, planes: [[u16; 3]; 2]) -> bool {
        let g = &bvh.grid;
        let q = |p: [u16; 3]| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        let ro_size = self.ro_lo.abs().max(self.ro_hi.abs());
        let scale = g.origin.abs() + g.step * GRID_STEPS as f32 + ro_size;
        let margin =
            (g.step * 4.0 + scale * (-18f32).exp2()) * self.inv_lo.abs().max(self.inv_hi.abs());
        // the distances to the planes at world coordinates w, bounded over the rays
        let range = |w: Vec3| {
            let (p0, p1) = (w - self.ro_hi, w - self.ro_lo);
            let c = [
                p0 * self.inv_lo,
                p0 * self.inv_hi,
                p1 * self.inv_lo,
                p1 * self.inv_hi,
            ];
            (
                c[0].min(c[1]).min(c[2].min(c[3])),
                c[0].max(c[1]).max(c[2].max(c[3])),
            )
        };
        let near = range(g.origin + q(planes[0]) * g.step).0 - margin;
        let far = range(g.origin + q(planes[1]) * g.step).1 + margin;
        let t_near = near.max_element().max(0.0);
        let t_far = far.min_element();
        !(t_far < 0.0 || t_near > t_far)
    }
}

/// Where the walks of a block's rays (of `octant`) start (`node`) and stop (`stop`: the first
/// node after the start's subtree, the start's miss link; `node == stop`: no walk).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockEntry {
    pub octant: usize,
    pub node: i32,
    pub stop: i32,
}

impl BvhTree {
    /// The entry point of rays bounded by `bounds`, as `glsl/bvh/entry.comp` finds it.
    pub fn block_entry(&self, bounds: &RayBounds) -> BlockEntry {
        let o = bounds.octant;
        let enters = |n: u32| bounds.may_enter(self, octant_planes(&self.planes[n as usize], o));
        let link = |n: u32| self.links[OCTANTS * n as usize + o];
        let empty = |n: u32| BlockEntry {
            octant: o,
            node: link(n),
            stop: link(n),
        };
        let mut n = 0u32;
        if !enters(n) {
            return empty(n);
        }
        while !self.nodes[n as usize].is_leaf() {
            let node = &self.nodes[n as usize];
            let (near, far) = (node.near_child(o), node.far_child(o));
            n = match (enters(near), enters(far)) {
                (true, true) => break,
                (true, false) => near,
                (false, true) => far,
                (false, false) => return empty(n),
            };
        }
        BlockEntry {
            octant: o,
            node: n as i32,
            stop: link(n),
        }
    }

    /// The entry point of every block of a `width`×`height` image, blocks row by row from the
    /// low corner (GL's order: [`block_of`](crate::accel::bvh::block_of)), each from the rays
    /// `ray(x, y)` of its active pixels (`None`: no ray); `None` for a block without a ray or with
    /// rays of more than one octant.
    pub fn block_entries(
        &self,
        (width, height): (u32, u32),
        ray: impl Fn(u32, u32) -> Option<(Vec3, Vec3)>,
    ) -> Vec<Option<BlockEntry>> {
        let (bw, bh) = (width.div_ceil(BLOCK), height.div_ceil(BLOCK));
        (0..bw * bh)
            .map(|b| {
                let (x0, y0) = (b % bw * BLOCK, b / bw * BLOCK);
                let pixels = (0..BLOCK * BLOCK)
                    .map(|k| (x0 + k % BLOCK, y0 + k / BLOCK))
                    .filter(|&(x, y)| x < width && y < height);
                RayBounds::of(pixels.filter_map(|(x, y)| ray(x, y)))
                    .map(|bounds| self.block_entry(&bounds))
            })
            .collect()
    }
}

/// Where a ray of `octant` walks from, and where it stops: `entry`'s node and stop if it is of
/// the entry's octant, else the root and [`END`].
pub(super) fn walk_range(entry: Option<&BlockEntry>, octant: usize) -> (i32, i32) {
    match entry {
        Some(e) if e.octant == octant => (e.node, e.stop),
        _ => (0, END),
    }
}

#[cfg(test)]
mod tests {
    use std::ops::ControlFlow;

    use super::*;
    use crate::reference::closest_among;

    /// The closest hit (id, t) of a walk from `entry`, and the nodes it visited.
    fn walk(
        bvh: &BvhTree,
        entry: Option<&BlockEntry>,
        (ro, rd): (Vec3, Vec3),
    ) -> (Option<(usize, f32)>, u64) {
        let (mut best, mut tests) = (None, 0);
        let nodes = bvh.traverse_from(entry, ro, rd, 0.0, f32::INFINITY, |ids| {
            let ids = ids.iter().map(|&i| i as usize);
            closest_among(&mut best, bvh.triangles(), ids, (ro, rd, -1), &mut tests);
            ControlFlow::Continue(best.map_or(f32::INFINITY, |b| b.t))
        });
        (best.map(|b| (b.id, b.t)), nodes)
    }

    /// Every ray of every block walked from the block's entry and from the root: the same hit,
    /// never more nodes. Returns the nodes visited both ways, the empty entries and the blocks
    /// without an entry (rays of more than one octant).
    fn check(
        bvh: &BvhTree,
        size: (u32, u32),
        ray: impl Fn(u32, u32) -> Option<(Vec3, Vec3)>,
    ) -> [u64; 4] {
        let entries = bvh.block_entries(size, &ray);
        let bw = size.0.div_ceil(BLOCK);
        let mut out = [0u64; 4];
        for (b, entry) in entries.iter().enumerate() {
            let (x0, y0) = (b as u32 % bw * BLOCK, b as u32 / bw * BLOCK);
            for (x, y) in (y0..y0 + BLOCK).flat_map(|y| (x0..x0 + BLOCK).map(move |x| (x, y))) {
                let Some(r) = (x < size.0 && y < size.1).then(|| ray(x, y)).flatten() else {
                    continue;
                };
                let (hit, nodes) = walk(bvh, entry.as_ref(), r);
                let (root_hit, root_nodes) = walk(bvh, None, r);
                assert_eq!(hit, root_hit, "pixel ({x}, {y}), entry {entry:?}");
                assert!(nodes <= root_nodes, "pixel ({x}, {y})");
                out[0] += nodes;
                out[1] += root_nodes;
            }
            match entry {
                Some(e) => out[2] += (e.node == e.stop) as u64,
                None => out[3] += 1,
            }
        }
        out
    }

    /// A pinhole camera at `eye` looking along +z, 60° wide, over a w×h image (GL's order).
    fn camera(eye: Vec3, (w, h): (u32, u32)) -> impl Fn(u32, u32) -> Option<(Vec3, Vec3)> {
        move |x, y| {
            let s = |p: u32, n: u32| ((p as f32 + 0.5) / n as f32 * 2.0 - 1.0) * 0.58;
            Some((
                eye,
                Vec3::new(s(x, w) * w as f32 / h as f32, s(y, h), 1.0).normalize(),
            ))
        }
    }

    #[test]
    fn block_entries_keep_every_hit_and_skip_nodes() {
        let bvh = BvhTree::new(crate::accel::bvh::tree::tests::soup());
        // the soup fills [0, 10.3]³: a camera in front of it, its image's edges beside it, and
        // the rays' x and y turning sign at the image's middle (blocks of two octants there)
        let size = (52, 36);
        let [nodes, root_nodes, empty, mixed] =
            check(&bvh, size, camera(Vec3::new(5.0, 5.0, -25.0), size));
        assert!(
            nodes * 10 < root_nodes * 9,
            "{nodes} nodes against {root_nodes} from the root"
        );
        assert!(empty > 0, "blocks whose rays all miss the root");
        assert!(mixed > 0, "blocks of two octants, no entry");
        // rays of one octant from points all over the soup, every block its own 64 (as
        // reflection rays come): the hits stay
        let mut s = 99u32;
        let mut rnd = move || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1u32 << 24) as f32
        };
        let rays: Vec<(Vec3, Vec3)> = (0..16 * 16)
            .map(|_| {
                let ro = Vec3::new(rnd(), rnd(), rnd()) * 10.0;
                (ro, Vec3::new(rnd() + 0.01, rnd() + 0.01, rnd() + 0.01))
            })
            .collect();
        let [_, _, _, mixed] = check(&bvh, (16, 16), |x, y| Some(rays[(16 * y + x) as usize]));
        assert_eq!(mixed, 0);
    }
}
