// BVH traversal shared by glsl/bvh/intersect1.comp and intersect2.comp — ours, after Wagner
// 2018 ch. 4.2 (ray–AABB slab test, Listing 4.5; depth-first traversal of the SAH BVH built on
// the CPU, ch. 3.2). CPU twin: src/reference/bvh/mod.rs (Bvh::traverse), same order and counts.
//
// The hierarchy in image buffers of 32-bit words (R32UI), after Wagner's textures of Fig. 4.3
// (his node bounds, node integers and per-leaf triangle ids):
//   bvhNodes  16 words (one 64-byte cache line) per node: lo.xyz, first, hi.xyz, meta, and the
//             node's miss link for each of the 8 ray octants — where a ray of that octant goes
//             on when it misses the node or is done with it (−1: the walk is over); an inner
//             node's left child is `first`, its right child first + 1, its meta −1 − the split
//             axis; a leaf's triangles are leaf slots first .. first + meta − 1
//   bvhLeafTriangles  12 words per leaf slot: v0, triangle id, edge1, 0, edge2, 0
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
// while the others walk on). The node's words are all loaded before the box test, and the
// outcome is chosen by selects. Each node is visited at most once and each leaf slot tested at
// most once, so the loop is bounded by their sum; a walk cut short (llvmpipe's loop limit, see
// loopLimit in common/intersect.glsl) counts the ray as truncated.
//
// The including kernel defines triangleHit (declared below), which tests one leaf slot's
// triangle, may lower the limit, and returns true to end the walk.

layout(r32ui, binding = IMAGE_BVH_NODES) readonly uniform uimageBuffer bvhNodes;
layout(r32ui, binding = IMAGE_BVH_LEAF_TRIANGLES) readonly uniform uimageBuffer bvhLeafTriangles;

bool triangleHit(int slot, inout float limit);

uint nodeWord(int at) { return imageLoad(bvhNodes, at).x; }
float nodeFloat(int at) { return uintBitsToFloat(imageLoad(bvhNodes, at).x); }
float leafFloat(int at) { return uintBitsToFloat(imageLoad(bvhLeafTriangles, at).x); }
vec3 leafVec3(int at) { return vec3(leafFloat(at), leafFloat(at + 1), leafFloat(at + 2)); }

// 1/rd with zero (and tiny) components replaced by 1e-20: the slab test never computes 0·inf.
float safeInverse(float d) { return 1.0 / (abs(d) < 1e-20 ? 1e-20 : d); }

// Listing 4.5: does the ray enter the box [lo, hi] at some tMin <= t <= limit? (Wagner tests
// t >= 0; ours: a shadow feeler from tMin = SHADOW_OFFSET on, since intersect2 takes no hit
// before the offset, skips the boxes around its origin that it leaves before the offset.)
bool boxEntered(vec3 lo, vec3 hi, vec3 ro, vec3 inv, float tMin, float limit)
{
    vec3 t0 = (lo - ro) * inv;
    vec3 t1 = (hi - ro) * inv;
    float tNear = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), tMin));
    float tFar = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    return tNear <= tFar && tNear <= limit;
}

// Algorithm 1 of Müller 2015 with the edges read from the leaf triangle: intersectEdges of
// common/intersect.glsl, the same operations on the same values as intersectTriangle.
bool intersectLeafTriangle(vec3 r0, vec3 rd, int slot, out int id, out float t, out float u,
                           out float v)
{
    int at = 12 * slot;
    id = int(imageLoad(bvhLeafTriangles, at + 3).x);
    return intersectEdges(r0, rd, leafVec3(at), leafVec3(at + 4), leafVec3(at + 8), t, u, v);
}

// The walk along ro + t·rd for tMin <= t <= limit; true if triangleHit ended it.
bool traverse(vec3 ro, vec3 rd, float tMin, float limit)
{
    vec3 inv = vec3(safeInverse(rd.x), safeInverse(rd.y), safeInverse(rd.z));
    int octant = (inv.x < 0.0 ? 1 : 0) | (inv.y < 0.0 ? 2 : 0) | (inv.z < 0.0 ? 4 : 0);
    int node = 0;
    // the leaf slots of the entered leaf still to test: slot .. slotEnd - 1
    int slot = 0, slotEnd = 0;
    int bound = imageSize(bvhNodes) / 16 + imageSize(bvhLeafTriangles) / 12 + 1;
    for (int guard = 0; guard < bound && (node >= 0 || slot < slotEnd); guard++) {
        if (slot < slotEnd) {
            if (triangleHit(slot, limit)) return true;
            slot++;
            continue;
        }
        nodesVisited++;
        int at = 16 * node;
        int first = int(nodeWord(at + 3)), meta = int(nodeWord(at + 7));
        int next = int(nodeWord(at + 8 + octant));
        vec3 lo = vec3(nodeFloat(at), nodeFloat(at + 1), nodeFloat(at + 2));
        vec3 hi = vec3(nodeFloat(at + 4), nodeFloat(at + 5), nodeFloat(at + 6));
        bool entered = boxEntered(lo, hi, ro, inv, tMin, limit);
        bool leaf = meta >= 0;
        // an inner node entered: its near child next; a leaf entered: its triangles next
        next = entered && !leaf ? first + ((octant >> (-1 - meta)) & 1) : next;
        slot = entered && leaf ? first : slot;
        slotEnd = entered && leaf ? first + meta : slotEnd;
        node = next;
    }
    if (node >= 0 || slot < slotEnd) truncated = 1u;
    return false;
}
