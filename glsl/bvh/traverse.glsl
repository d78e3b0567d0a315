// BVH traversal shared by glsl/bvh/intersect1.comp and intersect2.comp — ours, after Wagner
// 2018 ch. 4.2 (ray–AABB slab test, Listing 4.5; depth-first traversal of the SAH BVH built on
// the CPU, ch. 3.2). CPU twin: src/reference/bvh/mod.rs (Bvh::traverse), same order and counts.
//
// The hierarchy in one image buffer of 32-bit words, after Wagner's textures of Fig. 4.3 (his
// node bounds, node integers and per-leaf triangle ids), addressed by word (Bvh::gpu_words in
// src/reference/bvh/mod.rs) and read as RGBA32UI texels of 4 words:
//   per node 16 words (BVH_NODE_WORDS, one 64-byte cache line): lo.xyz, first, hi.xyz, meta,
//             and the node's miss link for each of the 8 ray octants — where a ray of that
//             octant goes on when it misses the node or is done with it (−1: the walk is over);
//             an inner node's left child is at `first`, its right child at first + 16, its
//             meta −1 − the split axis; a leaf's meta is its triangle count and its triangles
//             start at `first`
//   after the nodes, per leaf triangle 12 words (BVH_TRIANGLE_WORDS): v0, triangle id, edge1, 0,
//             edge2, 0
// (BVH_NODE_WORDS and BVH_TRIANGLE_WORDS: #defines of the host, src/accel/bvh.rs.)
// A node and a triangle thus have their bounds / v0 in texel 0 (first / id in its w), hi / edge1
// in texel 1 and the miss links / edge2 from texel 2 on, and a step reads either with the same
// three texel loads (on llvmpipe: eight 128-bit loads and a transpose each, where a 32-bit word
// costs a gather with its bounds check).
//
// Order (a deviation from Wagner, who visits both children and goes on with the nearer hit,
// and from a stack walk): stackless. Every inner node whose box the ray enters (at some
// 0 <= t <= limit) is followed by its near child — the left one, on the low side of the split
// plane, unless the ray points down the split axis — and every box missed, or beyond the
// limit, and every leaf done is followed by its miss link: a depth-first walk, near side first,
// pruned by the closest hit so far (or the light). On llvmpipe a per-invocation stack array
// costs several times more than these loads (docs/results/bvh_steps.md).
//
// One step per iteration: a node, or one triangle of the leaf the walk entered last (ours:
// llvmpipe runs the 8 invocations of a SIMD group in lock step, so a leaf loop inside the node
// loop kept the other lanes waiting while one tested its leaf; here a lane tests its triangles
// while the others walk on). llvmpipe executes both sides of an `if` under a lane mask, so the
// step loads its texels once, before it knows whether they are a node's or a triangle's, and
// the outcome of the box test is chosen by selects. Since that step's triangle test costs every
// lane, an iteration then takes a second, node-only step for the lanes still walking (a third
// did not pay: docs/results/bvh_steps.md). Each node is visited at most once and each leaf
// triangle tested at most once, and every iteration takes at least one step, so the loop is
// bounded by their sum; a walk cut short (llvmpipe's loop limit, see loopLimit in
// common/intersect.glsl) counts the ray as truncated.
//
// The including kernel defines triangleHit (declared below), which tests one leaf triangle
// (its word address, id, v0 and edges), may lower the limit, and returns true to end the walk.

#include "words.glsl"

bool triangleHit(int at, int id, vec3 v0, vec3 edge1, vec3 edge2, inout float limit);

// 1/rd with zero (and tiny) components replaced by 1e-20: the slab test never computes 0·inf.
float safeInverse(float d) { return 1.0 / (abs(d) < 1e-20 ? 1e-20 : d); }

