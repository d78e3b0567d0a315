// The entry point of each block of intersect1's rays — ours, not in Wagner 2018, whose kernel
// walks every ray from the root (ch. 4.2): the entry points of Reshetov, Soupikov and Hurley's
// multi-level ray tracing (MLRTA, SIGGRAPH 2005), found for the 8×8 pixels of each work group
// of bvh/intersect1.comp before it runs. CPU twin: src/reference/bvh/entry.rs
// (RayBounds::may_enter, Bvh::block_entry), bit for bit (one tree; the instances' entries below
// have no twin: tests/bvh_instances.rs holds their hits to the CPU reference).
//
// One invocation per block (pixels 8bx .. 8bx + 7, 8by .. 8by + 7 of the image; 8: the pixel
// kernels' work groups, PIXEL_GROUP on the host, as in common/images.glsl): it bounds the
// block's active rays by the smallest and largest origin coordinate and 1/direction per axis
// (where they all share one octant; else the block has no entry), then goes down the octant's
// records from the root while the bounds can enter only one child of the node (mayEnter):
// every ray of the block misses the other child, whose subtree its own walk would enter
// nowhere. Where both children may be entered, or at a leaf, it stops and stores (octant, the
// node's record, the texel after its subtree: its miss link); where the bounds miss the root,
// or both children of a node, an empty walk (record = end). The block's rays walk that subtree
// only (bvh/traverse.glsl) and find the hits of a walk from the root, visiting fewer nodes. The
// octant is stored plus one: a block without an entry stores 0, as do the entry texels before
// the first dispatch (the host uploads zeros; bvh/entries.glsl), and its rays walk from their
// roots.
//
// Two levels (BVH_INSTANCES, ours): the block's bounds are taken into each instance's object
// space (instanceBounds) and its tree is descended as above; the block stores the entry of the
// instance where the descent went deepest, tagged with its instance + 1 (entry.w), and its rays
// walk that instance's tree from there, the other instances' from their roots
// (bvh/traverse.glsl's traverseScene); no descent below a root: no entry.
//
// The kernel is timed as part of intersect1; what it saves there and what it costs:
// docs/design/bvh.md, step 26.
#include "../common/images.glsl"
#define BVH_WORDS_WRITABLE
#include "words.glsl"
#include "octant.glsl"

layout(local_size_x = BVH_ENTRY_GROUP) in;

#include "entries.glsl"
#include "pass_ray.glsl"

// the block's rays: per axis the smallest and largest 1/direction and origin (in the space of
// the tree descended), and the divisors of safeInverse in world space
vec3 invLo = vec3(0.0), invHi = vec3(0.0), roLo = vec3(0.0), roHi = vec3(0.0);
vec3 dLo = vec3(0.0), dHi = vec3(0.0);
// the grid of the records' planes (plane q of axis a at gridOrigin[a] + q·gridStep[a])
vec3 gridOrigin = vec3(0.0), gridStep = vec3(0.0);

// The bounds of the block's active rays (dLo, dHi, roLo, roHi); false if it has none. Ours,
// for llvmpipe: per axis the smallest and largest divisor of safeInverse (a nonzero rd), whose
// inverses are the bounds of the rays' 1/rd — 1/x falls on either side of 0, and rounding
// keeps the order — so that a ray costs no division; inactive rays, and pixels out of the
// image (inactive: bvh/pass_ray.glsl), count for nothing.
bool bound(ivec2 block)
{
    const float inf = 1.0 / 0.0;
    dLo = vec3(inf); dHi = vec3(-inf);
    roLo = vec3(inf); roHi = vec3(-inf);
    for (int k = 0; k < 64; k++) {
        ivec2 p = block * 8 + ivec2(k & 7, k >> 3);
        vec4 originState, dirTri;
        passRay(p, originState, dirTri);
        vec3 d = safeDivisors(dirTri.xyz);
        if (originState.w > 0.0) { // active, as intersect1 traces it
            dLo = min(dLo, d); dHi = max(dHi, d);
            roLo = min(roLo, originState.xyz); roHi = max(roHi, originState.xyz);
        }
    }
    invLo = 1.0 / dHi; invHi = 1.0 / dLo;
    return dLo.x <= dHi.x;
}

