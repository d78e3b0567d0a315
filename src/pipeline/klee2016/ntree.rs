//! The N-tree with a line space per inner node — Klee 2016, ch. 3.3 and 4.2 (Fig. 4, 5, 8, 9,
//! Listing 3), after Keul et al. \[KLM\].
//!
//! * **N-tree**: an octree with N cells per axis (N = 10 in the thesis). Levels: the root (level
//!   0), its N³ children (level 1), ..., the leaves at level `depth − 1`, which store triangles.
//!   `depth = 3` (reading A of the thesis' "maximale Tiefe von 3") therefore gives a root,
//!   inner nodes of size 1/N and leaves of size 1/N² of the scene cube; only the line spaces
//!   of level 1 are ever asked (the traversal starts at the root's children), so there is no
//!   cascade. Reading B takes the thesis' own numbering, "Tiefe null ist die Tiefe der Kinder
//!   des Wurzelknotens" (ch. 4.3.1): depths 0, 1, 2 below the root, i.e. `depth = 4` here,
//!   leaves of 1/N³ and line spaces asked at levels 1 and 2 (the cascade). `depth` counts
//!   levels with the root (`--ntree-depth`), so old inputs keep their meaning.
//! * **Node pool** (Fig. 8–9): groups of N³ nodes, group 0 the children of the root. A node is
//!   two u32 (red, green): red bit 0 = geometry, bit 1 = children, bits 2.. = the group of
//!   its children; green = the index of its line space in the line-space pool. A leaf (geometry,
//!   no children) keeps its triangle list instead: red bits 2.. = offset into `leaf_triangles`,
//!   green = count (ours: the thesis does not say how its leaves reference triangles).
//! * **Line space** (Fig. 4–5): for every pair of boundary cells (N×N per side, 6 sides) on
//!   different sides of the node, one bit: set when a child with geometry lies in the shaft
//!   between them (the convex hull of the two cells). Symmetric entries are stored once: the
//!   15 pairs of sides s < e, each N²×N² bits, `entry = pair(s, e)·N⁴ + cell_s·N² + cell_e`
//!   (150000 bits, 4688 u32 for N = 10; the thesis' own array had all 360000 entries).
//! * **Packing** (Listing 3): the bits 32 to a u32 in a 3D R32UI texture, a line space's
//!   words along x, continued on the next y row, line spaces one after the other along y,
//!   continued along z, at most 2048 (GL_MAX_3D_TEXTURE_SIZE) per axis.

use crate::scene::budget;
use anyhow::{bail, Result};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Red-channel flag: the node contains geometry.
pub const GEOMETRY_BIT: u32 = 1;
/// Red-channel flag: the node has children (a child group).
pub const CHILDREN_BIT: u32 = 2;

pub use super::shaft::{
    entry_index, face_axes, face_rect, linespace_entries, linespace_words, pair_index,
    shaft_hits_box, shaft_hits_cell, Aabb, FACES, FACE_PAIRS,
};

/// The boxes of the filled ones of N³ children (index x + N(y + Nz)), in index order.
fn filled_cells(n: u32, filled: &[bool]) -> Vec<Aabb> {
    let nn = n as usize;
    (0..nn * nn * nn)
        .filter(|&i| filled[i])
        .map(|i| {
            Aabb::cell(
                (i % nn) as u32,
                ((i / nn) % nn) as u32,
                (i / (nn * nn)) as u32,
            )
        })
        .collect()
}

/// The line space of a node from the geometry flags of its N³ children (index x + N(y + Nz)):
/// one bit per pair of boundary cells, 32 to a word. Hierarchical: a shaft between two
/// rectangles of cells contains the shafts of all pairs of cells in them, so a child that
/// misses the big shaft misses all the small ones; the rectangles are halved until single
/// cells remain (the thesis ORs one mask per filled child, Fig. 5 — the bits are the same).
pub fn build_linespace(n: u32, filled: &[bool]) -> Vec<u32> {
    let children = filled_cells(n, filled);
    let mut words = vec![0u32; linespace_words(n)];
    if children.is_empty() {
        return words;
    }
    let mut scratch: Vec<u32> = (0..children.len() as u32).collect();
    for s in 0..FACES {
        for e in s + 1..FACES {
            let full = [0, n, 0, n];
            subdivide(
                n,
                s,
                e,
                full,
                full,
                &children,
                &mut scratch,
                0,
                children.len(),
                &mut words,
            );
        }
    }
    words
}

