// The intersect1 kernel of the tracer designs with an acceleration structure (thesis grid,
// exact grid, BVH) — Müller 2015, ch. 4.1.2 — around the closest-hit search of the design
// (Listing 22 for the thesis grid, a 3D-DDA for the exact grid, a BVH walk), which the
// including kernel defines before including this file:
//     void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
//                     inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
// It adds its work to the globals of common/intersect_head.glsl. The evaluation of the hit
// (Listings 13 and 14) is in common/intersect1_hit.glsl; the base tracer's kernel
// (brute_force/intersect1.comp, Listing 12) calls it directly. With HIT_RECORDS (ours, the
// SAH BVH) the kernel only stores the closest hit (common/records.glsl) and
// common/evaluate_hit.comp evaluates it.
#include "intersect1_hit.glsl"

// Latency hiding on llvmpipe (ours; PREFETCH_RAYS, set by the host for the SAH BVH's intersect1
// where GL_RENDERER names llvmpipe — the grids' intersect1 keep the thesis' loads): each
// invocation also loads the ray texels of its place in the next work group, 8
// pixels on in x — the group the same llvmpipe thread runs next (its share of a dispatch is a
// contiguous run of work groups, row by row) — so that they are in the core's caches when that
// group starts: the first use of an invocation's own ray texels is where a SIMD group's walk
// waits for its ray (docs/design/frame.md; docs/design/bvh.md, step 21). One group ahead, not
// two; in intersect1 only. Their values are folded into `truncated` through
// prefetchZero, a uniform the host never sets (GL makes it 0 at link time), so that the
// compiler must keep the loads and nothing changes. Out of the image, imageLoad reads zeros.
#if PREFETCH_RAYS
uniform uint prefetchZero;
#endif
uint prefetchNextGroup(ivec2 storePos)
{
#if PREFETCH_RAYS
    ivec2 next = storePos + ivec2(8, 0); // gl_WorkGroupSize.x (common/intersect_head.glsl)
    uint o = floatBitsToUint(imageLoad(rayOriginTexture, next).w);
    uint d = floatBitsToUint(imageLoad(rayDirTexture, next).w);
    return (o ^ d) & prefetchZero;
#else
    return 0u;
#endif
}

void trace(ivec2 storePos)
{
    vec4 originState = imageLoad(rayOriginTexture, storePos);
    vec4 dirTri = imageLoad(rayDirTexture, storePos);
    truncated |= prefetchNextGroup(storePos);
    float rayState = originState.w;
    if (rayState <= 0.0) {
#if !HIT_RECORDS
        emptyColorBuffer(storePos);
#endif
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
#if HIT_RECORDS
    // closestHit left closestHitRecord: traceAndCount stores it with the counts
#else
    evaluateHit(storePos, ro, rd, rayState, t_min, triID, hit_u, hit_v);
#endif
}

void main()
{
    traceAndCount(COUNTER_INTERSECT1);
}
