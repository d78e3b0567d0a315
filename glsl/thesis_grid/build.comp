// build kernel of the thesis grid — Müller 2015, ch. 3.2.3 (Fig. 14) and 4.2.1,
// Listings 17, 19 and 20, Algorithms 2 and 3.
// One invocation per triangle: the voxels of its three vertices are stored, and every edge
// whose end points lie in different voxels is walked through the grid (traverseConnection);
// the triangle id goes into the list of every voxel visited. A triangle is therefore
// registered only along its edges: a large triangle is missing from the voxels its interior
// covers (the thesis' limitation; the exact variant fixes it).
// voxelslist holds voxel_array_length entries per voxel, initialised to -1 with
// glClearBufferData every frame; a free entry is claimed with atomicCompSwap and the fill
// level kept with atomicMax (Listing 20). A full list drops the id: counted, not hidden.
layout(local_size_x = 128, local_size_y = 1, local_size_z = 1) in;

#define SCENE_QUALIFIER readonly
#define COUNTER_SLOTS_PER_KERNEL 2
#include "../common/scene.glsl"
#include "../common/counters.glsl"
#include "../common/grid.glsl"

// The thesis' block names (Listing 19), though VerticesInVoxel holds triangle ids (N³ lists of
// voxel_array_length) and ContainedVertices the fill level of each voxel's list. Bindings
// from src/gl/slots.rs: VerticesInVoxel 10 as Listing 19, ContainedVertices 11 where Listing 19
// has 12 (ours puts rayslist at 12 and raycontains at 13, the four lists in a row).
layout(std430, binding = SSBO_VOXELSLIST) coherent buffer VerticesInVoxel { int voxelslist[]; };
layout(std430, binding = SSBO_VOXELCONTAINS) coherent buffer ContainedVertices { int voxelcontains[]; };

// the triangle of this thread. Listing 19 has triID = 3 * gl_GlobalInvocationID.x, the index
// of its first vertex (as Listing 12's triID = i); ours is the triangle's index, as in every
// kernel here, in the AOVs (triangle_id.npy) and in export-triangles
int triID = int(gl_GlobalInvocationID.x);
uint dropped = 0u;
uint truncated = 0u;
// the vertices' voxels, stored first; the edge walks skip them
int vertexVoxels[3];

// Listing 20: claim the first free entry of the voxel's list for this triangle
void storeTriIDInVoxelsList(int voxID)
{
    // invalid voxel ids are ignored
    if (voxID >= 0) {
        int start = voxID * voxel_array_length; // first position of the list
        int end = start + voxel_array_length - 1; // last position
        bool stored = false;
        for (int i = start; i <= end; i++) {
            int read = atomicCompSwap(voxelslist[i], -1, triID);
            if (read == -1) {
                atomicMax(voxelcontains[voxID], i + 1 - start);
                stored = true;
                i = end + 1; // leave the loop
            }
        }
        if (!stored) dropped++;
    }
}

void storeVoxel(ivec3 voxel)
{
    int id = getVoxelID(voxel);
    if (id != vertexVoxels[0] && id != vertexVoxels[1] && id != vertexVoxels[2])
        storeTriIDInVoxelsList(id);
}

#include "voxelwalk.glsl"

void main()
{
    countersBegin();
    if (triID < triangleCount()) {
        vec3 v[3];
        ivec3 vox[3];
        for (int k = 0; k < 3; k++) {
            v[k] = toGridSpace(vertex[3 * triID + k].xyz);
            vox[k] = clampVoxel(getVoxel(v[k]));
            vertexVoxels[k] = -2; // not yet stored
        }
        // the voxels of the vertices, each once
        for (int k = 0; k < 3; k++) {
            int id = getVoxelID(vox[k]);
            if (id != vertexVoxels[0] && id != vertexVoxels[1] && id != vertexVoxels[2])
                storeTriIDInVoxelsList(id);
            vertexVoxels[k] = id;
        }
        // the edges whose end points lie in different voxels
        for (int k = 0; k < 3; k++) {
            int l = (k + 1) % 3;
            if (vox[k] != vox[l]) traverseConnection(v[k], v[l], vox[k], vox[l]);
        }
    }
    countAdd(0, dropped);
    countAdd(1, truncated);
    countersEnd(0, COUNTER_DROPPED_TRIANGLE_REFS);
    countersEnd(1, COUNTER_TRUNCATED_RAYS);
}
