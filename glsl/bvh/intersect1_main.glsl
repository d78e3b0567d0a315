// The SAH BVH's intersect1 around its closest-hit search, which bvh/intersect1.comp defines
// before including this file: Müller 2015's intersect1 (common/intersect1_main.glsl, ch. 4.1.2)
// with two changes (ours). It only stores the closest hit: closestHit leaves closestHitRecord,
// which traceAndCount stores with the pixel's counts (bvh/records.glsl), and
// bvh/evaluate_hit.comp evaluates it (Listings 13 and 14, common/intersect1_hit.glsl) and
// empties an inactive ray's colour buffer. And on llvmpipe it loads the next work group's rays
// ahead.

// Latency hiding on llvmpipe (ours; PREFETCH_RAYS, set where the implementation's profile asks
// for it, Profile::prefetch_rays — the grids' intersect1 keep the thesis' loads): each
// invocation also loads the ray texels of its place in the next work group, 8
// pixels on in x — the group the same llvmpipe thread runs next (its share of a dispatch is a
// contiguous run of work groups, row by row) — so that they are in the core's caches when that
// group starts: the first use of an invocation's own ray texels is where a SIMD group's walk
// waits for its ray (docs/design/frame.md; docs/design/bvh.md, step 21). One group ahead, not
// two; in intersect1 only. Their values are folded into `truncated` through
// prefetchZero, a uniform the host never sets (GL makes it 0 at link time), so that the
// compiler must keep the loads and nothing changes. Out of the image the loads are invalid
// (GL 4.6 §8.26: R, G, B zero, A undefined): no result depends on their values.
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
    if (originState.w <= 0.0) return; // an inactive ray: bvh/evaluate_hit.comp
    raysTraced = uint(COUNTS_RAY);
    float t_min = 1.0 / 0.0; // +inf
    int triID = -1;
    float hit_u = 0.0, hit_v = 0.0;
    closestHit(storePos, originState.xyz, dirTri.xyz, int(dirTri.w), t_min, triID, hit_u, hit_v);
}

void main()
{
    traceAndCount(COUNTER_INTERSECT1);
}
