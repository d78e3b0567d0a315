// Declarations every intersection kernel (intersect1 / intersect2 of every design) shares:
// the scene SSBOs, the ray-state images, Algorithm 1 and the counters, plus the per-invocation
// work counts the kernels add to (ray–triangle tests, loops cut short, voxels visited, BVH nodes visited,
// rays traced).
layout(local_size_x = 8, local_size_y = 8) in;

#define SCENE_QUALIFIER readonly
#define COUNTER_SLOTS_PER_KERNEL 7
#include "scene.glsl"
#include "images.glsl"
#include "intersect.glsl"
#include "counters.glsl"

uint tests = 0u;         // ray–triangle tests of this invocation
uint truncated = 0u;     // 1 if a loop of this invocation ended early (see loopLimit)
uint voxelsVisited = 0u; // voxels whose triangle lists this invocation walked
uint nodesVisited = 0u;  // BVH nodes this invocation visited
uint cloudJumps = 0u;    // proximity-cloud jumps (exact grid, exact_grid/dda.glsl)
uint cellsSkipped = 0u;  // voxels those jumps passed over
uint raysTraced = 0u;    // 1 if this invocation traced its pixel's ray (ours: rays per ray kind)

// Whether this dispatch counts its pixel's ray in raysTraced: every dispatch but the later parts
// of a search the host splits over several dispatches (brute_force/*.comp define it as
// (firstTriangle == 0) before including this file).
#ifndef COUNTS_RAY
#define COUNTS_RAY true
#endif

// The pixel's work: defined by common/intersect1_main.glsl or common/intersect2_main.glsl (the
// base tracer's intersect1: brute_force/intersect1.comp itself).
void trace(ivec2 storePos);

// Ours: a design whose intersection kernels store their work counts per pixel instead (the SAH
// BVH: bvh/records.glsl, for bvh/pixel_counts.comp to add up) defines PIXEL_RECORDS before
// including this file and storePixelRecord after it.
#ifdef PIXEL_RECORDS
void storePixelRecord(int at, int testsSlot);
int pixelIndex(ivec2 storePos);
#endif

// main() of every intersection kernel: trace this invocation's pixel, then add its work counts
// to the 64-bit counters — its triangle tests to `testsSlot` (COUNTER_INTERSECT1 or 2) — or,
// with PIXEL_RECORDS, store them in the pixel's record. Ours: with HIT_LIST (the SAH BVH's
// intersect2, which includes bvh/hit_list.glsl first) an invocation takes a pixel of the
// pass' hit list instead, and its record is that of its list position.
void traceAndCount(int testsSlot)
{
#if defined(PIXEL_RECORDS) && defined(HIT_LIST)
    uint k = listGroup() * HIT_LIST_GROUP + gl_LocalInvocationIndex;
    if (k < hitCount()) {
        trace(hitPixel(k));
        storePixelRecord(int(k), testsSlot);
    }
#elif defined(PIXEL_RECORDS)
    ivec2 storePos = pixelPosition();
    if (insideImage(storePos)) {
        trace(storePos);
        storePixelRecord(pixelIndex(storePos), testsSlot);
    }
#else
    countersBegin();
    ivec2 storePos = pixelPosition();
    if (insideImage(storePos)) trace(storePos);
    countAdd(0, tests);
    countAdd(1, truncated);
    countAdd(2, voxelsVisited);
    countAdd(3, nodesVisited);
    countAdd(4, cloudJumps);
    countAdd(5, cellsSkipped);
    countAdd(6, raysTraced);
    countersEnd(0, testsSlot);
    countersEnd(1, COUNTER_TRUNCATED_RAYS);
    countersEnd(2, COUNTER_VOXELS_VISITED);
    countersEnd(3, COUNTER_NODES_VISITED);
    countersEnd(6, COUNTER_RAYS);
#ifdef COUNTER_CLOUD_JUMPS
    countersEnd(4, COUNTER_CLOUD_JUMPS);
    countersEnd(5, COUNTER_EMPTY_CELLS_SKIPPED);
#endif
#endif
}
