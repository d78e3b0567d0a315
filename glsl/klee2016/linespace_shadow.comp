// linespace_shadow kernel — Klee 2016, ch. 4.1 (Fig. 7, second phase) and ch. 4.3:
// Algorithm 1 (preparation and traversal), Algorithm 2 (isIntersection), Algorithm 3
// (isNodeIntersection, after Kay–Kajiya), Algorithm 4 with Listing 3 (getEntry: the bit in the
// 3D R32UI line-space texture), Listing 1 (struct Stack) and Listing 2 (struct Shaft).
// One invocation per pixel: the pixel's position and normal come from the G-buffer; its
// SAMPLES_U × SAMPLES_V shadow rays towards the rectangular light form one packet that walks
// the N-tree slice by slice along the axis k (coherent grid traversal [WIK+06, KWH09]).
//   SHADOW_MODE 0 (exact):     line spaces only skip empty shafts; the leaves' triangles are
//                              tested (Table 2, "Schnitttests mit Dreiecken").
//   SHADOW_MODE 1 (linespace): at the last depth with line spaces, a set bit is a hit (the
//                              thesis' approximation, Table 2 "Linespace-Abfrage").
//   SHADOW_MODE 2 (linespace-dda): every ray alone with a hierarchical 3D-DDA [AW87] and the
//                              same line-space termination (Table 3).
//   SHADOW_MODE 3 (variant1):  Table 2's "Variante 1" as defined: mode 0 without our
//                              near-origin rule (NEAR_ORIGIN_RULE 0).
//   SHADOW_MODE 4 (variant2):  Table 2's "Variante 2" as defined: mode 1 without it — the
//                              deepest level is never visited, no triangle is tested.
//   SHADOW_MODE 5 (linespace-fast, FAST_PATH 1): ours, mode 1's answer for less work — two
//                              walks, the nodes away from the origin first (phase 0: cheap
//                              line-space hits), then the nodes near it (phase 1: exact tests)
//                              for the rays still unblocked; a leaf's triangles are taken one
//                              by one for all its rays, and one that no ray of the packet can
//                              cross (packetMisses: plane, light pyramid) is skipped for all.
// NEAR_ORIGIN_RULE and BIT_IS_HIT come from the host (ShadowMode::near_origin_rule, bit_is_hit).
// The node containing the rays' common origin has no entry side, hence no line-space entry:
// it is always descended and its leaves are tested exactly (not said in the thesis; without
// it every surface would shadow itself); so is a node within NEAR_MARGIN child cells of it.
// The shadow value (fraction of unblocked rays) goes to shadowTexture and, multiplied into
// the diffuse colour, back into the diffuse texture.
// loopLimit: Mesa's llvmpipe (and lavapipe, under zink) silently ends the loops of a SIMD vector
// of invocations (8 on a 256-bit CPU) after 65535 iterations, and the vector iterates while
// any of its lanes does, so nested loops that diverge cost the vector the sum of its lanes'
// iterations. The kernel stays below the limit instead of detecting it: every loop iteration
// is counted (WITHIN_BUDGET; initShaft's NUM_RAYS by the host) and an invocation stops past
// LOOP_BUDGET, which the host sets to the limit's share of one lane (Profile::loop_limit; no
// bound elsewhere), so no vector reaches the limit. (A sentinel loop after the work, which
// ended early if the limit had been reached, proved no guard: on zink the traversal's loops
// were cut while the sentinel still ran whole, and 174 of 2,294 pixels of the bunny at 10x10
// rays came out too light, unreported — docs/drivers.md.) A pixel past its budget is counted
// as truncated: its batch's lit count is not kept, nor are its counts added to the counters,
// and shadowTexture marks where the pixel goes on (.b: the batch's first ray, .a: the next
// attempt). The host then runs the pass again for the marked pixels alone (attempt 1, 2, …;
// the others return at once), each from its first ray not done, in batches of half as many
// rays (batchRays; one dispatch per batch, the lit counts summed in shadowTexture.g), until no
// pixel is truncated; a pixel truncated with one ray per batch is refused. The next frame
// starts each row of 8 pixels in the latest attempt that completed one of them (main). A ray's
// result does not depend on the other rays of its packet, so the batches give the same image,
// and every ray's work is counted once, in the batch that completes it (ours; the thesis' GPU
// had no such limit; docs/design/linespace.md, "Ray batches per pixel").
layout(local_size_x = 8, local_size_y = 8) in;

#define N NTREE_N
#define COUNTER_SLOTS_PER_KERNEL 16
#include "../common/counters.glsl"
#include "../common/light_samples.glsl"

#define GEOMETRY_BIT 1u
#define CHILDREN_BIT 2u
#define INF uintBitsToFloat(0x7F800000u)

// the G-buffer: position (xyz, w: 1 = geometry), normal (xyz, facing the camera), diffuse (rgb)
layout(rgba32f, binding = IMAGE_GBUFFER_POSITION) uniform readonly image2D positionTexture;
layout(rgba32f, binding = IMAGE_GBUFFER_NORMAL) uniform readonly image2D normalTexture;
layout(rgba32f, binding = IMAGE_GBUFFER_DIFFUSE) uniform image2D diffuseTexture;
// r: shadow value, g: lit rays, b and a: where a truncated pixel goes on (main)
layout(rgba32f, binding = IMAGE_SHADOW_VALUE) uniform image2D shadowTexture;
// bit r (of 128) set where a batch that completed a pixel with geometry began at ray r: how
// its rays were split, which the CPU twin follows to count as the GPU did
layout(rgba32ui, binding = IMAGE_SHADOW_BATCHES) uniform uimage2D batchTexture;
// the line spaces, packed as Listing 3
layout(r32ui, binding = IMAGE_LINESPACE) uniform readonly uimage3D linespaceTexture;
// The node pool (Fig. 8–9): texture buffer, red = flags | child group << 2, green = line space.
layout(binding = SAMPLER_NODE_POOL) uniform usamplerBuffer nodePool;
layout(std430, binding = SSBO_TRI_VERTEX) readonly buffer TriangleBuffer { vec4 triVertex[]; };
layout(std430, binding = SSBO_LEAF_TRIANGLES) readonly buffer LeafTriangleBuffer {
    uint leafTriangles[];
};

