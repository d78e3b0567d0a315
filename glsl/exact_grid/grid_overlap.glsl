// The voxels a triangle overlaps, for the exact grid's count and fill passes (ours, replacing
// the thesis' edge walk of build.comp). The including kernel defines
//     void registerInVoxel(int voxID)
// and a global `uint truncated`. The voxel boxes are enlarged by a tiny margin so that a
// triangle touching a voxel face is registered on both sides (rounding cannot lose a hit).
// Every value the overlap verdict depends on is precise (see tribox.glsl): count and fill are
// two programs that must agree on it.

void registerTriangle(int triID)
{
    precise vec3 v0 = toGridSpace(vertex[3 * triID].xyz);
    precise vec3 v1 = toGridSpace(vertex[3 * triID + 1].xyz);
    precise vec3 v2 = toGridSpace(vertex[3 * triID + 2].xyz);
    precise vec3 margin = vec3(vx_edge * 1e-4);
    precise vec3 boxLo = min(v0, min(v1, v2)) - margin, boxHi = max(v0, max(v1, v2)) + margin;
    ivec3 lo = clampVoxel(getVoxel(boxLo));
    ivec3 hi = clampVoxel(getVoxel(boxHi));
    precise vec3 halfSize = vec3(0.5 * vx_edge) + margin;
    int z = lo.z;
    for (; z <= hi.z; z++)
        for (int y = lo.y; y <= hi.y; y++)
            for (int x = lo.x; x <= hi.x; x++) {
                precise vec3 center = (vec3(x, y, z) + 0.5) * vx_edge - 1.0;
                if (triBoxOverlap(center, halfSize, v0, v1, v2))
                    registerInVoxel(getVoxelID(ivec3(x, y, z)));
            }
    if (z <= hi.z) truncated = 1u;
}
