// intersect1 kernel of the thesis grid — Müller 2015, ch. 4.2.3, Listing 22.
// The ray's voxel list (rayslist, filled by the traversal kernel in traversal order) is walked;
// every triangle in every listed voxel's list (voxelslist) is tested with Algorithm 1. As in
// the thesis, the walk stops after the first voxel in which a hit was found, even if that hit
// lies beyond the voxel (where a closer triangle in a later voxel could hide it); the exact
// variant (exact_grid/intersect1.comp) does not. Listings 13, 14: common/intersect1_main.glsl.
#include "../common/intersect_head.glsl"
#include "../common/count_work.glsl"
#include "../common/grid.glsl"

// The thesis' block names (Listing 19), though VerticesInVoxel holds triangle ids (N³ lists of
// voxel_array_length) and ContainedVertices the fill level of each voxel's list.
layout(std430, binding = SSBO_VOXELSLIST) readonly buffer VerticesInVoxel { int voxelslist[]; };
layout(std430, binding = SSBO_VOXELCONTAINS) readonly buffer ContainedVertices { int voxelcontains[]; };
layout(std430, binding = SSBO_RAYSLIST) readonly buffer RaysList { int rayslist[]; };
layout(std430, binding = SSBO_RAYCONTAINS) readonly buffer RayContains { int raycontains[]; };

void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
    int threadID = storePos.y * imageSize(rayOriginTexture).x + storePos.x;
    int start = threadID * ray_array_length;
    // one past the ray's last voxel: Listing 22 loops `j <= voxellist_last` (and `i <=
    // vertexlist_last` below), which reads one entry past the stored ones (a -1 of the
    // re-initialised list, or the next list's first entry when the list is full); ours, `<`,
    // reads exactly the stored entries
    int voxellist_last = start + raycontains[threadID];
    int j = start;
    for (; j < voxellist_last; j++) {
        int voxID = rayslist[j];
        if (voxID >= 0) {
            voxelsVisited++;
            int start_vertex = voxID * voxel_array_length;
            int vertexlist_last = start_vertex + voxelcontains[voxID];
            for (int i = start_vertex; i < vertexlist_last; i++) {
                // current triangle; -1 marks the end of the list
                int tri = voxelslist[i];
                if (tri < 0) break;
                if (tri == lastTriID) continue;
                float t, u, v;
                tests++;
                // ours: equal distances go to the lower triangle id (Listing 22 does not say).
                // The build fills a voxel's list in no fixed order (atomicCompSwap), so
                // without it a tie would pick a triangle at random; with it, as Listing 12's
                // loop in id order
                if (intersectTriangle(ro, rd, vertex[3 * tri].xyz, vertex[3 * tri + 1].xyz,
                                      vertex[3 * tri + 2].xyz, t, u, v)
                    && (t < t_min || (t == t_min && tri < triID))) {
                    t_min = t;
                    triID = tri;
                    hit_u = u; hit_v = v;
                }
            }
            // a hit in this voxel: the rest of the list is discarded
            if (triID >= 0) break;
        }
    }
    if (triID < 0 && j < voxellist_last) truncated = 1u;
}

#include "../common/intersect1_main.glsl"
