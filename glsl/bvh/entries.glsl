// The entry point of each 8×8 block of intersect1's rays — ours (Reshetov, Soupikov and Hurley
// 2005; bvh/entry.comp finds and writes them, bvh/intersect1.comp reads them): a texel per
// block, an EntryTexel (src/accel/bvh/layout.rs: octant_plus_one, node, end, zero), in the last
// BVH_ENTRY_TEXELS texels of the word buffer (bvh/words.glsl; the host appends them, zeros, to
// BvhTree::gpu_words), the blocks of the image row by row as block_of (src/accel/bvh/layout.rs) and the CPU twin's
// BvhTree::block_entries (src/reference/bvh/entry.rs) number them.
//
// In the word buffer rather than an image of their own (ours): the BVH's kernels bind the
// pipeline's ray-state images at units 0–6 and the word buffer at 7, the 8 image units GL 4.5
// guarantees (GL_MAX_IMAGE_UNITS), and intersect1 reads its entry as it reads a node record.
// (Not a storage buffer: on llvmpipe its load per invocation is a loop of per-lane loads where
// the image's is one texel load; docs/design/bvh.md, step 26b.)

// (BVH_ENTRY_TEXELS: the image's blocks, BVH_BLOCKS_X of them a row; #defines of the host)
// the texel of the entry of the block of pixels 8·block .. 8·block + 7
int entryTexel(ivec2 block)
{
    return imageSize(bvh) - BVH_ENTRY_TEXELS + block.y * BVH_BLOCKS_X + block.x;
}