uniform vec3 minBound;       // ntree.minBound
uniform float invNodeSize;   // ntree.invNodeSize (1 / edge of a child of the root)
uniform vec3 lightCorner;
uniform vec3 lightEdgeU;
uniform vec3 lightEdgeV;
uniform vec3 lightColor;
uniform vec3 ambient;
uniform int fig7Shading;     // 1: Fig. 7's s · diffuse (--klee-shading fig7); 0: ours (lit)
uniform float shadowOffset;
uniform int tex_x_res;
uniform int tex_y_res;
uniform int ls_y_size;
uniform ivec2 tileOffset;
uniform int batchRays;       // the rays of a batch (NUM_RAYS: the whole packet at once)
uniform int batchIndex;      // this dispatch's batch of the attempt, from the pixel's first ray
uniform int attempt;         // 0: every pixel; a > 0: the pixels truncated in attempt a − 1
// this invocation's rays: rayBegin <= r < rayEnd (shadePixel)
int rayBegin = 0, rayEnd = NUM_RAYS;

uint triangleTests = 0u;
uint linespaceLookups = 0u;
uint nodesVisited = 0u;
uint truncated = 0u;
uint packetFailures = 0u;
uint loopIterations = 0u;
// where the time goes (shadow_pass::COUNTERS)
uint lookupsDepth0 = 0u, lookupsDepth1 = 0u;
uint descentsNear = 0u, descentsLinespace = 0u;
uint leafRays = 0u, raysBlockedLinespace = 0u, raysBlockedTriangle = 0u, trianglesCulled = 0u;
int phase = 0;          // linespace-fast: 0 the nodes away from the origin, 1 those near it
vec3 lightCorners[4];   // world space, Listing 2's corner order

// false once the invocation has used up its loop budget
bool loopStep()
{
    loopIterations++;
    if (loopIterations > LOOP_BUDGET) { truncated = 1u; return false; }
    return true;
}
// The loop guard (see loopLimit), written once at the head of every loop, after the loop's own
// condition: `while (cond && WITHIN_BUDGET)` counts one iteration each time the body runs, as
// a check at the top of the body would. Past the budget every loop ends at its next test, the
// invocation unwinds and the pixel is counted in truncated (and rendered again in batches), so
// the algorithm's loops below read as printed.
#define WITHIN_BUDGET loopStep()

// Listings 1 and 2 declare traverse_chilids and active_rays[] as bool; here they are uints
// (0u false, 1u true). GLSL allows bool members and arrays in private memory, but lavapipe (Mesa
// 22.3), under zink, fails to create any compute pipeline that indexes an array of them with a
// dynamic index (vkCreateComputePipelines: VK_ERROR_UNKNOWN; docs/drivers.md has the
// three-line reproduction), and stack[depth] and active_rays[r] are such indices.
struct Stack
{
    uvec2 parent_node;
    uvec2 nodelist[N * N];
    ivec2 offset[N * N];
    int nodelist_index;
    uint traverse_chilids;
    int current_slice;
    int last_slice;
    float u_min, u_max, v_min, v_max;
} stack[NUM_MAX_DEPTH];

// Listing 2. corner_dir: ours are the vectors from the origin to the light's corners (t = 1 at
// the light, in N-tree units), not normalised to k = 1 as the thesis says — the slice ranges
// (sliceRange, sliceUV) divide by the k component where they need it. destination: written
// (the light's centre, as the text says; Algorithm 1 line 6 prints light_dir) but never read:
// the thesis uses it for the end index, which here follows from the corner rays and tEnd.
struct Shaft {
    vec3 origin;
    vec3 destination;
    vec3 corner_dir[4];
    uint active_rays[NUM_RAYS];
    vec3 ray_start[NUM_MAX_DEPTH + 1];
    vec3 ray_direction[NUM_RAYS];
} shaft;

int active_rays = 0;    // the number of active rays
#define RAY_WORDS ((NUM_RAYS + 31) / 32)
uint activeBits[RAY_WORDS]; // shaft.active_rays as bits, for linespace-fast's loops over them
vec3 originWorld = vec3(0.0); // the shadow rays' common origin in world space
int k = 0, u = 1, v = 2, dir = 1; // traversal axis, the other two, direction along k (+1 / -1)

vec3 samplePoint(int r)
{
    return lightSamplePoint(lightCorner, lightEdgeU, lightEdgeV, r, SAMPLES_U, SAMPLES_V);
}

// Algorithm 1 (preparation, first part): the shadow rays of one surface point from the offset
// origin to the light samples, and the shaft, in the N-tree coordinate system. Sets
// active_rays to the number of samples in front of the surface. (Before every function that
// reads the shaft, so the compiler sees it written first.)
void initShaft(vec3 pos, vec3 normal)
{
    originWorld = pos + normal * shadowOffset;
    active_rays = 0;
    for (int w = 0; w < RAY_WORDS; w++) activeBits[w] = 0u;
    for (int r = 0; r < NUM_RAYS; r++) {
        // samples behind the surface are blocked by it (N·L <= 0)
        vec3 l = samplePoint(r);
        bool front = r >= rayBegin && r < rayEnd && dot(normal, l - pos) > 0.0;
        shaft.active_rays[r] = uint(front);
        if (front) active_rays++;
        if (front) activeBits[r >> 5] |= 1u << uint(r & 31);
        shaft.ray_direction[r] = (l - originWorld) * invNodeSize;
    }
    // initialise the shaft: transform into the N-tree coordinate system
    shaft.origin = (originWorld - minBound) * invNodeSize;
    vec3 centre = lightCorner + 0.5 * (lightEdgeU + lightEdgeV);
    shaft.destination = (centre - minBound) * invNodeSize;
    shaft.ray_start[0] = shaft.origin;
}

uvec2 fetchNode(uint group, ivec3 c)
{
    nodesVisited++;
    return texelFetch(nodePool, int(group) * N * N * N + c.x + N * (c.y + N * c.z)).rg;
}

// t of the light sample in the coordinates of a node at `level` (1 in the root's)
float tEnd(int level)
{
    float n = float(N);
    return level == 0 ? 1.0 : (level == 1 ? n : (level == 2 ? n * n : n * n * n));
}