// The octant of the bounds' rays, or −1 where they point up and down one axis (two octants or
// more: no entry, every ray walks from its root).
int boundsOctant()
{
    return any(lessThan(dLo * sign(dHi), vec3(0.0))) ? -1 : rayOctant(dLo);
}

// The distances from the rays' origins to the planes at world coordinates w, bounded over the
// rays: the interval products of w − origin and 1/direction, per axis.
void distanceBounds(vec3 w, out vec3 lo, out vec3 hi)
{
    vec3 p0 = w - roHi, p1 = w - roLo;
    vec3 c0 = p0 * invLo, c1 = p0 * invHi, c2 = p1 * invLo, c3 = p1 * invHi;
    lo = min(min(c0, c1), min(c2, c3));
    hi = max(max(c0, c1), max(c2, c3));
}

// May a ray of the bounds enter the box of `record` (from t = 0 on)? false only where the
// bounds' latest slab entry comes after their earliest exit (or the exit before 0), widened by
// a margin: per axis 4 grid steps and 2^-18 of the magnitudes of the grid's extent, its origin
// and the rays' origins, as a distance at the bounds' largest |1/d|. A ray's own boxEntered and
// these bounds err by a few roundings of those magnitudes, so a box refused here is one that
// every ray of the bounds misses by more than a step (RayBounds::may_enter).
bool mayEnter(uvec4 record)
{
    vec3 near, far;
    recordPlanes(record, near, far);
    vec3 scale = abs(gridOrigin) + gridStep * 65535.0 + max(abs(roLo), abs(roHi));
    vec3 margin = (gridStep * 4.0 + scale * 3.814697265625e-6) * max(abs(invLo), abs(invHi));
    vec3 nearLo, nearHi, farLo, farHi;
    distanceBounds(gridOrigin + near * gridStep, nearLo, nearHi);
    distanceBounds(gridOrigin + far * gridStep, farLo, farHi);
    vec3 tNears = nearLo - margin, tFars = farHi + margin;
    float tNear = max(max(max(tNears.x, tNears.y), tNears.z), 0.0);
    float tFar = min(min(tFars.x, tFars.y), tFars.z);
    return !(tFar < 0.0 || tNear > tFar);
}

// The entry of the bounds' rays in the records of `octant` of the tree whose header is at
// texel `base`: (octant + 1, first record, end, 0); `depth`: the levels it went down.
uvec4 entryPoint(int octant, int base, out int depth)
{
    uvec4 header = bvhRecord(base);
    gridOrigin = uintBitsToFloat(header.yzw);
    gridStep = uintBitsToFloat(bvhRecord(base + 1).xyz);
    int nodes = int(header.x);
    int n = base + BVH_HEADER_WORDS / 4 + octant * nodes;
    uvec4 record = bvhRecord(n); // n's
    bool empty = !mayEnter(record);
    depth = 0;
    // down one level a step, while n is an inner node (the tree's depth is below the node count)
    for (int d = 0; !empty && int(record.w) >= 0 && d < nodes; d++) {
        // an inner node's near child is the next record, its far child the near child's miss
        // link (a leaf's: the record after it)
        int near = n + 1;
        uvec4 nearRecord = bvhRecord(near);
        int far = int(nearRecord.w) < 0 ? near + 1 : int(nearRecord.w);
        uvec4 farRecord = bvhRecord(far);
        bool nearEntered = mayEnter(nearRecord), farEntered = mayEnter(farRecord);
        if (nearEntered && farEntered) break;
        empty = !nearEntered && !farEntered;
        if (!empty) {
            n = nearEntered ? near : far;
            record = nearEntered ? nearRecord : farRecord;
            depth++;
        }
    }
    // the texel after n's subtree: its miss link (a leaf's: the next record)
    int reference = int(record.w);
    int end = reference < 0 ? n + 1 : reference;
    return uvec4(uint(octant + 1), uint(empty ? end : n), uint(end), 0u);
}

#if BVH_INSTANCES
// The interval of r.xyz·x + r.w·w over the box lo <= x <= hi, widened by 2^-20 of the
// magnitudes of its terms and by 10^-19 per unit of |r.xyz|: it holds instanceRay's rounded
// dot product of every x in the box, and of x's with components below safeInverse's 1e-20 where
// the box holds their divisors (bvh/words.glsl).
vec2 rowBounds(vec4 r, float w, vec3 lo, vec3 hi)
{
    vec3 a = r.xyz * lo, b = r.xyz * hi;
    vec3 small = min(a, b), large = max(a, b);
    float terms = dot(abs(r.xyz), max(abs(lo), abs(hi))) + abs(r.w * w);
    float margin = terms * 9.5367431640625e-7 + 1e-19 * dot(abs(r.xyz), vec3(1.0));
    return vec2(small.x + small.y + small.z + r.w * w - margin,
                large.x + large.y + large.z + r.w * w + margin);
}

