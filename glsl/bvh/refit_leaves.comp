// The refit's boxes pass — ours (bvh/refit.glsl: after Wald et al. 2007's refit, the climb
// after Karras 2012 §4): one invocation per leaf. It writes the leaf's triangles into the word
// buffer as the CPU layout does (LeafTriangle in src/accel/bvh/layout.rs: v0 and the id,
// v1 − v0, v2 − v0, from the world-space vertices of common/scene.glsl) and the leaf's box: the
// bounds of its triangles widened by the last build's margin `pad` (build::pad: the same margin
// as the build's, not one measured over the moved scene, which would take a pass over every
// vertex first; see docs/design/bvh.md, "Moving objects"). Then it climbs: at each parent it
// counts its arrival; the first child's invocation stops there, the second's (whose sibling's
// box is then written) makes the parent's box, the union of its children's, and its subtree's
// SAH cost (its half area plus theirs), and goes on up. Every parent thus gets its box from
// both children's final boxes in one dispatch instead of one dispatch per level of the tree.
#define SCENE_QUALIFIER readonly
#include "../common/scene.glsl"
#include "refit.glsl"

// Two arrivals per inner node and refit: the first (the old count 0) stops, the second goes on.
// The host clears the counts before every refit (Refit::run), so that no refit depends on the
// ones before it: a refit that did not run to its end (a lost context, a dispatch cut short)
// would otherwise leave some counts odd and every later refit climbing from the wrong child.
layout(std430, binding = SSBO_REFIT_ARRIVALS) coherent buffer RefitArrivals { uint arrivals[]; };

uniform float pad;

// The transform pass' world-space vertices (common/scene.glsl). Ours: with SCENE_IMAGES read as
// an image buffer over the same SSBO (GpuScene::vertex_images, unit SCENE_VERTEX) — llvmpipe
// loads a storage-buffer vector lane by lane and component by component, an image texel for
// all lanes at once (docs/design/frame.md); nine such loads a leaf triangle were most of this
// pass (docs/design/bvh.md, "Moving objects").
#if SCENE_IMAGES
layout(rgba32f, binding = IMAGE_SCENE_VERTEX) readonly uniform imageBuffer vertexImage;
vec3 vertexPos(int k) { return imageLoad(vertexImage, k).xyz; }
#else
vec3 vertexPos(int k) { return vertex[k].xyz; }
#endif

void leafBox(int k)
{
    int first = nodeFirst(k), count = nodeMeta(k);
    int base = (BVH_HEADER_WORDS + 8 * BVH_NODE_WORDS * nodeCount) / 4; // the first triangle's texel
    vec3 lo = vec3(1.0 / 0.0), hi = vec3(-1.0 / 0.0);
    for (int s = first; s < first + count; s++) {
        int id = leafTriangleId(s);
        vec3 v0 = vertexPos(3 * id), v1 = vertexPos(3 * id + 1), v2 = vertexPos(3 * id + 2);
        lo = min(lo, min(v0, min(v1, v2)));
        hi = max(hi, max(v0, max(v1, v2)));
        int t = base + 3 * s;
        storeTexel(t, uvec4(floatBitsToUint(v0), uint(id)));
        storeTexel(t + 1, uvec4(floatBitsToUint(v1 - v0), 0u));
        storeTexel(t + 2, uvec4(floatBitsToUint(v2 - v0), 0u));
    }
    lo -= vec3(pad);
    hi += vec3(pad);
    storeBox(k, lo, hi, halfArea(lo, hi) * float(count));
}

void main()
{
    int k = passNode(true);
    if (k < 0) return;
    leafBox(k);
    for (int p = nodeParent(k); p >= 0; p = nodeParent(p)) {
        // release: this child's box is written before its arrival is counted (GLSL 4.60
        // §4.10: coherent stores, then a memory barrier, are visible to the invocation that sees
        // the count). memoryBarrier(), which orders buffer accesses as memoryBarrierBuffer()
        // does and more: Mesa 22.3's zink on lavapipe counted no arrival past a
        // memoryBarrierBuffer() in this divergent loop.
        memoryBarrier();
        if (atomicAdd(arrivals[p], 1u) == 0u) return;
        // acquire: the sibling's box is read after its arrival was seen
        memoryBarrier();
        int c = nodeFirst(p);
        vec4 leftLo = boxes[2 * c], leftHi = boxes[2 * c + 1];
        vec4 rightLo = boxes[2 * c + 2], rightHi = boxes[2 * c + 3];
        vec3 lo = min(leftLo.xyz, rightLo.xyz), hi = max(leftHi.xyz, rightHi.xyz);
        storeBox(p, lo, hi, halfArea(lo, hi) + leftLo.w + rightLo.w);
    }
}
