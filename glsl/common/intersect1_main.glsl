// The intersect1 kernel of the tracer designs with an acceleration structure (thesis grid,
// exact grid) — Müller 2015, ch. 4.1.2 — around the closest-hit search of the design
// (Listing 22 for the thesis grid, a 3D-DDA for the exact grid), which the
// including kernel defines before including this file:
//     void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
//                     inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
// It adds its work to the globals of common/intersect_head.glsl. The evaluation of the hit
// (Listings 13 and 14) is in common/intersect1_hit.glsl; the base tracer's kernel
// (brute_force/intersect1.comp, Listing 12) calls it directly. (The SAH BVH's intersect1 only
// stores its closest hit: bvh/intersect1_main.glsl.)
#include "vertex_attributes.glsl"
#include "intersect1_hit.glsl"

void trace(ivec2 storePos)
{
    vec4 originState = imageLoad(rayOriginTexture, storePos);
    vec4 dirTri = imageLoad(rayDirTexture, storePos);
    float rayState = originState.w;
    if (rayState <= 0.0) {
        emptyColorBuffer(storePos);
        return;
    }
    raysTraced = uint(COUNTS_RAY);
    vec3 ro = originState.xyz;
    vec3 rd = dirTri.xyz;
    int lastTriID = int(dirTri.w);

    float t_min = 1.0 / 0.0; // +inf
    int triID = -1;
    float hit_u = 0.0, hit_v = 0.0;
    closestHit(storePos, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
    evaluateHit(storePos, ro, rd, rayState, t_min, triID, hit_u, hit_v);
}

void main()
{
    traceAndCount(COUNTER_INTERSECT1);
}