// the two axes of a side's cells
ivec2 faceAxes(int axis)
{
    return axis == 0 ? ivec2(1, 2) : (axis == 1 ? ivec2(0, 2) : ivec2(0, 1));
}

// one slab of Kay–Kajiya: false when the ray runs parallel outside it
bool slab(int a, vec3 startPoint, vec3 direction, inout float tnear, inout float tfar,
          inout int nearAxis, inout int farAxis)
{
    float fN = float(N);
    if (direction[a] == 0.0) return !(startPoint[a] < 0.0 || startPoint[a] > fN);
    float inv = 1.0 / direction[a];
    float t0 = (0.0 - startPoint[a]) * inv;
    float t1 = (fN - startPoint[a]) * inv;
    if (t0 > t1) { float tmp = t0; t0 = t1; t1 = tmp; }
    if (t0 > tnear) { tnear = t0; nearAxis = a; }
    if (t1 < tfar) { tfar = t1; farAxis = a; }
    return true;
}

// Algorithm 3: isNodeIntersection — Kay–Kajiya on the node [0, N]^3. Sides are numbered
// 2·axis + (0 at coordinate 0, 1 at N) (the thesis: ±1, ±2, ±3).
bool isNodeIntersection(vec3 startPoint, vec3 direction, float t_end,
                        out int startFace, out ivec2 startDim, out int endFace, out ivec2 endDim)
{
    float fN = float(N);
    float tnear = -INF, tfar = INF;
    int nearAxis = 0, farAxis = 0;
    startFace = 0; endFace = 0; startDim = ivec2(0); endDim = ivec2(0);
    // the three slabs, written out (no loop: see loopLimit)
    if (!slab(0, startPoint, direction, tnear, tfar, nearAxis, farAxis)) return false;
    if (!slab(1, startPoint, direction, tnear, tfar, nearAxis, farAxis)) return false;
    if (!slab(2, startPoint, direction, tnear, tfar, nearAxis, farAxis)) return false;
    if (tnear > tfar || tfar < 0.0 || tnear > t_end) return false;
    vec3 startVec = startPoint + tnear * direction;
    vec3 endVec = startPoint + tfar * direction;
    startFace = 2 * nearAxis + (direction[nearAxis] > 0.0 ? 0 : 1);
    endFace = 2 * farAxis + (direction[farAxis] > 0.0 ? 1 : 0);
    ivec2 sa = faceAxes(nearAxis), ea = faceAxes(farAxis);
    startDim = clamp(ivec2(floor(vec2(startVec[sa.x], startVec[sa.y]))), ivec2(0), ivec2(N - 1));
    endDim = clamp(ivec2(floor(vec2(endVec[ea.x], endVec[ea.y]))), ivec2(0), ivec2(N - 1));
    return true;
}

// Ours: a node whose box, grown by NEAR_MARGIN child cells, holds the rays' origin is
// descended instead of asking its line space (rays starting just beside a node boundary would
// otherwise enter the neighbour through the side cell next to their own surface, whose shaft
// holds that surface: thin dark lines along every node boundary).
#define NEAR_MARGIN 1.0
bool nearOrigin(vec3 childStart)
{
    return all(greaterThanEqual(childStart, vec3(-NEAR_MARGIN)))
        && all(lessThanEqual(childStart, vec3(float(N) + NEAR_MARGIN)));
}

// Algorithm 4 and Listing 3: getEntry — the bit of the shaft between two boundary cells.
// Symmetric entries are stored once (sides s < e); two cells of one side have no shaft:
// true, conservatively (only a grazing ray gets there).
bool getEntry(uvec2 node, int startFace, ivec2 startDim, int endFace, ivec2 endDim)
{
    if (startFace == endFace) return true;
    int s = startFace, e = endFace;
    int cs = startDim.x + N * startDim.y, ce = endDim.x + N * endDim.y;
    if (s > e) { int t = s; s = e; e = t; t = cs; cs = ce; ce = t; }
    // the 15 side pairs (s, e), s < e, numbered row by row: row s starts after the
    // 5 + 4 + … + (6 − s) pairs of the rows before it, s·(11 − s)/2 (6 sides: 11 = 2·6 − 1)
    int pair = s * (11 - s) / 2 + (e - s - 1);
    int entry_num = pair * N * N * N * N + cs * N * N + ce;
    linespaceLookups++;
    uint ls_index = node.g;

    /* x-position in the linespace */
    int entry_num_compressed = entry_num / 32;
    int bit_position = entry_num - 32 * entry_num_compressed;

    /* y-position in the linespace */
    int y_position = (int(ls_index) * ls_y_size) + entry_num_compressed / tex_x_res;

    /* coordinates in the linespace_buffer */
    int y_coord = y_position % tex_y_res;
    int x_coord = entry_num_compressed % tex_x_res;
    int z_coord = y_position / tex_y_res;

    uint entry = imageLoad(linespaceTexture, ivec3(x_coord, y_coord, z_coord)).r;
    return ((entry >> uint(bit_position)) & 1u) != 0u;
}

void deactivateRay(int r)
{
    shaft.active_rays[r] = 0u;
    activeBits[r >> 5] &= ~(1u << uint(r & 31));
    active_rays--;
}

void countLookups(int depth, uint n)
{
    if (depth == 0) lookupsDepth0 += n; else lookupsDepth1 += n;
}

// Algorithm 2, one ray: true if the ray crosses the node and its line-space bit is set; at
// the last depth with line spaces (deactivate) the ray is then deactivated.
bool lineSpaceRay(int r, uvec2 node, vec3 childStart, float te, bool deactivate)
{
    if (r >= rayEnd || shaft.active_rays[r] == 0u) return false;
    int sf, ef;
    ivec2 sd, ed;
    if (!isNodeIntersection(childStart, shaft.ray_direction[r], te, sf, sd, ef, ed)) return false;
    if (!getEntry(node, sf, sd, ef, ed)) return false;
    if (deactivate) {
        deactivateRay(r);
        raysBlockedLinespace++;
    }
    return true;
}

