// One pass of Müller 2015's Fig. 8 loop in one kernel for the SAH BVH's two levels (ours, the
// BVH's default pass with `--bvh-levels two`; the pass: bvh/fused.glsl): an
// invocation per pixel (no block lists: an instance's empty entry leaves the block's other
// instances to walk). The closest hit is the walk of bvh/intersect1.comp; its hit record then
// gives the hit's instance, whose normal matrix the hit's evaluation turns the normals with
// (bvh/hit_record.glsl; t, u and v come out as the walk's).
#include "int64.glsl"
#include "fused.glsl"

void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
    walkFromEntry(storePos, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
    closestHitRecord = bestAt;
    hitFromRecord(closestHitRecord, ro, rd, t_min, triID, hit_u, hit_v);
}

void main()
{
    ivec2 storePos = pixelPosition();
    if (insideImage(storePos)) trace(storePos);
}
