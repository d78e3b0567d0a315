// Per-pixel records of the SAH BVH: work counts and hit records (ours; not in the thesis). Its
// intersection kernels (bvh/record_work.glsl, and the fused pass: bvh/fused.glsl) store each
// invocation's work — ray–triangle tests, BVH nodes visited, a loop cut short, the ray traced —
// in its pixel's record, which bvh/pixel_counts.comp adds to the 64-bit counters after the
// dispatch. Its intersect1 keeps the closest-hit search apart from the evaluation of the hit:
// it stores with the counts one word from which bvh/evaluate_hit.comp finds the hit again (t, triangle id, u, v;
// bvh/hit_record.glsl) and then does what Listings 13 and 14 do inside the thesis' intersect1.
// Both are plain vector stores: on llvmpipe an image store goes lane by lane and component by
// component, and a shared-memory atomic lane by lane, which made them cost more than the BVH
// walk itself (docs/design/frame.md).

// What intersect1's closestHit leaves for evaluate_hit.comp to find its hit again: the word address of the hit's leaf triangle
// (bvh/hit_record.glsl), −1 for none.
int closestHitRecord = -1;

// One record per pixel (three with the fused pass: bvh/fused.glsl), a PixelRecord (src/pipeline/mueller2015/records.rs): xy its counts
// (packCounts: tests_truncated, nodes_traced), z its hit record (hit; intersect1 only), w
// unused. One store per invocation: on llvmpipe every store costs a loop over the 8 lanes per
// component and about as much again for the store itself (docs/design/frame.md).
layout(std430, binding = SSBO_PIXEL_RECORDS) buffer PixelRecordBuffer { uvec4 pixelRecord[]; };
#if RECORD_STORE_64
// The same records as two 64-bit words (GL_ARB_gpu_shader_int64, which the including kernel
// enables): the counts' two words and the hit record's (its high half 0), for the stores of
// storeRecordPairs and storePixelRecord (intersect1 and the fused pass: one store of two
// components; intersect2: the counts) — on llvmpipe a store costs a loop over the 8 lanes per component, so two
// components cost less than three (docs/design/frame.md; docs/design/bvh.md, step 22).
layout(std430, binding = SSBO_PIXEL_RECORDS) buffer PixelRecordWords {
    u64vec2 pixelRecordWords[];
};
#endif

// A pixel's counts in two words, as each stored component costs a loop over the 8 lanes on
// llvmpipe: (tests | truncated << 31, nodes | traced << 31). A pixel counts fewer than 2^28 tests
// and nodes (2^26 where bvh/pixel_counts.comp sums 64 pixels: max_pixel_events in
// src/accel/mod.rs), and truncated and traced are 0 or 1.
uvec2 packCounts(uint tests, uint nodes, uint truncated, uint traced)
{
    return uvec2(tests | (truncated << 31), nodes | (traced << 31));
}
// (tests, nodes, truncated, traced)
uvec4 unpackCounts(uvec2 c)
{
    return uvec4(c & 0x7fffffffu, c >> 31);
}

// IMAGE_WIDTH × IMAGE_HEIGHT: the image size (#defines of the pipeline); one record per pixel
int pixelIndex(ivec2 storePos) { return storePos.y * IMAGE_WIDTH + storePos.x; }

// Record `at` as two pairs of words in one store: two 64-bit words where the profile has them
// (RECORD_STORE_64), else four 32-bit ones — intersect1's counts and hit record
// (bvh/record_work.glsl; its w then 0, which nothing reads), the fused pass' closest-hit and
// first-light counts (bvh/fused.glsl).
void storeRecordPairs(int at, uvec2 low, uvec2 high)
{
#if RECORD_STORE_64
    pixelRecordWords[at] = u64vec2(packUint2x32(low), packUint2x32(high));
#else
    pixelRecord[at] = uvec4(low, high);
#endif
}
