// BVH traversal shared by glsl/bvh/intersect1.comp and intersect2.comp — ours, after Wagner
// 2018 ch. 4.2 (ray–AABB slab test, Listing 4.5; depth-first traversal of the SAH BVH built on
// the CPU, ch. 3.2). CPU twin: src/reference/bvh/mod.rs (BvhTree::traverse), same order and counts
// (of one tree; the two levels of traverseScene have none, tests/bvh_instances.rs).
//
// The hierarchy in one image buffer of 32-bit words, after Wagner's textures of Fig. 4.3 (his
// node bounds, node integers and per-leaf triangle ids), read as RGBA32UI texels of 4 words
// (BvhTree::gpu_words; the types, field by field, in src/accel/bvh/layout.rs):
//   Header, 8 words (BVH_HEADER_WORDS): node_count N, grid_origin x, y, z, grid_step x, y, z,
//             zero (plane q of axis a lies at grid_origin[a] + q·grid_step[a]);
//   for each ray octant o (bit a set: the ray points down axis a) a copy of the N nodes in
//             that octant's depth-first order (the near child of every split first), one
//             NodeRecord each, one texel (BVH_NODE_WORDS), octant o's from texel 2 + o·N on:
//             the box as the planes where rays of the octant enter its slabs (near) and leave
//             them (far), 16-bit step counts on the grid — words near.x | near.y << 16,
//             near.z | far.x << 16, far.y | far.z << 16 — and `reference`: in an inner node its
//             miss link (the texel of the record where a ray goes on when it misses the node;
//             2 + o·N + N: the walk is over), in a leaf −1 − (s·32 + count), its triangles from
//             entry s of the leaf triangles on. An inner node's near child is the next record,
//             its far child the near child's miss link, and a leaf's miss link is the next
//             record;
//   then a LeafTriangle per leaf entry, 12 words (BVH_TRIANGLE_WORDS): v0, id, edge1, zero1,
//             edge2, zero2;
//   then an EntryTexel per block of the image (bvh/entries.glsl).
// (BVH_HEADER_WORDS, BVH_NODE_WORDS, BVH_TRIANGLE_WORDS, BVH_LEAF_COUNT_BITS: #defines of the
// host, src/accel/bvh/mod.rs. The Header is two texels, not uniforms: llvmpipe's uniform loads
// cost more than texel loads, docs/design/bvh.md, step 23.) A node step reads one texel, a triangle
// three (on llvmpipe each eight 128-bit loads, a transpose and a bounds check, where a 32-bit
// word costs a gather with its bounds check). Ours: the copies per octant (twice the memory of
// one 64-byte node with 8 links) save the texel of the links, the choice of the octant's link
// and near child, and the slab test's choice of planes (docs/design/bvh.md, step 16);
// the 16-bit planes (the box on the grid holds the node's float box: low planes rounded down,
// high ones up) save the second texel of a node, for two instructions more per plane (step 23).
//
// Order (a deviation from Wagner, who visits both children and goes on with the nearer hit,
// and from a stack walk): stackless. Every inner node whose box the ray enters (at some
// tMin <= t <= limit) is followed by its near child — the left one, on the low side of the split
// plane, unless the ray points down the split axis — and every box missed, or beyond the
// limit, and every leaf done is followed by its miss link: a depth-first walk, near side first,
// pruned by the closest hit so far (or the light). On llvmpipe a per-invocation stack array
// costs several times more than these loads (docs/design/bvh.md, steps 0 and 1).
//
// Two loops in a loop (ours; "while-while", Aila and Laine 2009): the inner node loop walks
// until the lane has entered a leaf or is done, the inner triangle loop then tests that leaf's
// triangles, and the outer loop goes on while the walk does. llvmpipe runs the 8 invocations of
// a SIMD group in lock step and executes both sides of an `if` under a lane mask, so each inner
// loop runs until its last lane leaves it, the others waiting: a lane that entered a leaf waits
// for the group's other lanes to enter theirs. That waiting costs less than the alternative, a
// single loop whose every iteration takes a node step or a triangle: there every lane pays
// Algorithm 1 and a triangle's texels in every step, where a node step reads one texel
// (docs/design/bvh.md, steps 5, 10 and 17). The walk's order and counts are the same either
// way. Each node is visited at most once, so the node steps are bounded by the records
// (`guard`, which also counts the nodes visited: no counter in the node loop), the triangle
// loop by its leaf's count (below 2^BVH_LEAF_COUNT_BITS), and the outer loop by the node steps,
// as each of its passes takes one; a walk cut short (that bound, or llvmpipe's loop limit, see
// loopLimit in common/intersect.glsl) counts the ray as truncated.
//
// The loops are do-whiles (ours): Mesa 22.3's llvmpipe tests a loop's lane mask only at the end
// of an iteration, and an `if` around a loop did not skip it, so a loop entered with no lane
// left to run, or a `while` whose last lanes leave at its top, still executes one whole pass
// under an empty mask. As do-whiles — entered where every active lane has work (the first step
// of a walk, of its next leaf search), the triangle loop behind the lanes that entered a leaf —
// each loop's exit test is its back edge, and what is left is one triangle pass per SIMD group
// (the last outer pass, whose lanes all end their walk without a leaf) (docs/design/bvh.md,
// step 18). The outer loop's first pass needs no test of its own: the test inside it holds
// (node < end, guard = 0 < bound) unless the walk's block entry is empty (node == end,
// bvh/entry.comp: every ray of the block misses the root), and the outer loop goes on only with
// node < end and guard < bound.
//
// The including kernel defines triangleHit (declared below), which tests one leaf triangle
// (its word address, id, v0 and edges) against the walk's ray (rayO, rayD: in the space of the
// tree walked), may lower the limit, and returns true to end the walk. The kernels walk the
// scene by traverseScene (below): one tree, or with BVH_INSTANCES the tree of every object
// whose box the ray enters.