// linespace-fast: Algorithm 2 at the last line-space depth over the active rays alone (their
// bits), so a packet with few rays left costs few loop iterations; the same rays in the same
// order as the loop of isIntersection
bool isIntersectionActive(uvec2 node, vec3 childStart, float te)
{
    bool found = false;
    for (int w = 0; w < RAY_WORDS && WITHIN_BUDGET; w++) {
        uint bits = activeBits[w];
        while (bits != 0u && WITHIN_BUDGET) {
            int r = 32 * w + findLSB(bits);
            bits &= bits - 1u;
            found = lineSpaceRay(r, node, childStart, te, true) || found;
        }
    }
    return found;
}

// Algorithm 2: isIntersection. deactivate: at the last depth with line spaces a set bit is a
// hit and deactivates the ray; elsewhere the first set bit returns true (descend).
bool isIntersection(uvec2 node, vec3 childStart, int level, bool deactivate)
{
    bool found_intersection = false;
    float te = tEnd(level);
    uint before = linespaceLookups;
    if (FAST_PATH == 1 && deactivate) {
        found_intersection = isIntersectionActive(node, childStart, te);
    } else {
        for (int r = rayBegin; r < rayEnd && WITHIN_BUDGET; r++) {
            bool found = lineSpaceRay(r, node, childStart, te, deactivate);
            if (found && !deactivate) { found_intersection = true; break; }
            found_intersection = found_intersection || found;
        }
    }
    countLookups(level - 1, linespaceLookups - before);
    return found_intersection;
}

// Algorithm 1 of Müller 2015 (Möller–Trumbore), hit for 0 < t < 1 (up to the light sample).
bool occludes(uint t, vec3 ro, vec3 rd)
{
    triangleTests++;
    vec3 v0 = triVertex[3u * t].xyz;
    vec3 v1 = triVertex[3u * t + 1u].xyz;
    vec3 v2 = triVertex[3u * t + 2u].xyz;
    vec3 edge1 = v1 - v0;
    vec3 edge2 = v2 - v0;
    vec3 pvec = cross(rd, edge2);
    float det = dot(edge1, pvec);
    float invDet = 1.0 / det;
    vec3 tvec = ro - v0;
    float uu = invDet * dot(tvec, pvec);
    vec3 qvec = cross(tvec, edge1);
    float vv = invDet * dot(rd, qvec);
    float tt = invDet * dot(edge2, qvec);
    return uu >= 0.0 && vv >= 0.0 && uu + vv <= 1.0 && tt > 0.0 && tt < 1.0;
}

// the exact triangle tests of a leaf for ray r
void leafRay(int r, uvec2 node, vec3 childStart, float te)
{
    if (r >= rayEnd || shaft.active_rays[r] == 0u) return;
    int sf, ef;
    ivec2 sd, ed;
    if (!isNodeIntersection(childStart, shaft.ray_direction[r], te, sf, sd, ef, ed)) return;
    leafRays++;
    vec3 rd = samplePoint(r) - originWorld;
    uint off = node.r >> 2;
    uint count = node.g;
    for (uint i = 0u; i < count && WITHIN_BUDGET; i++) {
        if (occludes(leafTriangles[off + i], originWorld, rd)) {
            deactivateRay(r);
            raysBlockedTriangle++;
            return;
        }
    }
}

// linespace-fast: the packet's rays lie in the pyramid from the origin to the (convex) light:
// its four side planes, unit normals pointing out (set by initPyramid)
vec3 sideNormal[4];

void initPyramid()
{
    // the light's corners in cyclic order (lightCorners is Listing 2's order)
    vec3 ring[4] = vec3[4](lightCorners[0], lightCorners[1], lightCorners[3], lightCorners[2]);
    vec3 centre = 0.25 * (ring[0] + ring[1] + ring[2] + ring[3]);
    for (int e = 0; e < 4; e++) {
        vec3 n = normalize(cross(ring[e] - originWorld, ring[(e + 1) & 3] - originWorld));
        sideNormal[e] = dot(n, centre - originWorld) > 0.0 ? -n : n;
    }
}

// linespace-fast: true when no ray of the packet can cross triangle t — the origin and the
// light's four corners lie on one side of the triangle's plane, or the triangle lies outside
// one side plane of the pyramid (initPyramid): every segment from the origin to a sample of
// the light stays clear of it. The margins (1e-5 world units, against Möller–Trumbore's
// rounding) keep the skip conservative: a triangle the exact test could hit is tested.
bool packetMisses(uint t)
{
    vec3 v0 = triVertex[3u * t].xyz;
    vec3 v1 = triVertex[3u * t + 1u].xyz;
    vec3 v2 = triVertex[3u * t + 2u].xyz;
    for (int e = 0; e < 4; e++) {
        vec3 n = sideNormal[e];
        if (dot(n, v0 - originWorld) > 1e-5 && dot(n, v1 - originWorld) > 1e-5
            && dot(n, v2 - originWorld) > 1e-5) return true;
    }
    vec3 n = cross(v1 - v0, v2 - v0);
    float eps = 1e-5 * length(n);
    float side = dot(n, originWorld - v0);
    if (abs(side) <= eps) return false;
    float s = sign(side);
    return s * dot(n, lightCorners[0] - v0) > eps && s * dot(n, lightCorners[1] - v0) > eps
        && s * dot(n, lightCorners[2] - v0) > eps && s * dot(n, lightCorners[3] - v0) > eps;
}

// linespace-fast: the active rays that cross a leaf (Kay–Kajiya), a bit each; their number
int crossingRays(vec3 childStart, float te, out uint crossing[RAY_WORDS])
{
    int n = 0;
    for (int w = 0; w < RAY_WORDS && WITHIN_BUDGET; w++) {
        crossing[w] = 0u;
        uint bits = activeBits[w];
        while (bits != 0u && WITHIN_BUDGET) {
            int r = 32 * w + findLSB(bits);
            bits &= bits - 1u;
            int sf, ef;
            ivec2 sd, ed;
            if (!isNodeIntersection(childStart, shaft.ray_direction[r], te, sf, sd, ef, ed))
                continue;
            crossing[w] |= 1u << uint(r & 31);
            n++;
            leafRays++;
        }
    }
    return n;
}

