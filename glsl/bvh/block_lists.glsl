// The fused pass' block lists (ours; BVH_BLOCK_LISTS, one tree, the image in one dispatch:
// src/accel/bvh/mod.rs, BlockLists): bvh/entry.comp sorts the image's 8×8 blocks into those
// whose rays may hit something (list 0) and those whose rays all miss the tree's root or are
// inactive (list 1: an empty entry, bvh/entries.glsl), each count kept as the work-group count
// of an indirect dispatch; bvh/fused_pass.comp runs a work group per block of list 0 and,
// compiled as FUSED_MISS, of list 1. Why: Mesa's llvmpipe (22.3) executes every instruction of
// a kernel in every SIMD group, the sides of each `if` no lane takes included — only a loop's
// further passes depend on the lanes — so a pixel whose ray misses everything paid the whole
// fused kernel: the walk's first pass, the hit's evaluation, a feeler's first pass and the
// shading (docs/design/frame.md, "The fused pass"). The miss kernel is the same pass with the
// walk left out, its hit path folded away by the compiler.
//
// Dispatches stay the tiles of the image (`--tile`: no dispatch long enough for a driver
// watchdog), so the lists are a pair per tile of BVH_TILE_BLOCKS × BVH_TILE_BLOCKS blocks, the
// tiles row by row, BVH_TILES_X of them a row, as the host's PixelGrid::tiles orders them.
// Layout (words): per tile t and list k a dispatch command (num_groups_x, y = 1, z = 1,
// padding) at words 4·(2t + k) — the host writes (0, 1, 1, 0) into every one before the entry
// pass — then per tile and list its blocks, from word 8·BVH_TILES + (2t + k)·BVH_TILE_BLOCKS²
// on (the first num_groups_x of them used).
#ifndef BVH_BLOCK_LISTS_GLSL
#define BVH_BLOCK_LISTS_GLSL
layout(std430, binding = SSBO_BVH_BLOCK_LISTS) buffer BlockLists { uint blockWords[]; };

// the word of list k of tile t where its entry i lies
uint blockListWord(uint t, uint k, uint i)
{
    const uint capacity = uint(BVH_TILE_BLOCKS * BVH_TILE_BLOCKS);
    return uint(8 * BVH_TILES) + (2u * t + k) * capacity + i;
}
#endif
