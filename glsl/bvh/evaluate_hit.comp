// The evaluation of the closest hit as a kernel of its own (ours) — Müller 2015, ch. 4.1.2,
// Listings 13 and 14, which the thesis runs at the end of intersect1 (evaluateHit in
// common/intersect1_hit.glsl, unchanged), for the SAH BVH, whose intersect1 stores hit records
// (bvh/records.glsl): one invocation per pixel reads its ray from the
// ray-state textures, finds its closest hit (t, triangle id, u, v) again from the hit record
// (bvh/hit_record.glsl), and evaluates it exactly as the thesis' intersect1 does; an inactive
// ray (rayState <= 0) gets an empty colour buffer. The host dispatches it right after
// intersect1, under the same ray kind, with the BVH's word buffer still bound.
layout(local_size_x = 8, local_size_y = 8) in;

#define SCENE_QUALIFIER readonly
#include "../common/scene.glsl"
#include "../common/images.glsl"
#include "../common/intersect.glsl"
#include "records.glsl"
#include "../common/intersect1_hit.glsl"
// a hit record: a leaf-triangle address
#include "hit_record.glsl"

void main()
{
    ivec2 storePos = pixelPosition();
    if (!insideImage(storePos)) return;
    vec4 originState = imageLoad(rayOriginTexture, storePos);
    float rayState = originState.w;
    if (rayState <= 0.0) {
        emptyColorBuffer(storePos);
        return;
    }
    vec3 ro = originState.xyz;
    vec3 rd = imageLoad(rayDirTexture, storePos).xyz;
    float t, u, v;
    int id;
    hitFromRecord(int(pixelRecord[pixelIndex(storePos)].z), ro, rd, t, id, u, v);
    evaluateHit(storePos, ro, rd, rayState, t, id, u, v);
}