// linespace-fast: a leaf's triangles one by one, each first against the whole packet
// (packetMisses), then for the active rays that cross the leaf (a bit per ray, found at the
// first triangle not skipped). A ray meets the leaf's triangles in the same order as in leafRay
// and stops at the same one, so the values and the tests of the unskipped triangles are mode 1's.
void leafTestsPacket(uvec2 node, vec3 childStart, int level)
{
    uint crossing[RAY_WORDS];
    int left = -1; // the rays crossing the leaf still active; -1: not yet found
    uint off = node.r >> 2;
    for (uint i = 0u; i < node.g && left != 0 && WITHIN_BUDGET; i++) {
        uint t = leafTriangles[off + i];
        if (packetMisses(t)) { trianglesCulled++; continue; }
        if (left < 0) left = crossingRays(childStart, tEnd(level), crossing);
        for (int w = 0; w < RAY_WORDS && WITHIN_BUDGET; w++) {
            uint bits = crossing[w];
            while (bits != 0u && WITHIN_BUDGET) {
                int r = 32 * w + findLSB(bits);
                bits &= bits - 1u;
                if (!occludes(t, originWorld, samplePoint(r) - originWorld)) continue;
                crossing[w] &= ~(1u << uint(r & 31));
                deactivateRay(r);
                left--;
                raysBlockedTriangle++;
            }
        }
    }
}

// the exact triangle tests of a leaf for every active ray crossing it
void leafTests(uvec2 node, vec3 childStart, int level)
{
    if (FAST_PATH == 1) { leafTestsPacket(node, childStart, level); return; }
    float te = tEnd(level);
    for (int r = rayBegin; r < rayEnd && WITHIN_BUDGET; r++) leafRay(r, node, childStart, te);
}

// linespace-fast: does the node at stack depth 0 belong to the other phase's walk? Near the
// origin (nearOrigin) is phase 1's, the rest phase 0's; depths below follow their parent.
bool phaseSkips(int depth, vec3 childStart)
{
    if (FAST_PATH == 0 || depth > 0) return false;
    return nearOrigin(childStart) != (phase == 1);
}

// linespace-fast, phase 1: the slices at depth 0 past the origin's neighbourhood hold no near
// node (the walk goes away from the origin, so it ends there)
bool phaseEnds(int depth, int slice)
{
    if (FAST_PATH == 0 || depth > 0 || phase == 0) return false;
    float kc = (shaft.ray_start[0][k] - float(slice)) * float(N);
    return kc < -NEAR_MARGIN || kc > float(N) + NEAR_MARGIN;
}

// the slices [first, last] the packet crosses in a node at stack depth d
bool sliceRange(int d, out int first, out int last)
{
    float fN = float(N);
    float ko = shaft.ray_start[d][k];
    float te = tEnd(d);
    first = 0; last = 0;
    if (dir > 0) {
        float kfar = -INF;
        for (int c = 0; c < 4; c++) kfar = max(kfar, ko + shaft.corner_dir[c][k] * te);
        kfar = min(kfar, fN);
        float knear = max(ko, 0.0);
        if (knear >= fN || kfar <= 0.0 || knear > kfar) return false;
        first = clamp(int(floor(knear)), 0, N - 1);
        last = max(clamp(int(ceil(kfar)) - 1, 0, N - 1), first);
    } else {
        float kfar = INF;
        for (int c = 0; c < 4; c++) kfar = min(kfar, ko + shaft.corner_dir[c][k] * te);
        kfar = max(kfar, 0.0);
        float knear = min(ko, fN);
        if (knear <= 0.0 || kfar >= fN || knear < kfar) return false;
        first = clamp(int(ceil(knear)) - 1, 0, N - 1);
        last = min(clamp(int(floor(kfar)), 0, N - 1), first);
    }
    return true;
}

// u_min/u_max/v_min/v_max of the packet in slice j at depth d (Fig. 10(b)–(c)): the corner
// rays where they enter and leave the slice (the thesis adds the constant delta_uv per slice;
// computing it from the slice's bounds gives the same range)
void sliceUV(int d, int j)
{
    float ko = shaft.ray_start[d][k];
    float te = tEnd(d);
    float a = float(j), b = float(j) + 1.0;
    stack[d].u_min = INF; stack[d].u_max = -INF;
    stack[d].v_min = INF; stack[d].v_max = -INF;
    for (int c = 0; c < 4; c++) {
        vec3 cd = shaft.corner_dir[c];
        float kend = ko + cd[k] * te;
        float lo = dir > 0 ? ko : kend, hi = dir > 0 ? kend : ko;
        for (int q = 0; q < 2; q++) {
            float kk = clamp(q == 0 ? a : b, lo, hi);
            float lambda = (kk - ko) / cd[k];
            float pu = shaft.ray_start[d][u] + lambda * cd[u];
            float pv = shaft.ray_start[d][v] + lambda * cd[v];
            stack[d].u_min = min(stack[d].u_min, pu);
            stack[d].u_max = max(stack[d].u_max, pu);
            stack[d].v_min = min(stack[d].v_min, pv);
            stack[d].v_max = max(stack[d].v_max, pv);
        }
    }
}

bool initLevel(int d, uvec2 parent)
{
    int first, last;
    if (!sliceRange(d, first, last)) return false;
    stack[d].parent_node = parent;
    stack[d].nodelist_index = 0;
    stack[d].traverse_chilids = 0u;
    stack[d].current_slice = first;
    stack[d].last_slice = last;
    return true;
}

