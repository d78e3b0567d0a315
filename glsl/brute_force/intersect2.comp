// intersect2 kernel of the base tracer — Müller 2015, ch. 3.1.1 and 4.1.2, Listing 15.
// The shadow feeler is tested against every triangle but the hit one, and the loop stops at
// the first hit (any hit). The feeler set-up, the N·L early out and the shadow flags are in
// common/intersect2_main.glsl.
#include "../common/intersect_head.glsl"

// Listing 15's loop body: does triangle i (not the hit triangle: no self-shadowing) block the
// feeler between the 0.02 offset and the light?
bool occludes(int i, int n, vec3 ro, vec3 rd, float lightDistance, int lastTriID)
{
    if (i >= n || i == lastTriID) return false;
    float t, u, v;
    tests++;
    return intersectTriangle(ro, rd, vertex[3 * i].xyz, vertex[3 * i + 1].xyz,
                             vertex[3 * i + 2].xyz, t, u, v)
        && t > SHADOW_OFFSET && t < lightDistance;
}

// any hit: the loop ends with the first occluder; TRIANGLES_PER_ITERATION at a time (see
// loopLimit in common/intersect.glsl)
bool occluded(ivec2 storePos, vec3 ro, vec3 rd, float lightDistance, int lastTriID)
{
    int count = triangleCount();
    bool shadow = false;
    int i = 0;
    for (; (i < count) && (!shadow); i += TRIANGLES_PER_ITERATION) {
        shadow = shadow || occludes(i, count, ro, rd, lightDistance, lastTriID);
        shadow = shadow || occludes(i + 1, count, ro, rd, lightDistance, lastTriID);
        shadow = shadow || occludes(i + 2, count, ro, rd, lightDistance, lastTriID);
        shadow = shadow || occludes(i + 3, count, ro, rd, lightDistance, lastTriID);
        shadow = shadow || occludes(i + 4, count, ro, rd, lightDistance, lastTriID);
        shadow = shadow || occludes(i + 5, count, ro, rd, lightDistance, lastTriID);
        shadow = shadow || occludes(i + 6, count, ro, rd, lightDistance, lastTriID);
        shadow = shadow || occludes(i + 7, count, ro, rd, lightDistance, lastTriID);
    }
    if (!shadow && i < count) truncated = 1u;
    return shadow;
}

#include "../common/intersect2_main.glsl"
