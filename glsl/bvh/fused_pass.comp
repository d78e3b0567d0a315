// One pass of Müller 2015's Fig. 8 loop (intersect1, Listings 13 and 14, intersect2 with
// Listing 15, shading with Listing 16) in one kernel, for the SAH BVH with one tree — ours, the
// BVH's default pass (docs/listings.md); the pass itself: bvh/fused.glsl. A
// work group per block of the entry pass' first list, the blocks whose rays may hit
// (bvh/fused_lists.glsl); the closest hit is the walk of bvh/intersect1.comp, whose test gives
// the hit's t, u and v.
#include "int64.glsl"
#include "fused.glsl"
#include "fused_lists.glsl"

void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
    walkFromEntry(storePos, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
}

void main()
{
    traceList(0u);
}
