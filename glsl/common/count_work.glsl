// traceAndCount (the declaration of common/intersect_head.glsl) of the designs that add their
// work to the 64-bit counters (common/counters.glsl): the base tracer's and the grids'
// intersection kernels, which include this file after common/intersect_head.glsl. Each
// invocation traces its pixel, then each work group adds its invocations' counts — triangle
// tests to `testsSlot`, loops cut short, voxels visited, BVH nodes visited, proximity-cloud
// jumps and the voxels they passed over (exact_grid/dda.glsl; 0 in the other designs, reported
// with --proximity-clouds only), rays traced.
void traceAndCount(int testsSlot)
{
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
    countersEnd(4, COUNTER_CLOUD_JUMPS);
    countersEnd(5, COUNTER_EMPTY_CELLS_SKIPPED);
}
