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
// The lists cover the whole image, one indirect dispatch each, whatever `--tile` splits the other
// kernels into: per-tile pairs of lists, each dispatched with its tile as a uniform, rendered
// right on llvmpipe but not on Mesa 22.3's zink, where the second pass of a frame traced rays
// that had ended (docs/design/frame.md, "The fused pass").
// Layout (words): list k's dispatch command (num_groups_x, y, z, padding) at words 4k, which
// bvh/block_lists.comp writes from the count after the entry pass (within GL's limit on work
// groups per dimension: common/work_lists.glsl); list k's count at word BLOCK_LIST_COUNTS + k,
// which it sets to 0 before the entry pass; list k's blocks from word 16 + k·BVH_ENTRY_TEXELS on.
#ifndef BVH_BLOCK_LISTS_GLSL
#define BVH_BLOCK_LISTS_GLSL
#include "../common/work_lists.glsl"
layout(std430, binding = SSBO_BVH_BLOCK_LISTS) buffer BlockLists { uint blockWords[]; };

#define BLOCK_LIST_COUNTS 8
// the word of list k where its entry i lies
uint blockListWord(uint k, uint i) { return 16u + k * uint(BVH_ENTRY_TEXELS) + i; }
uint blockListCount(uint k) { return blockWords[BLOCK_LIST_COUNTS + k]; }
#endif
