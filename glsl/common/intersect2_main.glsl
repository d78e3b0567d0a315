// The part of the intersect2 kernel all tracer designs share — Müller 2015, ch. 4.1.2,
// Listing 15 — around the any-hit search of the design, which the including kernel defines
// before including this file:
//     bool occluded(ivec2 storePos, vec3 ro, vec3 rd, float lightDistance, int lastTriID)
// (true if a triangle other than lastTriID is hit with SHADOW_OFFSET < t < lightDistance).
//
// Dispatched once per light source (uniform lightSource). One shadow feeler per pixel from
// the hit point of intersect1 towards the light. Ours: an area light is dispatched once per
// light sample, each dispatch's feelers towards that sample setting the sample's own flag bit
// (common/light_target.glsl); the shading kernel weights the light by the share of unset bits. Early out: N·L <= 0 means the light is behind
// the surface — shadow without a test. The 0.02 offset (SHADOW_OFFSET) is the thesis'
// correction for smoother transitions between the shadow and the lighting. The flag goes into
// the shadow texture: one RGBA channel per light (the thesis, lights 0..3) or one bit per
// light in an RGBA32UI texture (SHADOW_BITS, the bitwise flags of ch. 5). Flags are only ever
// set here, so the host clears the shadow texture before every pass (ch. 3.1.3 clears the
// textures once a frame, which would let a reflection pass inherit the flags of the pass
// before it); see RayTracer::pass in src/pipeline/mueller2015/mod.rs.

#include "light_target.glsl"
#include "feeler.glsl"

// Is this light's shadow flag already set at storePos? (For a kernel that splits its search
// over several dispatches: brute_force/intersect2.comp.)
bool shadowFlagSet(ivec2 storePos)
{
#if SHADOW_BITS
    return (imageLoad(shadowTexture, storePos)[lightSource >> 5]
            & (1u << uint(lightSource & 31))) != 0u;
#else
    return imageLoad(shadowTexture, storePos)[lightSource] > 0.5;
#endif
}

void trace(ivec2 storePos)
{
    vec4 originState = imageLoad(rayOriginTexture, storePos);
    // only rays that hit something in this pass have rayState > 0 here
    if (originState.w <= 0.0) return;
    int lastTriID = int(imageLoad(rayDirTexture, storePos).w);
    vec3 n = imageLoad(normalTexture, storePos).xyz;
    // Ours: the pixel's shadow flags are loaded here, before the search, where Listing 15
    // loads them after it to set the flag — no other invocation writes this texel in the
    // dispatch, so the value is the same, and its load's latency hides behind the search (on
    // llvmpipe a load after the walk waits for memory at the end of every invocation:
    // docs/design/frame.md; docs/design/bvh.md, step 27).
#if SHADOW_BITS
    uvec4 flags = imageLoad(shadowTexture, storePos);
#else
    vec4 shadows = imageLoad(shadowTexture, storePos);
#endif
    bool shadow = feelerBlocked(storePos, originState.xyz, n, lastTriID, feelerTarget());

    // set the shadow flag if needed
    if (shadow) {
#if SHADOW_BITS
        flags[lightSource >> 5] |= 1u << uint(lightSource & 31);
        imageStore(shadowTexture, storePos, flags);
#else
        switch (lightSource) {
            case 0: shadows.x = 1.0; break;
            case 1: shadows.y = 1.0; break;
            case 2: shadows.z = 1.0; break;
            case 3: shadows.w = 1.0; break;
        }
        imageStore(shadowTexture, storePos, shadows);
#endif
    }
}

void main()
{
    traceAndCount(COUNTER_INTERSECT2);
}
