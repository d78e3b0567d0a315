// One pass of Müller 2015's Fig. 8 loop in one kernel, for the SAH BVH (ours; its default, the
// four kernels with `--four-kernels`, docs/listings.md): the body its entry files share. Per pixel the
// closest hit (intersect1, the SAH BVH's walk of bvh/intersect1.comp: the entry file's
// closestHit), its evaluation (Listings 13 and 14: common/intersect1_hit.glsl's hitTexels, with
// the t, u and v the walk's test of the closest triangle found — bvh/evaluate_hit.comp finds
// the same again from the hit record), a shadow feeler towards every light and light sample
// (Listing 15: common/feeler.glsl, the walk of bvh/intersect2.comp) and the shading (Listing 16:
// mueller2015/shade.glsl) — the same functions on the same values as the four kernels, so the
// same image and counts. What it saves is the traffic between them: the four-kernel pass
// stores the hit's four ray-state texels, loads them again in every intersect2 dispatch and in
// shading, and stores and loads the shadow flags; on llvmpipe each stored texel costs more
// than a node step (docs/design/frame.md). Here the values stay in registers; a pass stores
// the ray state only where a reflection pass follows (storeRayState), and the first pass
// the AOVs' texels where the host keeps AOVs (STORE_AOVS). The blocks' entry points
// (bvh/entry.comp) run before it; without AOVs both compute the eye rays in place
// (bvh/pass_ray.glsl).
//
// The variants are entry files over this body, each defining closestHit and main
// (src/accel/bvh/mod.rs, fused_kernels): with one tree the entry pass also sorts the blocks
// into those whose rays may hit and those whose rays cannot (bvh/block_lists.glsl), and
// bvh/fused_pass.comp runs a work group per block of the first list, bvh/fused_miss.comp (no
// walk) per block of the second (bvh/fused_lists.glsl); with two levels
// bvh/fused_instances.comp runs an invocation per pixel and finds the hit's instance again
// from its record.
//
// The work counts go to per-pixel records (bvh/records.glsl), which pixel_counts.comp adds to
// the counter bank of each ray kind: the closest-hit search's packed in words 0–1 of record 0
// (packCounts, as intersect1's; no hit record: nothing reads it after this kernel); the
// feelers towards the first light packed in its words 2–3 where that light is a point light
// (FIRST_LIGHT_PACKED: one feeler a pixel, so one store of the record for both kinds), else
// unpacked in record RECORD_FIRST_LIGHT (an area light's samples: several feelers a pixel);
// the other lights' unpacked in record RECORD_OTHER_LIGHTS (plainRecords in pixel_counts).
#include "../common/intersect_head.glsl"
#include "records.glsl"
#include "traverse.glsl"
#include "entries.glsl"
#include "vertex_attributes.glsl"
#include "../common/intersect1_hit.glsl"
#include "hit_record.glsl"
#include "../common/feeler.glsl"
#include "pass_ray.glsl"
// the lights, their shadow slots and Listing 16's lighting, as shading.comp has them
#include "../mueller2015/shade.glsl"

#if PASS_EYE_RAYS
// the eye rays in place: the first pass, whose ray state is stored where a reflection pass
// follows (ours: as constants, llvmpipe leaves out the output colour's load and the stores
// where they are not needed instead of running them under an empty lane mask; the loaded
// variant, which serves the first pass with AOVs and the reflection passes, takes uniforms)
const int storeRayState = EYE_PASS_STORES_RAYS;
const int firstPass = 1;
#else
// 1 where a reflection pass follows this one: the rays' state is stored for it
uniform int storeRayState;
// 1 in the first pass of a frame
uniform int firstPass;
#endif

// What triangleHit does with a triangle of the walk (its ray: rayO, rayD of bvh/traverse.glsl):
// with anyHit unset, keep the closest hit (bvh/intersect1.comp's triangleHit); with it set, end
// the walk at the first triangle on the feeler's segment (bvh/intersect2.comp's).
int rayLast = -1;
bool anyHit = false;
float rayLight = 0.0;
float bestT = 0.0;
int bestID = -1;
int bestAt = -1;
// the closest hit's barycentrics, as its test found them (ours: kept for the hit's evaluation)
float bestU = 0.0, bestV = 0.0;

bool triangleHit(int at, int tri, vec3 v0, vec3 edge1, vec3 edge2, inout float limit)
{
    float t, u, v;
    bool hit = intersectEdges(rayO, rayD, v0, edge1, edge2, t, u, v);
    if (tri == rayLast) return false;
    tests++;
    if (anyHit) return hit && t > SHADOW_OFFSET && t < rayLight;
    if (hit && (t < bestT || (t == bestT && tri < bestID))) {
        bestT = t;
        bestID = tri;
        bestAt = at;
        bestU = u;
        bestV = v;
    }
    limit = bestT;
    return false;
}

// The closest hit of the pass' ray (t_min +inf, triID −1, hit_u and hit_v 0 where none),
// which the entry file defines, as the grids' intersect1 define theirs
// (common/intersect1_main.glsl).
void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                inout float t_min, inout int triID, inout float hit_u, inout float hit_v);

// The walk of bvh/intersect1.comp from the ray's block's entry: the closest hit in bestT,
// bestID, bestU, bestV and its hit record in bestAt (a closestHit of the entry files).
void walkFromEntry(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                   inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
    rayLast = lastTriID;
    bestT = t_min; bestID = triID;
    float limit = bestT;
    traverseScene(ro, rd, 0.0, limit, bvhRecord(entryTexel(storePos >> 3)));
    t_min = bestT; triID = bestID; hit_u = bestU; hit_v = bestV;
}