// Algorithm 1 (continuation): returns the number of rays still active
int traverse()
{
    float fN = float(N);
    if (!initLevel(0, uvec2(GEOMETRY_BIT | CHILDREN_BIT, 0u))) return active_rays;
    int depth = 0;
    while (depth >= 0 && WITHIN_BUDGET) {
        bool next_depth = false;
        // for all slices of the node, from current_slice on (the loop ends at last_slice or
        // when a child is to be traversed: next_depth)
        for (int slice = stack[depth].current_slice; WITHIN_BUDGET; slice += dir) {
            if (phaseEnds(depth, slice)) break;
            if (stack[depth].traverse_chilids == 0u) {
                sliceUV(depth, slice);
                int cu0 = max(int(floor(stack[depth].u_min)), 0);
                int cu1 = min(int(floor(stack[depth].u_max)), N - 1);
                int cv0 = max(int(floor(stack[depth].v_min)), 0);
                int cv1 = min(int(floor(stack[depth].v_max)), N - 1);
                stack[depth].nodelist_index = 0;
                for (int cu = cu0; cu <= cu1 && WITHIN_BUDGET; cu++) {
                    for (int cv = cv0; cv <= cv1 && WITHIN_BUDGET; cv++) {
                        ivec3 c;
                        c[k] = slice; c[u] = cu; c[v] = cv;
                        // linespace-fast: the other walk's cell
                        if (phaseSkips(depth, (shaft.ray_start[0] - vec3(c)) * fN)) continue;
                        uvec2 node = fetchNode(stack[depth].parent_node.r >> 2, c);
                        // Algorithm 1 line 24 lists nodes with geometry *and* children; ours
                        // lists leaves too (their triangles are tested below), and the list is
                        // taken last-in-first-out (nodelist_index counts down)
                        if ((node.r & GEOMETRY_BIT) != 0u) {
                            int i = stack[depth].nodelist_index++;
                            stack[depth].nodelist[i] = node;
                            stack[depth].offset[i] = ivec2(cu, cv);
                        }
                    }
                }
            }
            while (stack[depth].nodelist_index > 0 && WITHIN_BUDGET) {
                int i = --stack[depth].nodelist_index;
                uvec2 node = stack[depth].nodelist[i];
                ivec3 uvk_offset;
                uvk_offset[k] = slice;
                uvk_offset[u] = stack[depth].offset[i].x;
                uvk_offset[v] = stack[depth].offset[i].y;
                // ray_start[depth + 1] = n × (ray_start[depth] − uvk_offset)
                vec3 childStart = (shaft.ray_start[depth] - vec3(uvk_offset)) * fN;
                if ((node.r & CHILDREN_BIT) == 0u) {
                    leafTests(node, childStart, depth + 1);
                } else {
                    // Algorithm 1 line 32 prints "if ISINTERSECTION then continue" (skip the
                    // node when a ray hits geometry in its line space); the prose says the
                    // opposite — a hit means the children are traversed, an empty shaft is
                    // skipped (Empty-Space-Skipping). We follow the prose: descend only when
                    // isIntersection is true
                    // ours: a node near the origin is descended; the variants ask it too
                    bool inside = NEAR_ORIGIN_RULE == 1 && nearOrigin(childStart);
                    bool descend;
                    if (inside) {
                        descend = true;
                        descentsNear++;
                    } else if (BIT_IS_HIT == 1 && depth == LAST_LS_DEPTH) {
                        isIntersection(node, childStart, depth + 1, true);
                        descend = false;
                    } else {
                        descend = isIntersection(node, childStart, depth + 1, false);
                        if (descend) descentsLinespace++;
                    }
                    if (descend && depth + 1 < NUM_MAX_DEPTH) {
                        shaft.ray_start[depth + 1] = childStart;
                        if (initLevel(depth + 1, node)) {
                            stack[depth].traverse_chilids = 1u;
                            stack[depth].current_slice = slice;
                            next_depth = true;
                        }
                    }
                }
                if (active_rays == 0) return 0;
                if (next_depth) break;
            }
            if (next_depth) break;
            stack[depth].traverse_chilids = 0u;
            if (slice == stack[depth].last_slice) break;
        }
        // the thesis adds 2 and subtracts 1 at the end of the while loop
        depth += next_depth ? 1 : -1;
    }
    return active_rays;
}

// Table 3's DDA: one ray with a hierarchical 3D-DDA and the same line-space termination.
// True: blocked.
struct Dda { uint group; vec3 start; ivec3 cell; vec3 t_max; float t; float t_end; };
Dda dstack[NUM_MAX_DEPTH];

bool ddaInit(int d, uint group, vec3 start, float t_end, vec3 direction)
{
    float fN = float(N);
    bool inside = all(greaterThanEqual(start, vec3(0.0))) && all(lessThan(start, vec3(fN)));
    float t0 = 0.0;
    if (!inside) {
        float tnear = 0.0, tfar = INF;
        for (int a = 0; a < 3; a++) {
            if (direction[a] == 0.0) {
                if (start[a] < 0.0 || start[a] > fN) return false;
                continue;
            }
            float ta = -start[a] / direction[a];
            float tb = (fN - start[a]) / direction[a];
            tnear = max(tnear, min(ta, tb));
            tfar = min(tfar, max(ta, tb));
        }
        if (tnear > tfar || tnear > t_end) return false;
        t0 = tnear;
    }
    vec3 p = start + t0 * direction;
    ivec3 cell = clamp(ivec3(floor(p)), ivec3(0), ivec3(N - 1));
    vec3 tm = vec3(INF);
    for (int a = 0; a < 3; a++) {
        if (direction[a] > 0.0) tm[a] = (float(cell[a]) + 1.0 - start[a]) / direction[a];
        else if (direction[a] < 0.0) tm[a] = (float(cell[a]) - start[a]) / direction[a];
    }
    dstack[d].group = group; dstack[d].start = start; dstack[d].cell = cell;
    dstack[d].t_max = tm; dstack[d].t = t0; dstack[d].t_end = t_end;
    return true;
}

