// shading kernel — Müller 2015, ch. 3.1.1 and 4.1.3, Listing 16.
// One invocation per pixel. The shadow flags say which lights reach the hit point; for those
// the Phong model (diffuse + specular, with the ambient light) lights the colour of
// colorBuffer. The lit colour is added to the output texture with the weights of Listing 16:
//     final = weight * final + (1 - weight) * temp;   final.w = weight + (1 - weight) * pColor.w
// A ray that missed (rayState 0, colour buffer not empty) adds the background the same way.
// Finally the rayState is decremented.
// Ours, after Klee 2016: AREA_LIGHTS rectangular area lights, each lit as a point light at its
// centre weighted by the share of its SAMPLES_U × SAMPLES_V feelers that intersect2 found
// unblocked (the sample bits after the point lights' bits; docs/mueller2015.md, "Area lights").
layout(local_size_x = 8, local_size_y = 8) in;

#define SCENE_QUALIFIER readonly
#include "../common/scene.glsl"
#include "../common/images.glsl"

uniform vec4 camPosition;
uniform vec4 ambientColor;
// the point lights (POINT_LIGHTS: a #define of the pipeline; ours: Listing 16 loops over a
// uniform count, which llvmpipe kept as a loop with its lane masks — as a constant it unrolls,
// docs/design/frame.md)
const int lightCount = POINT_LIGHTS;
#if AREA_LIGHTS > 0 && !SHADOW_BITS
#error "area lights need the bitwise shadow flags (a bit per light sample)"
#endif
#if AREA_LIGHTS > 0
// per area light: corner, edge u, edge v (xyz) and colour (rgb), four vec4 each
uniform vec4 areaLight[4 * AREA_LIGHTS];
#endif

// The point lights (common/scene.glsl). Ours: with SCENE_IMAGES the same buffers read as image
// buffers — llvmpipe loads a storage-buffer vector lane by lane and component by component, an
// image texel for all lanes at once (docs/design/frame.md; common/intersect1_hit.glsl).
#if SCENE_IMAGES
layout(rgba32f, binding = IMAGE_SCENE_LIGHT_POS) readonly uniform imageBuffer lightPosImage;
layout(rgba32f, binding = IMAGE_SCENE_LIGHT_COLOR) readonly uniform imageBuffer lightColorImage;
vec3 pointLightPos(int l) { return imageLoad(lightPosImage, l).xyz; }
vec3 pointLightColor(int l) { return imageLoad(lightColorImage, l).rgb; }
#else
vec3 pointLightPos(int l) { return lightPos[l].xyz; }
vec3 pointLightColor(int l) { return lightColor[l].rgb; }
#endif

#include "shade.glsl"

// The pixel's shadow flags as one bit per slot (shade.glsl): the bitwise flags as they are,
// the thesis' RGBA flags (channel l > 0.5: light l blocked) as bits 0–3.
uvec4 blockedSlots(ivec2 storePos)
{
#if SHADOW_BITS
    return imageLoad(shadowTexture, storePos);
#else
    bvec4 set = greaterThan(imageLoad(shadowTexture, storePos), vec4(0.5));
    return uvec4(uint(set.x) | uint(set.y) << 1 | uint(set.z) << 2 | uint(set.w) << 3, 0u, 0u, 0u);
#endif
}

void main()
{
    ivec2 storePos = pixelPosition();
    if (!insideImage(storePos)) return;
    vec4 pColor = imageLoad(colorBufferTexture, storePos);
    // empty colour buffer (weight -1, ours: see common/intersect1_hit.glsl): the ray was
    // inactive in this pass
    if (pColor.w < 0.0) return;
    vec4 originState = imageLoad(rayOriginTexture, storePos);
    float rayState = originState.w;

    vec3 temp_color;
    if (rayState > 0.0) {
        vec3 n = imageLoad(normalTexture, storePos).xyz;
        int triID = int(imageLoad(rayDirTexture, storePos).w);
        vec4 mat = material[triMaterial[triID]];
        temp_color = litColor(originState.xyz, n, mat, pColor.rgb, blockedSlots(storePos));
    } else {
        // the ray left the scene in this pass: the background colour
        temp_color = pColor.rgb;
    }

    // Listing 16: weighted addition of the colour to the output colour
    vec4 final_color = imageLoad(finalTexture, storePos);
    imageStore(finalTexture, storePos, addToFinal(final_color, temp_color, pColor.w));

    if (rayState > 0.0)
        imageStore(rayOriginTexture, storePos, vec4(originState.xyz, rayState - 1.0));
}
