//! Moving objects without a CPU rebuild — ours: the BVH's boxes refitted bottom-up on the GPU
//! every frame in which a model matrix changed, the topology of the last CPU build kept (Wald,
//! Boulos and Shirley 2007, "Ray tracing deformable scenes using dynamic bounding volume
//! hierarchies"; Kopta et al. 2012, "Fast, effective BVH updates for animated scenes"), in two
//! dispatches: the boxes bottom-up with an arrival counter per inner node (Karras 2012), then the
//! records (`glsl/bvh/refit.glsl`), and a CPU rebuild when the refitted
//! tree's SAH cost has grown past [`REBUILD_GROWTH`] times the last build's
//! (`docs/design/bvh.md`, "Moving objects").
//!
//! Where each part of [`BvhTree::gpu_words`] comes from, after a build and after a refit:
//!
//! | words | after a CPU build ([`BvhTree::new`]) | after a GPU refit | CPU twin of the refit |
//! |---|---|---|---|
//! | [`Header`](super::Header): node count | `gpu_words` | `refit_records.comp` (node 0): unchanged | — |
//! | Header: grid origin, step | `Grid::over` the root's box | `refit_records.comp` (`gridOver`, every invocation; node 0 stores it) | [`BvhTree::refit`] |
//! | [`NodeRecord`](super::NodeRecord) planes, every octant | `Grid::planes` of the built boxes | `refit_records.comp` (`axisPlanes`) of the refitted boxes | [`BvhTree::refit`] |
//! | NodeRecord `reference` (miss link, leaf triangles) | `octant_records` | `refit_records.comp`: the record's texel plus the node's subtree size, or the leaf's reference ([`Topology::of`]) | — |
//! | [`LeafTriangle`](super::LeafTriangle) v0, id, edges | `gpu_words` from the CPU's world transform | `refit_leaves.comp` from the transform pass' `vertex` SSBO | [`BvhTree::refit`] |
//! | node boxes (not uploaded) | the build, padded by `build::pad` | `refit_leaves.comp` (SSBO `REFIT_BOXES`), padded by the build's pad | [`BvhTree::refit`] |
//!
//! The block entries after the leaf triangles are `glsl/bvh/entry.comp`'s every pass, either way.

use std::sync::Arc;

use anyhow::{anyhow, Result};
use glam::Vec3;
use glow::HasContext;
use rayon::prelude::*;

use super::layout::{Aabb, Node, LEAF_COUNT_BITS, OCTANTS};
use super::planes::Grid;
use super::tree::BvhTree;
use crate::gl::resources::{bind_image_unit, GpuTimers, Owned, Ssbo};
use crate::gl::slots::{image, ssbo};
use crate::gl::{sync, Gl, Kernel};

/// Rebuild on the CPU when the refitted tree's SAH cost exceeds the last build's by this factor
/// (measured on the turning dragon and bunny: `docs/design/bvh.md`, "Moving objects").
pub const REBUILD_GROWTH: f64 = 1.3;

/// Invocations of a work group of the refit's kernels (`REFIT_GROUP`).
pub const REFIT_GROUP: u32 = 64;

/// The timer of the refit's passes, all together (`bvh_refit_ms` in the statistics).
pub const REFIT_TIMER: &str = "bvh_refit";

impl BvhTree {
    /// The CPU twin of the GPU refit: the same topology over `triangles` (moved: same count,
    /// same ids), every node's box made again bottom-up (a leaf's: its triangles' bounds widened
    /// by the build's [`BvhTree::pad`]; an inner node's: its children's union), the grid over the
    /// new root box, the planes on it, and the SAH cost of the refitted tree.
    pub fn refit(&mut self, triangles: Vec<[Vec3; 3]>) {
        assert_eq!(
            triangles.len(),
            self.triangles.len(),
            "a refit keeps the triangles"
        );
        self.triangles = triangles;
        let pad = Vec3::splat(self.pad);
        for k in (0..self.nodes.len()).rev() {
            let node = self.nodes[k];
            let b = if node.is_leaf() {
                let mut b = Aabb::EMPTY;
                let entries = node.first as usize..(node.first + node.count()) as usize;
                for &id in &self.tris[entries] {
                    self.triangles[id as usize]
                        .iter()
                        .for_each(|&p| b.grow_point(p));
                }
                Aabb {
                    lo: b.lo - pad,
                    hi: b.hi + pad,
                }
            } else {
                let mut b = aabb(&self.nodes[node.first as usize]);
                b.grow(&aabb(&self.nodes[node.first as usize + 1]));
                b
            };
            (self.nodes[k].lo, self.nodes[k].hi) = (b.lo.to_array(), b.hi.to_array());
        }
        self.grid = Grid::over(&aabb(&self.nodes[0]));
        let grid = self.grid;
        self.planes = self.nodes.par_iter().map(|n| grid.planes(n)).collect();
        self.stats.sah_cost = sah_cost(&self.nodes);
    }
}

