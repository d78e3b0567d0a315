// A ray's inverse direction and octant, for bvh/traverse.glsl and bvh/entry.comp (ours; CPU
// twin: safe_inverse and octant in src/reference/bvh/mod.rs).

// 1/rd with zero (and tiny) components replaced by 1e-20: the slab test never computes 0·inf.
// safeDivisor: the rd it inverts.
float safeDivisor(float d) { return abs(d) < 1e-20 ? 1e-20 : d; }
vec3 safeDivisors(vec3 d) { return vec3(safeDivisor(d.x), safeDivisor(d.y), safeDivisor(d.z)); }
float safeInverse(float d) { return 1.0 / safeDivisor(d); }
vec3 safeInverses(vec3 d) { return vec3(safeInverse(d.x), safeInverse(d.y), safeInverse(d.z)); }

// The octant of a ray with 1/direction `inv`: bit a set where it points down axis a — the copy
// of the nodes it walks (bvh/traverse.glsl).
int rayOctant(vec3 inv) { return (inv.x < 0.0 ? 1 : 0) | (inv.y < 0.0 ? 2 : 0) | (inv.z < 0.0 ? 4 : 0); }
