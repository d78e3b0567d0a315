//! Wagner 2018's bounding volume hierarchy (B.Sc. thesis, ch. 3.2, 4.2.1, 4.2.2), built on the
//! CPU exactly as Listings 4.3 (`RecursiveBuild`) and 4.4 (`FindBestSplit`) with the
//! simplified SAH of eq. 4.1, and laid out as the three textures of Fig. 4.3. GPU-free; the
//! GPU side is `pipeline::wagner2018`, the traversal's CPU twin `reference::wagner2018`.
//!
//! ```text
//! SAH(AABB) = (xdim·ydim + ydim·zdim + zdim·xdim) · t          (eq. 4.1, t: triangles inside)
//! RecursiveBuild(list): bounds; count < 4 → Leaf; FindBestSplit; no better split → Leaf;
//!                       LeftChild = RecursiveBuild(left); RightChild = RecursiveBuild(right)
//! FindBestSplit(list):  minimumCost = SAH(list); per axis split(list, distance):
//!                       SAH(left) + SAH(right) < minimumCost → remember, else increase distance
//! ```
//!
//! Where the listings leave a choice, we chose (also in `docs/wagner2018.md`):
//! - **`distance`** is the distance of the split plane from the node's minimum along the axis,
//!   and a triangle's box goes left when its centre (centroid of the box) lies below the plane.
//!   **"increase distance"** moves the plane to the next box centre along the axis: every
//!   distinct centre coordinate is tried once, from the lowest up, so each step moves one
//!   group of equal centres from the right list to the left one. (A fixed step would leave
//!   the step size unspecified; this is the finest step that changes the lists.)
//! - **"remember split"** keeps the split and lowers `minimumCost` to its cost, and the search
//!   goes on (every distance of every axis is tried; X, then Y, then Z). So the split kept is
//!   the one of least cost, the first such on a tie. Read literally, the listing steps the
//!   distance only after a failure, i.e. stops an axis at the first split that beats the
//!   node: that split is almost always the first one (one triangle off the node's edge), and
//!   the tree becomes a list of depth ≈ n; we do not read it so.
//! - **"no better split"**: no split's SAH(left) + SAH(right) is below the node's own SAH
//!   (eq. 4.1 over the whole list); also when all centres coincide (no plane separates them).
//!   Such a node is a leaf however many triangles it holds (Listing 4.3, line 9).
//! - `split(list, distance)` builds both lists per distance, which makes the listing quadratic
//!   in the list length (one reason, we think, for the thesis' five-minute build over 100k
//!   triangles, ch. 5.1). We sort the list by centre once per axis and sweep the distances with
//!   running bounds: the same candidates, the same costs (bounds are min/max, exact in any
//!   order), the same tree, in O(n log n) per node.
//! - Guard: the recursion is refused beyond [`MAX_DEPTH`] levels (the kernel's traversal stack),
//!   with an error naming the limit; no input can blow the host's stack or run unbounded.
//!
//! Layout (Fig. 4.3): nodes in depth-first order (a node's left child follows it), texture 1:
//! two RGBA32F texels per node, the box's centre and half extent (Listing 4.5 takes the box as
//! centre `ac` and half extents `h`); texture 2: one RGBA32I texel per node, (1, first, count,
//! 0) for a leaf — its triangles are `first..first + count` of texture 3 — or (0, left child,
//! right child, 0); texture 3: one R32I texel per triangle id, grouped per leaf. Each layout is
//! a `#[repr(C)]` record ([`BoundsTexels`], [`NodeTexel`], [`TriangleTexel`]), named with its
//! fields in `glsl/wagner2018/raytrace.comp`.

use std::time::Instant;

use anyhow::{bail, Result};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

pub use crate::accel::aabb::Aabb;

/// Listing 4.3, line 5: a list of fewer boxes than this is a leaf.
pub const LEAF_BELOW: usize = 4;
/// The deepest node (the root at depth 0) a build may make: the traversal keeps at most one
/// node per level on its stack (`WAGNER_STACK` in `glsl/wagner2018/raytrace.comp`). A deeper
/// tree is refused.
pub const MAX_DEPTH: u32 = 64;

