// eye-ray-generation kernel — Müller 2015, ch. 3.1.1 and 4.1.1, Listing 11.
// One invocation per pixel. From the upper-left corner of the image plane (camImgPosition)
// the pixel's position is reached by adding the pixel spacings camWidth (to the right) and
// camHeight (downwards). That point is the ray origin (rayState 1 in rayOrigin.w); the
// direction from the camera through it goes to rayDir with triangle id -1 in rayDir.w.
// Ours: +0.5 to hit the pixel centre, where the thesis uses the pixel corner. And the
// direction is built from camImgOffset = camImgPosition − camPosition (computed by the host in
// f64), not as the listing's pixelCoord − camPosition: two world positions a near distance
// (0.05) apart cancel catastrophically once the camera's coordinates reach about 4e5, and every
// ray would point along a rounding error.
layout(local_size_x = 8, local_size_y = 8) in;

#include "../common/images.glsl"

#include "../common/eye_ray.glsl"

void main()
{
    ivec2 storePos = pixelPosition();
    if (!insideImage(storePos)) return;
    vec4 originState, dirTri;
    eyeRay(storePos, originState, dirTri);
    imageStore(rayOriginTexture, storePos, originState);
    imageStore(rayDirTexture, storePos, dirTri);
}
