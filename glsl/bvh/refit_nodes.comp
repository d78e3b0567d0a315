// The refit's pass over one level of inner nodes — ours (bvh/refit.glsl: after Wald et al.
// 2007's refit): one invocation per inner node of the level; its box is the union of its
// children's, which the pass before wrote (the leaves' pass, or the level below), and its
// subtree's SAH cost its half area plus theirs. The host runs the levels deepest first.
#include "refit.glsl"

void main()
{
    int k = passNode();
    if (k < 0) return;
    int c = nodeFirst(k);
    vec4 leftLo = boxes[2 * c], leftHi = boxes[2 * c + 1];
    vec4 rightLo = boxes[2 * c + 2], rightHi = boxes[2 * c + 3];
    vec3 lo = min(leftLo.xyz, rightLo.xyz), hi = max(leftHi.xyz, rightHi.xyz);
    storeBox(k, lo, hi, halfArea(lo, hi) + leftLo.w + rightLo.w);
}
