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

layout(std430, binding = SSBO_VOXEL_START) readonly buffer VoxelStart { uint voxelStart[]; };
layout(std430, binding = SSBO_VOXEL_FILL) coherent buffer VoxelFill { uint voxelFill[]; };
layout(std430, binding = SSBO_VOXEL_TRIS_FILLED) writeonly buffer VoxelTris { int voxelTris[]; };

uint truncated = 0u;
int currentTriangle = -1;

void registerInVoxel(int voxID)
{
    uint slot = voxelStart[voxID] + atomicAdd(voxelFill[voxID], 1u);
    voxelTris[slot] = currentTriangle;
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
