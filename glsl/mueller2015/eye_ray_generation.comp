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

uniform vec4 camImgPosition;
uniform vec4 camWidth;
uniform vec4 camHeight;
uniform vec4 camImgOffset;

void main()
{
    ivec2 storePos = pixelPosition();
    if (!insideImage(storePos)) return;
    // xy coordinate of the pixel in the texture (row 0 is the bottom row)
    float x = float(storePos.x), y = float(storePos.y);

    // position of the pixel's projection onto the image plane in scene space; the texture
    // height inverts the y direction (camHeight points down the image)
    vec4 across = (x + 0.5) * camWidth
                + (float(imageSize(rayDirTexture).y) - y - 0.5) * camHeight;
    vec4 pixelCoord = camImgPosition + across;

    // Listing 11: normalize(pixelCoord - camPosition); ours, the same vector without the
    // cancellation (see the header)
    vec3 direction = normalize(camImgOffset.xyz + across.xyz);

    imageStore(rayOriginTexture, storePos, vec4(pixelCoord.xyz, 1.0));
    imageStore(rayDirTexture, storePos, vec4(direction, -1.0));
}
