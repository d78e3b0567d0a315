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

// Which pixels an invocation of a pixel kernel (8×8 work groups, PIXEL_GROUP on the host) works
// on — ours, not in the thesis; any one-to-one map does, and a GPU hardly cares. On llvmpipe:
// - Mesa's llvmpipe hands each of its N threads one contiguous 1/N of a dispatch's work groups,
//   row after row, so with an object in the middle of the image one thread got the busy rows
//   and the others waited. Work-group row y < rows − 1 therefore covers the
//   tile's row y·tileRowStride mod (rows − 1), and the last row itself: where the N threads
//   divide the rows the stride is N, which gives thread t the rows t, t + N, t + 2N, … —
//   neighbours of the other threads' rows, so every share costs about the same; else a stride
//   coprime to rows − 1 near (rows − 1)/φ, which spreads every contiguous share over the tile
//   (PixelGrid::row_stride, Profile::dispatch_threads; examples/walk_schedule.rs weighs the
//   shares; docs/design/frame.md).
// - llvmpipe runs 8 invocations of consecutive x as one SIMD group; they take a 4×2 block of
//   pixels instead of a row of 8, whose rays diverge less (docs/design/frame.md).
uniform int tileRowStride;

// This invocation's pixel within its work group's 8×8: SIMD group l.y takes block
// (l.y & 1, l.y >> 1) of 4×2 pixels, lane l.x a pixel of it.
ivec2 groupPixel()
{
    ivec2 l = ivec2(gl_LocalInvocationID.xy);
    return ivec2((l.y & 1) * 4 + (l.x & 3), (l.y >> 1) * 2 + (l.x >> 2));
}

// The pixel this invocation works on (storePos in the thesis, ch. 4).
ivec2 pixelPosition()
{
    int rows = int(gl_NumWorkGroups.y), y = int(gl_WorkGroupID.y);
    int row = y == rows - 1 ? y : y * max(tileRowStride, 1) % max(rows - 1, 1);
    return ivec2(gl_WorkGroupID.x, row) * 8 + groupPixel() + tileOffset;
}
bool insideImage(ivec2 p) { return all(lessThan(p, imageSize(rayOriginTexture))); }
