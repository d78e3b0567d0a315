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

// main() of every intersection kernel: trace this invocation's pixel and account for its work,
// its triangle tests under `testsSlot` (COUNTER_INTERSECT1 or 2). The design defines it after
// including this file (as it defines closestHit and occluded): common/count_work.glsl adds the
// counts to the 64-bit counters (the base tracer, the grids); the SAH BVH stores them in
// per-pixel records (bvh/record_work.glsl, ours).
void traceAndCount(int testsSlot);
