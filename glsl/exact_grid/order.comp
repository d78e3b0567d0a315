// Exact grid, pass 4 of 4: order — ours. The fill pass claims list positions with atomicAdd, so
// a voxel's list comes out in whatever order the triangles won their race: the closest hit does
// not care, but an any-hit shadow feeler stops at the first occluder of the list, so its
// triangle-test count would differ from run to run. This pass puts every list in ascending
// triangle id (the CPU twin's order): one invocation per reference k finds its voxel (the last
// v with voxelStart[v] <= k: a binary search, as the starts are a prefix sum), counts the ids
// of its list below its own (its rank: ids are unique within a list) and writes its id to
// voxelStart[v] + rank of the ordered list.
layout(local_size_x = 128, local_size_y = 1, local_size_z = 1) in;

#define COUNTER_SLOTS_PER_KERNEL 1
#include "../common/counters.glsl"

layout(std430, binding = SSBO_VOXEL_COUNT) readonly buffer VoxelCount { uint voxelCount[]; };
layout(std430, binding = SSBO_VOXEL_START) readonly buffer VoxelStart { uint voxelStart[]; };
layout(std430, binding = SSBO_VOXEL_TRIS_FILLED) readonly buffer VoxelTrisFilled { int voxelTrisFilled[]; };
layout(std430, binding = SSBO_VOXEL_TRIS) writeonly buffer VoxelTris { int voxelTris[]; };

uniform int referenceCount; // gridTotal
uniform int voxelTotal;      // N³

#define IDS_PER_ITERATION 8

// ids of list [first, first + n) below `id`, IDS_PER_ITERATION per iteration (see loopLimit in
// common/intersect.glsl: a list of up to 8·65535 ids is counted whole)
uint rankIn(uint first, uint n, int id, inout uint truncated)
{
    uint rank = 0u, j = 0u;
    for (; j + uint(IDS_PER_ITERATION) <= n; j += uint(IDS_PER_ITERATION)) {
        for (uint u = 0u; u < uint(IDS_PER_ITERATION); u++)
            rank += voxelTrisFilled[first + j + u] < id ? 1u : 0u;
    }
    for (; j < n; j++) rank += voxelTrisFilled[first + j] < id ? 1u : 0u;
    if (j < n) truncated = 1u;
    return rank;
}

void main()
{
    countersBegin();
    uint truncated = 0u;
    uint k = gl_GlobalInvocationID.x;
    if (k < uint(referenceCount)) {
        // the last voxel whose list starts at or before k
        int lo = 0, hi = voxelTotal - 1;
        while (lo < hi) {
            int mid = (lo + hi + 1) / 2;
            if (voxelStart[mid] <= k) lo = mid; else hi = mid - 1;
        }
        uint first = voxelStart[lo];
        int id = voxelTrisFilled[k];
        voxelTris[first + rankIn(first, voxelCount[lo], id, truncated)] = id;
    }
    countAdd(0, truncated);
    countersEnd(0, COUNTER_TRUNCATED_RAYS);
}
