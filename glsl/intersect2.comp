// intersect2 kernel — Müller 2015, ch. 3.1.1 and 4.1.2, Listing 15.
// Dispatched once per light source (uniform lightSource). One shadow feeler per pixel from
// the hit point of intersect1 towards the light. Early out: N·L <= 0 means the light is behind
// the surface — shadow without a test. Otherwise every triangle but the hit one is tested and
// the loop stops at the first hit (any hit) with 0.02 < t < distance to the light; the 0.02
// is the thesis' correction for smoother transitions between the shadow and the lighting.
// The flag goes into the shadow texture: one RGBA channel per light (the thesis, lights 0..3)
// or one bit per light in an RGBA32UI texture (SHADOW_BITS, the bitwise flags of ch. 5).
layout(local_size_x = 8, local_size_y = 8) in;

#define SCENE_QUALIFIER readonly
#define COUNTER_SLOTS_PER_KERNEL 1
#include "common/scene.glsl"
#include "common/images.glsl"
#include "common/intersect.glsl"
#include "common/counters.glsl"

uniform int lightSource;

uint trace(ivec2 storePos)
{
    vec4 originState = imageLoad(rayOriginTexture, storePos);
    // only rays that hit something in this pass have rayState > 0 here
    if (originState.w <= 0.0) return 0u;
    int lastTriID = int(imageLoad(rayDirTexture, storePos).w);
    vec3 n = imageLoad(normalTexture, storePos).xyz;
    vec3 ro = originState.xyz;
    vec3 toLight = lightPos[lightSource].xyz - ro;
    float lightDistance = length(toLight);
    vec3 rd = toLight / lightDistance;

    uint tests = 0u;
    // light in the back half-space of the hit point: shadow without a test
    bool shadow = dot(n, rd) <= 0.0;
    int count = triangleCount();
    for (int i = 0; (i < count) && (!shadow); i++) {
        // no self-shadowing of the hit triangle
        if (i != lastTriID) {
            float t, u, v;
            tests++;
            if (intersectTriangle(ro, rd, vertex[3 * i].xyz, vertex[3 * i + 1].xyz,
                                  vertex[3 * i + 2].xyz, t, u, v)
                && t > SHADOW_OFFSET && t < lightDistance)
                shadow = true;
        }
    }

    // set the shadow flag if needed
    if (shadow) {
#if SHADOW_BITS
        uvec4 flags = imageLoad(shadowTexture, storePos);
        flags[lightSource >> 5] |= 1u << uint(lightSource & 31);
        imageStore(shadowTexture, storePos, flags);
#else
        vec4 shadows = imageLoad(shadowTexture, storePos);
        switch (lightSource) {
            case 0: shadows.x = 1.0; break;
            case 1: shadows.y = 1.0; break;
            case 2: shadows.z = 1.0; break;
            case 3: shadows.w = 1.0; break;
        }
        imageStore(shadowTexture, storePos, shadows);
#endif
    }
    return tests;
}

void main()
{
    countersBegin();
    ivec2 storePos = pixelPosition();
    uint tests = insideImage(storePos) ? trace(storePos) : 0u;
    countAdd(0, tests);
    countersEnd(0, COUNTER_INTERSECT2);
}