fn aabb(n: &Node) -> Aabb {
    Aabb {
        lo: n.lo.into(),
        hi: n.hi.into(),
    }
}

/// The SAH cost of `nodes` relative to the root ([`super::BvhStats::sah_cost`]).
pub fn sah_cost(nodes: &[Node]) -> f64 {
    let root = aabb(&nodes[0]).half_area() as f64;
    let cost = |n: &Node| {
        let rel = match root > 0.0 {
            true => aabb(n).half_area() as f64 / root,
            false => 1.0,
        };
        rel * n.count().max(1) as f64
    };
    nodes.iter().map(cost).sum()
}

/// The tree's topology as the refit's kernels read it (`glsl/bvh/refit.glsl` lays the words out):
/// the nodes, their parents, the leaves, every record's texel and reference, the leaf triangles.
pub struct Topology {
    pub words: Vec<u32>,
    /// the number of leaves (the boxes pass' invocations)
    pub leaves: u32,
}

impl Topology {
    pub fn of(tree: &BvhTree) -> Topology {
        let nodes = &tree.nodes;
        let n = nodes.len();
        let mut parent = vec![u32::MAX; n];
        let mut leaves = Vec::new();
        for (k, node) in nodes.iter().enumerate() {
            match node.is_leaf() {
                true => leaves.push(k as u32),
                false => {
                    (parent[node.first as usize], parent[node.first as usize + 1]) =
                        (k as u32, k as u32)
                }
            }
        }
        let count = leaves.len() as u32;
        let mut words: Vec<u32> = nodes
            .iter()
            .flat_map(|n| [n.first, n.meta as u32])
            .collect();
        words.extend(parent);
        leaves.resize(n, 0);
        words.extend(leaves);
        let texels: Vec<Vec<u32>> = (0..OCTANTS).map(|o| tree.record_texels(o)).collect();
        words.extend((0..n).flat_map(|k| texels.iter().map(move |t| t[k])));
        words.extend(reference_words(nodes));
        words.extend(&tree.tris);
        Topology {
            words,
            leaves: count,
        }
    }
}

/// Per node, what its records' `reference` is made from in every octant's copy: a leaf's
/// reference itself (< 0, as `octant_records` makes it), an inner node's subtree size (> 0): each
/// copy lists the nodes depth first (`octant_order`), so a subtree's records are contiguous and
/// an inner node's miss link, the record after them, is its own texel plus that size.
fn reference_words(nodes: &[Node]) -> Vec<u32> {
    let mut size = vec![1u32; nodes.len()];
    // children follow their parents in `nodes` (the build's order), so sizes go bottom-up
    for k in (0..nodes.len()).rev().filter(|&k| !nodes[k].is_leaf()) {
        let c = nodes[k].first as usize;
        size[k] = 1 + size[c] + size[c + 1];
    }
    let word = |(n, s): (&Node, u32)| match n.is_leaf() {
        true => (-1 - ((n.first << LEAF_COUNT_BITS | n.count()) as i32)) as u32,
        false => s,
    };
    nodes.iter().zip(size).map(word).collect()
}

/// The refit's two kernels (`glsl/bvh/refit_*.comp`).
pub struct RefitKernels {
    pub leaves: Kernel,
    pub records: Kernel,
}

/// The refit of one build: its topology and the node boxes, on the GPU.
pub struct Refit {
    topology: Ssbo,
    boxes: Ssbo,
    /// the topology (RGBA32UI) and the boxes (RGBA32F) as image buffers for the records' pass
    /// (`refitViews`), where the GL has the units and the texels
    views: Option<[Owned<glow::Texture>; 2]>,
    /// the arrival count of every node (`glsl/bvh/refit_leaves.comp`), zeros when made
    arrivals: Ssbo,
    leaves: u32,
    nodes: u32,
    pad: f32,
}