bool occluded(ivec2 storePos, vec3 ro, vec3 rd, float lightDistance, int lastTriID)
{
    rayLast = lastTriID; rayLight = lightDistance;
    return traverseScene(ro, rd, SHADOW_OFFSET, lightDistance, uvec4(0u)); // from the root
}

// The work counts of one kind so far, unpacked (tests, nodes, rays, truncated), and the
// globals of common/intersect_head.glsl cleared for the next kind.
uvec4 takeCounts()
{
    uvec4 c = uvec4(tests, nodesVisited, raysTraced, truncated);
    tests = 0u; nodesVisited = 0u; raysTraced = 0u; truncated = 0u;
    return c;
}

// The feelers of the hit at p (normal n, triangle id) towards every point light and every
// area light's samples (the slots of shade.glsl), their counts added to first (light 0's,
// Bank::occluded) and others.
uvec4 feelers(ivec2 storePos, vec3 p, vec3 n, int id, inout uvec4 first, inout uvec4 others)
{
    uvec4 blocked = uvec4(0u);
    anyHit = true;
    for (int l = 0; l < lightCount; l++) {
        if (feelerBlocked(storePos, p, n, id, pointLightPos(l)))
            blocked[l >> 5] |= 1u << uint(l & 31);
        if (l == 0) first += takeCounts(); else others += takeCounts();
    }
    // (no loop of no pass: Mesa 22.3 kept a loop over AREA_LIGHTS = 0 with its walk, and
    // llvmpipe ran its first pass under an empty lane mask — measured in
    // docs/design/frame.md, the fused pass' table)
#if AREA_LIGHTS > 0
    for (int a = 0; a < AREA_LIGHTS; a++) {
        for (int r = 0; r < areaSamples; r++) {
            int s = lightCount + a * areaSamples + r;
            if (feelerBlocked(storePos, p, n, id, areaLightSample(a, r)))
                blocked[s >> 5] |= 1u << uint(s & 31);
            if (lightCount + a == 0) first += takeCounts(); else others += takeCounts();
        }
    }
#endif
    return blocked;
}

// (tests, nodes, rays, truncated) packed as packCounts does (at most one ray)
uvec2 packedCounts(uvec4 c) { return packCounts(c.x, c.y, c.w, c.z); }

void storeRecords(ivec2 storePos, uvec4 primary, uvec4 first, uvec4 others)
{
    int at = pixelIndex(storePos);
#if FIRST_LIGHT_PACKED
    storeRecordPairs(at, packedCounts(primary), packedCounts(first));
#else
    pixelRecord[at].xy = packedCounts(primary);
    pixelRecord[RECORD_FIRST_LIGHT * IMAGE_WIDTH * IMAGE_HEIGHT + at] = first;
#endif
#if RECORD_OTHER_LIGHTS > 0
    pixelRecord[RECORD_OTHER_LIGHTS * IMAGE_WIDTH * IMAGE_HEIGHT + at] = others;
#endif
}

// The pass' AOV texels where the host keeps AOVs (the first hit's: storeFirstHit): the normal,
// and where the hit was lit its shadow flags in the layout of the shadow texture.
void storeAovs(ivec2 storePos, vec4 normal, bool lit, uvec4 blocked)
{
#if STORE_AOVS
    imageStore(normalTexture, storePos, normal);
    if (lit) storeBlockedSlots(storePos, blocked);
#endif
}

// The pass for one pixel (the declaration of common/intersect_head.glsl).
void trace(ivec2 storePos)
{
    uvec4 primary = uvec4(0u), first = uvec4(0u), others = uvec4(0u);
    vec4 originState, dirTri;
    passRay(storePos, originState, dirTri);
    float rayState = originState.w;
    // an inactive ray: nothing to trace, an empty colour buffer, nothing to shade
    if (rayState > 0.0) {
        raysTraced = 1u;
        vec3 ro = originState.xyz, rd = dirTri.xyz;
        float t = 1.0 / 0.0; // +inf
        int id = -1;
        float u = 0.0, v = 0.0;
        closestHit(storePos, ro, rd, int(dirTri.w), t, id, u, v);
        primary = takeCounts();

        storeFirstHit(storePos, t, id, u, v);
        vec4 hitPoint, dirOut, normal, colorWeight, mat;
        hitTexels(ro, rd, rayState, t, id, u, v, hitPoint, dirOut, normal, colorWeight, mat);

        vec3 temp_color = colorWeight.rgb; // a miss: the background
        bool lit = hitPoint.w > 0.0;
        uvec4 blocked = uvec4(0u);
        if (lit) {
            blocked = feelers(storePos, hitPoint.xyz, normal.xyz, id, first, others);
            temp_color = litColor(hitPoint.xyz, normal.xyz, mat, colorWeight.rgb, blocked);
        }
        // the output colour so far: none in the first pass, whose texture the host cleared
        // (ours: one load fewer where llvmpipe loads every texel)
        vec4 final_color = vec4(0.0);
        if (firstPass == 0) final_color = imageLoad(finalTexture, storePos);
        imageStore(finalTexture, storePos, addToFinal(final_color, temp_color, colorWeight.w));
        storeAovs(storePos, normal, lit, blocked);
        if (storeRayState != 0) {
            // shading's decrement of the rayState (Listing 16's kernel)
            hitPoint.w = max(hitPoint.w - 1.0, 0.0);
            imageStore(rayOriginTexture, storePos, hitPoint);
            imageStore(rayDirTexture, storePos, dirOut);
        }
    }
    storeRecords(storePos, primary, first, others);
}
