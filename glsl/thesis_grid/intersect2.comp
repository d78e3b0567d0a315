// intersect2 kernel of the thesis grid — Müller 2015, ch. 3.2.1 (Fig. 10) and 4.2.3: the
// shadow feeler's voxel list (from the traversal kernel in shadow mode) is walked and the
// triangles of the listed voxels tested until the first occluder (any hit). Feeler set-up,
// N·L early out and flags: common/intersect2_main.glsl (Listing 15).
#include "../common/intersect_head.glsl"
#include "../common/count_work.glsl"
#include "../common/grid.glsl"

// The thesis' block names (Listing 19), though VerticesInVoxel holds triangle ids (N³ lists of
// voxel_array_length) and ContainedVertices the fill level of each voxel's list.
layout(std430, binding = SSBO_VOXELSLIST) readonly buffer VerticesInVoxel { int voxelslist[]; };
layout(std430, binding = SSBO_VOXELCONTAINS) readonly buffer ContainedVertices { int voxelcontains[]; };
layout(std430, binding = SSBO_RAYSLIST) readonly buffer RaysList { int rayslist[]; };
layout(std430, binding = SSBO_RAYCONTAINS) readonly buffer RayContains { int raycontains[]; };

bool occluded(ivec2 storePos, vec3 ro, vec3 rd, float lightDistance, int lastTriID)
{
    int threadID = storePos.y * imageSize(rayOriginTexture).x + storePos.x;
    int start = threadID * ray_array_length;
    // `<`, not Listing 22's `<=` (see thesis_grid/intersect1.comp)
    int voxellist_last = start + raycontains[threadID];
    int j = start;
    bool shadow = false;
    for (; j < voxellist_last && !shadow; j++) {
        int voxID = rayslist[j];
        if (voxID < 0) continue;
        voxelsVisited++;
        int start_vertex = voxID * voxel_array_length;
        int vertexlist_last = start_vertex + voxelcontains[voxID];
        for (int i = start_vertex; i < vertexlist_last && !shadow; i++) {
            int tri = voxelslist[i];
            if (tri < 0) break;
            if (tri == lastTriID) continue;
            float t, u, v;
            tests++;
            shadow = intersectTriangle(ro, rd, vertex[3 * tri].xyz, vertex[3 * tri + 1].xyz,
                                       vertex[3 * tri + 2].xyz, t, u, v)
                  && t > SHADOW_OFFSET && t < lightDistance;
        }
    }
    if (!shadow && j < voxellist_last) truncated = 1u;
    return shadow;
}

#include "../common/intersect2_main.glsl"
