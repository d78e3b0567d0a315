// The traverse and intersect kernel — the streaming tracer, ch. 3, Fig. 1 and Fig. 2: "traversing
// the grid until a voxel with a non empty reference list is encountered and then intersecting the
// ray with all the enlisted triangles. If no intersection was found, this process is repeated. The
// actual grid traversal is accomplished with the fast 3D-DDA algorithm as described by
// Amanatides and Woo." The hardware's instruction and loop limits made the paper's kernel short
// and called many times, "an occlusion query providing the halting condition – we loop this
// kernel until no pixels (rays) are updated"; here every call does at most STEPS_PER_CALL
// steps (a step: one triangle test, or one move to the next cell), and the host calls again
// until the query counts no fragment.
// The state travels between calls in the three textures of Fig. 2 — read from one set, written
// to the other (ping-pong):
//   stateTMax: tMax (x, y, z) of the 3D-DDA, ray state (w)
//   stateCell: the current cell (x, y, z), the number of its triangles processed (w)
//   stateHit:  the hit record of the closest intersection so far (u, v, t, triangle id)
// Closest hit: a hit is final once it lies within the current cell (t <= the cell's exit), as
// the exact grid's walk (glsl/exact_grid/intersect1.comp); equal distances go to the lower id.
// Shadow rays (anyHit): "determining any (instead of closest) intersection closer than the given
// light source is sufficient" (ch. 3) — the first hit with shadowOffset < t < limit ends it.
// naiveShadow (--stream-naive-shadows, for measuring that optimisation): a shadow ray searched
// like an eye ray — the closest hit beyond shadowOffset, the walk not stopped at the light —
// and a blocker only when that hit lies before the light (the same verdicts, more work).
// Without masking (--stream-no-mask), a ray the masking kernel would have masked arrives with
// -1 triangles processed: this call finishes it with no hit, and the shadow rays' limit is
// |rayDirection.w| (negative for a light behind the surface).
// Proximity clouds (ch. 3, Fig. 3's B channel): in an empty cell at distance dist >= 2 from the
// nearest non-empty one, the ray jumps out of the cube of cells within dist - 1 of it, all empty.
layout(early_fragment_tests) in;

#include "grid.glsl"
#include "rays.glsl"
#include "counters.glsl"

layout(binding = SAMPLER_STREAM_READ_TMAX) uniform sampler2D stateTMax;
layout(binding = SAMPLER_STREAM_READ_CELL) uniform sampler2D stateCell;
layout(binding = SAMPLER_STREAM_READ_HIT) uniform sampler2D stateHit;

uniform int anyHit;
uniform int naiveShadow;
uniform float shadowOffset;
uniform int proximityClouds;
// the counter of this call's triangle tests (closest-hit or shadow rays)
uniform int testCounter;

layout(location = 0) out vec4 outTMax;
layout(location = 1) out vec4 outCell;
layout(location = 2) out vec4 outHit;

// stepCell: the 3D-DDA's move into the next cell; false when it leaves the grid.
bool stepCell(vec3 o, vec3 d, inout ivec3 cell, inout vec3 tMax)
{
    int a = minAxis(tMax);
    cell[a] += d[a] > 0.0 ? 1 : -1;
    if (!insideGrid(cell)) return false;
    tMax[a] = planeT(o, d, a, cell[a]);
    return true;
}

