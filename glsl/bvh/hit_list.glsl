// The hit list of a pass (ours; the SAH BVH's four kernels: src/pipeline/mueller2015/records.rs,
// HitList): bvh/evaluate_hit.comp appends every pixel whose ray hit something, and the
// pass' intersect2 dispatches (bvh/intersect2.comp) and their counts (bvh/pixel_counts.comp)
// work through the list instead of the image. Why: Mesa's llvmpipe (22.3) runs every
// instruction of a kernel in every SIMD group — an `if` no lane takes included, only a loop's
// further passes depend on the lanes (docs/design/frame.md, "The fused pass") — so a
// feeler kernel over the image paid its loads, the first pass of its walk and its stores for
// every pixel, 262,144 at 512², where the bunny traces 59,936 feelers; and a SIMD group of
// eight pixels of which some had a hit walked with the others masked. From the list, eight
// lanes are eight hits of the same 4×2 block or its neighbour.
//
// Layout (words): intersect2's dispatch command (num_groups_x, y, z, padding) at words 0–3 and
// pixel_counts' at 4–7 (bvh/hit_list.comp writes them from the count), the count at word 8,
// the frame's entries over all its passes at word 9 (the statistics' `hit_list_pixels`), the
// entries from word HIT_LIST_ENTRIES on: a pixel's index (pixelIndex, bvh/records.glsl).
// An intersect2 invocation stores its counts in the record of its list position, not of its
// pixel, so pixel_counts sums the first `count` records (the closest-hit search's counts of
// those records were added before: nothing reads them again).
#ifndef BVH_HIT_LIST_GLSL
#define BVH_HIT_LIST_GLSL
#include "../common/work_lists.glsl"

#define HIT_LIST_COUNT 8
#define HIT_LIST_FRAME_ENTRIES 9
#define HIT_LIST_ENTRIES 16
// the entries of one intersect2 work group (its 8×8 invocations: common/intersect_head.glsl)
#define HIT_LIST_GROUP 64u
layout(std430, binding = SSBO_HIT_LIST) buffer HitList { uint hitWords[]; };

uint hitCount() { return hitWords[HIT_LIST_COUNT]; }
// the pixel of entry k (the inverse of bvh/records.glsl's pixelIndex)
ivec2 hitPixel(uint k)
{
    uint p = hitWords[HIT_LIST_ENTRIES + k];
    return ivec2(p % uint(IMAGE_WIDTH), p / uint(IMAGE_WIDTH));
}
#endif
