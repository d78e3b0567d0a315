// BVH traversal shared by glsl/bvh/intersect1.comp and intersect2.comp — ours, after Wagner
// 2018 ch. 4.2 (ray–AABB slab test, Listing 4.5; depth-first traversal of the SAH BVH built on
// the CPU, ch. 3.2). CPU twin: src/reference/bvh.rs (Bvh::traverse), same order and counts.
//
// Nodes (32 bytes, std430): bounds lo/hi; an inner node (count 0) names its left child in
// `first`, the right child is first + 1; a leaf names its first triangle id in bvhTris and
// holds `count` of them. Wagner kept the tree in three textures (Fig. 4.3): here it is one
// storage buffer of nodes and one of triangle ids.
//
// Order: of two children hit, the nearer (smaller entry distance; the left on a tie) is
// visited first, the other pushed with its entry distance; a node is skipped when its entry
// lies beyond the current limit (the closest hit so far, or the light). Deviations from
// Wagner: an ordered traversal with pruning (his visits children in fixed order), a bounded
// stack of BVH_STACK entries (a push onto a full stack drops the node and counts the ray as
// truncated; the builder keeps the depth below it) and a loop bounded by 2·nodes + 2
// iterations (each node is visited at most once), so no input can exceed llvmpipe's loop limit
// (see loopLimit in common/intersect.glsl).
//
// The including kernel defines leafHit (declared below), which tests a leaf's triangles, may
// lower the limit, and returns true to end the walk.

struct BvhNode { vec3 lo; int first; vec3 hi; int count; };
layout(std430, binding = SSBO_BVH_NODES) readonly buffer BvhNodeBuffer { BvhNode bvhNodes[]; };
layout(std430, binding = SSBO_BVH_TRIS) readonly buffer BvhTriBuffer { int bvhTris[]; };

#define BVH_STACK 64

bool leafHit(uint first, uint count, inout float limit);

// 1/rd with zero (and tiny) components replaced by 1e-20: the slab test never computes 0·inf.
float safeInverse(float d) { return 1.0 / (abs(d) < 1e-20 ? 1e-20 : d); }

// Listing 4.5: does the ray enter node n's box at some 0 <= t <= limit? tNear: the entry.
bool boxEntry(int n, vec3 ro, vec3 inv, float limit, out float tNear)
{
    vec3 t0 = (bvhNodes[n].lo - ro) * inv;
    vec3 t1 = (bvhNodes[n].hi - ro) * inv;
    tNear = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    float tFar = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    return tNear <= tFar && tNear <= limit;
}

// true if leafHit ended the walk
bool traverse(vec3 ro, vec3 rd, float limit)
{
    vec3 inv = vec3(safeInverse(rd.x), safeInverse(rd.y), safeInverse(rd.z));
    float tNear;
    if (!boxEntry(0, ro, inv, limit, tNear)) return false;
    int stackNode[BVH_STACK];
    float stackT[BVH_STACK];
    int sp = 0;
    int node = 0;
    int bound = 2 * bvhNodes.length() + 2;
    for (int guard = 0; guard < bound; guard++) {
        nodesVisited++;
        int first = bvhNodes[node].first, count = bvhNodes[node].count;
        bool descend = false;
        if (count > 0) {
            if (leafHit(uint(first), uint(count), limit)) return true;
        } else {
            float tl, tr;
            bool hl = boxEntry(first, ro, inv, limit, tl);
            bool hr = boxEntry(first + 1, ro, inv, limit, tr);
            if (hl && hr) {
                int near = first, far = first + 1;
                float tFar = tr;
                if (tr < tl) { near = first + 1; far = first; tFar = tl; }
                if (sp < BVH_STACK) { stackNode[sp] = far; stackT[sp] = tFar; sp++; }
                else truncated = 1u;
                node = near;
                descend = true;
            } else if (hl || hr) {
                node = hl ? first : first + 1;
                descend = true;
            }
        }
        // nothing to descend into: the nearest node on the stack still within reach
        while (!descend && sp > 0) {
            sp--;
            if (stackT[sp] <= limit) { node = stackNode[sp]; descend = true; }
        }
        if (!descend) return false;
    }
    truncated = 1u;
    return false;
}
