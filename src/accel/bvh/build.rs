//! The binned SAH build of [`super::BvhTree`] (Wald 2007, Wagner's [13]; the cost of eq. 4.1).
//!
//! Every node bins its triangles' centroids into [`BINS`] bins per axis (as many as it has
//! triangles when they are fewer), all three axes in one
//! pass, and the partition that follows the split also measures both children (bounds and
//! centroid bounds), so every node reads its triangles twice. The triangles are partitioned
//! in place (bounds and id together, in SIMD boxes, so every pass reads memory in order).
//! Large nodes bin in parallel chunks, and subtrees above [`PARALLEL_BUILD`] triangles build
//! their children in parallel (rayon). The result does not depend on the number of threads.

use glam::{Vec3, Vec3A};
use rayon::prelude::*;

use super::layout::{Aabb, BvhStats, Node, BINS, LEAF_SIZE, MAX_LEAF, PARALLEL_BUILD, SAH_DEPTH};

/// Nodes of more triangles bin in parallel chunks of [`BIN_CHUNK`].
const PARALLEL_BINNING: usize = 1 << 15;
const BIN_CHUNK: usize = 1 << 13;

/// A box in SIMD registers (the build's own; the tree keeps [`Aabb`]).
#[derive(Clone, Copy)]
struct Bx {
    lo: Vec3A,
    hi: Vec3A,
}

impl Bx {
    const EMPTY: Bx = Bx {
        lo: Vec3A::splat(f32::INFINITY),
        hi: Vec3A::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, o: &Bx) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
    }

    fn grow_point(&mut self, p: Vec3A) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    fn half_area(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    fn aabb(&self) -> Aabb {
        Aabb {
            lo: self.lo.into(),
            hi: self.hi.into(),
        }
    }
}

/// What the build knows of a triangle: its bounds, widened by a margin (see [`prims_of`]),
/// and its id.
#[derive(Clone, Copy)]
struct Prim {
    bounds: Bx,
    id: u32,
}

impl Prim {
    /// The centre of its bounds, times 2.
    fn centroid2(&self) -> Vec3A {
        self.bounds.lo + self.bounds.hi
    }
}

/// A subtree before it is laid out.
pub(super) enum Tree {
    Leaf {
        bounds: Aabb,
        start: usize,
        count: usize,
    },
    Inner {
        bounds: Aabb,
        axis: usize,
        children: Box<[Tree; 2]>,
    },
}

impl Tree {
    pub(super) fn bounds(&self) -> &Aabb {
        match self {
            Tree::Leaf { bounds, .. } | Tree::Inner { bounds, .. } => bounds,
        }
    }
}

/// Triangles binned together: their bounds and their number.
#[derive(Clone, Copy)]
struct Bin {
    bounds: Bx,
    count: usize,
}

impl Bin {
    const EMPTY: Bin = Bin {
        bounds: Bx::EMPTY,
        count: 0,
    };

    fn merge(&mut self, o: &Bin) {
        self.bounds.grow(&o.bounds);
        self.count += o.count;
    }

    /// eq. 4.1 for one side: half surface area times triangle count.
    fn cost(&self) -> f32 {
        self.bounds.half_area() * self.count as f32
    }
}

/// [`BINS`] bins per axis.
type Bins = [[Bin; BINS]; 3];

/// A node's triangles as the build sees them: their bounds, the bounds of their centroids
/// (times 2) and their number.
#[derive(Clone, Copy)]
struct Extent {
    bounds: Bx,
    centroids2: Bx,
    count: usize,
}

impl Extent {
    fn of(prims: &[Prim]) -> Extent {
        let (mut bounds, mut centroids2) = (Bx::EMPTY, Bx::EMPTY);
        for p in prims {
            bounds.grow(&p.bounds);
            centroids2.grow_point(p.centroid2());
        }
        Extent {
            bounds,
            centroids2,
            count: prims.len(),
        }
    }

    fn cost(&self) -> f32 {
        self.bounds.half_area() * self.count as f32
    }
}

/// How centroids map to bins on each axis: bin = (2·centroid − lo) · scale.
#[derive(Clone, Copy)]
struct Binning {
    lo: Vec3A,
    scale: Vec3A,
    /// bins per axis: [`BINS`], or as many as triangles in a smaller node
    bins: usize,
}

impl Binning {
    /// `count` triangles over the (doubled) centroid bounds `c`; an axis without extent gets
    /// scale 0 (one bin).
    fn over(c: &Bx, count: usize) -> Binning {
        let bins = count.clamp(2, BINS);
        let extent = c.hi - c.lo;
        let scale = |e: f32| {
            if e > 0.0 && e.is_finite() {
                bins as f32 / e
            } else {
                0.0
            }
        };
        Binning {
            lo: c.lo,
            scale: Vec3A::new(scale(extent.x), scale(extent.y), scale(extent.z)),
            bins,
        }
    }