impl Refit {
    /// The buffers of `tree`'s refit.
    /// `max_units`: the profile's compute image units, for the records' pass' views.
    pub fn new(gl: &Arc<Gl>, tree: &BvhTree, max_block: i64, max_units: i32) -> Result<Refit> {
        let t = Topology::of(tree);
        // whole texels, so that the records' pass' view holds every word it reads
        let mut padded = t.words.clone();
        padded.resize(padded.len().next_multiple_of(4), 0);
        let words = bytemuck::cast_slice(&padded);
        let n = tree.nodes.len();
        let arrivals = Ssbo::new(gl, "bvh refit arrivals", 4 * n, None, max_block)?;
        arrivals.clear_u32(gl, 0);
        let topology = Ssbo::new(
            gl,
            "bvh refit topology",
            words.len(),
            Some(words),
            max_block,
        )?;
        let boxes = Ssbo::new(gl, "bvh refit boxes", 32 * n, None, max_block)?;
        let views = match (
            topology.texel_view(gl, max_units, image::REFIT_TOPOLOGY, glow::RGBA32UI)?,
            boxes.texel_view(gl, max_units, image::REFIT_BOXES, glow::RGBA32F)?,
        ) {
            (Some(t), Some(b)) => Some([t, b]),
            _ => None,
        };
        Ok(Refit {
            topology,
            boxes,
            views,
            arrivals,
            leaves: t.leaves,
            nodes: n as u32,
            pad: tree.pad,
        })
    }

    /// Run the refit's two passes (the BVH's word buffer bound for reading and writing, the
    /// scene's `vertex` SSBO holding this frame's world-space vertices), the shader bits pending
    /// before each (`gl::sync`): the records' pass reads the boxes the boxes' pass wrote (GL 4.6
    /// §7.13). Timed together as
    /// [`REFIT_TIMER`].
    /// `words_storage`: the word buffer is bound as the storage buffer `BVH_WORDS` too (the
    /// passes store through it, else as image texels; `glsl/bvh/refit.glsl`).
    pub fn run(&self, gl: &Gl, timers: &mut GpuTimers, k: &RefitKernels, words_storage: bool) {
        self.run_leaves(gl, timers, k, words_storage, self.leaves);
    }

    /// A refit whose boxes pass covers the first `leaves` leaves only: a refit abandoned
    /// halfway, as a lost dispatch would leave it, for the tests that the next one is whole.
    #[doc(hidden)]
    pub fn run_abandoned(
        &self,
        gl: &Gl,
        timers: &mut GpuTimers,
        k: &RefitKernels,
        words_storage: bool,
    ) {
        self.run_leaves(gl, timers, k, words_storage, self.leaves / 2);
    }

    fn run_leaves(
        &self,
        gl: &Gl,
        timers: &mut GpuTimers,
        k: &RefitKernels,
        words_storage: bool,
        leaves: u32,
    ) {
        // every refit counts its arrivals from zero (glsl/bvh/refit_leaves.comp); the clear's
        // own barrier (BUFFER_UPDATE, gl::sync) orders the last refit's atomics before it
        self.arrivals.clear_u32(gl, 0);
        self.topology.bind(gl, ssbo::REFIT_TOPOLOGY);
        self.boxes.bind(gl, ssbo::REFIT_BOXES);
        self.arrivals.bind(gl, ssbo::REFIT_ARRIVALS);
        if let Some([t, b]) = &self.views {
            bind_image_unit(
                gl,
                image::REFIT_TOPOLOGY,
                t.raw(),
                glow::READ_ONLY,
                glow::RGBA32UI,
            );
            bind_image_unit(
                gl,
                image::REFIT_BOXES,
                b.raw(),
                glow::READ_ONLY,
                glow::RGBA32F,
            );
        }
        timers.time(gl, REFIT_TIMER, || {
            for (kernel, count) in [(&k.leaves, leaves), (&k.records, self.nodes)] {
                sync::before(gl, sync::SHADER);
                kernel.use_program();
                kernel.set_i32("nodeCount", self.nodes as i32);
                kernel.set_i32("orderCount", count as i32);
                kernel.set_i32("wordsStorage", words_storage as i32);
                kernel.set_i32("refitViews", self.views.is_some() as i32);
                if std::ptr::eq(kernel, &k.leaves) {
                    kernel.set_f32("pad", self.pad);
                }
                // SAFETY: dispatch of the program in use.
                unsafe { gl.dispatch_compute(count.div_ceil(REFIT_GROUP).max(1), 1, 1) };
                sync::after_pass(gl);
            }
        });
    }

