// Declarations every intersection kernel (intersect1 / intersect2 of every design) shares:
// the scene SSBOs, the ray-state images, Algorithm 1 and the counters, plus the per-invocation
// work counts the kernels add to (ray–triangle tests, loops cut short, voxels visited, BVH nodes visited).
layout(local_size_x = 8, local_size_y = 8) in;

#define SCENE_QUALIFIER readonly
#define COUNTER_SLOTS_PER_KERNEL 4
#include "scene.glsl"
#include "images.glsl"
#include "intersect.glsl"
#include "counters.glsl"

uint tests = 0u;         // ray–triangle tests of this invocation
uint truncated = 0u;     // 1 if a loop of this invocation ended early (see loopLimit)
uint voxelsVisited = 0u; // voxels whose triangle lists this invocation walked
uint nodesVisited = 0u;  // BVH nodes this invocation visited