#include "words.glsl"
#include "octant.glsl"

bool triangleHit(int at, int id, vec3 v0, vec3 edge1, vec3 edge2, inout float limit);

// the ray of the walk, in the space of the tree walked (traverseScene sets it), for triangleHit
vec3 rayO = vec3(0.0), rayD = vec3(0.0);

// the word address of the first leaf triangle (after the records)
int triangleBase = 0;

// Listing 4.5: does the ray enter the box of `record` (its planes where the ray enters and
// leaves the slabs, 16-bit step counts on the grid) at some tMin <= t <= limit? (Wagner tests
// t >= 0; ours: a shadow feeler from tMin = SHADOW_OFFSET on, since intersect2 takes no hit
// before the offset, skips the boxes around its origin that it leaves before the offset.)
//
// Ours: the distance to plane q of axis a, (origin[a] + q·step[a] − ro[a])/rd[a], as
// q·gridA[a] + gridB[a], rounded after the product and after the sum (on llvmpipe, whose Mesa
// lowers fma so; a GL implementation that fuses them moves a distance by a rounding, and the
// twin's node counts with it, not the hits). In world units its rounding error is about 2^-23
// of the root's extent plus the ray origin's distance from the grid — where (plane − ro)·inv
// errs by 2^-24 of the distance to the plane — and the boxes' padding of 1e-5 of the scene's
// extent (src/accel/bvh/build.rs) covers it for origins within some 80 extents of the scene
// (docs/design/bvh.md, step 23).
//
// Ours: the largest entry and the smallest exit distance by integer max and min of the floats'
// bits — llvmpipe's float min and max are NaN-aware, three instructions each, the integer ones
// one. For t >= +0 the bits are in the order of the floats; the entry distance is at least
// tMin >= +0, and where an exit distance is negative so is the smallest of the bits: the box is
// missed either way (an exit at exactly −0.0 too: a box the ray leaves at its origin). No
// distance is NaN (safeInverse, and gridA and gridB clamped finite). The CPU twin (BvhTree::enter,
// RayGrid::t) computes the same bits.
bool boxEntered(uvec4 record, vec3 gridA, vec3 gridB, float tMin, float limit)
{
    vec3 near, far;
    recordPlanes(record, near, far);
    ivec3 tNears = floatBitsToInt(near * gridA + gridB);
    ivec3 tFars = floatBitsToInt(far * gridA + gridB);
    int tNear = max(max(tNears.x, tNears.y), max(tNears.z, floatBitsToInt(tMin)));
    int tFar = min(min(tFars.x, tFars.y), min(tFars.z, floatBitsToInt(limit)));
    return tNear <= tFar;
}

