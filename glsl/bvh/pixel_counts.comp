// The per-pixel work counts of an intersection dispatch added to the 64-bit counters (ours;
// bvh/records.glsl). Each invocation sums PIXELS_PER_INVOCATION consecutive pixels'
// counts (or an 8×8 block's: BLOCK_LISTED, below) — (ray–triangle tests, BVH nodes visited,
// loops cut short, rays traced) — and adds the sums to the counter slots `countSlots` through
// common/counters.glsl (one global atomic per work group and counter). A pixel's counts are
// below 2^32 over the pixels an invocation sums, so its sums fit: a ray visits each node and
// tests each leaf triangle at most once, and the host refuses a structure with more of them
// (max_pixel_events in src/accel/mod.rs).
// PIXELS_PER_INVOCATION and COUNT_GROUP: #defines of the host (src/pipeline/mueller2015/records.rs)
layout(local_size_x = COUNT_GROUP) in;

#define COUNTER_SLOTS_PER_KERNEL 4
#include "../common/counters.glsl"
#include "records.glsl"

// the global counter slot of each component
uniform ivec4 countSlots;
// The records summed: IMAGE_WIDTH × IMAGE_HEIGHT of them from record recordBase on, packed
// (packCounts) in words 0–1 — the intersection kernels' — or with packedHigh in words 2–3 (the
// fused pass' first-light feelers beside its closest-hit counts), or with plainRecords
// unpacked as (tests, nodes, rays, truncated): the fused pass' records of a kind one pixel
// counts several feelers of (bvh/fused_pass.comp).
uniform int recordBase;
uniform int plainRecords;
uniform int packedHigh;

// Ours: with RECORD_IMAGE the records are read through an RGBA32UI image buffer over the same
// storage (src/pipeline/mueller2015/records.rs) — llvmpipe loads a storage-buffer vector lane
// by lane and component by component, an image texel for all lanes at once
// (docs/design/frame.md).
#if RECORD_IMAGE
layout(rgba32ui, binding = IMAGE_PIXEL_RECORDS) readonly uniform uimageBuffer recordImage;
uvec4 recordCounts(int k)
{
    uvec4 r = imageLoad(recordImage, recordBase + k);
    return plainRecords != 0 ? r.xywz : unpackCounts(packedHigh != 0 ? r.zw : r.xy);
}
#else
uvec4 recordCounts(int k)
{
    if (plainRecords != 0) return pixelRecord[recordBase + k].xywz;
    if (packedHigh != 0) return unpackCounts(pixelRecord[recordBase + k].zw);
    return unpackCounts(pixelRecord[recordBase + k].xy);
}
#endif

// Ours: with hitListed the records of an intersect2 dispatch over the hit list
// (bvh/hit_list.glsl), one per list entry: the first `count` records, in a dispatch whose
// command bvh/hit_list.comp wrote (work groups in rows: common/work_lists.glsl).
uniform int hitListed;
#include "hit_list.glsl"

// Ours: with BLOCK_LISTED (a variant of its own, src/pipeline/mueller2015/records.rs: only it
// declares the lists' buffer, which the accelerator binds for a fused pass over its lists; and
// llvmpipe would run both sides of a uniform choice) the records of a fused pass over the block
// lists (bvh/block_lists.glsl; a list's blocks as bvh/fused_pass.comp takes them), an
// invocation per 8×8 block of the image: list 0's blocks (those whose rays may hit) and then
// list 1's, each block's pixels' records summed. With missesCleared (the first pass, whose
// miss blocks the host's clears stand for: RayTracer::fused_pass) list 1's records are not
// read, as no kernel wrote them: every pixel of such a block traced its eye ray, which visited
// nothing (record 0's closest-hit counts: one ray each), and no feeler (every other record).
// Why: the miss blocks are most of an image the object fills a part of, and the records they
// would read (and the fill they would need) cost as much as the hit blocks' (docs/design/frame.md).
#if BLOCK_LISTED
uniform int missesCleared;
#include "block_lists.glsl"

// The counts of the block at list position i (of both lists' BVH_ENTRY_TEXELS, list 0 first).
uvec4 blockCounts(uint i)
{
    uint hitBlocks = blockListCount(0u);
    uint list = i < hitBlocks ? 0u : 1u;
    uint b = blockWords[blockListWord(list, i - list * hitBlocks)];
    ivec2 origin = ivec2(b % uint(BVH_BLOCKS_X), b / uint(BVH_BLOCKS_X)) * 8;
    ivec2 size = min(ivec2(IMAGE_WIDTH, IMAGE_HEIGHT) - origin, ivec2(8));
    uvec4 sum = uvec4(0u);
    if (list == 1u && missesCleared != 0) {
        bool closestHit = recordBase == 0 && plainRecords == 0 && packedHigh == 0;
        sum.w = closestHit ? uint(size.x * size.y) : 0u; // (tests, nodes, truncated, traced)
    } else {
        for (int y = 0; y < size.y; y++) {
            int row = (origin.y + y) * IMAGE_WIDTH + origin.x;
            for (int x = 0; x < size.x; x++) sum += recordCounts(row + x);
        }
    }
    return sum;
}
#endif

void main()
{
    countersBegin();
    uvec4 sum = uvec4(0u);
    uint invocation = linearGroup() * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
#if BLOCK_LISTED
    if (invocation < uint(BVH_ENTRY_TEXELS)) sum = blockCounts(invocation);
#else
    int first = int(invocation) * PIXELS_PER_INVOCATION;
    int records = hitListed != 0 ? int(hitCount()) : IMAGE_WIDTH * IMAGE_HEIGHT;
    int end = min(first + PIXELS_PER_INVOCATION, records);
    for (int k = first; k < end; k++) sum += recordCounts(k);
#endif
    for (int c = 0; c < 4; c++) countAdd(c, sum[c]);
    for (int c = 0; c < 4; c++) countersEnd(c, countSlots[c]);
}
