// The lights and the shading of one hit — Müller 2015, ch. 4.1.3, Listing 16, with the area
// lights of shading.comp (ours, after Klee 2016) — in one file for both kernels that light a
// hit: shading.comp, from the values it loads from the ray-state textures, and the SAH BVH's
// fused pass (bvh/fused.glsl, ours), from the values it holds in registers. The lights'
// uniforms and reads, the shadow slots' layout in the shadow texture, the Phong terms.

uniform vec4 camPosition;
uniform vec4 ambientColor;
// the point lights (POINT_LIGHTS: a #define of the pipeline; ours: Listing 16 loops over a
// uniform count, which llvmpipe kept as a loop with its lane masks — as a constant it unrolls,
// also the fused pass' loop of feelers around its walk: docs/design/frame.md, the fused pass'
// table)
const int lightCount = POINT_LIGHTS;
#if AREA_LIGHTS > 0 && !SHADOW_BITS
#error "area lights need the bitwise shadow flags (a bit per light sample)"
#endif
// an area light's samples (common/light_samples.glsl)
const int areaSamples = SAMPLES_U * SAMPLES_V;

// The point lights (common/scene.glsl). Ours: with SCENE_IMAGES (where the GL has the image
// units: GpuScene::vertex_images) the same buffers read as image buffers — llvmpipe loads a
// storage-buffer vector lane by lane and component by component, an image texel for all lanes
// at once (docs/design/frame.md; bvh/vertex_attributes.glsl).
#if SCENE_IMAGES
layout(rgba32f, binding = IMAGE_SCENE_LIGHT_POS) readonly uniform imageBuffer lightPosImage;
layout(rgba32f, binding = IMAGE_SCENE_LIGHT_COLOR) readonly uniform imageBuffer lightColorImage;
vec3 pointLightPos(int l) { return imageLoad(lightPosImage, l).xyz; }
vec3 pointLightColor(int l) { return imageLoad(lightColorImage, l).rgb; }
#else
vec3 pointLightPos(int l) { return lightPos[l].xyz; }
vec3 pointLightColor(int l) { return lightColor[l].rgb; }
#endif

// The area lights, where the scene has them: no loop over AREA_LIGHTS = 0 (Mesa 22.3 kept such
// a loop, and llvmpipe ran its first pass under an empty lane mask: bvh/fused.glsl's feelers).
#if AREA_LIGHTS > 0
// per area light: corner, edge u, edge v (xyz) and colour (rgb), four vec4 each
uniform vec4 areaLight[4 * AREA_LIGHTS];

#include "../common/light_samples.glsl"
// Sample r of area light a, the target of its feeler (Klee's sample positions), for the fused
// pass, which traces a hit's feelers itself (intersect2's: common/light_target.glsl).
vec3 areaLightSample(int a, int r)
{
    return lightSamplePoint(areaLight[4 * a].xyz, areaLight[4 * a + 1].xyz,
                            areaLight[4 * a + 2].xyz, r, SAMPLES_U, SAMPLES_V);
}
#endif

// The pixel's shadow flags as one bit per slot (below): the bitwise flags as they are, the
// thesis' RGBA flags (channel l > 0.5: light l blocked) as bits 0–3.
uvec4 blockedSlots(ivec2 storePos)
{
#if SHADOW_BITS
    return imageLoad(shadowTexture, storePos);
#else
    bvec4 set = greaterThan(imageLoad(shadowTexture, storePos), vec4(0.5));
    return uvec4(uint(set.x) | uint(set.y) << 1 | uint(set.z) << 2 | uint(set.w) << 3, 0u, 0u, 0u);
#endif
}

// The inverse: the slots as the shadow texture holds them (the fused pass' shadow AOV).
void storeBlockedSlots(ivec2 storePos, uvec4 blocked)
{
#if SHADOW_BITS
    imageStore(shadowTexture, storePos, blocked);
#else
    imageStore(shadowTexture, storePos, vec4(notEqual(blocked.xxxx & uvec4(1u, 2u, 4u, 8u),
                                                      uvec4(0u))));
#endif
}

// The Phong terms of Listing 16's loop for a light from direction L.
vec3 phong(vec3 n, vec3 L, vec3 view, vec4 mat, vec3 albedo)
{
    float diffuse = max(dot(n, L), 0.0);
    vec3 R = reflect(-L, n);
    float specular = mat.y * pow(max(dot(R, view), 0.0), mat.z);
    return diffuse * albedo + vec3(specular);
}

// Whether shadow slot s is set in `blocked` (one bit per slot: point light l is slot l, then
// the area lights' samples; pipeline::mueller2015::shadow_slots).
bool slotBlocked(uvec4 blocked, int s)
{
    return (blocked[s >> 5] & (1u << uint(s & 31))) != 0u;
}

#if AREA_LIGHTS > 0
// The share of area light a's feelers that no triangle blocked: its sample slots are
// lightCount + a·U·V … + U·V − 1 (a sample behind the surface counts as blocked, as Listing 15
// treats a point light behind it).
float unblockedShare(uvec4 blocked, int a)
{
    const int samples = areaSamples;
    int first = lightCount + a * samples;
    int count = 0;
    for (int s = first; s < first + samples; s++)
        count += int(slotBlocked(blocked, s));
    return float(samples - count) / float(samples);
}
#endif

// Listing 16's lit colour of the hit at p (normal n, material mat of its triangle, colour
// albedo) with the shadow slots `blocked`: the ambient term and Phong per light that reaches it.
vec3 litColor(vec3 p, vec3 n, vec4 mat, vec3 albedo, uvec4 blocked)
{
    vec3 view = normalize(camPosition.xyz - p);
    vec3 temp_color = ambientColor.rgb * albedo;
    for (int l = 0; l < lightCount; l++) {
        if (slotBlocked(blocked, l)) continue;
        vec3 L = normalize(pointLightPos(l) - p);
        temp_color += pointLightColor(l) * phong(n, L, view, mat, albedo);
    }
#if AREA_LIGHTS > 0
    for (int a = 0; a < AREA_LIGHTS; a++) {
        float share = unblockedShare(blocked, a);
        if (share <= 0.0) continue;
        vec3 centre = areaLight[4 * a].xyz
                    + 0.5 * (areaLight[4 * a + 1].xyz + areaLight[4 * a + 2].xyz);
        vec3 L = normalize(centre - p);
        temp_color += share * areaLight[4 * a + 3].rgb * phong(n, L, view, mat, albedo);
    }
#endif
    return temp_color;
}

// Listing 16: the weighted addition of temp_color (with the colour buffer's weight
// colorWeight) to the output colour final_color.
vec4 addToFinal(vec4 final_color, vec3 temp_color, float colorWeight)
{
    float weight = final_color.w;
    final_color.rgb = weight * final_color.rgb + (1.0 - weight) * temp_color;
    final_color.w = weight + (1.0 - weight) * colorWeight;
    return final_color;
}