// One node step: where the walk goes after the record at texel `node` (its box entered or
// not) — the next record after an inner node entered (its near child) or a leaf (entered or
// not: a leaf's miss link is the next record), the miss link after an inner node missed. An
// entered leaf's reference goes to `leaf` (the triangles follow in the triangle loop).
void nodeStep(bool entered, int reference, inout int node, inout int leaf)
{
    bool inner = reference >= 0; // the miss link of an inner node, −1 − (s·32 + count) of a leaf
    leaf = entered && !inner ? reference : leaf;
    node = !entered && inner ? reference : node + 1;
}

// One pass of the node loop: the step of the record at texel `node`, and where that step goes
// on to the next record — after an inner node entered or a leaf missed — the step of that record
// too, whose texel is loaded and tested beside the first (ours). On llvmpipe the second
// record's independent load and test cost less than a pass of their own (docs/design/bvh.md,
// step 24). `steps`: 1 or 2, the
// nodes visited; the walk's order and counts are those of single steps. (At the octant's last
// record the second texel is the next octant's root or the first leaf triangle, or for an
// empty last octant past the buffer, which imageLoad reads as 0: loaded, never used.)
void nodePass(vec3 gridA, vec3 gridB, float tMin, float limit, int end,
              inout int node, inout int leaf, out int steps)
{
    uvec4 r0 = bvhRecord(node), r1 = bvhRecord(node + 1);
    bool e0 = boxEntered(r0, gridA, gridB, tMin, limit);
    bool e1 = boxEntered(r1, gridA, gridB, tMin, limit);
    int ref0 = int(r0.w), ref1 = int(r1.w);
    bool second = (ref0 >= 0) == e0 && node + 1 < end;
    steps = second ? 2 : 1;
    node += steps - 1;
    nodeStep(second ? e1 : e0, second ? ref1 : ref0, node, leaf);
}

// The triangle loop: the entered leaf's triangles at words slot, slot + BVH_TRIANGLE_WORDS, ...
// below slotEnd, one per pass (a do-while, entered only by lanes with a triangle to test; at
// most a leaf's count of passes); true if triangleHit ended the walk.
bool leafTriangles(inout int slot, int slotEnd, inout float limit)
{
    if (slot >= slotEnd) return false;
    do {
        uvec4 t0 = bvhTexel(slot), t1 = bvhTexel(slot + 4), t2 = bvhTexel(slot + 8);
        if (triangleHit(slot, int(t0.w), uintBitsToFloat(t0.xyz), uintBitsToFloat(t1.xyz),
                        uintBitsToFloat(t2.xyz), limit))
            return true;
        slot += BVH_TRIANGLE_WORDS;
    } while (slot < slotEnd);
    return false;
}

// The start of a walk along ro + t·rd through the tree whose header is at texel `base` (0 with
// one level): the slab factors gridA, gridB (boxEntered), the first record `node` and the texel
// after the last, `end`, and the global triangleBase. `entry`: the entry point of the ray's block
// (bvh/entry.comp: its octant + 1, first record and the texel after its subtree) — a ray of that
// octant walks that subtree only, the others (and every ray where entry.x is 0, no entry, as in
// intersect2) the whole tree.
void treeStart(vec3 ro, vec3 rd, uvec3 entry, int base, out vec3 gridA, out vec3 gridB,
               out int node, out int end)
{
    vec3 inv = safeInverses(rd);
    int octant = rayOctant(inv);
    // the header: the node count N and the grid (plane q of axis a at origin[a] + q·step[a])
    uvec4 header = bvhRecord(base);
    vec3 gridOrigin = uintBitsToFloat(header.yzw);
    vec3 gridStep = uintBitsToFloat(bvhRecord(base + 1).xyz);
    int nodes = int(header.x);
    triangleBase = 4 * base + BVH_HEADER_WORDS + 8 * BVH_NODE_WORDS * nodes;
    // a slab's distances: q·gridA + gridB for its planes q (boxEntered), the factors clamped to
    // the finite floats (an overflow to ±inf could make 0·inf or inf − inf; Grid::ray)
    const float finite = 3.40282347e38;
    gridA = clamp(gridStep * inv, -finite, finite);
    gridB = clamp((gridOrigin - ro) * inv, -finite, finite);
    // the root: the first record of the octant's copy; end: the texel after its last
    node = base + BVH_HEADER_WORDS / 4 + octant * nodes;
    end = node + nodes;
    if (int(entry.x) == octant + 1) {
        node = int(entry.y);
        end = int(entry.z);
    }
}