/// One step of [`build_linespace`]: the candidates (children that may lie in the shaft of the
/// rectangles `ra` of side `s` and `rb` of side `e`) are `scratch[from..to]`; the ones inside
/// are pushed after them for the halves.
#[allow(clippy::too_many_arguments)]
fn subdivide(
    n: u32,
    s: usize,
    e: usize,
    ra: [u32; 4],
    rb: [u32; 4],
    children: &[Aabb],
    scratch: &mut Vec<u32>,
    from: usize,
    to: usize,
    words: &mut [u32],
) {
    let a = face_rect(n, s, ra[0], ra[1], ra[2], ra[3]);
    let b = face_rect(n, e, rb[0], rb[1], rb[2], rb[3]);
    let ext = [ra[1] - ra[0], ra[3] - ra[2], rb[1] - rb[0], rb[3] - rb[2]];
    let (imax, &emax) = ext.iter().enumerate().max_by_key(|(_, v)| **v).unwrap();
    if emax == 1 {
        // two single cells: one child in the shaft is enough
        if scratch[from..to]
            .iter()
            .any(|&c| shaft_hits_box(&a, &b, &children[c as usize]))
        {
            let idx = entry_index(n, s, ra[0], ra[2], e, rb[0], rb[2]).unwrap();
            words[idx / 32] |= 1 << (idx % 32);
        }
        return;
    }
    let base = scratch.len();
    for i in from..to {
        let c = scratch[i];
        if shaft_hits_box(&a, &b, &children[c as usize]) {
            scratch.push(c);
        }
    }
    let end = scratch.len();
    if end > base {
        let split = |r: [u32; 4], lohi: usize| -> ([u32; 4], [u32; 4]) {
            let (lo, hi) = (r[2 * lohi], r[2 * lohi + 1]);
            let mid = lo + (hi - lo) / 2;
            let mut r1 = r;
            let mut r2 = r;
            r1[2 * lohi + 1] = mid;
            r2[2 * lohi] = mid;
            (r1, r2)
        };
        if imax < 2 {
            let (r1, r2) = split(ra, imax);
            subdivide(n, s, e, r1, rb, children, scratch, base, end, words);
            subdivide(n, s, e, r2, rb, children, scratch, base, end, words);
        } else {
            let (r1, r2) = split(rb, imax - 2);
            subdivide(n, s, e, ra, r1, children, scratch, base, end, words);
            subdivide(n, s, e, ra, r2, children, scratch, base, end, words);
        }
    }
    scratch.truncate(base);
}

/// The brute-force line space: every entry against every filled child (the tests' oracle for
/// [`build_linespace`]).
pub fn build_linespace_brute_force(n: u32, filled: &[bool]) -> Vec<u32> {
    let mut words = vec![0u32; linespace_words(n)];
    let children = filled_cells(n, filled);
    for s in 0..FACES {
        for e in 0..FACES {
            if s == e {
                continue;
            }
            for sv in 0..n {
                for su in 0..n {
                    let a = face_rect(n, s, su, su + 1, sv, sv + 1);
                    for ev in 0..n {
                        for eu in 0..n {
                            let b = face_rect(n, e, eu, eu + 1, ev, ev + 1);
                            if children.iter().any(|c| shaft_hits_box(&a, &b, c)) {
                                let idx = entry_index(n, s, su, sv, e, eu, ev).unwrap();
                                words[idx / 32] |= 1 << (idx % 32);
                            }
                        }
                    }
                }
            }
        }
    }
    words
}