    /// The bins of `p` on the three axes.
    fn bins(&self, p: &Prim) -> [usize; 3] {
        let b = (p.centroid2() - self.lo) * self.scale;
        [b.x, b.y, b.z].map(|f| (f as usize).min(self.bins - 1))
    }

    fn bin_serial(&self, prims: &[Prim]) -> Bins {
        let mut bins = [[Bin::EMPTY; BINS]; 3];
        for p in prims {
            for (axis, k) in self.bins(p).into_iter().enumerate() {
                let b = &mut bins[axis][k];
                b.bounds.grow(&p.bounds);
                b.count += 1;
            }
        }
        bins
    }

    fn bin_all(&self, prims: &[Prim]) -> Bins {
        if prims.len() < PARALLEL_BINNING {
            return self.bin_serial(prims);
        }
        prims
            .par_chunks(BIN_CHUNK)
            .map(|c| self.bin_serial(c))
            .reduce(
                || [[Bin::EMPTY; BINS]; 3],
                |mut a, b| {
                    for (x, y) in a.iter_mut().flatten().zip(b.iter().flatten()) {
                        x.merge(y);
                    }
                    a
                },
            )
    }
}

/// A split: the axis, the number of bins left of the plane and the cost.
struct Split {
    axis: usize,
    bins_left: usize,
    cost: f32,
}

/// The cheapest split of the bins by eq. 4.1, if any separates the triangles.
fn best_split(bins: &Bins, binning: &Binning) -> Option<Split> {
    let mut best: Option<Split> = None;
    for (axis, bins) in bins.iter().enumerate() {
        if binning.scale[axis] == 0.0 {
            continue;
        }
        // right-to-left sweep: the cost of every right side
        let mut right = [(0.0f32, 0usize); BINS];
        let mut acc = Bin::EMPTY;
        for k in (1..binning.bins).rev() {
            acc.merge(&bins[k]);
            right[k] = (acc.cost(), acc.count);
        }
        let mut left = Bin::EMPTY;
        for k in 1..binning.bins {
            left.merge(&bins[k - 1]);
            if left.count == 0 || right[k].1 == 0 {
                continue;
            }
            let cost = left.cost() + right[k].0;
            if best.as_ref().is_none_or(|b| cost < b.cost) {
                best = Some(Split {
                    axis,
                    bins_left: k,
                    cost,
                });
            }
        }
    }
    best
}

/// Bounds of every triangle, in id order. The bounds are widened by a small margin relative
/// to the scene so that rounding in the slab test (and ulp differences of the GPU's
/// transformed vertices) never loses a triangle that touches its box.
fn prims_of(triangles: &[[Vec3; 3]]) -> Vec<Prim> {
    let pad = Vec3A::splat(pad(triangles));
    triangles
        .par_iter()
        .enumerate()
        .map(|(id, t)| {
            let mut b = Bx::EMPTY;
            t.iter().for_each(|&p| b.grow_point(p.into()));
            Prim {
                bounds: Bx {
                    lo: b.lo - pad,
                    hi: b.hi + pad,
                },
                id: id as u32,
            }
        })
        .collect()
}

/// The margin every triangle's bounds are widened by ([`prims_of`]): 10^-5 of the scene's
/// extent (its largest side or coordinate). The GPU refit widens by the last build's margin
/// (`accel::bvh::refit`).
pub(super) fn pad(triangles: &[[Vec3; 3]]) -> f32 {
    let mut scene = Aabb::EMPTY;
    for t in triangles {
        t.iter().for_each(|&p| scene.grow_point(p));
    }
    let extent = (scene.hi - scene.lo)
        .max_element()
        .max(scene.hi.abs().max_element());
    1e-5 * extent.max(1e-20)
}

/// Build the hierarchy over `triangles`; the tree and the triangle ids in leaf order.
pub(super) fn build(triangles: &[[Vec3; 3]]) -> (Tree, Vec<u32>) {
    let mut prims = prims_of(triangles);
    let all = Extent::of(&prims);
    let tree = subtree(&mut prims, 0, all, 0);
    (tree, prims.iter().map(|p| p.id).collect())
}

