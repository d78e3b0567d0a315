// The ray a pass traces at a pixel, for the SAH BVH's fused pass (bvh/fused_pass.comp) and
// entry pass (bvh/entry.comp): with eyeRays set (the first pass, where the host keeps no
// AOVs), the eye ray of Listing 11 computed in place (common/eye_ray.glsl), which the host
// then does not dispatch the eye-ray kernel for (ours: on llvmpipe the two texels it stores
// and these kernels load cost more than computing them again); else the ray-state texels
// (Müller 2015, ch. 3.1.2).
#include "eye_ray.glsl"

uniform int eyeRays;

void passRay(ivec2 storePos, out vec4 originState, out vec4 dirTri)
{
    if (eyeRays != 0) {
        eyeRay(storePos, originState, dirTri);
    } else {
        originState = imageLoad(rayOriginTexture, storePos);
        dirTri = imageLoad(rayDirTexture, storePos);
    }
}
