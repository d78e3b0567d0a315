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

// the lights, their shadow slots and Listing 16's lighting (shared with the SAH BVH's fused pass)
#include "shade.glsl"

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