/// Centre and half extent as the kernel's box (Listing 4.5's `ac` and `h`), in f32, the
/// half extent rounded up until centre ± half covers the box: the box the GPU tests is
/// never smaller than the bounds of its triangles.
pub fn centre_half(b: &Aabb) -> (Vec3, Vec3) {
    let c = 0.5 * (b.lo + b.hi);
    let mut h = 0.5 * (b.hi - b.lo);
    for a in 0..3 {
        while c[a] - h[a] > b.lo[a] || c[a] + h[a] < b.hi[a] {
            h[a] = h[a].next_up();
        }
    }
    (c, h)
}

/// A node of the hierarchy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// The bounds of its triangles (`vmin`, `vmax` of Listing 4.3).
    pub bounds: Aabb,
    /// The box as texture 1 holds it and both traversals test it: centre and half extent.
    pub centre: Vec3,
    pub half: Vec3,
    pub kind: NodeKind,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeKind {
    /// Children by node index (the left one is the next node).
    Inner { left: u32, right: u32 },
    /// Triangles `first..first + count` of [`WagnerBvh::tri_ids`].
    Leaf { first: u32, count: u32 },
}

/// The facts of a build, for the statistics.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WagnerStats {
    pub nodes: usize,
    pub leaves: usize,
    /// The deepest node (root: 0).
    pub depth: u32,
    /// The largest leaf (triangles).
    pub max_leaf: usize,
    /// SAH cost relative to the root: Σ inner A(n)/A(root) + Σ leaves A(l)/A(root)·N(l), as
    /// the SAH BVH reports it (A: surface area).
    pub sah_cost: f64,
    /// Bytes of the three textures of Fig. 4.3.
    pub bytes: usize,
    /// The build on the CPU (Listings 4.3, 4.4), in milliseconds.
    pub build_ms: f64,
}

/// The hierarchy over a list of triangles (triangle id = index).
#[derive(Debug, Clone)]
pub struct WagnerBvh {
    pub triangles: Vec<[Vec3; 3]>,
    pub nodes: Vec<Node>,
    /// Triangle ids grouped per leaf (texture 3).
    pub tri_ids: Vec<u32>,
    pub stats: WagnerStats,
}

/// What the build knows of each triangle: its box and the box's centre.
struct Builder {
    boxes: Vec<Aabb>,
    centres: Vec<Vec3>,
    nodes: Vec<Node>,
    tri_ids: Vec<u32>,
    depth: u32,
    max_depth: u32,
}

/// A split found by Listing 4.4: the axis, and how many boxes (in centre order) go left.
#[derive(Debug, Clone, Copy)]
struct Split {
    axis: usize,
    left: usize,
    cost: f64,
}

impl WagnerBvh {
    /// Build the hierarchy over `triangles` (Listing 4.3 from the whole list). Refused with
    /// an error beyond [`MAX_DEPTH`] levels.
    pub fn build(triangles: Vec<[Vec3; 3]>) -> Result<WagnerBvh> {
        Self::build_limited(triangles, MAX_DEPTH)
    }

    /// [`WagnerBvh::build`], refused beyond `max_depth` levels (at most [`MAX_DEPTH`]).
    pub fn build_limited(triangles: Vec<[Vec3; 3]>, max_depth: u32) -> Result<WagnerBvh> {
        let start = Instant::now();
        let boxes: Vec<Aabb> = triangles.iter().map(Aabb::of_triangle).collect();
        let mut b = Builder {
            centres: boxes.iter().map(|b| 0.5 * (b.lo + b.hi)).collect(),
            boxes,
            nodes: Vec::new(),
            tri_ids: Vec::with_capacity(triangles.len()),
            depth: 0,
            max_depth: max_depth.min(MAX_DEPTH),
        };
        let mut list: Vec<u32> = (0..triangles.len() as u32).collect();
        if !list.is_empty() {
            b.recursive_build(&mut list, 0)?;
        }
        let stats = b.stats(start);
        Ok(WagnerBvh {
            triangles,
            nodes: b.nodes,
            tri_ids: b.tri_ids,
            stats,
        })
    }