// One pass of the walk's outer loop: the node loop to the next leaf entered (or the walk's end)
// and that leaf's triangles (`slot`, `slotEnd`: those still to test); true if triangleHit ended
// the walk. `guard`: the node steps so far, below `bound`.
bool walkPass(vec3 gridA, vec3 gridB, float tMin, inout float limit, int end, inout int node,
              inout int guard, int bound, inout int slot, inout int slotEnd)
{
    int leaf = 0; // the leaf reference of the leaf entered (0: none yet)
    do {
        int steps;
        nodePass(gridA, gridB, tMin, limit, end, node, leaf, steps);
        guard += steps;
    } while (guard < bound && node < end && leaf == 0);
    int code = -1 - leaf; // s·32 + count: the leaf's triangles from entry s on
    slot = leaf < 0 ? triangleBase + BVH_TRIANGLE_WORDS * (code >> BVH_LEAF_COUNT_BITS) : 0;
    int count = leaf < 0 ? code & ((1 << BVH_LEAF_COUNT_BITS) - 1) : 0;
    slotEnd = slot + BVH_TRIANGLE_WORDS * count;
    return leafTriangles(slot, slotEnd, limit);
}

// The walk along ro + t·rd for tMin <= t <= limit through the tree whose header is at texel
// `base`, from `entry` (treeStart); true if triangleHit ended it; `limit` as triangleHit left it.
bool traverse(vec3 ro, vec3 rd, float tMin, inout float limit, uvec3 entry, int base)
{
    vec3 gridA, gridB;
    int node, end;
    treeStart(ro, rd, entry, base, gridA, gridB, node, end);
    // the entered leaf's triangles still to test: at words slot, slot + BVH_TRIANGLE_WORDS, ...
    // below slotEnd
    int slot = 0, slotEnd = 0;
    // every node of the octant visited at most once, and each takes one of the buffer's
    // texels; guard: the node steps so far (the nodes visited)
    int bound = imageSize(bvh) + 1;
    int guard = 0;
    do {
        // The outer loop's own test, again (it holds in every pass a lane takes): without it
        // llvmpipe changed the state of lanes that had left the loop at the end of an earlier
        // pass while other lanes went on — a lane whose walk ended at the leaf it entered
        // (miss link END) was left with untested triangles (tests/edge_cases.rs, the tie scene).
        if (guard < bound && node < end) {
            if (walkPass(gridA, gridB, tMin, limit, end, node, guard, bound, slot, slotEnd)) {
                nodesVisited += uint(guard);
                return true;
            }
        }
    } while (guard < bound && node < end);
    nodesVisited += uint(guard);
    // (slot < slotEnd: llvmpipe's loop limit can still cut a triangle loop short)
    if (node < end || slot < slotEnd) truncated = 1u;
    return false;
}

