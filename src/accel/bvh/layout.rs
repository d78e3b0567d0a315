//! The SAH bounding volume hierarchy — ours, after Wagner 2018 ch. 3.2 and 4.2: built on the CPU
//! top-down, each node split where the simplified SAH of eq. 4.1 (half surface area times
//! triangle count, summed over both children) is lowest, a leaf when it holds at most
//! [`LEAF_SIZE`] triangles or no split beats the node's own SAH (Listings 4.3, 4.4). Where
//! Wagner tries split distances one after another, we evaluate [`BINS`] bins per axis (binned
//! SAH, Wald 2007, his [13]) and build the two children in parallel (rayon) above
//! [`PARALLEL_BUILD`] triangles.
//!
//! Layout for upload — after Wagner's three textures of Fig. 4.3, as one buffer of 32-bit
//! words read as texels of four (`BvhTree::gpu_words`):
//! - a [`Header`]: the node count and the grid of the records' planes (`planes::Grid`, over the
//!   root's box);
//! - for each of the 8 ray octants a copy of the nodes in that octant's depth-first order (the
//!   near child of every split first), one 16-byte [`NodeRecord`] each: the box as its near and far
//!   planes for rays of that octant, 16-bit step counts on the grid (`BvhTree::planes`), and in
//!   an inner node its miss link for that octant (the record to go on with when the node is
//!   missed), in a leaf the place and count of its triangles — an inner node's near child is
//!   the record after it, its far child the near child's miss link, a leaf's miss link the
//!   record after it;
//! - after the records, per entry of `BvhTree::tris` (the triangle ids per leaf) a
//!   [`LeafTriangle`]: v0 and its id, edge1, edge2 (12 words);
//! - after them (appended by the accelerator) an [`EntryTexel`] per block of the image.
//!
//! Each record is a `#[repr(C)]` type documented field by field (this file holds the types
//! alone; `tree.rs` builds and writes them), the GLSL naming it and its
//! fields; `BvhTree::gpu_words` writes them through `bytemuck`.

use bytemuck::{Pod, Zeroable};

pub use crate::accel::aabb::Aabb;

/// Bins per axis of the binned SAH.
pub const BINS: usize = 16;
/// Wagner's leaf size: a node of at most this many triangles is a leaf.
pub const LEAF_SIZE: usize = 4;
/// A node of more triangles is split even when the SAH says a split does not pay.
pub const MAX_LEAF: usize = 16;
/// Below this depth the SAH chooses the split; deeper, the triangles are halved (by centroid
/// order on the widest axis), which bounds the depth by this plus log2(triangles).
pub const SAH_DEPTH: u32 = 40;
/// The deepest tree the build makes: [`SAH_DEPTH`] plus the halving below it.
pub const MAX_DEPTH: u32 = SAH_DEPTH + 32;
/// The miss link after the last node of a walk.
pub const END: i32 = -1;
/// Ray octants: bit a is set when the ray points down axis a.
pub const OCTANTS: usize = 8;
/// Subtrees of more triangles build their two children in parallel.
pub const PARALLEL_BUILD: usize = 4096;

/// One node: its bounds and integers (in `BvhTree::gpu_words` as one record per octant).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Node {
    pub lo: [f32; 3],
    /// Inner node: the left child (the right is `first + 1`); leaf: the first of its
    /// triangles in `BvhTree::tris`.
    pub first: u32,
    pub hi: [f32; 3],
    /// Leaf: the number of its triangles (> 0); inner node: −1 − the split axis.
    pub meta: i32,
}

impl Node {
    pub fn is_leaf(&self) -> bool {
        self.meta > 0
    }

    /// A leaf's triangle count (0 for an inner node).
    pub fn count(&self) -> u32 {
        self.meta.max(0) as u32
    }

    /// An inner node's split axis: its left child lies on the low side.
    pub fn axis(&self) -> usize {
        (-1 - self.meta).clamp(0, 2) as usize
    }

    /// An inner node's near child for rays of `octant` (bit a set: the ray points down axis
    /// a): the left one, on the low side of the split, unless the ray points down the axis.
    pub fn near_child(&self, octant: usize) -> u32 {
        self.first + ((octant >> self.axis()) & 1) as u32
    }

    /// The other child of an inner node for rays of `octant`.
    pub fn far_child(&self, octant: usize) -> u32 {
        2 * self.first + 1 - self.near_child(octant)
    }
}

/// The facts of a build, for the statistics.
#[derive(Debug, Clone, Copy, Default)]
pub struct BvhStats {
    pub nodes: usize,
    pub leaves: usize,
    /// The deepest leaf (root: 0).
    pub depth: u32,
    /// SAH cost relative to the root: Σ inner A(n)/A(root) + Σ leaves A(l)/A(root)·N(l)
    /// (A: surface area; one unit per node traversal and per triangle test).
    pub sah_cost: f64,
    /// Bytes as uploaded (`BvhTree::gpu_words`).
    pub bytes: usize,
    pub build_ms: f64,
}

