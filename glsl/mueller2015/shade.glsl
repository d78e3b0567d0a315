// The shading of one hit — Müller 2015, ch. 4.1.3, Listing 16, with the area lights of
// shading.comp (ours, after Klee 2016) — as functions of the values shading.comp loads from
// the ray-state textures, so that the SAH BVH's fused pass (bvh/fused_pass.comp, ours) lights
// a hit with the same code from the values it holds in registers. The including kernel
// declares the uniforms camPosition, ambientColor and (with area lights) areaLight, the
// point-light count lightCount, and pointLightPos / pointLightColor.

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
    const int samples = SAMPLES_U * SAMPLES_V;
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
