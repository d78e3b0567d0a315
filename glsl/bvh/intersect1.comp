// intersect1 kernel of the BVH — ours, after Wagner 2018 ch. 3.2 (SAH BVH, eq. 4.1) and 4.2
// (traversal, Möller–Trumbore Listing 4.2 = Müller's Algorithm 1): the closest hit of each ray
// by an ordered traversal of the CPU-built BVH (bvh/traverse.glsl), from its block's entry
// point (bvh/entry.comp, ours: Reshetov et al. 2005). Deviations: see there;
// equal distances go to the lower triangle id, as in the base tracer's loop, so the image
// equals the base tracer's. Listings 13, 14 of Müller 2015: bvh/evaluate_hit.comp
// (bvh/intersect1_main.glsl).
#include "int64.glsl"
#include "../common/intersect_head.glsl"
#include "records.glsl"
// the work counts stored per pixel (storePixelRecord), not added to the counters
#include "record_work.glsl"
#include "traverse.glsl"

// the entry point of each 8×8 block of rays (bvh/entry.comp, run before this kernel)
#include "entries.glsl"

// the ray's last triangle and its closest hit so far, for triangleHit: its distance, triangle
// id and the word address of its leaf triangle (the hit record; u and v are found again from
// it); the ray itself: rayO, rayD of bvh/traverse.glsl
int rayLast = -1;
float bestT = 0.0;
int bestID = -1;
int bestAt = -1;

bool triangleHit(int at, int tri, vec3 v0, vec3 edge1, vec3 edge2, inout float limit)
{
    float t, u, v;
    bool hit = intersectEdges(rayO, rayD, v0, edge1, edge2, t, u, v);
    if (tri == rayLast) return false;
    tests++;
    if (hit && (t < bestT || (t == bestT && tri < bestID))) {
        bestT = t;
        bestID = tri;
        bestAt = at;
    }
    limit = bestT;
    return false;
}

void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
    rayLast = lastTriID;
    bestT = t_min; bestID = triID;
    float limit = bestT;
    traverseScene(ro, rd, 0.0, limit, bvhRecord(entryTexel(storePos >> 3)));
    t_min = bestT; triID = bestID;
    closestHitRecord = bestAt;
}

// an invocation per pixel, its work in the pixel's record
bool workItem(out ivec2 storePos, out int record)
{
    storePos = pixelPosition();
    record = pixelIndex(storePos);
    return insideImage(storePos);
}

#include "intersect1_main.glsl"
