// BVH traversal shared by glsl/bvh/intersect1.comp and intersect2.comp — ours, after Wagner
// 2018 ch. 4.2 (ray–AABB slab test, Listing 4.5; depth-first traversal of the SAH BVH built on
// the CPU, ch. 3.2). CPU twin: src/reference/bvh.rs (Bvh::traverse), same order and counts.
//
// The hierarchy in texture buffers, as Wagner's three textures of Fig. 4.3 (his node bounds,
// node integers and per-leaf triangle ids), plus the miss links:
//   bvhNodes  two RGBA32F texels per node: (lo, first) and (hi, meta), the integers as bits;
//             an inner node's left child is `first`, its right child first + 1, its meta
//             −1 − the split axis; a leaf's triangles are leaf slots first .. first + meta − 1
//   bvhLinks  R32I, 8 per node: where a ray of each octant goes on when it misses the node or
//             is done with it (−1: the walk is over)
//   bvhLeafTriangles  three RGBA32F texels per leaf slot: (v0, triangle id), edge1, edge2
//
// Order (a deviation from Wagner, who visits both children and goes on with the nearer hit,
// and from a stack walk): stackless. Every inner node whose box the ray enters (at some
// 0 <= t <= limit) is followed by its near child — the left one, on the low side of the split
// plane, unless the ray points down the split axis — and every box missed, or beyond the
// limit, and every leaf done is followed by its miss link: a depth-first walk, near side first,
// pruned by the closest hit so far (or the light). On llvmpipe a per-invocation stack array
// costs several times more than these texel fetches (docs/results/bvh_steps.md). Each node is
// visited at most once, so the loop is bounded by the node count; a walk cut short (llvmpipe's
// loop limit, see loopLimit in common/intersect.glsl) counts the ray as truncated.
//
// The including kernel defines leafHit (declared below), which tests a leaf's triangles, may
// lower the limit, and returns true to end the walk.

layout(binding = SAMPLER_BVH_NODES) uniform samplerBuffer bvhNodes;
layout(binding = SAMPLER_BVH_LINKS) uniform isamplerBuffer bvhLinks;
layout(binding = SAMPLER_BVH_LEAF_TRIANGLES) uniform samplerBuffer bvhLeafTriangles;

bool leafHit(int first, int count, inout float limit);

// 1/rd with zero (and tiny) components replaced by 1e-20: the slab test never computes 0·inf.
float safeInverse(float d) { return 1.0 / (abs(d) < 1e-20 ? 1e-20 : d); }

// Listing 4.5: does the ray enter the box [lo, hi] at some 0 <= t <= limit?
bool boxEntered(vec3 lo, vec3 hi, vec3 ro, vec3 inv, float limit)
{
    vec3 t0 = (lo - ro) * inv;
    vec3 t1 = (hi - ro) * inv;
    float tNear = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    float tFar = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    return tNear <= tFar && tNear <= limit;
}

// Algorithm 1 of Müller 2015 with the edges read from the leaf triangle: intersectEdges of
// common/intersect.glsl, the same operations on the same values as intersectTriangle.
bool intersectLeafTriangle(vec3 r0, vec3 rd, int slot, out int id, out float t, out float u,
                           out float v)
{
    vec4 v0id = texelFetch(bvhLeafTriangles, 3 * slot);
    vec3 edge1 = texelFetch(bvhLeafTriangles, 3 * slot + 1).xyz;
    vec3 edge2 = texelFetch(bvhLeafTriangles, 3 * slot + 2).xyz;
    id = floatBitsToInt(v0id.w);
    return intersectEdges(r0, rd, v0id.xyz, edge1, edge2, t, u, v);
}

// true if leafHit ended the walk
bool traverse(vec3 ro, vec3 rd, float limit)
{
    vec3 inv = vec3(safeInverse(rd.x), safeInverse(rd.y), safeInverse(rd.z));
    int octant = (inv.x < 0.0 ? 1 : 0) | (inv.y < 0.0 ? 2 : 0) | (inv.z < 0.0 ? 4 : 0);
    int node = 0;
    int bound = textureSize(bvhNodes) / 2 + 1;
    for (int guard = 0; guard < bound; guard++) {
        if (node < 0) return false;
        nodesVisited++;
        vec4 loFirst = texelFetch(bvhNodes, 2 * node);
        vec4 hiMeta = texelFetch(bvhNodes, 2 * node + 1);
        int first = floatBitsToInt(loFirst.w), meta = floatBitsToInt(hiMeta.w);
        if (boxEntered(loFirst.xyz, hiMeta.xyz, ro, inv, limit)) {
            if (meta < 0) {
                // inner node: the near child next
                node = first + (inv[-1 - meta] < 0.0 ? 1 : 0);
                continue;
            }
            if (leafHit(first, meta, limit)) return true;
        }
        node = texelFetch(bvhLinks, 8 * node + octant).x;
    }
    if (node >= 0) truncated = 1u;
    return false;
}