    /// The SAH cost of the refitted tree (after [`Refit::run`]): the root's subtree cost over
    /// its half area, as the refit's passes found them (`glsl/bvh/refit.glsl`).
    pub fn sah_cost(&self, gl: &Gl) -> Result<f64> {
        let mut bytes = [0u8; 32];
        self.boxes.read_bytes(gl, &mut bytes);
        let f: [f32; 8] = bytemuck::cast(bytes);
        let root = Aabb {
            lo: Vec3::new(f[0], f[1], f[2]),
            hi: Vec3::new(f[4], f[5], f[6]),
        };
        let area = root.half_area() as f64;
        if !f[3].is_finite() {
            return Err(anyhow!("the refit's SAH cost is {}", f[3]));
        }
        Ok(match area > 0.0 {
            true => f[3] as f64 / area,
            false => 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::tree::tests::soup;
    use super::*;
    use glam::Mat4;

    #[test]
    fn a_refit_of_unmoved_triangles_gives_the_build_s_words() {
        let tris = soup();
        let mut bvh = BvhTree::new(tris.clone());
        let (words, cost) = (bvh.gpu_words(), bvh.stats.sah_cost);
        bvh.refit(tris);
        assert_eq!(bvh.gpu_words(), words);
        assert!((bvh.stats.sah_cost - cost).abs() < 1e-9 * cost, "{cost}");
    }

    #[test]
    fn a_refit_holds_every_moved_triangle_in_its_leaves_boxes() {
        let tris = soup();
        let mut bvh = BvhTree::new(tris.clone());
        let turn = Mat4::from_rotation_y(0.7) * Mat4::from_rotation_x(0.3);
        let moved: Vec<_> = tris
            .iter()
            .map(|t| t.map(|p| turn.transform_point3(p)))
            .collect();
        bvh.refit(moved.clone());
        for n in &bvh.nodes {
            let q = bvh.grid.planes(n);
            let b = aabb(n);
            let on_grid = |p: Vec3| {
                (0..3).all(|a| {
                    bvh.grid.plane(a, q[a]) <= p[a] as f64
                        && p[a] as f64 <= bvh.grid.plane(a, q[3 + a])
                })
            };
            let entries = n.first as usize..(n.first + n.count()) as usize;
            for &id in bvh.tris.get(entries).filter(|_| n.is_leaf()).unwrap_or(&[]) {
                for p in moved[id as usize] {
                    assert!(b.contains(&Aabb { lo: p, hi: p }) && on_grid(p));
                }
            }
        }
        // the build's boxes, turned, are looser than a fresh build's over the turned triangles
        assert!(bvh.stats.sah_cost > BvhTree::new(moved).stats.sah_cost);
    }

    #[test]
    fn the_topology_names_every_node_s_parent_every_leaf_and_every_record() {
        let bvh = BvhTree::new(soup());
        let t = Topology::of(&bvh);
        let n = bvh.nodes.len();
        let parent = &t.words[2 * n..3 * n];
        assert_eq!(parent[0], u32::MAX, "the root has none");
        for (k, node) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
            let c = node.first as usize;
            assert_eq!((parent[c], parent[c + 1]), (k as u32, k as u32));
        }
        let mut leaves = t.words[3 * n..3 * n + t.leaves as usize].to_vec();
        leaves.sort_unstable();
        let want: Vec<u32> = (0..n as u32)
            .filter(|&k| bvh.nodes[k as usize].is_leaf())
            .collect();
        assert_eq!(leaves, want);
        let words = bvh.gpu_words();
        for k in 0..n {
            for o in 0..OCTANTS {
                let texel = t.words[4 * n + OCTANTS * k + o];
                assert_eq!(texel, bvh.record_texels(o)[k]);
                // as recordReference in glsl/bvh/refit.glsl makes it
                let word = t.words[12 * n + k];
                let reference = match (word as i32) < 0 {
                    true => word,
                    false => texel + word,
                };
                let want = words[4 * texel as usize + 3];
                assert_eq!(reference, want, "node {k}, octant {o}");
            }
        }
        assert_eq!(&t.words[13 * n..], &bvh.tris[..]);
    }
}
