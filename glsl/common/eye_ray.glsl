// The eye ray of a pixel — Müller 2015, ch. 3.1.1 and 4.1.1, Listing 11 (the body of
// mueller2015/eye_ray_generation.comp, whose header says what is ours) — as a function, so that
// the SAH BVH's fused pass (bvh/fused_pass.comp) and its entry pass (bvh/entry.comp) compute
// the primary rays in place instead of loading what the eye-ray kernel stored (ours; the
// values are the same). From the upper-left corner of the image plane (camImgPosition) the
// pixel's position is reached by adding the pixel spacings camWidth (to the right) and
// camHeight (downwards): the ray origin, rayState 1; the direction from the camera through it,
// triangle id −1.
uniform vec4 camImgPosition;
uniform vec4 camWidth;
uniform vec4 camHeight;
uniform vec4 camImgOffset;

void eyeRay(ivec2 storePos, out vec4 originState, out vec4 dirTri)
{
    // xy coordinate of the pixel in the texture (row 0 is the bottom row)
    float x = float(storePos.x), y = float(storePos.y);

    // position of the pixel's projection onto the image plane in scene space; the texture
    // height inverts the y direction (camHeight points down the image)
    vec4 across = (x + 0.5) * camWidth
                + (float(imageSize(rayDirTexture).y) - y - 0.5) * camHeight;
    vec4 pixelCoord = camImgPosition + across;

    // Listing 11: normalize(pixelCoord - camPosition); ours, the same vector without the
    // cancellation (see eye_ray_generation.comp)
    vec3 direction = normalize(camImgOffset.xyz + across.xyz);
    originState = vec4(pixelCoord.xyz, 1.0);
    dirTri = vec4(direction, -1.0);
}