/// Read one bit of a line space (the thesis' `entry >> bit_position & 1`).
pub fn get_bit(words: &[u32], entry: usize) -> bool {
    (words[entry / 32] >> (entry % 32)) & 1 != 0
}

/// The line spaces packed into a 3D R32UI texture as Listing 3 lays them out.
#[derive(Debug, Clone)]
pub struct PackedLinespaces {
    pub tex_x_res: u32,
    pub tex_y_res: u32,
    pub tex_z_res: u32,
    /// Rows (y) one line space takes.
    pub ls_y_size: u32,
    pub words_per_linespace: u32,
    /// Texels, x fastest, then y, then z.
    pub texels: Vec<u32>,
}

impl PackedLinespaces {
    /// Listing 3: the texel of word `entry_num_comp` of line space `ls_index`.
    pub fn texel(&self, ls_index: u32, entry_num_comp: u32) -> (u32, u32, u32) {
        let y_position = ls_index * self.ls_y_size + entry_num_comp / self.tex_x_res;
        let y_coord = y_position % self.tex_y_res;
        let x_coord = entry_num_comp % self.tex_x_res;
        let z_coord = y_position / self.tex_y_res;
        (x_coord, y_coord, z_coord)
    }

    fn offset(&self, (x, y, z): (u32, u32, u32)) -> usize {
        x as usize + self.tex_x_res as usize * (y as usize + self.tex_y_res as usize * z as usize)
    }

    /// Algorithm 4 / Listing 3: the bit `entry_num` of line space `ls_index`.
    pub fn get_entry(&self, ls_index: u32, entry_num: usize) -> bool {
        let comp = (entry_num / 32) as u32;
        let bit = (entry_num % 32) as u32;
        (self.texels[self.offset(self.texel(ls_index, comp))] >> bit) & 1 != 0
    }

    /// The words of line space `ls_index` read back from the texture layout.
    pub fn unpack(&self, ls_index: u32) -> Vec<u32> {
        (0..self.words_per_linespace)
            .map(|w| self.texels[self.offset(self.texel(ls_index, w))])
            .collect()
    }

    pub fn bytes(&self) -> usize {
        4 * self.texels.len()
    }

    /// Texels of the layout: x · y · z.
    pub fn texel_count(&self) -> usize {
        self.tex_x_res as usize * self.tex_y_res as usize * self.tex_z_res as usize
    }
}

/// The 3D texture layout of Listing 3 for `count` line spaces of `words_per` words each with at
/// most `max_dim` texels per axis (no texels yet).
pub fn linespace_layout(words_per: usize, count: usize, max_dim: u32) -> Result<PackedLinespaces> {
    let tex_x_res = (words_per as u32).clamp(1, max_dim);
    let ls_y_size = (words_per as u32).div_ceil(tex_x_res);
    let rows = (count as u64 * ls_y_size as u64).max(1);
    let tex_y_res = rows.min(max_dim as u64) as u32;
    let tex_z_res = rows.div_ceil(tex_y_res as u64);
    if tex_z_res > max_dim as u64 {
        bail!(
            "{count} line spaces of {words_per} words need {rows} texture rows, more than a \
             {max_dim}×{max_dim}×{max_dim} 3D texture (GL_MAX_3D_TEXTURE_SIZE) holds; use a smaller \
             --ntree-n or --ntree-depth"
        );
    }
    Ok(PackedLinespaces {
        tex_x_res,
        tex_y_res,
        tex_z_res: tex_z_res as u32,
        ls_y_size,
        words_per_linespace: words_per as u32,
        texels: Vec::new(),
    })
}