    /// Texture 1: every node's box, in node order.
    pub fn bounds_texels(&self) -> Vec<BoundsTexels> {
        self.nodes
            .iter()
            .map(|n| BoundsTexels {
                centre: n.centre.to_array(),
                centre_w: 0.0,
                half: n.half.to_array(),
                half_w: 0.0,
            })
            .collect()
    }

    /// Texture 2: every node's kind and links, in node order.
    pub fn node_texels(&self) -> Vec<NodeTexel> {
        self.nodes
            .iter()
            .map(|n| match n.kind {
                NodeKind::Inner { left, right } => NodeTexel {
                    leaf: 0,
                    left_or_first: left as i32,
                    right_or_count: right as i32,
                    unused: 0,
                },
                NodeKind::Leaf { first, count } => NodeTexel {
                    leaf: 1,
                    left_or_first: first as i32,
                    right_or_count: count as i32,
                    unused: 0,
                },
            })
            .collect()
    }

    /// Texture 3: the triangle ids, grouped per leaf.
    pub fn triangle_texels(&self) -> Vec<TriangleTexel> {
        self.tri_ids
            .iter()
            .map(|&id| TriangleTexel { id: id as i32 })
            .collect()
    }
}

/// A node's two texels of texture 1 (`bvhBounds`, RGBA32F): its box as Listing 4.5 takes it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct BoundsTexels {
    /// texel 2·node, xyz: the box's centre (`ac`)
    pub centre: [f32; 3],
    /// texel 2·node, w: 0
    pub centre_w: f32,
    /// texel 2·node + 1, xyz: its half extent (`h`), rounded up ([`centre_half`])
    pub half: [f32; 3],
    /// texel 2·node + 1, w: 0
    pub half_w: f32,
}
const _: () = assert!(size_of::<BoundsTexels>() == 32);

/// A node's texel of texture 2 (`bvhNodes`, RGBA32I).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct NodeTexel {
    /// x: 1 for a leaf, 0 for an inner node
    pub leaf: i32,
    /// y: an inner node's left child, a leaf's first triangle in texture 3
    pub left_or_first: i32,
    /// z: an inner node's right child, a leaf's triangle count
    pub right_or_count: i32,
    /// w: 0
    pub unused: i32,
}
const _: () = assert!(size_of::<NodeTexel>() == 16);

/// A texel of texture 3 (`bvhTriangles`, R32I).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct TriangleTexel {
    /// x: a triangle id (its texels in `triVertices`, `triNormals`, `triColors`: 3·id..3·id + 3)
    pub id: i32,
}
const _: () = assert!(size_of::<TriangleTexel>() == 4);

impl Builder {
    /// Listing 4.3: the node of `list` and, recursively, its children; returns its index.
    fn recursive_build(&mut self, list: &mut [u32], depth: u32) -> Result<u32> {
        if depth > self.max_depth {
            bail!(
                "Wagner 2018's BVH (Listings 4.3, 4.4) gets deeper than {} levels (MAX_DEPTH; \
                 the kernel's traversal stack holds {MAX_DEPTH}): this scene's triangles do not \
                 split well by eq. 4.1 — use --bvh-variant sah",
                self.max_depth
            );
        }
        self.depth = self.depth.max(depth);
        let mut bounds = Aabb::EMPTY; // vmin, vmax
        for &i in list.iter() {
            bounds.grow(&self.boxes[i as usize]);
        }
        let index = self.nodes.len() as u32;
        let (centre, half) = centre_half(&bounds);
        self.nodes.push(Node {
            bounds,
            centre,
            half,
            kind: NodeKind::Leaf { first: 0, count: 0 },
        });
        let split = match list.len() < LEAF_BELOW {
            true => None,
            false => self.find_best_split(list, &bounds),
        };
        let Some(split) = split else {
            self.nodes[index as usize].kind = NodeKind::Leaf {
                first: self.tri_ids.len() as u32,
                count: list.len() as u32,
            };
            self.tri_ids.extend_from_slice(list);
            return Ok(index);
        };
        self.sort_by_centre(list, split.axis);
        let (left_list, right_list) = list.split_at_mut(split.left);
        let left = self.recursive_build(left_list, depth + 1)?;
        let right = self.recursive_build(right_list, depth + 1)?;
        self.nodes[index as usize].kind = NodeKind::Inner { left, right };
        Ok(index)
    }

