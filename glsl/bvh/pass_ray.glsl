// The ray a pass traces at a pixel, for the SAH BVH's fused pass (bvh/fused.glsl) and entry
// pass (bvh/entry.comp), ours: with PASS_EYE_RAYS (a #define of the host: the kernels of the
// first pass, where the host keeps no AOVs) the eye ray of Listing 11 computed in place
// (common/eye_ray.glsl), which the host then does not dispatch the eye-ray kernel for (ours:
// on llvmpipe the two texels it stores and these kernels load cost more than computing them
// again); else the ray-state texels (Müller 2015, ch. 3.1.2). A #define, not a uniform: llvmpipe
// runs both sides of an `if`, so a uniform choice paid the two texel loads in the first pass
// too (docs/design/frame.md, "The fused pass").
#include "../common/eye_ray.glsl"

void passRay(ivec2 storePos, out vec4 originState, out vec4 dirTri)
{
#if PASS_EYE_RAYS
    eyeRay(storePos, originState, dirTri);
#else
    originState = imageLoad(rayOriginTexture, storePos);
    dirTri = imageLoad(rayDirTexture, storePos);
#endif
    // no ray outside the image — the entry pass bounds a block's rays by what passRay gives for
    // all its 64 pixels. Said here, not left to the load: GL 4.6 §8.26 gives an out-of-range
    // imageLoad zeros in R, G and B only, its A (the ray state) is undefined.
    if (!insideImage(storePos)) originState.w = 0.0;
}
