// Exact grid, pass 1 of 4: count — ours, after Müller 2015 ch. 3.2 (rebuilt every frame on
// the GPU, one invocation per triangle like the build kernel of Listing 19). Every triangle
// adds 1 to the count of every voxel it overlaps (triangle/box test, not only its edges).
layout(local_size_x = 128, local_size_y = 1, local_size_z = 1) in;

#define SCENE_QUALIFIER readonly
#define COUNTER_SLOTS_PER_KERNEL 1
#include "../common/scene.glsl"
#include "../common/counters.glsl"
#include "../common/grid.glsl"
#include "tribox.glsl"

layout(std430, binding = SSBO_VOXEL_COUNT) coherent buffer VoxelCount { uint voxelCount[]; };

uint truncated = 0u;

void registerInVoxel(int voxID) { atomicAdd(voxelCount[voxID], 1u); }

#include "grid_overlap.glsl"

void main()
{
    countersBegin();
    int triID = int(gl_GlobalInvocationID.x);
    if (triID < triangleCount()) registerTriangle(triID);
    countAdd(0, truncated);
    countersEnd(0, COUNTER_TRUNCATED_RAYS);
}
