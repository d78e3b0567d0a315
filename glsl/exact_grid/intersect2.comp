// intersect2 kernel of the exact grid — ours, after Müller 2015 ch. 3.2.1 (Fig. 10): the
// shadow feeler walks the grid with a 3D-DDA from the hit point to the light and tests the
// triangles of each voxel until the first occluder (any hit). Feeler set-up, N·L early out
// and flags: common/intersect2_main.glsl (Listing 15).
#include "../common/intersect_head.glsl"
#include "../common/count_work.glsl"
#include "../common/grid.glsl"
#include "dda.glsl"

bool occluded(ivec2 storePos, vec3 ro, vec3 rd, float lightDistance, int lastTriID)
{
    Walk w;
    if (!beginWalk(ro, rd, lightDistance, w)) return false;
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
                && t > SHADOW_OFFSET && t < lightDistance)
                return true;
        }
        if (!stepWalk(w)) return false;
    }
    truncated = 1u;
    return false;
}

#include "../common/intersect2_main.glsl"
