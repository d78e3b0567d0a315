// The evaluation of the closest hit as a kernel of its own (ours) — Müller 2015, ch. 4.1.2,
// Listings 13 and 14, which the thesis runs at the end of intersect1 (evaluateHit in
// common/intersect1_hit.glsl, unchanged), for the SAH BVH, whose intersect1 stores hit records
// (bvh/records.glsl): one invocation per pixel reads its ray from the
// ray-state textures, finds its closest hit (t, triangle id, u, v) again from the hit record
// (bvh/hit_record.glsl), and evaluates it exactly as the thesis' intersect1 does; an inactive
// ray (rayState <= 0) gets an empty colour buffer. The host dispatches it right after
// intersect1, under the same ray kind, with the BVH's word buffer still bound. Ours too: it
// appends the pixels with a hit — the feelers of the pass — to the hit list
// (bvh/hit_list.glsl).
#if HIT_LIST_BALLOT
#extension GL_ARB_shader_ballot : require
#extension GL_ARB_gpu_shader_int64 : require
#endif
layout(local_size_x = 8, local_size_y = 8) in;

#define SCENE_QUALIFIER readonly
#include "../common/scene.glsl"
#include "../common/images.glsl"
#include "../common/intersect.glsl"
#include "records.glsl"
#include "vertex_attributes.glsl"
#include "../common/intersect1_hit.glsl"
// a hit record: a leaf-triangle address
#include "hit_record.glsl"

#include "hit_list.glsl"

#if HIT_LIST_BALLOT
// This invocation's pixel appended to the pass' hit list (bvh/hit_list.glsl) if its ray hit:
// the subgroup's hits as one mask (GL_ARB_shader_ballot, where the profile takes it:
// Profile::hit_list_ballot), one reservation for them all, each hit's place its rank in the
// mask — a run of entries is one subgroup's block. Every invocation calls it, in uniform
// control flow, hit or not.
// Safe by construction (ours): GL_ARB_shader_ballot defines readInvocationARB's result only
// where the lane read is active, and says nothing of when lanes that took different sides of
// a branch run together again (NVIDIA's subgroups of 32 schedule their lanes independently,
// Volta on; SPIR-V under zink promises no reconvergence at a merge). So no branch stands
// between the ballot and the read: the only branch, on `total`, is uniform (the ballot's
// value is the same in every lane), and every lane of the subgroup runs the atomic — the
// first lane with a hit adds the subgroup's count, the others 0 — so the lane read, which
// has a hit, is active at the read whatever the scheduling.
void appendHit(ivec2 storePos, bool hit)
{
    uvec2 mask = unpackUint2x32(ballotARB(hit));
    uvec2 below = mask & unpackUint2x32(gl_SubGroupLtMaskARB);
    uint rank = uint(bitCount(below.x) + bitCount(below.y));
    // the lowest lane with a hit (lane 0 where none has one: its base is not used)
    uint first = mask.x != 0u ? uint(findLSB(mask.x))
               : mask.y != 0u ? 32u + uint(findLSB(mask.y)) : 0u;
    uint total = uint(bitCount(mask.x) + bitCount(mask.y));
    if (total > 0u) {
        uint mine = atomicAdd(hitWords[HIT_LIST_COUNT],
                              total * uint(gl_SubGroupInvocationARB == first));
        uint base = readInvocationARB(mine, first);
        if (hit) hitWords[HIT_LIST_ENTRIES + base + rank] = uint(pixelIndex(storePos));
    }
}
#else
// The same with a shared counter: each hit's place in the work group's run, one global atomic
// the run's place in the list (every invocation of the work group calls it: its barriers).
shared uint groupHits;
shared uint groupBase;
void appendHit(ivec2 storePos, bool hit)
{
    if (gl_LocalInvocationIndex == 0u) groupHits = 0u;
    memoryBarrierShared();
    barrier();
    uint at = hit ? atomicAdd(groupHits, 1u) : 0u;
    memoryBarrierShared();
    barrier();
    if (gl_LocalInvocationIndex == 0u) groupBase = atomicAdd(hitWords[HIT_LIST_COUNT], groupHits);
    memoryBarrierShared();
    barrier();
    if (hit) hitWords[HIT_LIST_ENTRIES + groupBase + at] = uint(pixelIndex(storePos));
}
#endif

void main()
{
    ivec2 storePos = pixelPosition();
    bool hit = false;
    if (insideImage(storePos)) {
        vec4 originState = imageLoad(rayOriginTexture, storePos);
        float rayState = originState.w;
        if (rayState <= 0.0) {
            emptyColorBuffer(storePos);
        } else {
            vec3 ro = originState.xyz;
            vec3 rd = imageLoad(rayDirTexture, storePos).xyz;
            float t, u, v;
            int id;
            hitFromRecord(int(pixelRecord[pixelIndex(storePos)].z), ro, rd, t, id, u, v);
            evaluateHit(storePos, ro, rd, rayState, t, id, u, v);
            hit = id >= 0;
        }
    }
    appendHit(storePos, hit);
}
