// 3D-DDA through the exact grid (Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray
// Tracing", 1987; the per-ray grid walk of Purcell et al., "Ray Tracing on Programmable Graphics
// Hardware", 2002, and of the streaming GPU ray tracer with a uniform grid and proximity clouds
// that builds on it) — ours, replacing the thesis' traversal kernel and per-ray voxel lists: the
// intersection kernels walk the grid themselves, voxel by voxel in ray order. With proximityClouds
// set, stepWalk leaves an empty voxel whose proximity-cloud distance (Cohen & Sheffer 1994, the
// streaming tracer ch. 3; exact_grid/proximity.comp) is d >= 2 by a jump out of the empty cube of
// Chebyshev radius d - 1 around it (jumpWalk), as the streaming tracer's traversal does.

layout(std430, binding = SSBO_VOXEL_COUNT) readonly buffer VoxelCount { uint voxelCount[]; };
layout(std430, binding = SSBO_VOXEL_START) readonly buffer VoxelStart { uint voxelStart[]; };
layout(std430, binding = SSBO_VOXEL_TRIS) readonly buffer VoxelTris { int voxelTris[]; };
layout(std430, binding = SSBO_VOXEL_DIST) readonly buffer VoxelDist { uint voxelDist[]; };

uniform int proximityClouds;  // 1: jump out of empty voxels by their distances (voxelDist)

struct Walk {
    ivec3 voxel;   // current voxel
    ivec3 step;    // +-1 per axis
    vec3 tMax;     // ray parameter of the next voxel face per axis
    vec3 tDelta;   // parameter distance between voxel faces per axis
    float tEnd;    // the walk ends at this parameter (grid exit or ray end)
    vec3 ro, rd;   // the ray in grid space, for jumpWalk's planes
    vec3 inv;      // 1 / rd
};

// Start a walk of ro + t·rd (scene space) for t in [0, tEnd]; false if the ray misses the grid.
bool beginWalk(vec3 ro, vec3 rd, float tEnd, out Walk w)
{
    vec3 rog = toGridSpace(ro);
    vec3 rdg = rd * gridScale;
    vec2 span = clipToGrid(rog, rdg);
    float t0 = max(span.x, 0.0);
    w.tEnd = min(span.y, tEnd);
    if (t0 > w.tEnd) return false;
    w.voxel = clampVoxel(getVoxel(rog + t0 * rdg));
    w.step = ivec3(sign(rdg));
    vec3 nextFace = (vec3(w.voxel) + vec3(greaterThan(rdg, vec3(0.0)))) * vx_edge - 1.0;
    vec3 inv = 1.0 / rdg;
    w.ro = rog; w.rd = rdg; w.inv = inv;
    w.tMax = mix((nextFace - rog) * inv, vec3(1.0 / 0.0), equal(rdg, vec3(0.0)));
    w.tDelta = abs(vx_edge * inv);
    return true;
}

// Parameter at which the ray leaves the current voxel.
float voxelExit(Walk w) { return min(w.tMax.x, min(w.tMax.y, w.tMax.z)); }

// planeT: the parameter of the face through which voxel column k of axis a is left (the one
// beyond it in the direction of travel), as beginWalk computes tMax; +inf for a still axis.
float planeT(Walk w, int a, int k)
{
    if (w.step[a] == 0) return 1.0 / 0.0;
    float face = float(k + int(w.step[a] > 0)) * vx_edge - 1.0;
    return (face - w.ro[a]) * w.inv[a];
}

vec3 planesOf(Walk w, ivec3 v)
{
    return vec3(planeT(w, 0, v.x), planeT(w, 1, v.y), planeT(w, 2, v.z));
}

// jumpWalk — the streaming tracer ch. 3 (proximity clouds, after Cohen & Sheffer 1994), in grid
// space: the current voxel is empty at distance dist >= 2, so the cube of Chebyshev radius dist - 1
// around it holds no non-empty voxel; land in the voxel where the ray leaves that cube. The exit
// axis' voxel is the first beyond the cube's face, the others the exit point's (within the cube) as
// the plane parameters place it; tMax is recomputed for the landing voxel, so the DDA goes on
// from there. False when the cube is left beyond the walk's end or the grid. CPU twin:
// reference::grid::Walk::jump (the same algorithm as stream/traverse_intersect.frag's jump).
bool jumpWalk(inout Walk w, uint dist)
{
    ivec3 rad = ivec3(int(dist) - 1);
    ivec3 lo = max(w.voxel - rad, ivec3(0));
    ivec3 hi = min(w.voxel + rad, ivec3(voxel_amount - 1));
    ivec3 far = mix(lo, hi, greaterThan(w.step, ivec3(0)));
    vec3 tBox = planesOf(w, far);
    float exitT = min(tBox.x, min(tBox.y, tBox.z));
    if (exitT > w.tEnd) return false;
    int a = tBox.x == exitT ? 0 : (tBox.y == exitT ? 1 : 2);
    ivec3 v = clamp(getVoxel(w.ro + exitT * w.rd), lo, hi);
    for (int b = 0; b < 3; b++) {
        if (b == a || w.step[b] == 0) continue;
        // the exit point's voxel as the planes place it (floor() may round across a face)
        int s = w.step[b];
        if (planeT(w, b, v[b] - s) > exitT) v[b] -= s;
        else if (planeT(w, b, v[b]) < exitT) v[b] += s;
        v[b] = clamp(v[b], lo[b], hi[b]);
    }
    v[a] = far[a] + w.step[a];
    if (getVoxelID(v) < 0) return false;
    ivec3 d = abs(v - w.voxel);
    cellsSkipped += uint(max(d.x + d.y + d.z - 1, 0));
    w.voxel = v;
    w.tMax = planesOf(w, v);
    return true;
}

// Step into the next voxel (or jump out of an empty one's cloud); false when the walk has
// ended.
bool stepWalk(inout Walk w)
{
    float exitT = voxelExit(w);
    if (exitT > w.tEnd) return false;
    if (proximityClouds != 0) {
        int id = getVoxelID(w.voxel);
        uint dist = voxelDist[id];
        if (voxelCount[id] == 0u && dist >= 2u) {
            cloudJumps++;
            return jumpWalk(w, dist);
        }
    }
    if (w.tMax.x == exitT) { w.voxel.x += w.step.x; w.tMax.x += w.tDelta.x; }
    else if (w.tMax.y == exitT) { w.voxel.y += w.step.y; w.tMax.y += w.tDelta.y; }
    else { w.voxel.z += w.step.z; w.tMax.z += w.tDelta.z; }
    return getVoxelID(w.voxel) >= 0;
}