/// Pack `count` line spaces of `words_per` words each (concatenated in `words`) into the 3D
/// texture layout of Listing 3 with at most `max_dim` texels per axis.
pub fn pack_linespaces(
    words: &[u32],
    words_per: usize,
    count: usize,
    max_dim: u32,
) -> Result<PackedLinespaces> {
    assert_eq!(words.len(), words_per * count);
    let mut p = linespace_layout(words_per, count, max_dim)?;
    p.texels = vec![0u32; p.texel_count()];
    for ls in 0..count {
        for w in 0..words_per {
            let o = p.offset(p.texel(ls as u32, w as u32));
            p.texels[o] = words[ls * words_per + w];
        }
    }
    Ok(p)
}

/// The N-tree of a scene with its line spaces.
#[derive(Debug, Clone)]
pub struct NTree {
    /// Cells per axis of every node (N).
    pub n: u32,
    /// Levels including the root; the leaves are at level depth − 1.
    pub depth: u32,
    /// The root cube's minimum corner (ntree.minBound) in world space.
    pub min_bound: Vec3,
    /// Edge of a child of the root in world units (1 / ntree.invNodeSize).
    pub node_size: f32,
    /// The node pool: groups of N³ (red, green) texels; group 0 = the children of the root.
    pub nodes: Vec<[u32; 2]>,
    /// Line spaces, `linespace_words(n)` words each; line space 0 is the root's.
    pub linespaces: Vec<u32>,
    pub linespace_count: usize,
    /// Triangle ids of the leaves.
    pub leaf_triangles: Vec<u32>,
    pub leaf_count: usize,
    pub build_ms: f64,
    /// Wall time of the line spaces' build (CPU, or GPU with its set-up and read-back).
    pub linespace_build_ms: f64,
    /// GPU time of the line spaces' build when the GPU built them (timer queries).
    pub linespace_gpu_ms: Option<f64>,
    /// The host bytes the build estimated, step by step, before allocating them.
    pub estimated_bytes: u64,
}

impl NTree {
    pub fn inv_node_size(&self) -> f32 {
        1.0 / self.node_size
    }

    /// World position to N-tree coordinates (root's children are unit cells), Algorithm 1
    /// line 5: `(pos − ntree.minBound) × ntree.invNodeSize`.
    pub fn to_ntree(&self, p: Vec3) -> Vec3 {
        (p - self.min_bound) * self.inv_node_size()
    }

    /// The stack depth whose nodes carry the last line spaces (the level above the leaves):
    /// nodes examined at stack depth d are at level d + 1, so this is depth − 3.
    pub fn last_linespace_depth(&self) -> i32 {
        self.depth as i32 - 3
    }

    /// Bytes of the node pool texture buffer (RG32UI) and of the leaf triangle lists.
    pub fn node_bytes(&self) -> usize {
        8 * self.nodes.len() + 4 * self.leaf_triangles.len()
    }

    /// Geometry flags of a child group.
    pub fn group_filled(&self, group: u32) -> Vec<bool> {
        let g = (self.n as usize).pow(3);
        self.nodes[group as usize * g..(group as usize + 1) * g]
            .iter()
            .map(|t| t[0] & GEOMETRY_BIT != 0)
            .collect()
    }

    /// Build the N-tree over `triangles` (world space): geometry by exact triangle/box overlap
    /// (separating axes), children down to level depth − 1, then one line space per node with
    /// children (the root's included, as line space 0) on the CPU — the twin of the GPU build
    /// (`linespace_build`).
    pub fn build(triangles: &[[Vec3; 3]], n: u32, depth: u32) -> Result<NTree> {
        let mut tree = Self::build_nodes(triangles, n, depth)?;
        tree.build_linespaces_cpu();
        Ok(tree)
    }

