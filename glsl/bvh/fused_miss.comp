// One pass of Müller 2015's Fig. 8 loop in one kernel for the SAH BVH with one tree (ours, the
// BVH's default pass; the pass: bvh/fused.glsl) over the entry pass' second
// list: the blocks whose rays all miss the tree's root, or none of whose rays is active
// (bvh/fused_lists.glsl). Their walk, which would visit nothing from the empty entry, is left
// out — no hit — and with it the compiler folds away the hit's evaluation, its feelers and its
// shading: the pass stores the background colour and the counts of a ray that visited nothing.
#include "int64.glsl"
#include "fused.glsl"
#include "fused_lists.glsl"

void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
}

void main()
{
    traceList(1u);
}
