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
uniform int lightCount;
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

bool inShadow(ivec2 storePos, int l)
{
#if SHADOW_BITS
    uvec4 flags = imageLoad(shadowTexture, storePos);
    return (flags[l >> 5] & (1u << uint(l & 31))) != 0u;
#else
    return imageLoad(shadowTexture, storePos)[l] > 0.5;
#endif
}

#if AREA_LIGHTS > 0
// The share of area light a's feelers at storePos that no triangle blocked: its sample bits
// are lightCount + a·U·V … + U·V − 1 (a sample behind the surface counts as blocked, as
// Listing 15 treats a point light behind it).
float unblockedShare(ivec2 storePos, int a)
{
    const int samples = SAMPLES_U * SAMPLES_V;
    uvec4 flags = imageLoad(shadowTexture, storePos);
    int first = lightCount + a * samples;
    int blocked = 0;
    for (int s = first; s < first + samples; s++)
        blocked += int((flags[s >> 5] >> uint(s & 31)) & 1u);
    return float(samples - blocked) / float(samples);
}
#endif

// The Phong terms of Listing 16's loop for a light from direction L.
vec3 phong(vec3 n, vec3 L, vec3 view, vec4 mat, vec3 albedo)
{
    float diffuse = max(dot(n, L), 0.0);
    vec3 R = reflect(-L, n);
    float specular = mat.y * pow(max(dot(R, view), 0.0), mat.z);
    return diffuse * albedo + vec3(specular);
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
        vec3 p = originState.xyz;
        vec3 n = imageLoad(normalTexture, storePos).xyz;
        int triID = int(imageLoad(rayDirTexture, storePos).w);
        vec4 mat = material[triMaterial[triID]];
        vec3 view = normalize(camPosition.xyz - p);
        temp_color = ambientColor.rgb * pColor.rgb;
        for (int l = 0; l < lightCount; l++) {
            if (inShadow(storePos, l)) continue;
            vec3 L = normalize(pointLightPos(l) - p);
            temp_color += pointLightColor(l) * phong(n, L, view, mat, pColor.rgb);
        }
#if AREA_LIGHTS > 0
        for (int a = 0; a < AREA_LIGHTS; a++) {
            float share = unblockedShare(storePos, a);
            if (share <= 0.0) continue;
            vec3 centre = areaLight[4 * a].xyz
                        + 0.5 * (areaLight[4 * a + 1].xyz + areaLight[4 * a + 2].xyz);
            vec3 L = normalize(centre - p);
            temp_color += share * areaLight[4 * a + 3].rgb * phong(n, L, view, mat, pColor.rgb);
        }
#endif
    } else {
        // the ray left the scene in this pass: the background colour
        temp_color = pColor.rgb;
    }

    // Listing 16: weighted addition of the colour to the output colour
    vec4 final_color = imageLoad(finalTexture, storePos);
    float weight = final_color.w;
    final_color.rgb = weight * final_color.rgb + (1.0 - weight) * temp_color;
    final_color.w = weight + (1.0 - weight) * pColor.w;
    imageStore(finalTexture, storePos, final_color);

    if (rayState > 0.0)
        imageStore(rayOriginTexture, storePos, vec4(originState.xyz, rayState - 1.0));
}