    /// The N-tree's nodes and leaves without its line spaces (`linespace_count` says how many
    /// there will be; `linespaces` stays empty until [`NTree::build_linespaces_cpu`] or the GPU
    /// build fills it).
    pub fn build_nodes(triangles: &[[Vec3; 3]], n: u32, depth: u32) -> Result<NTree> {
        if !(2..=16).contains(&n) {
            bail!("--ntree-n {n}: must lie in 2..=16");
        }
        if !(3..=4).contains(&depth) {
            bail!(
                "--ntree-depth {depth}: must be 3 or 4 levels counting the root (3: leaves at \
                 1/N², reading A of the thesis' depth 3; 4: leaves at 1/N³, reading B, three \
                 levels below the root; the line spaces sit on the levels above the leaves)"
            );
        }
        if triangles.is_empty() {
            bail!("the scene has no triangles to build an N-tree over");
        }
        let t0 = std::time::Instant::now();
        let what = format!("the N-tree of N = {n}, depth {depth}");
        let mut budget = budget::Tracker::new(&what, "--ntree-n with --ntree-depth");
        // the f64 copy, the id lists
        let tri_bytes = std::mem::size_of::<[DVec3; 3]>() + 2 * 4;
        // and what any build takes: the work lists, the thread pool, and the CPU line-space
        // build's masks of two layers of child positions (`linespace_cpu`)
        let masks = 2 * 4 * (n as u64).pow(2) * linespace_words(n) as u64;
        let fixed = (64 << 10) + masks;
        budget
            .add(fixed + triangles.len() as u64 * tri_bytes as u64)
            .map_err(anyhow::Error::msg)?;
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for t in triangles {
            for p in t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
        let center = (lo + hi) * 0.5;
        // a cube, padded so that no vertex lies on the outer boundary
        let edge = (hi - lo).max_element().max(1e-6) * 1.01;
        let min_bound = center - Vec3::splat(edge * 0.5);
        let node_size = edge / n as f32;
        let mut tree = NTree {
            n,
            depth,
            min_bound,
            node_size,
            nodes: Vec::new(),
            linespaces: Vec::new(),
            linespace_count: 0,
            leaf_triangles: Vec::new(),
            leaf_count: 0,
            build_ms: 0.0,
            linespace_build_ms: 0.0,
            linespace_gpu_ms: None,
            estimated_bytes: 0,
        };
        let tris: Vec<[DVec3; 3]> = triangles.iter().map(|t| t.map(|p| p.as_dvec3())).collect();
        let all: Vec<u32> = (0..triangles.len() as u32).collect();
        // inner nodes in line-space order: (group of its children); the root first
        let mut inner_groups = vec![0u32];
        // per inner node: its children's group, and its line space three times over (the
        // line spaces, their concatenation and the packed texels of the upload with the
        // driver's copy; a software driver's GPU memory is the host's), added before either
        // is allocated so that a tree too large is refused while its geometry is sorted
        let group_bytes = 8 * (n as u64).pow(3) + 3 * 4 * linespace_words(n) as u64;
        budget.add(group_bytes).map_err(anyhow::Error::msg)?;
        tree.nodes.resize((n as usize).pow(3), [0, 0]);
        let mut work = vec![(0u32, 1u32, min_bound.as_dvec3(), edge as f64, all)];
        let nn = n as usize;
        while let Some(top) = work.pop() {
            // the groups on top of the stack whose children are leaves push no work, so their
            // triangles are sorted in parallel and applied in the order they would be popped
            let mut batch = vec![top];
            while batch[0].1 == depth - 1 && work.last().is_some_and(|w| w.1 == depth - 1) {
                batch.push(work.pop().expect("checked"));
            }
            for _ in &batch {
                budget
                    .add(24 * (nn * nn * nn) as u64)
                    .map_err(anyhow::Error::msg)?;
            }
            let sorted: Vec<Vec<Vec<u32>>> = batch
                .par_iter()
                .map(|(_, _, origin, size, ids)| bucket_triangles(&tris, ids, *origin, *size, n))
                .collect();
            for ((group, level, origin, size, _), buckets) in batch.into_iter().zip(sorted) {
                let cell = size / n as f64;
                // the children's id lists (grown by doubling: up to twice their length), counted
                // as they are made; they are a group's references, never more than a level's
                let refs: usize = buckets.iter().map(Vec::len).sum();
                budget.add(8 * refs as u64).map_err(anyhow::Error::msg)?;
                for (i, b) in buckets.into_iter().enumerate() {
                    if b.is_empty() {
                        continue;
                    }
                    let slot = group as usize * nn * nn * nn + i;
                    if level < depth - 1 {
                        budget.add(group_bytes).map_err(anyhow::Error::msg)?;
                        let child_group = (tree.nodes.len() / (nn * nn * nn)) as u32;
                        tree.nodes.resize(tree.nodes.len() + nn * nn * nn, [0, 0]);
                        let ls = inner_groups.len() as u32;
                        inner_groups.push(child_group);
                        tree.nodes[slot] = [GEOMETRY_BIT | CHILDREN_BIT | (child_group << 2), ls];
                        let (x, y, z) = (i % nn, (i / nn) % nn, i / (nn * nn));
                        let child_origin = origin + DVec3::new(x as f64, y as f64, z as f64) * cell;
                        work.push((child_group, level + 1, child_origin, cell, b));
                    } else {
                        let off = tree.leaf_triangles.len() as u32;
                        if off >= 1 << 30 {
                            bail!("more than 2^30 leaf triangle references");
                        }
                        budget.add(4 * b.len() as u64).map_err(anyhow::Error::msg)?;
                        tree.nodes[slot] = [GEOMETRY_BIT | (off << 2), b.len() as u32];
                        tree.leaf_triangles.extend_from_slice(&b);
                        tree.leaf_count += 1;
                    }
                }
            }
        }
        if tree.nodes.len() / (n as usize).pow(3) >= 1 << 30 {
            bail!("more than 2^30 node groups");
        }
        tree.build_ms = t0.elapsed().as_secs_f64() * 1e3;
        tree.linespace_count = inner_groups.len();
        tree.estimated_bytes = budget.total();
        Ok(tree)
    }

    /// The line spaces of every inner node on the CPU, in line-space order: one mask per
    /// child position OR-ed ([`super::linespace_cpu::build_linespaces`], the same bits as
    /// [`build_linespace`]), timed into `linespace_build_ms`.
    pub fn build_linespaces_cpu(&mut self) {
        let t1 = std::time::Instant::now();
        let filled: Vec<Vec<bool>> = self
            .inner_groups()
            .into_iter()
            .map(|g| self.group_filled(g))
            .collect();
        self.linespaces = super::linespace_cpu::build_linespaces(self.n, &filled);
        self.linespace_build_ms = t1.elapsed().as_secs_f64() * 1e3;
    }

    /// Per line space (in order) the summed-volume table of its children's geometry flags:
    /// (N+1)³ counts, entry x + (N+1)·(y + (N+1)·z) = filled children below (x, y, z) on
    /// every axis.
    pub fn occupancy_sat(&self, rows: &[u32]) -> Vec<u32> {
        let n = self.n as usize;
        let m = n + 1;
        let mut sat = vec![0u32; self.linespace_count * m * m * m];
        for (ls, table) in sat.chunks_mut(m * m * m).enumerate() {
            for z in 1..m {
                for y in 1..m {
                    for x in 1..m {
                        let f = (rows[ls * n * n + (y - 1) + n * (z - 1)] >> (x - 1)) & 1;
                        let at = |x: usize, y: usize, z: usize| x + m * (y + m * z);
                        table[at(x, y, z)] = f
                            + table[at(x - 1, y, z)]
                            + table[at(x, y - 1, z)]
                            + table[at(x, y, z - 1)]
                            - table[at(x - 1, y - 1, z)]
                            - table[at(x - 1, y, z - 1)]
                            - table[at(x, y - 1, z - 1)]
                            + table[at(x - 1, y - 1, z - 1)];
                    }
                }
            }
        }
        sat
    }

    /// The geometry flags of every inner node's children as the GPU build reads them: per line
    /// space (in order) N² rows, row y + N·z with bit x set when child (x, y, z) has geometry.
    pub fn occupancy_rows(&self) -> Vec<u32> {
        let n = self.n as usize;
        let mut rows = vec![0u32; self.linespace_count * n * n];
        for (ls, g) in self.inner_groups().into_iter().enumerate() {
            for (i, filled) in self.group_filled(g).into_iter().enumerate() {
                if filled {
                    rows[ls * n * n + i / n] |= 1 << (i % n);
                }
            }
        }
        rows
    }

    /// Line space `i` as words.
    pub fn linespace(&self, i: usize) -> &[u32] {
        let w = linespace_words(self.n);
        &self.linespaces[i * w..(i + 1) * w]
    }

    /// The child group of every inner node, in line-space order (root first).
    pub fn inner_groups(&self) -> Vec<u32> {
        let mut g = vec![0u32; self.linespace_count];
        for t in &self.nodes {
            if t[0] & CHILDREN_BIT != 0 {
                g[t[1] as usize] = t[0] >> 2;
            }
        }
        g
    }
}

/// The triangles `ids` sorted into the N³ children (edge `size / N`, index x + N(y + Nz)) of the
/// node at `origin`: a triangle goes to every child its box overlaps (exact, separating axes,
/// the child widened by 10⁻⁶ of its edge), in the order of `ids`.
fn bucket_triangles(
    tris: &[[DVec3; 3]],
    ids: &[u32],
    origin: DVec3,
    size: f64,
    n: u32,
) -> Vec<Vec<u32>> {
    let cell = size / n as f64;
    let nn = n as usize;
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); nn * nn * nn];
    let last = glam::IVec3::splat(n as i32 - 1);
    for &id in ids {
        let t = &tris[id as usize];
        let tlo = t[0].min(t[1]).min(t[2]);
        let thi = t[0].max(t[1]).max(t[2]);
        let c0 = ((tlo - origin) / cell)
            .floor()
            .as_ivec3()
            .clamp(glam::IVec3::ZERO, last);
        let c1 = ((thi - origin) / cell)
            .floor()
            .as_ivec3()
            .clamp(glam::IVec3::ZERO, last);
        for z in c0.z..=c1.z {
            for y in c0.y..=c1.y {
                for x in c0.x..=c1.x {
                    let bmin = origin + DVec3::new(x as f64, y as f64, z as f64) * cell;
                    let eps = cell * 1e-6;
                    if tri_box_overlap(bmin - eps, bmin + DVec3::splat(cell) + eps, t) {
                        buckets[x as usize + nn * (y as usize + nn * z as usize)].push(id);
                    }
                }
            }
        }
    }
    buckets
}