// jumpCloud: out of the cube of cells within Chebyshev distance dist - 1 of the current cell
// (all empty, by the distance's definition), where the ray leaves it: along the exit axis the
// first cell beyond the cube's face, along the others the exit point's cell (within the
// cube's range), placed by the same plane parameters the DDA steps by. False when that lies
// beyond the ray's limit or the grid.
bool jumpCloud(vec3 o, vec3 d, float limit, float dist, inout ivec3 cell, inout vec3 tMax)
{
    ivec3 lo = max(cell - ivec3(int(dist) - 1), ivec3(0));
    ivec3 hi = min(cell + ivec3(int(dist) - 1), gridSize - 1);
    ivec3 far = ivec3(d.x > 0.0 ? hi.x : lo.x, d.y > 0.0 ? hi.y : lo.y, d.z > 0.0 ? hi.z : lo.z);
    vec3 tBox = tMaxOf(o, d, far);
    float exitT = min(tBox.x, min(tBox.y, tBox.z));
    if (exitT > limit) return false;
    int a = minAxis(tBox);
    ivec3 c = clamp(ivec3(floor((o + exitT * d - gridMin) / cellSize)), lo, hi);
    for (int b = 0; b < 3; ++b) {
        // the exit point's cell as the DDA's own plane parameters place it: not past a plane
        // the ray crosses after exitT, not before one it crossed earlier (floor() may round
        // across a plane the point lies on)
        if (b == a || d[b] == 0.0) continue;
        int s = d[b] > 0.0 ? 1 : -1;
        if (planeT(o, d, b, c[b] - s) > exitT) c[b] -= s;
        else if (planeT(o, d, b, c[b]) < exitT) c[b] += s;
        c[b] = clamp(c[b], lo[b], hi[b]);
    }
    c[a] = far[a] + (d[a] > 0.0 ? 1 : -1);
    if (!insideGrid(c)) return false;
    cell = c;
    tMax = tMaxOf(o, d, c);
    return true;
}

// One triangle of the current cell against the ray: the closest-hit rule, or for a shadow ray
// whether it blocks (then true).
bool testTriangle(vec3 o, vec3 d, int id, float limit, inout vec4 hit)
{
    float t, u, v;
    if (!intersectStored(o, d, id, t, u, v)) return false;
    if (anyHit != 0) {
        if (t > shadowOffset && t < limit) {
            hit = vec4(u, v, t, float(id));
            return true;
        }
        return false;
    }
    if (naiveShadow != 0 && t <= shadowOffset) return false;
    if (hit.w < 0.0 || t < hit.z || (t == hit.z && float(id) < hit.w)) hit = vec4(u, v, t, float(id));
    return false;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 o = texelFetch(rayOrigin, px, 0), d = texelFetch(rayDirection, px, 0);
    vec3 tMax = texelFetch(stateTMax, px, 0).xyz;
    vec4 cellK = texelFetch(stateCell, px, 0);
    vec4 hit = texelFetch(stateHit, px, 0);
    ivec3 cell = ivec3(cellK.xyz);
    int k = int(cellK.w);
    float limit = anyHit != 0 ? abs(d.w) : INF;
    uint tests = 0u, entered = 0u, jumps = 0u, skipped = 0u;
    // a ray the masking kernel would have masked (masking off): finished, no hit
    bool done = k < 0;
    for (int i = 0; i < STEPS_PER_CALL && !done; ++i) {
        vec3 c = texelFetch(cells, cell, 0).rgb;
        if (k < int(c.g)) {
            int id = int(texelFetch(references, int(c.r) + k).r);
            k += 1;
            if (float(id) == o.w) continue;
            tests += 1u;
            done = testTriangle(o.xyz, d.xyz, id, limit, hit);
            continue;
        }
        float exitT = min(tMax.x, min(tMax.y, tMax.z));
        if ((hit.w >= 0.0 && hit.z <= exitT) || exitT > limit) {
            done = true;
            break;
        }
        bool cloud = proximityClouds != 0 && c.g == 0.0 && c.b >= 2.0;
        jumps += cloud ? 1u : 0u;
        ivec3 from = cell;
        bool moved = cloud ? jumpCloud(o.xyz, d.xyz, limit, c.b, cell, tMax)
                           : stepCell(o.xyz, d.xyz, cell, tMax);
        if (!moved) {
            done = true;
            break;
        }
        // the empty cells the DDA would have entered on the way: one per step, |cell - from|_1
        // steps to the landing cell (0 for a plain step)
        ivec3 span = abs(cell - from);
        skipped += uint(span.x + span.y + span.z) - 1u;
        k = 0;
        entered += 1u;
    }
    // the naive shadow ray's verdict: a blocker only before the light
    if (done && naiveShadow != 0 && hit.z >= abs(d.w)) hit = vec4(0.0, 0.0, INF, -1.0);
    outTMax = vec4(tMax, done ? RAY_DONE : RAY_ACTIVE);
    outCell = vec4(vec3(cell), float(k));
    outHit = hit;
    countAdd(testCounter, tests);
    countAdd(COUNTER_VOXELS_VISITED, entered);
    countAdd(COUNTER_CLOUD_JUMPS, jumps);
    countAdd(COUNTER_EMPTY_CELLS_SKIPPED, skipped);
}
