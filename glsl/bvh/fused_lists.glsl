// The main() of the fused pass' entry files over the block lists (ours; one tree:
// bvh/fused_pass.comp for the blocks whose rays may hit, bvh/fused_miss.comp for those whose
// rays cannot; bvh/block_lists.glsl): a work group per block of the entry's list. Why: Mesa's
// llvmpipe (22.3) executes every instruction of a kernel in every SIMD group, the sides of each
// `if` no lane takes included, so a pixel whose ray misses everything paid the whole fused
// kernel (docs/design/frame.md, "The fused pass").
#include "block_lists.glsl"

void traceList(uint list)
{
    // the last row of work groups may have more than the list (common/work_lists.glsl)
    uint i = listGroup();
    if (i >= blockListCount(list)) return;
    uint b = blockWords[blockListWord(list, i)];
    ivec2 storePos = ivec2(b % uint(BVH_BLOCKS_X), b / uint(BVH_BLOCKS_X)) * 8 + groupPixel();
    if (insideImage(storePos)) trace(storePos);
}
