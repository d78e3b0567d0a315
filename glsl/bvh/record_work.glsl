// traceAndCount (the declaration of common/intersect_head.glsl) of the SAH BVH's intersect1 and
// intersect2 (ours): each invocation stores its work in a per-pixel record (bvh/records.glsl),
// which bvh/pixel_counts.comp adds to the 64-bit counters after the dispatch, instead of
// common/count_work.glsl's atomics. The kernel defines which pixel an invocation traces and
// which record holds its work (a hook, as closestHit is; false: none):
//     bool workItem(out ivec2 storePos, out int record)
// intersect1: its pixel and the pixel's record; intersect2: an entry of the pass' hit list
// (bvh/hit_list.glsl) and the record of its list position.
bool workItem(out ivec2 storePos, out int record);

// The store of the invocation's work in record `at`: the counts, and in intersect1 the hit
// record too.
void storePixelRecord(int at, int testsSlot)
{
    uvec2 counts = packCounts(tests, nodesVisited, truncated, raysTraced);
    // (a constant condition: one of the two stores is compiled)
    if (testsSlot == COUNTER_INTERSECT1) {
        storeRecordPairs(at, counts, uvec2(uint(closestHitRecord), 0u));
    } else {
#if RECORD_STORE_64
        pixelRecordWords[at].x = packUint2x32(counts);
#else
        pixelRecord[at].xy = counts;
#endif
    }
}

void traceAndCount(int testsSlot)
{
    ivec2 storePos;
    int record;
    if (workItem(storePos, record)) {
        trace(storePos);
        storePixelRecord(record, testsSlot);
    }
}
