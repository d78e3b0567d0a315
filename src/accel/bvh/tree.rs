//! The SAH BVH as built and uploaded: [`BvhTree::new`] builds the tree over a list of
//! triangles ([`build`]: the binned SAH), its boxes on the grid ([`planes`]) and its miss
//! links, and [`BvhTree::gpu_words`] writes it in the layout of [`layout`]'s records.

use bytemuck::Zeroable;
use glam::Vec3;

use super::build;
use super::layout::{
    Aabb, BvhStats, Header, LeafTriangle, Node, NodeRecord, END, HEADER_WORDS, LEAF_COUNT_BITS,
    NODE_WORDS, OCTANTS, TRIANGLE_WORDS,
};
use super::planes::{Grid, Planes};

/// The hierarchy over a list of triangles, as built and uploaded (its kernels' CPU twin:
/// `reference::bvh`).
pub struct BvhTree {
    pub(super) triangles: Vec<[Vec3; 3]>,
    pub nodes: Vec<Node>,
    /// Miss links: `links[OCTANTS * n + octant]` is where a ray of that octant goes on after
    /// node n ([`END`]: nowhere).
    pub links: Vec<i32>,
    /// Triangle ids in leaf order.
    pub tris: Vec<u32>,
    /// The grid over the root's box on which the records store the boxes.
    pub grid: Grid,
    /// Every node's box on the grid, as the kernels and [`BvhTree::traverse`] test it.
    pub planes: Vec<Planes>,
    pub stats: BvhStats,
    /// The margin of every triangle's bounds in the node boxes (`build::pad`): 10^-5 of the
    /// extent of the scene it was built over, kept by a refit ([`BvhTree::refit`]).
    pub pad: f32,
}

impl BvhTree {
    /// Build the hierarchy over `triangles` (triangle id = index).
    pub fn new(triangles: Vec<[Vec3; 3]>) -> BvhTree {
        let start = std::time::Instant::now();
        let pad = build::pad(&triangles);
        let (tree, ids) = build::build(&triangles);
        let mut nodes = vec![Node::zeroed()];
        build::layout(&tree, 0, &mut nodes);
        let links = miss_links(&nodes);
        let grid = Grid::over(&Aabb {
            lo: nodes[0].lo.into(),
            hi: nodes[0].hi.into(),
        });
        let planes = {
            use rayon::prelude::*;
            nodes.par_iter().map(|n| grid.planes(n)).collect()
        };
        let mut stats = BvhStats {
            nodes: nodes.len(),
            leaves: nodes.iter().filter(|n| n.is_leaf()).count(),
            bytes: 4 * (triangle_base(nodes.len()) + TRIANGLE_WORDS * ids.len()),
            ..BvhStats::default()
        };
        build::measure(&tree, 0, tree.bounds().half_area() as f64, &mut stats);
        stats.build_ms = start.elapsed().as_secs_f64() * 1e3;
        BvhTree {
            triangles,
            nodes,
            links,
            tris: ids,
            grid,
            planes,
            stats,
            pad,
        }
    }

    /// The hierarchy as uploaded: one buffer of 32-bit words read as texels of 4 words
    /// (`glsl/bvh/traverse.glsl`):
    /// - a [`Header`];
    /// - for each octant o = 0..8, from texel [`BvhTree::root_texel`] on, a [`NodeRecord`] of
    ///   each of the N nodes in the depth-first order of that octant (the order of
    ///   [`BvhTree::links`]: the near child of every split first). An inner node's near child is
    ///   the next record; a leaf's miss link is always the next record (the octant's depth-first
    ///   order goes on there after a subtree of one);
    /// - from word [`BvhTree::triangle_base`] on, a [`LeafTriangle`] per entry of
    ///   [`BvhTree::tris`].
    ///
    /// (s < 2^26 always in a leaf's `reference`: `TextureBuffer::new` refuses a buffer of 2^31
    /// bytes, and each entry takes 48.)
    pub fn gpu_words(&self) -> Vec<u32> {
        use rayon::prelude::*;
        let n = self.nodes.len();
        let mut out = vec![0u32; self.stats.bytes / 4];
        let (head, rest) = out.split_at_mut(HEADER_WORDS);
        let (octants, triangles) = rest.split_at_mut(OCTANTS * NODE_WORDS * n);
        bytemuck::cast_slice_mut::<u32, Header>(head)[0] = Header {
            node_count: n as u32,
            grid_origin: self.grid.origin.to_array(),
            grid_step: self.grid.step.to_array(),
            zero: 0,
        };
        bytemuck::cast_slice_mut::<u32, NodeRecord>(octants)
            .par_chunks_mut(n)
            .enumerate()
            .for_each(|(o, records)| self.octant_records(o, records));
        bytemuck::cast_slice_mut::<u32, LeafTriangle>(triangles)
            .par_iter_mut()
            .zip(self.tris.par_iter())
            .for_each(|(t, &id)| {
                let [v0, v1, v2] = self.triangles[id as usize];
                *t = LeafTriangle {
                    v0: v0.to_array(),
                    id,
                    edge1: (v1 - v0).to_array(),
                    zero1: 0,
                    edge2: (v2 - v0).to_array(),
                    zero2: 0,
                };
            });
        out
    }

