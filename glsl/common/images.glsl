// The ray-state textures of Müller 2015, ch. 3.1.2 (RGBA32F image2D, cleared every frame):
//   rayOrigin   xyz: ray origin / hit point,  w: rayState (0 inactive, 1 active, 2 reflected)
//   rayDir      xyz: ray direction,           w: id of the triangle last hit (-1: none)
//   normal      xyz: interpolated normal at the hit
//   colorBuffer rgb: hit colour,              a: its weight (1 - reflection coefficient)
//   shadow      shadow flags: RGBA32F, one light per channel (the thesis, 4 lights), or
//               RGBA32UI, one bit per light (the bitwise flags proposed in ch. 5, 128 lights)
//   finalTex    rgb: output colour,           a: accumulated weight (Listing 16)
// primaryHit is ours (not in the thesis): the first hit's t and triangle id for the AOVs.

layout(rgba32f, binding = IMAGE_RAY_ORIGIN) uniform image2D rayOriginTexture;
layout(rgba32f, binding = IMAGE_RAY_DIR) uniform image2D rayDirTexture;
layout(rgba32f, binding = IMAGE_NORMAL) uniform image2D normalTexture;
layout(rgba32f, binding = IMAGE_COLOR_BUFFER) uniform image2D colorBufferTexture;
#if SHADOW_BITS
layout(rgba32ui, binding = IMAGE_SHADOW) uniform uimage2D shadowTexture;
#else
layout(rgba32f, binding = IMAGE_SHADOW) uniform image2D shadowTexture;
#endif
layout(rgba32f, binding = IMAGE_FINAL) uniform image2D finalTexture;
layout(rgba32f, binding = IMAGE_PRIMARY_HIT) uniform image2D primaryHitTexture;

// Tiles: a frame is dispatched in tiles so that no single dispatch runs long enough for a
// driver watchdog to kill it; tileOffset is the tile's lower-left pixel.
uniform ivec2 tileOffset;

// The pixel this invocation works on (storePos in the thesis, ch. 4).
ivec2 pixelPosition() { return ivec2(gl_GlobalInvocationID.xy) + tileOffset; }
bool insideImage(ivec2 p) { return all(lessThan(p, imageSize(rayOriginTexture))); }
