// The SAH BVH's refit on the GPU — ours: the bottom-up refit of Wald, Boulos and Shirley 2007
// ("Ray tracing deformable scenes using dynamic bounding volume hierarchies", ACM TOG 26(1)),
// as Kopta et al. 2012 ("Fast, effective BVH updates for animated scenes", I3D) run it every
// frame between rebuilds, here with one dispatch per level of the tree (the host's passes:
// src/accel/bvh/refit.rs) instead of atomics: the topology of the last CPU build is kept, the
// boxes, the leaf triangles, the grid of the records' planes and every octant's records are made
// again from the world-space vertices the transform pass wrote (common/scene.glsl). Shared by
// bvh/refit_leaves.comp, bvh/refit_nodes.comp and bvh/refit_records.comp, one dispatch each
// per pass, a barrier between them (src/gl/sync.rs).
//
// The topology, as 32-bit words (Topology::of in src/accel/bvh/refit.rs; N = nodeCount):
//   words 0 .. 2N:    per node k its Node integers (src/accel/bvh/layout.rs): first (an inner
//                     node: its left child, the right is first + 1; a leaf: its first entry of
//                     the leaf triangles) and meta (a leaf: its count > 0; inner: < 0);
//   words 2N .. 3N:   the nodes in the passes' order: the leaves, then the inner nodes level by
//                     level, the deepest first; a pass takes orderCount of them from orderStart;
//   words 3N .. 11N:  per node k and octant o the texel of its record in octant o's copy;
//   words 11N ..:     per entry s of the leaf triangles its triangle id.
// The boxes: per node k, boxes[2k] = (lo, the subtree's SAH cost), boxes[2k + 1] = (hi, 0): a
// leaf's cost is its half area times its count, an inner node's its half area plus its
// children's, so the root's cost over its half area is BvhStats::sah_cost.
layout(local_size_x = REFIT_GROUP) in;

#define BVH_WORDS_WRITABLE
#include "words.glsl"

layout(std430, binding = SSBO_REFIT_TOPOLOGY) readonly buffer RefitTopology { uint topology[]; };
layout(std430, binding = SSBO_REFIT_BOXES) buffer RefitBoxes { vec4 boxes[]; };

uniform int nodeCount;
uniform int orderStart;
uniform int orderCount;

int nodeFirst(int k) { return int(topology[2 * k]); }
int nodeMeta(int k) { return int(topology[2 * k + 1]); }
// the node of this invocation in its pass, or -1 beyond the pass
int passNode()
{
    int i = int(gl_GlobalInvocationID.x);
    return i < orderCount ? int(topology[2 * nodeCount + orderStart + i]) : -1;
}
int recordTexel(int k, int octant) { return int(topology[3 * nodeCount + 8 * k + octant]); }
int leafTriangleId(int s) { return int(topology[11 * nodeCount + s]); }

// Aabb::half_area: xdim·ydim + ydim·zdim + zdim·xdim
float halfArea(vec3 lo, vec3 hi)
{
    vec3 d = max(hi - lo, vec3(0.0));
    return d.x * d.y + d.y * d.z + d.z * d.x;
}

void storeBox(int k, vec3 lo, vec3 hi, float cost)
{
    boxes[2 * k] = vec4(lo, cost);
    boxes[2 * k + 1] = vec4(hi, 0.0);
}