bool ddaBlocked(int r)
{
    float fN = float(N);
    vec3 direction = shaft.ray_direction[r];
    ivec3 stp = ivec3(direction.x > 0.0 ? 1 : -1, direction.y > 0.0 ? 1 : -1,
                      direction.z > 0.0 ? 1 : -1);
    vec3 t_delta = 1.0 / abs(direction);
    if (!ddaInit(0, 0u, shaft.origin, 1.0, direction)) return false;
    vec3 rd = samplePoint(r) - originWorld;
    int depth = 0;
    while (depth >= 0 && WITHIN_BUDGET) {
        ivec3 cell = dstack[depth].cell;
        if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, ivec3(N)))
            || dstack[depth].t > dstack[depth].t_end) {
            depth--;
            continue;
        }
        vec3 tm = dstack[depth].t_max;
        int a = (tm.x <= tm.y && tm.x <= tm.z) ? 0 : (tm.y <= tm.z ? 1 : 2);
        dstack[depth].t = tm[a];
        dstack[depth].cell[a] += stp[a];
        dstack[depth].t_max[a] += t_delta[a];
        uvec2 node = fetchNode(dstack[depth].group, cell);
        if ((node.r & GEOMETRY_BIT) == 0u) continue;
        vec3 childStart = (dstack[depth].start - vec3(cell)) * fN;
        float te = tEnd(depth + 1);
        if ((node.r & CHILDREN_BIT) == 0u) {
            uint off = node.r >> 2;
            for (uint i = 0u; i < node.g && WITHIN_BUDGET; i++) {
                if (occludes(leafTriangles[off + i], originWorld, rd)) {
                    raysBlockedTriangle++;
                    return true;
                }
            }
            continue;
        }
        bool inside = nearOrigin(childStart);
        bool descend = inside;
        if (inside) descentsNear++;
        if (!inside) {
            int sf, ef;
            ivec2 sd, ed;
            if (isNodeIntersection(childStart, direction, te, sf, sd, ef, ed)) {
                uint before = linespaceLookups;
                bool set = getEntry(node, sf, sd, ef, ed);
                countLookups(depth, linespaceLookups - before);
                if (set && depth == LAST_LS_DEPTH) { raysBlockedLinespace++; return true; }
                if (set) descentsLinespace++;
                descend = set;
            }
        }
        if (descend && depth + 1 < NUM_MAX_DEPTH) {
            if (ddaInit(depth + 1, node.r >> 2, childStart, te, direction)) depth++;
        }
    }
    return false;
}

// Algorithm 1 (preparation): how many of this batch's shadow rays of one surface point reach
// the light
int litRays(vec3 pos, vec3 normal)
{
    initShaft(pos, normal);
    if (active_rays == 0) return 0;
    vec3 centre = lightCorner + 0.5 * (lightEdgeU + lightEdgeV);
    if (SHADOW_MODE == 2) {
        int lit = 0;
        for (int r = rayBegin; r < rayEnd && WITHIN_BUDGET; r++) {
            if (shaft.active_rays[r] != 0u && !ddaBlocked(r)) lit++;
        }
        return lit;
    }
    lightCorners = vec3[4](lightCorner, lightCorner + lightEdgeV, lightCorner + lightEdgeU,
                           lightCorner + lightEdgeU + lightEdgeV);
    for (int c = 0; c < 4; c++) {
        shaft.corner_dir[c] = (lightCorners[c] - originWorld) * invNodeSize;
    }
    // the traversal axis k: the dominant axis of the light vector, if all four corner rays go
    // the same way along it; else the axis along which they do with the largest minimum
    vec3 lv = abs(centre - originWorld);
    int dominant = (lv.x >= lv.y && lv.x >= lv.z) ? 0 : (lv.y >= lv.z ? 1 : 2);
    k = -1;
    float best = -1.0;
    for (int a = 0; a < 3; a++) {
        bool allPos = true, allNeg = true;
        float m = INF;
        for (int c = 0; c < 4; c++) {
            allPos = allPos && shaft.corner_dir[c][a] > 0.0;
            allNeg = allNeg && shaft.corner_dir[c][a] < 0.0;
            m = min(m, abs(shaft.corner_dir[c][a]));
        }
        if (!(allPos || allNeg)) continue;
        if (a == dominant) { k = a; break; }
        if (m > best) { best = m; k = a; }
    }
    if (k < 0) {
        if (rayBegin == 0) packetFailures++;
        return rayEnd - rayBegin;
    }
    ivec2 uvAxes = faceAxes(k);
    u = uvAxes.x; v = uvAxes.y;
    dir = shaft.corner_dir[0][k] > 0.0 ? 1 : -1;
    if (FAST_PATH == 1) {
        // linespace-fast: first the nodes away from the origin, then, for the rays they left
        // unblocked, those near it
        initPyramid();
        phase = 0;
        if (traverse() == 0) return 0;
        phase = 1;
    }
    return traverse();
}

// The shadow pass of one pixel for its rays rayBegin..rayEnd, `before` its state: the lit
// count of its rays before rayBegin in .g, the first ray of its attempt in .b. Stored: the lit
// count with this batch's (.g) — or, where the batch was truncated, the count before it, the
// batch's first ray (.b) and the next attempt (.a); the shaded colour after the pixel's last ray.
void shadePixel(ivec2 storePos, vec4 pos, vec4 before)
{
    vec3 n = normalize(imageLoad(normalTexture, storePos).xyz);
    float lit = float(litRays(pos.xyz, n));
    if (truncated != 0u) {
        imageStore(shadowTexture, storePos,
                   vec4(0.0, before.g, float(rayBegin), float(attempt + 1)));
        return;
    }
    lit += before.g;
    float s = lit / float(NUM_RAYS);
    imageStore(shadowTexture, storePos, vec4(s, lit, before.b, float(attempt)));
    uvec4 starts = rayBegin == 0 ? uvec4(0u) : imageLoad(batchTexture, storePos);
    starts[rayBegin >> 5] |= 1u << uint(rayBegin & 31);
    imageStore(batchTexture, storePos, starts);
    if (rayEnd == NUM_RAYS) {
        // Fig. 7 multiplies the shadow value into the diffuse colour (fig7Shading); ours, the
        // default, lights it with the light's colour and N·L plus the ambient light:
        // diffuse · (ambient + light · s · max(N·L, 0)). Back into the diffuse texture either
        // way
        vec4 diffuse = imageLoad(diffuseTexture, storePos);
        vec3 l = normalize(lightCorner + 0.5 * (lightEdgeU + lightEdgeV) - pos.xyz);
        vec3 c = fig7Shading != 0
            ? s * diffuse.rgb
            : diffuse.rgb * (ambient + lightColor * s * max(dot(n, l), 0.0));
        imageStore(diffuseTexture, storePos, vec4(c, 1.0));
    }
}

// the latest attempt that completed a pixel of each row of the work group in the last frame
shared uint rowAttempt[8];