#if BVH_INSTANCES
// Two levels: the next instance from k on whose world box the ray ro + t·rd (1/direction
// `inv`) enters at some tMin <= t <= limit (Listing 4.5 in floats; each box tested counts as a
// node visited), its walk started (treeStart, with the ray in its object space: rayO, rayD, and
// the block's entry where it is this instance's: entry.w = k + 1); the instance after it, or
// `count` where none is left (then node = end: no walk).
int nextInstance(int k, int count, vec3 ro, vec3 rd, vec3 inv, float tMin, float limit,
                 uvec4 entry, out vec3 gridA, out vec3 gridB, out int node, out int end)
{
    gridA = vec3(0.0); gridB = vec3(0.0);
    node = 0; end = 0;
    bool entered = false;
    int base = 0;
    while (k < count && !entered) {
        uvec4 lo = bvhRecord(1 + k * BVH_INSTANCE_TEXELS);
        vec3 hi = uintBitsToFloat(bvhRecord(2 + k * BVH_INSTANCE_TEXELS).xyz);
        vec3 t0 = (uintBitsToFloat(lo.xyz) - ro) * inv, t1 = (hi - ro) * inv;
        vec3 tNear = min(t0, t1), tFar = max(t0, t1);
        float enter = max(max(tNear.x, tNear.y), max(tNear.z, tMin));
        float leave = min(min(tFar.x, tFar.y), min(tFar.z, limit));
        nodesVisited++;
        entered = enter <= leave;
        base = int(lo.w);
        k++;
    }
    if (entered) {
        instanceRay(k - 1, ro, rd, rayO, rayD);
        uvec3 own = int(entry.w) == k ? entry.xyz : uvec3(0u);
        treeStart(rayO, rayD, own, base, gridA, gridB, node, end);
    }
    return k;
}
#endif

// The scene's walk along ro + t·rd for tMin <= t <= limit (the kernels' entry to the walk);
// true if triangleHit ended it; `limit` as triangleHit left it. `entry`: the ray's block entry
// (bvh/entries.glsl; 0: none). One level: the one tree, from the entry. Two levels
// (BVH_INSTANCES, ours: src/accel/bvh/instances.rs): the instances in the list's order, each
// whose world box the ray enters walked with the ray in the object's space, from the block's
// entry where it is this instance's, else from its root (nextInstance), the limit carried from
// one tree to the next. One loop for all the trees (ours): a lane whose tree is done starts its
// next instance in the next pass of the outer loop while the other lanes of its SIMD group go
// on with theirs — llvmpipe runs the lanes in lock step, and a loop per instance made every
// lane wait for the group's longest walk of each instance in turn (docs/design/bvh.md, "Two
// levels"). The thesis' scenes have 2–7 objects; a list of many would want a tree over the
// instances. One instance (BVH_INSTANCE_COUNT, the host's): its tree walked at once, without
// the instance loop or the world box (the root's box in object space stands in for it) —
// on llvmpipe the loop's instance switch costs every pass of the outer loop, under an empty
// lane mask where no lane switches.
bool traverseScene(vec3 ro, vec3 rd, float tMin, inout float limit, uvec4 entry)
{
#if BVH_INSTANCES && BVH_INSTANCE_COUNT == 1
    instanceRay(0, ro, rd, rayO, rayD);
    uvec3 own = entry.w == 1u ? entry.xyz : uvec3(0u);
    return traverse(rayO, rayD, tMin, limit, own, int(bvhRecord(1).w));
#elif BVH_INSTANCES
    const int count = BVH_INSTANCE_COUNT;
    vec3 inv = safeInverses(rd);
    vec3 gridA, gridB;
    int node, end;
    int k = nextInstance(0, count, ro, rd, inv, tMin, limit, entry, gridA, gridB, node, end);
    int slot = 0, slotEnd = 0;
    // every node of every tree visited at most once: as in traverse
    int bound = imageSize(bvh) + 1;
    int guard = 0;
    do {
        if (guard < bound && node < end) {
            if (walkPass(gridA, gridB, tMin, limit, end, node, guard, bound, slot, slotEnd)) {
                nodesVisited += uint(guard);
                return true;
            }
        }
        if (node >= end && k < count) {
            // (slot < slotEnd: llvmpipe's loop limit cut the last leaf of this tree short)
            if (slot < slotEnd) truncated = 1u;
            k = nextInstance(k, count, ro, rd, inv, tMin, limit, entry, gridA, gridB, node, end);
        }
    } while (guard < bound && (node < end || k < count));
    nodesVisited += uint(guard);
    // instances left unvisited count the ray as truncated too
    if (node < end || slot < slotEnd || k < count) truncated = 1u;
    return false;
#else
    rayO = ro; rayD = rd;
    return traverse(ro, rd, tMin, limit, entry.xyz, 0);
#endif
}