/// Triangle/box overlap by separating axes (Akenine-Möller 2001): the box's 3 axes, the
/// triangle's normal and the 9 edge cross products.
pub fn tri_box_overlap(bmin: DVec3, bmax: DVec3, tri: &[DVec3; 3]) -> bool {
    let c = (bmin + bmax) * 0.5;
    let h = (bmax - bmin) * 0.5;
    let v = [tri[0] - c, tri[1] - c, tri[2] - c];
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    // box axes
    for i in 0..3 {
        let mn = v[0][i].min(v[1][i]).min(v[2][i]);
        let mx = v[0][i].max(v[1][i]).max(v[2][i]);
        if mn > h[i] || mx < -h[i] {
            return false;
        }
    }
    // edge × box axes
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    for ed in &e {
        for a in &axes {
            let ax = ed.cross(*a);
            if ax.length_squared() < 1e-30 {
                continue;
            }
            let p = [v[0].dot(ax), v[1].dot(ax), v[2].dot(ax)];
            let r = h.x * ax.x.abs() + h.y * ax.y.abs() + h.z * ax.z.abs();
            let mn = p[0].min(p[1]).min(p[2]);
            let mx = p[0].max(p[1]).max(p[2]);
            if mn > r || mx < -r {
                return false;
            }
        }
    }
    // triangle plane
    let nrm = e[0].cross(e[1]);
    let d = nrm.dot(v[0]);
    let r = h.x * nrm.x.abs() + h.y * nrm.y.abs() + h.z * nrm.z.abs();
    d.abs() <= r
}