// Listing 4.5: does the ray enter the box [lo, hi] at some tMin <= t <= limit? (Wagner tests
// t >= 0; ours: a shadow feeler from tMin = SHADOW_OFFSET on, since intersect2 takes no hit
// before the offset, skips the boxes around its origin that it leaves before the offset.)
//
// Ours: the near and far plane of each slab chosen by the ray's direction (down: the axes the
// ray points down, 1/rd < 0) instead of by min and max of the two distances — the same values
// (lo <= hi and rounding is monotonic, so (lo − ro)·inv <= (hi − ro)·inv for inv > 0), which
// the CPU twin computes with min and max, in fewer instructions: llvmpipe's min and max are
// NaN-aware, three instructions each, a select one (docs/results/bvh_steps.md).
bool boxEntered(vec3 lo, vec3 hi, vec3 ro, vec3 inv, bvec3 down, float tMin, float limit)
{
    vec3 tNears = (mix(lo, hi, down) - ro) * inv;
    vec3 tFars = (mix(hi, lo, down) - ro) * inv;
    float tNear = max(max(tNears.x, tNears.y), max(tNears.z, tMin));
    float tFar = min(min(tFars.x, tFars.y), tFars.z);
    return tNear <= tFar && tNear <= limit;
}

// One node step: the box test of the node whose texels are t0, t1 and (its octant's miss links)
// t2, and where the walk goes next.
void nodeStep(uvec4 t0, uvec4 t1, uvec4 t2, vec3 ro, vec3 inv, int octant, float tMin,
              float limit, inout int node, inout int slot, inout int slotEnd)
{
    bvec3 down = lessThan(inv, vec3(0.0)); // the axes of the octant's bits
    int o = octant & 3;
    uint link = o == 0 ? t2.x : o == 1 ? t2.y : o == 2 ? t2.z : t2.w;
    nodesVisited++;
    vec3 lo = uintBitsToFloat(t0.xyz), hi = uintBitsToFloat(t1.xyz);
    bool entered = boxEntered(lo, hi, ro, inv, down, tMin, limit);
    int first = int(t0.w), meta = int(t1.w);
    bool leaf = meta >= 0;
    // an inner node entered: its near child next; a leaf entered: its triangles next
    int next = int(link);
    next = entered && !leaf ? first + BVH_NODE_WORDS * ((octant >> (-1 - meta)) & 1) : next;
    slot = entered && leaf ? first : slot;
    slotEnd = entered && leaf ? first + BVH_TRIANGLE_WORDS * meta : slotEnd;
    node = next;
}

// The walk along ro + t·rd for tMin <= t <= limit; true if triangleHit ended it.
bool traverse(vec3 ro, vec3 rd, float tMin, float limit)
{
    vec3 inv = vec3(safeInverse(rd.x), safeInverse(rd.y), safeInverse(rd.z));
    int octant = (inv.x < 0.0 ? 1 : 0) | (inv.y < 0.0 ? 2 : 0) | (inv.z < 0.0 ? 4 : 0);
    int node = 0;
    // the entered leaf's triangles still to test: at words slot, slot + BVH_TRIANGLE_WORDS, ...
    // below slotEnd
    int slot = 0, slotEnd = 0;
    // every node visited and every leaf triangle tested at most once; each takes at least
    // BVH_TRIANGLE_WORDS of the buffer's 4 words a texel
    int bound = 4 * imageSize(bvh) / BVH_TRIANGLE_WORDS + 1;
    for (int guard = 0; guard < bound && (node >= 0 || slot < slotEnd); guard++) {
        bool tri = slot < slotEnd;
        int at = tri ? slot : node;
        uvec4 t0 = bvhTexel(at), t1 = bvhTexel(at + 4);
        uvec4 t2 = bvhTexel(at + (tri ? 8 : 8 + (octant & 4)));
        if (tri) {
            if (triangleHit(slot, int(t0.w), uintBitsToFloat(t0.xyz), uintBitsToFloat(t1.xyz),
                            uintBitsToFloat(t2.xyz), limit))
                return true;
            slot += BVH_TRIANGLE_WORDS;
        } else {
            nodeStep(t0, t1, t2, ro, inv, octant, tMin, limit, node, slot, slotEnd);
        }
        if (slot >= slotEnd && node >= 0) {
            t0 = bvhTexel(node); t1 = bvhTexel(node + 4);
            t2 = bvhTexel(node + 8 + (octant & 4));
            nodeStep(t0, t1, t2, ro, inv, octant, tMin, limit, node, slot, slotEnd);
        }
    }
    if (node >= 0 || slot < slotEnd) truncated = 1u;
    return false;
}