    /// The nodes in the depth-first order of octant `o` (its records' order in
    /// [`BvhTree::gpu_words`]), from its miss links: after an inner node its near child, after a
    /// leaf (a subtree of one) its miss link.
    fn octant_order(&self, o: usize) -> Vec<u32> {
        let mut order = Vec::with_capacity(self.nodes.len());
        let mut k = 0i32;
        while k != END {
            order.push(k as u32);
            let node = &self.nodes[k as usize];
            k = match node.is_leaf() {
                true => self.links[OCTANTS * k as usize + o],
                false => node.near_child(o) as i32,
            };
        }
        order
    }

    /// The texel of every node's record in octant `o`'s copy ([`BvhTree::gpu_words`]), and after
    /// them the texel after the copy (where [`END`] points).
    pub fn record_texels(&self, o: usize) -> Vec<u32> {
        self.texels_in_order(o, &self.octant_order(o))
    }

    /// [`BvhTree::record_texels`] of octant `o`, whose order is `order`.
    fn texels_in_order(&self, o: usize, order: &[u32]) -> Vec<u32> {
        let base = self.root_texel(o);
        let mut record = vec![0u32; self.nodes.len() + 1];
        for (i, &k) in order.iter().enumerate() {
            record[k as usize] = (base + i) as u32;
        }
        record[self.nodes.len()] = (base + self.nodes.len()) as u32;
        record
    }

    /// The node records of octant `o` ([`BvhTree::gpu_words`]) into `out`.
    pub(crate) fn octant_records(&self, o: usize, out: &mut [NodeRecord]) {
        let order = self.octant_order(o);
        let record = self.texels_in_order(o, &order);
        let end = record[self.nodes.len()];
        for (r, &k) in out.iter_mut().zip(&order) {
            let node = &self.nodes[k as usize];
            debug_assert!(node.first < 1 << (31 - LEAF_COUNT_BITS), "see gpu_words");
            let [near, far] = octant_planes(&self.planes[k as usize], o);
            let reference = match (node.is_leaf(), self.links[OCTANTS * k as usize + o]) {
                (true, _) => -1 - ((node.first << LEAF_COUNT_BITS | node.count()) as i32),
                (false, END) => end as i32,
                (false, l) => record[l as usize] as i32,
            };
            *r = NodeRecord {
                near,
                far,
                reference,
            };
        }
    }

    /// The texel index of the root's record in octant `o`'s copy of the nodes
    /// ([`BvhTree::gpu_words`]).
    pub fn root_texel(&self, o: usize) -> usize {
        (HEADER_WORDS + o * self.nodes.len() * NODE_WORDS) / 4
    }

    /// The word address of the first leaf triangle in [`BvhTree::gpu_words`].
    pub fn triangle_base(&self) -> usize {
        triangle_base(self.nodes.len())
    }

    /// The triangles it was built over.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }
}

/// The word address of the first leaf triangle in [`BvhTree::gpu_words`] of `n` nodes: after the
/// header and the octants' records.
fn triangle_base(n: usize) -> usize {
    HEADER_WORDS + OCTANTS * NODE_WORDS * n
}

/// A box's near and far planes (step counts x, y, z) for rays of `octant`: per axis the low
/// plane is the near one, unless the rays point down the axis.
pub fn octant_planes(q: &Planes, octant: usize) -> [[u16; 3]; 2] {
    let (mut near, mut far) = ([q[0], q[1], q[2]], [q[3], q[4], q[5]]);
    for a in 0..3 {
        if (octant >> a) & 1 == 1 {
            std::mem::swap(&mut near[a], &mut far[a]);
        }
    }
    [near, far]
}

