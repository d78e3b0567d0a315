// 3D-DDA through the exact grid (Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray
// Tracing", 1987; the per-ray grid walk of Purcell et al., "Ray Tracing on Programmable Graphics
// Hardware", 2002, and of the streaming GPU ray tracer with a uniform grid and proximity clouds
// that builds on it) — ours, replacing the thesis' traversal kernel and per-ray voxel lists: the
// intersection kernels walk the grid themselves, voxel by voxel in ray order.

layout(std430, binding = SSBO_VOXEL_COUNT) readonly buffer VoxelCount { uint voxelCount[]; };
layout(std430, binding = SSBO_VOXEL_START) readonly buffer VoxelStart { uint voxelStart[]; };
layout(std430, binding = SSBO_VOXEL_TRIS) readonly buffer VoxelTris { int voxelTris[]; };

struct Walk {
    ivec3 voxel;   // current voxel
    ivec3 step;    // +-1 per axis
    vec3 tMax;     // ray parameter of the next voxel face per axis
    vec3 tDelta;   // parameter distance between voxel faces per axis
    float tEnd;    // the walk ends at this parameter (grid exit or ray end)
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
    w.tMax = mix((nextFace - rog) * inv, vec3(1.0 / 0.0), equal(rdg, vec3(0.0)));
    w.tDelta = abs(vx_edge * inv);
    return true;
}

// Parameter at which the ray leaves the current voxel.
float voxelExit(Walk w) { return min(w.tMax.x, min(w.tMax.y, w.tMax.z)); }

// Step into the next voxel; false when the walk has ended.
bool stepWalk(inout Walk w)
{
    float exitT = voxelExit(w);
    if (exitT > w.tEnd) return false;
    if (w.tMax.x == exitT) { w.voxel.x += w.step.x; w.tMax.x += w.tDelta.x; }
    else if (w.tMax.y == exitT) { w.voxel.y += w.step.y; w.tMax.y += w.tDelta.y; }
    else { w.voxel.z += w.step.z; w.tMax.z += w.tDelta.z; }
    return getVoxelID(w.voxel) >= 0;
}