/// The header of `BvhTree::gpu_words`: its first two texels, 32 bytes (`glsl/bvh/traverse.glsl`
/// reads them as `header` and `bvhTexel(4)`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Header {
    /// bytes 0–3: N, the nodes of the tree (each octant's copy has N records)
    pub node_count: u32,
    /// bytes 4–15: the grid's origin x, y, z: plane q of axis a lies at
    /// `grid_origin[a] + q·grid_step[a]` (`planes::Grid`)
    pub grid_origin: [f32; 3],
    /// bytes 16–27: the grid's steps x, y, z
    pub grid_step: [f32; 3],
    /// bytes 28–31: 0
    pub zero: u32,
}
const _: () = assert!(std::mem::size_of::<Header>() == 32);

/// A node record of one octant's copy of the nodes in `BvhTree::gpu_words`: one texel, 16
/// bytes (`glsl/bvh/words.glsl`'s `recordPlanes` unpacks its planes, `glsl/bvh/traverse.glsl`'s
/// `nodePass` reads `reference` as `int(record.w)`). The planes are the 16-bit step counts of
/// `BvhTree::planes` on the grid; as words, `near.x | near.y << 16`, `near.z | far.x << 16`,
/// `far.y | far.z << 16` (the host is little-endian: asserted below).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct NodeRecord {
    /// bytes 0–5 (word 0, word 1 bits 0–15): the planes x, y, z where rays of the record's
    /// octant enter the box's slabs — per axis the box's low plane, or its high plane where the
    /// octant's rays point down the axis ([`octant_planes`])
    pub near: [u16; 3],
    /// bytes 6–11 (word 1 bits 16–31, word 2): the planes x, y, z where they leave them
    pub far: [u16; 3],
    /// bytes 12–15 (word 3): an inner node (≥ 0): its miss link, the texel of the record where a
    /// ray of the octant goes on when it misses the node (the texel after the octant's last
    /// record for [`END`]: the walk is over); a leaf (< 0): −1 − (s·2^[`LEAF_COUNT_BITS`] +
    /// count), its count triangles from entry s of `BvhTree::tris` on
    pub reference: i32,
}
const _: () = assert!(std::mem::size_of::<NodeRecord>() == 16);
const _: () = assert!(
    cfg!(target_endian = "little"),
    "a record's 16-bit planes pack into its words low half first"
);

/// A leaf triangle in `BvhTree::gpu_words`, one per entry of `BvhTree::tris`: three texels,
/// 48 bytes (`glsl/bvh/traverse.glsl`'s `leafTriangles`, `glsl/bvh/hit_record.glsl`'s
/// `hitFromRecord`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct LeafTriangle {
    /// bytes 0–11: its first vertex
    pub v0: [f32; 3],
    /// bytes 12–15: its triangle id
    pub id: u32,
    /// bytes 16–27: v1 − v0, the first difference Algorithm 1 forms
    pub edge1: [f32; 3],
    /// bytes 28–31: 0
    pub zero1: u32,
    /// bytes 32–43: v2 − v0
    pub edge2: [f32; 3],
    /// bytes 44–47: 0
    pub zero2: u32,
}
const _: () = assert!(std::mem::size_of::<LeafTriangle>() == 48);

/// A block's entry point (`glsl/bvh/entries.glsl`): one texel, 16 bytes, per block of the
/// image after the leaf triangles, which `glsl/bvh/entry.comp` writes every pass; the host
/// uploads them zeroed (no entry).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct EntryTexel {
    /// bytes 0–3: the octant of the block's rays + 1 (0: no entry, every ray walks from its
    /// octant's root)
    pub octant_plus_one: u32,
    /// bytes 4–7: the texel of the record the block's rays of that octant walk from
    pub node: u32,
    /// bytes 8–11: the texel after the entry node's subtree, where their walk stops
    pub end: u32,
    /// bytes 12–15: 0
    pub zero: u32,
}
const _: () = assert!(std::mem::size_of::<EntryTexel>() == 16);

/// Words of the header of `BvhTree::gpu_words` ([`Header`]).
pub const HEADER_WORDS: usize = std::mem::size_of::<Header>() / 4;
/// Words of one node record of one octant in `BvhTree::gpu_words` ([`NodeRecord`]): one texel.
pub const NODE_WORDS: usize = std::mem::size_of::<NodeRecord>() / 4;
/// Words of one leaf triangle in `BvhTree::gpu_words` ([`LeafTriangle`]).
pub const TRIANGLE_WORDS: usize = std::mem::size_of::<LeafTriangle>() / 4;
/// Bits of a leaf's triangle count in its record's `reference` ([`NodeRecord`]).
pub const LEAF_COUNT_BITS: u32 = 5;
const _: () = assert!(
    MAX_LEAF < 1 << LEAF_COUNT_BITS,
    "a leaf's count fits its bits"
);

/// Pixels per side of a block of rays with one entry point (`glsl/bvh/entries.glsl`): one work
/// group of intersect1 (`PIXEL_GROUP`).
pub const BLOCK: u32 = 8;

/// The index of the block of pixel (x, y) (GL's order, rows from the bottom) among the blocks
/// of an image `width` pixels wide, as `BvhTree::block_entries` (`reference::bvh`) lists them
/// and intersect1 reads them (`storePos >> 3`).
pub fn block_of(width: u32, x: u32, y: u32) -> usize {
    ((y / BLOCK) * width.div_ceil(BLOCK) + x / BLOCK) as usize
}