/// Build the subtree over `prims` (which start at `offset` in leaf order; `node` is their
/// extent).
fn subtree(prims: &mut [Prim], offset: usize, node: Extent, depth: u32) -> Tree {
    let leaf = Tree::Leaf {
        bounds: node.bounds.aabb(),
        start: offset,
        count: prims.len(),
    };
    if prims.len() <= LEAF_SIZE {
        return leaf;
    }
    let (mid, axis, sides) = if depth < SAH_DEPTH {
        let binning = Binning::over(&node.centroids2, prims.len());
        match best_split(&binning.bin_all(prims), &binning) {
            // Listing 4.4: split only where it pays (unless the node is too large for a leaf)
            Some(s) if s.cost < node.cost() || prims.len() > MAX_LEAF => {
                let (mid, sides) = partition(prims, |p| binning.bins(p)[s.axis] < s.bins_left);
                (mid, s.axis, sides)
            }
            Some(_) => return leaf,
            None if prims.len() <= MAX_LEAF => return leaf,
            // no binned split separates them: halve in centroid order
            None => median(prims, &node.centroids2),
        }
    } else {
        median(prims, &node.centroids2)
    };
    let (left, right) = prims.split_at_mut(mid);
    let [l, r] = sides;
    let (l, r) = if left.len() + right.len() > PARALLEL_BUILD {
        rayon::join(
            || subtree(left, offset, l, depth + 1),
            || subtree(right, offset + mid, r, depth + 1),
        )
    } else {
        (
            subtree(left, offset, l, depth + 1),
            subtree(right, offset + mid, r, depth + 1),
        )
    };
    Tree::Inner {
        bounds: node.bounds.aabb(),
        axis,
        children: Box::new([l, r]),
    }
}

/// Reorder `prims` so that those for which `left` holds come first; their number and the
/// extents of both sides (measured as each triangle is classified, once).
fn partition(prims: &mut [Prim], left: impl Fn(&Prim) -> bool) -> (usize, [Extent; 2]) {
    let (mut i, mut j) = (0, prims.len());
    let mut sides = [Bx::EMPTY, Bx::EMPTY, Bx::EMPTY, Bx::EMPTY];
    while i < j {
        let p = prims[i];
        let side = if left(&p) {
            i += 1;
            0
        } else {
            j -= 1;
            prims.swap(i, j);
            2
        };
        sides[side].grow(&p.bounds);
        sides[side + 1].grow_point(p.centroid2());
    }
    let extent = |k: usize, count| Extent {
        bounds: sides[k],
        centroids2: sides[k + 1],
        count,
    };
    (i, [extent(0, i), extent(2, prims.len() - i)])
}

/// Sort `prims` by centroid on the widest centroid axis (then by id); the middle, the axis
/// and the extents of both halves.
fn median(prims: &mut [Prim], centroids2: &Bx) -> (usize, usize, [Extent; 2]) {
    let d = centroids2.hi - centroids2.lo;
    let axis = if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    };
    prims.sort_unstable_by(|a, b| {
        (a.centroid2()[axis].total_cmp(&b.centroid2()[axis])).then(a.id.cmp(&b.id))
    });
    let mid = prims.len() / 2;
    let (l, r) = prims.split_at(mid);
    (mid, axis, [Extent::of(l), Extent::of(r)])
}

/// Write `tree` into `nodes[index]`, its children into two adjacent new nodes.
pub(super) fn layout(tree: &Tree, index: usize, nodes: &mut Vec<Node>) {
    let b = tree.bounds();
    let (lo, hi) = (b.lo.to_array(), b.hi.to_array());
    match tree {
        Tree::Leaf { start, count, .. } => {
            nodes[index] = Node {
                lo,
                first: *start as u32,
                hi,
                meta: *count as i32,
            };
        }
        Tree::Inner { children, axis, .. } => {
            let first = nodes.len();
            nodes.extend([<Node as bytemuck::Zeroable>::zeroed(); 2]);
            nodes[index] = Node {
                lo,
                first: first as u32,
                hi,
                meta: -1 - *axis as i32,
            };
            layout(&children[0], first, nodes);
            layout(&children[1], first + 1, nodes);
        }
    }
}

/// Add the SAH cost and the depth of `tree` to `stats`.
pub(super) fn measure(tree: &Tree, depth: u32, root_area: f64, stats: &mut BvhStats) {
    let rel = if root_area > 0.0 {
        tree.bounds().half_area() as f64 / root_area
    } else {
        1.0
    };
    match tree {
        Tree::Leaf { count, .. } => {
            stats.sah_cost += rel * *count as f64;
            stats.depth = stats.depth.max(depth);
        }
        Tree::Inner { children, .. } => {
            stats.sah_cost += rel;
            for c in children.iter() {
                measure(c, depth + 1, root_area, stats);
            }
        }
    }
}
