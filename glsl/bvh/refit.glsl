// The SAH BVH's refit on the GPU — ours: the bottom-up refit of Wald, Boulos and Shirley 2007
// ("Ray tracing deformable scenes using dynamic bounding volume hierarchies", ACM TOG 26(1)),
// as Kopta et al. 2012 ("Fast, effective BVH updates for animated scenes", I3D) run it every
// frame between rebuilds, in two dispatches (the host's passes: src/accel/bvh/refit.rs): the
// leaves and, through an arrival counter per inner node, every inner node (Karras 2012,
// "Maximizing parallelism in the construction of BVHs, octrees, and k-d trees", HPG, §4: the
// second child to arrive makes the parent), then the records. The topology of the last CPU
// build is kept; the boxes, the leaf triangles, the grid of the records' planes and every
// octant's records are made again from the world-space vertices the transform pass wrote
// (common/scene.glsl). Shared by bvh/refit_leaves.comp and bvh/refit_records.comp, a barrier
// between them (src/gl/sync.rs).
//
// The topology, as 32-bit words (Topology::of in src/accel/bvh/refit.rs; N = nodeCount):
//   words 0 .. 2N:    per node k its Node integers (src/accel/bvh/layout.rs): first (an inner
//                     node: its left child, the right is first + 1; a leaf: its first entry of
//                     the leaf triangles) and meta (a leaf: its count > 0; inner: < 0);
//   words 2N .. 3N:   per node k its parent (the root: -1);
//   words 3N .. 4N:   the leaves, orderCount of them (the rest unused);
//   words 4N .. 12N:  per node k and octant o the texel of its record in octant o's copy;
//   words 12N .. 13N: per node k what its records' `reference` is made from, the same in every
//                     octant: a leaf's reference itself (< 0: its leaf triangles), an inner
//                     node's subtree size (> 0): its miss link is its own texel plus that size,
//                     the copies being depth-first orders (BvhTree::octant_order);
//   words 13N ..:     per entry s of the leaf triangles its triangle id.
// The boxes: per node k, boxes[2k] = (lo, the subtree's SAH cost), boxes[2k + 1] = (hi, 0): a
// leaf's cost is its half area times its count, an inner node's its half area plus its
// children's, so the root's cost over its half area is BvhStats::sah_cost.
layout(local_size_x = REFIT_GROUP) in;

#define BVH_WORDS_WRITABLE
#include "words.glsl"

layout(std430, binding = SSBO_REFIT_TOPOLOGY) readonly buffer RefitTopology { uint topology[]; };
// coherent: the boxes pass reads the boxes other invocations of its dispatch wrote (GL 4.6
// §7.12.1; refit_leaves.comp)
layout(std430, binding = SSBO_REFIT_BOXES) coherent buffer RefitBoxes { vec4 boxes[]; };

// The refit's stores of the word buffer's texels (node records, leaf triangles). Ours: with
// wordsStorage set (the host's: where the buffer fits GL_MAX_SHADER_STORAGE_BLOCK_SIZE) through
// the same buffer bound as a storage buffer — llvmpipe stores an image texel component by
// component, lane by lane, at about three times a storage-buffer vector's cost
// (docs/design/frame.md, docs/design/bvh.md "Moving objects") — else as image texels. The
// walks read the texels as images after the refit's barrier (gl::sync: image access included).
layout(std430, binding = SSBO_BVH_WORDS) writeonly buffer BvhWords { uvec4 bvhWords[]; };
uniform int wordsStorage;

void storeTexel(int texel, uvec4 value)
{
    if (wordsStorage != 0) bvhWords[texel] = value;
    else imageStore(bvh, texel, value);
}

uniform int nodeCount;
uniform int orderCount;

int nodeFirst(int k) { return int(topology[2 * k]); }
int nodeMeta(int k) { return int(topology[2 * k + 1]); }
int nodeParent(int k) { return int(topology[2 * nodeCount + k]); }
// the node of this invocation: a leaf in the boxes' pass, any node in the records' pass; -1
// beyond the pass
int passNode(bool leaves)
{
    int i = int(gl_GlobalInvocationID.x);
    if (i >= orderCount) return -1;
    return leaves ? int(topology[3 * nodeCount + i]) : i;
}
// the texel of node k's record in octant o's copy
uint recordTexel(int k, int octant) { return topology[4 * nodeCount + 8 * k + octant]; }
// the `reference` of the record at `texel`, from its node's reference word
uint referenceOf(uint word, uint texel) { return int(word) < 0 ? word : texel + word; }
int leafTriangleId(int s) { return int(topology[13 * nodeCount + s]); }

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
