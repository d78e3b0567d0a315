// Exact grid, pass 3 of 4: fill — ours. Every triangle writes its id into the compact list of
// every voxel it overlaps (the same test as count.comp): position voxelStart[v] plus a
// per-voxel cursor claimed with atomicAdd. The lists need no fixed capacity and never drop;
// order.comp then sorts each by triangle id.
layout(local_size_x = 128, local_size_y = 1, local_size_z = 1) in;

#define SCENE_QUALIFIER readonly
#define COUNTER_SLOTS_PER_KERNEL 1
#include "../common/scene.glsl"
#include "../common/counters.glsl"
#include "../common/grid.glsl"
#include "tribox.glsl"

layout(std430, binding = SSBO_VOXEL_COUNT) readonly buffer VoxelCount { uint voxelCount[]; };
layout(std430, binding = SSBO_VOXEL_START) readonly buffer VoxelStart { uint voxelStart[]; };
layout(std430, binding = SSBO_VOXEL_FILL) coherent buffer VoxelFill { uint voxelFill[]; };
layout(std430, binding = SSBO_VOXEL_TRIS_FILLED) writeonly buffer VoxelTris { int voxelTris[]; };

uint truncated = 0u;
int currentTriangle = -1;

// Ours: a claim past the voxel's count is not written. count.comp made the same test, but in
// another program: GLSL lets a compiler fuse a·b + c into one rounding in one of them and not
// in the other, so on a GPU the two may disagree on a triangle that touches a voxel's face.
// Such a claim would write into the next voxel's list (or past the buffer); it is counted as
// truncated instead, and the host refuses the frame.
void registerInVoxel(int voxID)
{
    uint k = atomicAdd(voxelFill[voxID], 1u);
    if (k < voxelCount[voxID]) voxelTris[voxelStart[voxID] + k] = currentTriangle;
    else truncated = 1u;
}

#include "grid_overlap.glsl"

void main()
{
    countersBegin();
    currentTriangle = int(gl_GlobalInvocationID.x);
    if (currentTriangle < triangleCount()) registerTriangle(currentTriangle);
    countAdd(0, truncated);
    countersEnd(0, COUNTER_TRUNCATED_RAYS);
}
