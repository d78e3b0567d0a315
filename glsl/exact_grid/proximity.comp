// Exact grid, pass 5 (with --proximity-clouds): proximity clouds — the streaming tracer ch. 3 after
// Cohen & Sheffer, "Proximity clouds — an acceleration technique for 3D grid traversal", 1994: for
// every voxel the distance, in voxels, to the nearest non-empty voxel (0 for a non-empty one),
// rebuilt every frame after the lists. The metric is Chebyshev (L∞), as the streaming tracer's grid
// (stream/grid.glsl, reference::proximity): a voxel at distance d >= 2 is the centre of a cube
// of Chebyshev radius d - 1 that holds no non-empty voxel, so the DDA may jump to where the ray
// leaves that cube (exact_grid/dda.glsl, jumpWalk) without passing a non-empty voxel.
// Ours: the streaming tracer computes the clouds once on the CPU (a chamfer transform); the exact
// grid is rebuilt per frame on the GPU, so the L∞ transform runs here in its separable form, three
// 1D passes along x, y and z, each d'(i) = min_j max(|i - j|, d(j)) over the voxel's line
// (exact for L∞: the max of the per-axis distances is minimised axis by axis). Distances are
// capped at cloudCap (reference::proximity::EXACT_GRID_CLOUD_CAP, at most voxel_amount): a
// voxel scans outward only while |i - j| < its distance so far, so the cap bounds the pass;
// min(d, cap) is still safe and the passes give it exactly.
// Pass 0 reads the counts (distance 0 where a voxel has references, cloudCap else).
layout(local_size_x = 128, local_size_y = 1, local_size_z = 1) in;

#include "../common/grid.glsl"

layout(std430, binding = SSBO_VOXEL_COUNT) readonly buffer VoxelCount { uint voxelCount[]; };
layout(std430, binding = SSBO_DIST_IN) readonly buffer DistIn { uint distIn[]; };
layout(std430, binding = SSBO_DIST_OUT) writeonly buffer DistOut { uint distOut[]; };

uniform int axis;       // 0, 1, 2: the pass' axis
uniform int fromCounts; // 1 (the x pass): the input is voxelCount
uniform int cloudCap;   // the largest distance

uint inputAt(int id)
{
    if (fromCounts != 0) return voxelCount[id] > 0u ? 0u : uint(cloudCap);
    return distIn[id];
}

void main()
{
    int id = int(gl_GlobalInvocationID.x);
    int n = voxel_amount;
    if (id >= n * n * n) return;
    ivec3 v = ivec3(id % n, (id / n) % n, id / (n * n));
    int stride = axis == 0 ? 1 : (axis == 1 ? n : n * n);
    int i = v[axis];
    uint best = inputAt(id);
    // outward from i; nothing at |i - j| >= best can lower it
    for (int r = 1; r < n && uint(r) < best; r++) {
        if (i - r >= 0) best = min(best, max(uint(r), inputAt(id - r * stride)));
        if (i + r < n) best = min(best, max(uint(r), inputAt(id + r * stride)));
    }
    distOut[id] = best;
}