// The world bounds (wdLo, wdHi: divisors; wroLo, wroHi: origins) in instance k's object space,
// as roLo, roHi, invLo, invHi; its octant, or −1 where the bounds' directions point up and down
// an axis or come within 1e-18 of 0 on one (where safeInverse would change them).
int instanceBounds(int k, vec3 wdLo, vec3 wdHi, vec3 wroLo, vec3 wroHi)
{
    int at = 1 + k * BVH_INSTANCE_TEXELS + 2;
    vec4 r0 = uintBitsToFloat(bvhRecord(at));
    vec4 r1 = uintBitsToFloat(bvhRecord(at + 1));
    vec4 r2 = uintBitsToFloat(bvhRecord(at + 2));
    vec2 ox = rowBounds(r0, 1.0, wroLo, wroHi), oy = rowBounds(r1, 1.0, wroLo, wroHi);
    vec2 oz = rowBounds(r2, 1.0, wroLo, wroHi);
    vec2 dx = rowBounds(r0, 0.0, wdLo, wdHi), dy = rowBounds(r1, 0.0, wdLo, wdHi);
    vec2 dz = rowBounds(r2, 0.0, wdLo, wdHi);
    roLo = vec3(ox.x, oy.x, oz.x); roHi = vec3(ox.y, oy.y, oz.y);
    vec3 lo = vec3(dx.x, dy.x, dz.x), hi = vec3(dx.y, dy.y, dz.y);
    // min(|x|) over [lo, hi] per axis: 0 where the interval holds 0
    vec3 nearest = max(max(lo, -hi), vec3(0.0));
    if (any(lessThan(nearest, vec3(1e-18)))) return -1;
    invLo = 1.0 / hi; invHi = 1.0 / lo;
    return rayOctant(lo);
}

// The block's entry: that of the instance whose tree its bounds go deepest into, with its
// instance + 1 in w; none where no descent leaves a root.
uvec4 blockEntry()
{
    vec3 wdLo = dLo, wdHi = dHi, wroLo = roLo, wroHi = roHi;
    uvec4 best = uvec4(0u);
    int deepest = 0;
    for (int k = 0; k < BVH_INSTANCE_COUNT; k++) {
        int octant = instanceBounds(k, wdLo, wdHi, wroLo, wroHi);
        if (octant < 0) continue;
        int depth;
        uvec4 e = entryPoint(octant, int(bvhRecord(1 + k * BVH_INSTANCE_TEXELS).w), depth);
        if (depth > deepest) {
            deepest = depth;
            best = uvec4(e.xyz, uint(k + 1));
        }
    }
    return best;
}
#else
// The block's entry in the one tree, where its rays share an octant.
uvec4 blockEntry()
{
    int octant = boundsOctant(), depth;
    return octant < 0 ? uvec4(0u) : entryPoint(octant, 0, depth);
}
#endif

#if BVH_BLOCK_LISTS
#include "block_lists.glsl"
// Block b into list 1 where none of its rays can hit (no active ray, or an empty walk:
// node = end), else into list 0 (bvh/block_lists.glsl).
void listBlock(int b, bool rays, uvec4 entry)
{
    uint list = !rays || (entry.x != 0u && entry.y == entry.z) ? 1u : 0u;
    uint at = atomicAdd(blockWords[BLOCK_LIST_COUNTS + list], 1u);
    blockWords[blockListWord(list, at)] = uint(b);
}
#endif

void main()
{
    int b = int(gl_GlobalInvocationID.x);
    if (b >= BVH_ENTRY_TEXELS) return;
    ivec2 block = ivec2(b % BVH_BLOCKS_X, b / BVH_BLOCKS_X);
    bool rays = bound(block);
    uvec4 entry = rays ? blockEntry() : uvec4(0u);
    imageStore(bvh, entryTexel(block), entry);
#if BVH_BLOCK_LISTS
    listBlock(b, rays, entry);
#endif
}
