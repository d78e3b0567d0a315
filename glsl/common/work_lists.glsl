// Work lists that a kernel fills and a later indirect dispatch works through (ours; the SAH BVH's
// block lists, bvh/block_lists.glsl, and hit list, bvh/hit_list.glsl): how many work groups a
// list needs is known on the GPU only, so a kernel writes the dispatch command — within GL's
// limit on the work groups of one dimension, which the specification guarantees only as 65535
// (GL 4.6 §19, MAX_COMPUTE_WORK_GROUP_COUNT; the host's MAX_GROUPS_X) — and the work groups of
// that dispatch find their entries from their linear index.
#ifndef WORK_LISTS_GLSL
#define WORK_LISTS_GLSL

// The dispatch command (num_groups_x, y, z, padding) for `groups` work groups, as the four
// words a list's buffer holds it in: one row where it fits, else as many rows as needed of
// equal length — at most rows − 1 work groups more than `groups`, which find no entry and
// return.
uvec4 groupsCommand(uint groups)
{
    uint maxX = uint(MAX_GROUPS_X);
    if (groups <= maxX) return uvec4(groups, 1u, 1u, 0u);
    uint rows = (groups + maxX - 1u) / maxX;
    return uvec4((groups + rows - 1u) / rows, rows, 1u, 0u);
}

// This work group's index in a dispatch of rows (x first).
uint linearGroup() { return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x; }

// the threads that split a dispatch's work groups in contiguous shares (PixelGrid::threads)
uniform int listThreads;

// The list position of this work group, of a dispatch whose command groupsCommand wrote:
// llvmpipe hands each of its N threads a contiguous 1/N of the work groups, and a list in the
// order it was filled would give one thread the part of the image an object fills (as
// pixelPosition's row stride avoids, common/images.glsl); so the first N·q work groups of
// n (q = n / N) are dealt out in turn — work group a + N·b takes position a·q + b — and each
// share takes entries from the whole list. A one-to-one map of [0, n): any GPU is served.
uint listGroup()
{
    uint n = gl_NumWorkGroups.x * gl_NumWorkGroups.y, i = linearGroup();
    uint threads = uint(max(listThreads, 1)), q = n / threads;
    return i < threads * q ? (i % threads) * q + i / threads : i;
}
#endif