void main()
{
    countersBegin();
    ivec2 storePos = ivec2(gl_GlobalInvocationID.xy) + tileOffset;
    bool inside = all(lessThan(storePos, imageSize(positionTexture)));
    // the pixel's state; at the frame's first dispatch the pixel starts from ray 0 with nothing
    // lit, in the attempt that completed its row's pixels in the last frame (.a: the latest of
    // the row's; 0 after the host forgot them: ShadowPass::forget_attempts) — a pixel whose
    // batches were truncated then starts with smaller ones now, without the truncated work.
    // The row (ours): llvmpipe runs a row of the 8×8 group as one SIMD vector, which iterates
    // while any lane does, so lanes started in different attempts would make it pay for each.
    bool first = attempt == 0 && batchIndex == 0;
    vec4 before = inside ? imageLoad(shadowTexture, storePos) : vec4(0.0);
    // (the barriers outside any branch: GLSL 4.50 §8.16 allows them only in uniform flow)
    uint row = gl_LocalInvocationID.y;
    if (gl_LocalInvocationID.x == 0u) rowAttempt[row] = 0u;
    memoryBarrierShared();
    barrier();
    if (first && inside) atomicMax(rowAttempt[row], uint(before.a));
    memoryBarrierShared();
    barrier();
    if (first) before = vec4(0.0, 0.0, 0.0, float(rowAttempt[row]));
    if (first && inside && before.a > 0.0) imageStore(shadowTexture, storePos, before);
    rayBegin = int(before.b) + batchIndex * batchRays;
    rayEnd = min(rayBegin + batchRays, NUM_RAYS);
    // a pixel of this attempt (.a; a truncated batch moved it to the next) with rays left
    if (inside && before.a == float(attempt) && rayBegin < NUM_RAYS) {
        vec4 pos = imageLoad(positionTexture, storePos);
        if (pos.w > 0.0) {
            shadePixel(storePos, pos, before);
        } else {
            imageStore(shadowTexture, storePos, vec4(1.0, float(NUM_RAYS), 0.0, 0.0));
        }
    }
    // a truncated batch's counts are dropped: the batches that complete its rays count them
    if (truncated != 0u) {
        triangleTests = 0u; linespaceLookups = 0u; nodesVisited = 0u; packetFailures = 0u;
        lookupsDepth0 = 0u; lookupsDepth1 = 0u; descentsNear = 0u; descentsLinespace = 0u;
        leafRays = 0u; raysBlockedLinespace = 0u; raysBlockedTriangle = 0u;
        trianglesCulled = 0u; loopIterations = 0u;
    }
    // the kernel's counters, named by the host (shadow_pass::COUNTERS): local slot = global slot
    countAdd(COUNTER_TRIANGLE_TESTS, triangleTests);
    countAdd(COUNTER_LINESPACE_LOOKUPS, linespaceLookups);
    countAdd(COUNTER_NODES_VISITED, nodesVisited);
    countAdd(COUNTER_TRUNCATED, truncated);
    countAdd(COUNTER_PACKET_FAILURES, packetFailures);
    countAdd(COUNTER_LOOKUPS_DEPTH0, lookupsDepth0);
    countAdd(COUNTER_LOOKUPS_DEPTH1, lookupsDepth1);
    countAdd(COUNTER_DESCENTS_NEAR, descentsNear);
    countAdd(COUNTER_DESCENTS_LINESPACE, descentsLinespace);
    countAdd(COUNTER_LEAF_RAYS, leafRays);
    countAdd(COUNTER_RAYS_BLOCKED_LINESPACE, raysBlockedLinespace);
    countAdd(COUNTER_RAYS_BLOCKED_TRIANGLE, raysBlockedTriangle);
    countAdd(COUNTER_TRIANGLES_CULLED, trianglesCulled);
    countAdd(COUNTER_LOOP_ITERATIONS, loopIterations);
    if (loopIterations > 0u) {
        atomicMax(groupCount[COUNTER_LOOP_ITERATIONS_GROUP_MAX], loopIterations);
        atomicMax(groupCount[COUNTER_LOOP_ITERATIONS_MAX], loopIterations);
    }
    countersEnd(COUNTER_TRIANGLE_TESTS, COUNTER_TRIANGLE_TESTS);
    countersEnd(COUNTER_LINESPACE_LOOKUPS, COUNTER_LINESPACE_LOOKUPS);
    countersEnd(COUNTER_NODES_VISITED, COUNTER_NODES_VISITED);
    countersEnd(COUNTER_TRUNCATED, COUNTER_TRUNCATED);
    countersEnd(COUNTER_PACKET_FAILURES, COUNTER_PACKET_FAILURES);
    countersEnd(COUNTER_LOOKUPS_DEPTH0, COUNTER_LOOKUPS_DEPTH0);
    countersEnd(COUNTER_LOOKUPS_DEPTH1, COUNTER_LOOKUPS_DEPTH1);
    countersEnd(COUNTER_DESCENTS_NEAR, COUNTER_DESCENTS_NEAR);
    countersEnd(COUNTER_DESCENTS_LINESPACE, COUNTER_DESCENTS_LINESPACE);
    countersEnd(COUNTER_LEAF_RAYS, COUNTER_LEAF_RAYS);
    countersEnd(COUNTER_RAYS_BLOCKED_LINESPACE, COUNTER_RAYS_BLOCKED_LINESPACE);
    countersEnd(COUNTER_RAYS_BLOCKED_TRIANGLE, COUNTER_RAYS_BLOCKED_TRIANGLE);
    countersEnd(COUNTER_TRIANGLES_CULLED, COUNTER_TRIANGLES_CULLED);
    countersEnd(COUNTER_LOOP_ITERATIONS, COUNTER_LOOP_ITERATIONS);
    countersEnd(COUNTER_LOOP_ITERATIONS_GROUP_MAX, COUNTER_LOOP_ITERATIONS_GROUP_MAX);
    // the most iterations one invocation ran: a maximum over the work groups, in the low word
    // (the shared maxima above were made visible by countersEnd's barriers)
    if (gl_LocalInvocationIndex == 0u && groupCount[COUNTER_LOOP_ITERATIONS_MAX] > 0u)
        atomicMax(counters[2 * COUNTER_LOOP_ITERATIONS_MAX], groupCount[COUNTER_LOOP_ITERATIONS_MAX]);
}
