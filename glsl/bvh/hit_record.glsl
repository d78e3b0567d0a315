// The SAH BVH's hit record (ours; bvh/records.glsl): intersect1 stores the word address of
// the closest hit's LeafTriangle in the BVH's buffer (−1: no hit; PixelRecord.hit in
// src/pipeline/mueller2015/records.rs), one word per pixel instead
// of (t, triangle id, u, v) — on llvmpipe each stored component is a loop over the 8 lanes —
// and bvh/evaluate_hit.comp finds the hit again here: the same Algorithm 1 (intersectEdges of
// common/intersect.glsl) on the same ray and the same words as the walk's triangleHit, so the
// same t, u and v. With two levels (BVH_INSTANCES) the leaf triangle is in its object's space
// and its zero1 word (t1.w) is its instance + 1 (src/accel/bvh/instances.rs): the ray is taken
// there as the walk took it (instanceRay), and the instance's normal matrix set for the hit
// evaluation (hitNormalMatrix, bvh/vertex_attributes.glsl, included before this file); with
// one level that word is 0.
#include "words.glsl"

void hitFromRecord(int at, vec3 ro, vec3 rd, out float t, out int id, out float u, out float v)
{
    t = 1.0 / 0.0; // +inf: no hit, as intersect1 starts
    id = -1;
    u = 0.0; v = 0.0;
    if (at < 0) return;
    uvec4 t0 = bvhTexel(at), t1 = bvhTexel(at + 4), t2 = bvhTexel(at + 8);
    id = int(t0.w);
    vec3 o = ro, d = rd;
#if BVH_INSTANCES
    int k = int(t1.w) - 1;
    instanceRay(k, ro, rd, o, d);
    // the rows of the inverse model matrix are the columns of its transpose
    int rows = 1 + k * BVH_INSTANCE_TEXELS + 2;
    hitNormalMatrix = mat3(uintBitsToFloat(bvhRecord(rows).xyz),
                           uintBitsToFloat(bvhRecord(rows + 1).xyz),
                           uintBitsToFloat(bvhRecord(rows + 2).xyz));
#endif
    intersectEdges(o, d, uintBitsToFloat(t0.xyz), uintBitsToFloat(t1.xyz),
                   uintBitsToFloat(t2.xyz), t, u, v);
}
