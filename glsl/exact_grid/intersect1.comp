// intersect1 kernel of the exact grid — ours, after Müller 2015 ch. 4.2.3 (Listing 22): the
// ray walks the grid with a 3D-DDA (exact_grid/dda.glsl) and tests the triangles of each voxel's
// compact list with Algorithm 1. Unlike the thesis, a hit ends the walk only if it lies inside
// the current voxel (t <= the voxel's exit parameter): a hit beyond it could be hidden by a
// triangle of a later voxel. Equal distances go to the lower triangle id, as in the base
// tracer's loop, so the image equals the base tracer's. Listings 13, 14:
// common/intersect1_main.glsl.
#include "../common/intersect_head.glsl"
#include "../common/count_work.glsl"
#include "../common/grid.glsl"
#include "dda.glsl"

void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
    Walk w;
    if (!beginWalk(ro, rd, 1.0 / 0.0, w)) return;
    bool ended = false;
    for (int guard = 0; guard < 3 * voxel_amount + 3; guard++) {
        int voxID = getVoxelID(w.voxel);
        voxelsVisited++;
        uint first = voxelStart[voxID], last = first + voxelCount[voxID];
        for (uint k = first; k < last; k++) {
            int tri = voxelTris[k];
            if (tri == lastTriID) continue;
            float t, u, v;
            tests++;
            if (intersectTriangle(ro, rd, vertex[3 * tri].xyz, vertex[3 * tri + 1].xyz,
                                  vertex[3 * tri + 2].xyz, t, u, v)
                && (t < t_min || (t == t_min && tri < triID))) {
                t_min = t;
                triID = tri;
                hit_u = u; hit_v = v;
            }
        }
        // a hit inside this voxel is the closest; otherwise go on
        if (triID >= 0 && t_min <= voxelExit(w)) { ended = true; break; }
        if (!stepWalk(w)) { ended = true; break; }
    }
    if (!ended) truncated = 1u;
}

#include "../common/intersect1_main.glsl"
