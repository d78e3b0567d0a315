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
#define COUNTER_SLOTS_PER_KERNEL 2
#include "common/scene.glsl"
#include "common/images.glsl"
#include "common/intersect.glsl"
#include "common/counters.glsl"

uniform int lightSource;

// Listing 15's loop body: does triangle i (not the hit triangle: no self-shadowing) block the
// feeler between the 0.02 offset and the light?
bool occludes(int i, int n, vec3 ro, vec3 rd, float lightDistance, int lastTriID, inout uint tests)
{
    if (i >= n || i == lastTriID) return false;
    float t, u, v;
    tests++;
    return intersectTriangle(ro, rd, vertex[3 * i].xyz, vertex[3 * i + 1].xyz,
                             vertex[3 * i + 2].xyz, t, u, v)
        && t > SHADOW_OFFSET && t < lightDistance;
}

uint truncated = 0u;

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
    int i = 0;
    // any hit: the loop ends with the first occluder; TRIANGLES_PER_ITERATION at a time (see
    // loopLimit in common/intersect.glsl)
    for (; (i < count) && (!shadow); i += TRIANGLES_PER_ITERATION) {
        shadow = shadow || occludes(i, count, ro, rd, lightDistance, lastTriID, tests);
        shadow = shadow || occludes(i + 1, count, ro, rd, lightDistance, lastTriID, tests);
        shadow = shadow || occludes(i + 2, count, ro, rd, lightDistance, lastTriID, tests);
        shadow = shadow || occludes(i + 3, count, ro, rd, lightDistance, lastTriID, tests);
        shadow = shadow || occludes(i + 4, count, ro, rd, lightDistance, lastTriID, tests);
        shadow = shadow || occludes(i + 5, count, ro, rd, lightDistance, lastTriID, tests);
        shadow = shadow || occludes(i + 6, count, ro, rd, lightDistance, lastTriID, tests);
        shadow = shadow || occludes(i + 7, count, ro, rd, lightDistance, lastTriID, tests);
    }
    if (!shadow && i < count) truncated = 1u;

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
    countAdd(1, truncated);
    countersEnd(0, COUNTER_INTERSECT2);
    countersEnd(1, COUNTER_TRUNCATED_RAYS);
}