    /// Listing 4.4: the split of least SAH(left) + SAH(right) below SAH(list), over every
    /// distance of every axis; `None`: no better split.
    fn find_best_split(&self, list: &mut [u32], bounds: &Aabb) -> Option<Split> {
        let mut minimum_cost = bounds.half_area_f64() * list.len() as f64;
        let mut best = None;
        for axis in 0..3 {
            self.sort_by_centre(list, axis);
            if let Some(s) = self.sweep(list, axis, minimum_cost) {
                minimum_cost = s.cost;
                best = Some(s);
            }
        }
        best
    }

    /// One axis of Listing 4.4: the plane from the lowest box centre up, past one distinct
    /// centre at a time ("increase distance"); the cheapest split below `minimum_cost`.
    fn sweep(&self, sorted: &[u32], axis: usize, minimum_cost: f64) -> Option<Split> {
        let n = sorted.len();
        // SAH of every right list, from the right end
        let mut right = vec![0.0f64; n];
        let mut acc = Aabb::EMPTY;
        for k in (1..n).rev() {
            acc.grow(&self.boxes[sorted[k] as usize]);
            right[k] = acc.half_area_f64() * (n - k) as f64;
        }
        let mut best: Option<Split> = None;
        let mut left = Aabb::EMPTY;
        for k in 1..n {
            left.grow(&self.boxes[sorted[k - 1] as usize]);
            let (below, at) = (
                self.centres[sorted[k - 1] as usize][axis],
                self.centres[sorted[k] as usize][axis],
            );
            // a plane between equal centres separates nothing
            if at <= below {
                continue;
            }
            let cost = left.half_area_f64() * k as f64 + right[k];
            if cost < best.map_or(minimum_cost, |b| b.cost) {
                best = Some(Split {
                    axis,
                    left: k,
                    cost,
                });
            }
        }
        best
    }

    /// Sort by box centre along `axis` (ties by triangle id: the same order every time).
    fn sort_by_centre(&self, list: &mut [u32], axis: usize) {
        let c = &self.centres;
        list.sort_unstable_by(|&a, &b| {
            c[a as usize][axis]
                .total_cmp(&c[b as usize][axis])
                .then(a.cmp(&b))
        });
    }

    fn stats(&self, start: Instant) -> WagnerStats {
        let root_area = self.nodes.first().map_or(0.0, |n| n.bounds.half_area_f64());
        let mut s = WagnerStats {
            nodes: self.nodes.len(),
            depth: self.depth,
            bytes: self.nodes.len() * (32 + 16) + 4 * self.tri_ids.len(),
            ..WagnerStats::default()
        };
        for n in &self.nodes {
            let area = if root_area > 0.0 {
                n.bounds.half_area_f64() / root_area
            } else {
                1.0
            };
            match n.kind {
                NodeKind::Inner { .. } => s.sah_cost += area,
                NodeKind::Leaf { count, .. } => {
                    s.leaves += 1;
                    s.max_leaf = s.max_leaf.max(count as usize);
                    s.sah_cost += area * count as f64;
                }
            }
        }
        s.build_ms = start.elapsed().as_secs_f64() * 1e3;
        s
    }
}
