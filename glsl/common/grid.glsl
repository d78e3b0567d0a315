// Uniform grid helpers — Müller 2015, ch. 3.2.2 (Eq. 6) and 4.2, Listings 17 and 18.
// voxel_amount (N of the N³ voxels) is a #define injected by the host, as Listing 17 does.
// The thesis' scene space is [-1, 1)³; we map the scene's bounds (recomputed every frame, so
// moving objects stay inside) onto it with one uniform scale, so ray parameters t are the same
// in scene and grid space.

uniform vec4 gridCenter;  // xyz: centre of the scene's bounds
uniform float gridScale;  // 2 / (largest extent of the bounds, slightly enlarged)

// length of a voxel edge (Listing 19)
const float vx_edge = 2.0 / float(voxel_amount);

// (precise: the exact grid's count and fill passes must map a vertex alike, exact_grid/tribox.glsl)
vec3 toGridSpace(vec3 p)
{
    precise vec3 g = (p - gridCenter.xyz) * gridScale;
    return g;
}

// Listing 18: the voxel containing a grid-space point. A point on a voxel face belongs to the
// voxel whose front, left or bottom face it is (Eq. 6). floor() rather than the listing's
// truncating ivec3() so that points just outside the grid map to -1, not 0.
ivec3 getVoxel(vec3 coords)
{
    // shift [-1, 1) -> [0, 2)
    precise vec3 shifted = coords + vec3(1.0);
    precise vec3 cells = shifted / vx_edge;
    return ivec3(floor(cells));
}

ivec3 clampVoxel(ivec3 v) { return clamp(v, ivec3(0), ivec3(voxel_amount - 1)); }

// Listing 18: voxel coordinate -> voxel id, -1 for coordinates outside the grid
int getVoxelID(ivec3 voxel)
{
    if (all(greaterThanEqual(voxel, ivec3(0))) && all(lessThan(voxel, ivec3(voxel_amount))))
        return voxel.z * voxel_amount * voxel_amount + voxel.y * voxel_amount + voxel.x;
    return -1;
}

// Clip the ray ro + t·rd (grid space) to the grid box [-1, 1]³: the parameter interval
// [tEnter, tExit] inside it (empty when tEnter > tExit).
vec2 clipToGrid(vec3 ro, vec3 rd)
{
    vec3 inv = 1.0 / rd;
    vec3 t0 = (vec3(-1.0) - ro) * inv;
    vec3 t1 = (vec3(1.0) - ro) * inv;
    vec3 tn = min(t0, t1), tf = max(t0, t1);
    return vec2(max(max(tn.x, tn.y), tn.z), min(min(tf.x, tf.y), tf.z));
}
