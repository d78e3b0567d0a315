// The refit's first pass — ours (bvh/refit.glsl: after Wald et al. 2007's refit): one invocation
// per leaf. It writes the leaf's triangles into the word buffer as the CPU layout does
// (LeafTriangle in src/accel/bvh/layout.rs: v0 and the id, v1 − v0, v2 − v0, from the
// world-space vertices of common/scene.glsl) and the leaf's box: the bounds of its triangles
// widened by the last build's margin `pad` (build::pad: the same margin as the build's, not one
// measured over the moved scene, which would take a pass over every vertex first; see
// docs/design/bvh.md, "Moving objects").
#define SCENE_QUALIFIER readonly
#include "../common/scene.glsl"
#include "refit.glsl"

uniform float pad;

void main()
{
    int k = passNode();
    if (k < 0) return;
    int first = nodeFirst(k), count = nodeMeta(k);
    int base = (BVH_HEADER_WORDS + 8 * BVH_NODE_WORDS * nodeCount) / 4; // the first triangle's texel
    vec3 lo = vec3(1.0 / 0.0), hi = vec3(-1.0 / 0.0);
    for (int s = first; s < first + count; s++) {
        int id = leafTriangleId(s);
        vec3 v0 = vertex[3 * id].xyz, v1 = vertex[3 * id + 1].xyz, v2 = vertex[3 * id + 2].xyz;
        lo = min(lo, min(v0, min(v1, v2)));
        hi = max(hi, max(v0, max(v1, v2)));
        int t = base + 3 * s;
        imageStore(bvh, t, uvec4(floatBitsToUint(v0), uint(id)));
        imageStore(bvh, t + 1, uvec4(floatBitsToUint(v1 - v0), 0u));
        imageStore(bvh, t + 2, uvec4(floatBitsToUint(v2 - v0), 0u));
    }
    lo -= vec3(pad);
    hi += vec3(pad);
    storeBox(k, lo, hi, halfArea(lo, hi) * float(count));
}