/// The miss links of every node for every octant (`links[OCTANTS·n + o]`): the depth-first
/// order of octant o (every node before its subtree, the near child's subtree before the far
/// child's) continues after a node's subtree at its miss link, [`END`] after the last. The
/// near child's miss link is the far child, the far child's its parent's — in one pass down
/// the nodes, as [`build::layout`] places every node's children after it.
fn miss_links(nodes: &[Node]) -> Vec<i32> {
    let mut links = vec![END; OCTANTS * nodes.len()];
    for (k, node) in nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
        debug_assert!(node.first as usize > k, "children after their parent");
        for o in 0..OCTANTS {
            let (near, far) = (node.near_child(o) as usize, node.far_child(o) as usize);
            links[OCTANTS * near + o] = far as i32;
            links[OCTANTS * far + o] = links[OCTANTS * k + o];
        }
    }
    links
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::accel::bvh::layout::{MAX_DEPTH, MAX_LEAF};

    /// A small deterministic triangle soup: a jittered grid of triangles, a few duplicates
    /// (equal centroids) and a long sliver.
    pub(crate) fn soup() -> Vec<[Vec3; 3]> {
        let mut out = Vec::new();
        let mut s = 12345u32;
        let mut rnd = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1u32 << 24) as f32
        };
        for _ in 0..3000 {
            let c = Vec3::new(rnd(), rnd(), rnd()) * 10.0;
            let e = 0.3;
            out.push([
                c,
                c + Vec3::new(rnd() * e, rnd() * e, 0.0),
                c + Vec3::new(0.0, rnd() * e, rnd() * e),
            ]);
        }
        let dup = out[7];
        out.extend(std::iter::repeat_n(dup, 40));
        out.push([
            Vec3::ZERO,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(10.0, 0.01, 0.0),
        ]);
        out
    }

    #[test]
    fn every_triangle_in_exactly_one_leaf_and_bounds_nest() {
        let tris = soup();
        let bvh = BvhTree::new(tris.clone());
        let mut seen = vec![0u32; tris.len()];
        for n in &bvh.nodes {
            let nb = Aabb {
                lo: Vec3::from(n.lo),
                hi: Vec3::from(n.hi),
            };
            if n.is_leaf() {
                assert!(n.count() as usize <= MAX_LEAF);
                for &t in &bvh.tris[n.first as usize..(n.first + n.count()) as usize] {
                    seen[t as usize] += 1;
                    for p in tris[t as usize] {
                        assert!(nb.contains(&Aabb { lo: p, hi: p }), "triangle {t} outside");
                    }
                }
            } else {
                for c in [n.first, n.first + 1] {
                    let c = &bvh.nodes[c as usize];
                    let cb = Aabb {
                        lo: Vec3::from(c.lo),
                        hi: Vec3::from(c.hi),
                    };
                    assert!(nb.contains(&cb), "child outside its parent");
                }
            }
        }
        assert!(seen.iter().all(|&k| k == 1), "every triangle exactly once");
        // every node but the root is some inner node's child, exactly once
        let mut parents = vec![0u32; bvh.nodes.len()];
        for n in bvh.nodes.iter().filter(|n| !n.is_leaf()) {
            parents[n.first as usize] += 1;
            parents[n.first as usize + 1] += 1;
        }
        assert_eq!(parents[0], 0);
        assert!(parents[1..].iter().all(|&p| p == 1));
        let s = bvh.stats;
        assert_eq!(s.nodes, 2 * s.leaves - 1);
        assert!(s.depth <= MAX_DEPTH, "depth {}", s.depth);
        // far better than one leaf of everything
        assert!(
            s.sah_cost > 1.0 && s.sah_cost < tris.len() as f64 / 20.0,
            "{s:?}"
        );
    }

    #[test]
    fn gpu_words_hold_every_node_and_leaf_triangle_at_its_address() {
        let bvh = BvhTree::new(soup());
        let words = bvh.gpu_words();
        let n = bvh.nodes.len();
        let base = HEADER_WORDS + OCTANTS * NODE_WORDS * n;
        assert_eq!(bvh.triangle_base(), base);
        assert_eq!(words.len(), base + TRIANGLE_WORDS * bvh.tris.len());
        assert_eq!(4 * words.len(), bvh.stats.bytes);
        let f = |w: &[u32]| Vec3::from_array([0, 1, 2].map(|k| f32::from_bits(w[k])));
        assert_eq!((words[0], f(&words[1..4])), (n as u32, bvh.grid.origin));
        assert_eq!((f(&words[4..7]), words[7]), (bvh.grid.step, 0));
        for octant in 0..OCTANTS {
            // the octant's records, near child right after its parent: each node's texel
            let mut at = vec![usize::MAX; n];
            let root = HEADER_WORDS / 4 + octant * n;
            let mut next = root;
            let mut todo = vec![0usize];
            while let Some(k) = todo.pop() {
                at[k] = next;
                next += 1;
                let node = &bvh.nodes[k];
                if !node.is_leaf() {
                    let near = node.first as usize + ((octant >> node.axis()) & 1);
                    todo.push(2 * node.first as usize + 1 - near);
                    todo.push(near);
                }
            }
            assert_eq!(next, root + n);
            assert_eq!(bvh.root_texel(octant), root);
            for (k, node) in bvh.nodes.iter().enumerate() {
                let w = &words[4 * at[k]..4 * at[k] + NODE_WORDS];
                // the planes where rays of the octant enter and leave the slabs, 16 bits each
                let q = bvh.planes[k];
                let (lo, hi) = ([q[0], q[1], q[2]], [q[3], q[4], q[5]]);
                let down = |a: usize| (octant >> a) & 1 == 1;
                let near = [0, 1, 2].map(|a| if down(a) { hi[a] } else { lo[a] } as u32);
                let far = [0, 1, 2].map(|a| if down(a) { lo[a] } else { hi[a] } as u32);
                let halves = w[..3].iter().flat_map(|&x| [x & 0xffff, x >> 16]);
                assert_eq!(halves.collect::<Vec<_>>(), [near, far].concat());
                if !node.is_leaf() {
                    // the miss link: the texel of the octant's next record after the subtree
                    let want = match bvh.links[OCTANTS * k + octant] {
                        END => root + n,
                        link => at[link as usize],
                    };
                    assert_eq!(w[3], want as u32, "miss link of node {k}, octant {octant}");
                    continue;
                }
                // a leaf's miss link is the next record
                assert_eq!(
                    bvh.links[OCTANTS * k + octant],
                    at.iter()
                        .position(|&t| t == at[k] + 1)
                        .map_or(END, |l| l as i32)
                );
                // the leaf's triangles: v0, id, edge1, 0, edge2, 0 each
                let reference = -1 - w[3] as i32;
                let count = reference & ((1 << LEAF_COUNT_BITS) - 1);
                let first = (reference >> LEAF_COUNT_BITS) as usize;
                assert_eq!((first, count as u32), (node.first as usize, node.count()));
                for s in first..first + count as usize {
                    let t = &words[base + TRIANGLE_WORDS * s..][..TRIANGLE_WORDS];
                    let id = bvh.tris[s];
                    let [v0, v1, v2] = bvh.triangles[id as usize];
                    assert_eq!(
                        (f(&t[0..3]), t[3], f(&t[4..7]), t[7], f(&t[8..11]), t[11]),
                        (v0, id, v1 - v0, 0, v2 - v0, 0)
                    );
                }
            }
        }
    }

    #[test]
    fn miss_links_thread_every_node_once_per_octant() {
        let bvh = BvhTree::new(soup());
        for octant in 0..OCTANTS {
            // a walk that enters every box: the near child, else the miss link
            let (mut node, mut order) = (0i32, Vec::new());
            while node != END && order.len() <= bvh.nodes.len() {
                order.push(node as usize);
                let n = &bvh.nodes[node as usize];
                node = if n.is_leaf() {
                    bvh.links[OCTANTS * node as usize + octant]
                } else {
                    n.first as i32 + ((octant >> n.axis()) & 1) as i32
                };
            }
            let mut seen = order.clone();
            seen.sort_unstable();
            seen.dedup();
            assert_eq!(seen.len(), bvh.nodes.len(), "octant {octant}: every node");
            assert_eq!(order.len(), bvh.nodes.len(), "octant {octant}: once");
            // missing the root ends the walk
            assert_eq!(bvh.links[octant], END);
        }
    }
}
