// intersect2 kernel of the base tracer — Müller 2015, ch. 3.1.1 and 4.1.2, Listing 15.
// The shadow feeler is tested against every triangle but the hit one, and the loop stops at
// the first hit (any hit). The feeler set-up, the N·L early out and the setting of the shadow
// flag are in common/intersect2_main.glsl, which calls occluded below.
// Ours: as in intersect1.comp, the host may split the triangles over several dispatches
// (firstTriangle <= i < endTriangle) where the GL implementation ends long loops (loopLimit in
// common/intersect.glsl). The shadow flag carries the result from one dispatch to the next: it
// is only ever set, so a feeler whose flag a dispatch before set is done.
// the first of the dispatches counts the feeler (raysTraced, common/intersect_head.glsl)
#define COUNTS_RAY (firstTriangle == 0)
#include "../common/intersect_head.glsl"
#include "../common/count_work.glsl"

// this dispatch's triangles (ours): firstTriangle <= i < endTriangle; one dispatch: 0 and
// triangleCount()
uniform int firstTriangle;
uniform int endTriangle;

// in common/intersect2_main.glsl: is this light's shadow flag set at storePos?
bool shadowFlagSet(ivec2 storePos);

bool occluded(ivec2 storePos, vec3 ro, vec3 rd, float lightDistance, int lastTriID)
{
    // ours: an occluder found by a dispatch before this one
    if (firstTriangle > 0 && shadowFlagSet(storePos)) return true;
    bool shadow = false;
    // Listing 15 (its i steps by 3 over the vertices; ours counts triangles, as intersect1.comp)
    for (int i = firstTriangle; (i < endTriangle) && (!shadow); i++)
    { // prevent the self-shadowing of a triangle
        if (i != lastTriID)
        {
            // the intersection test after Purcell et al. (Algorithm 1)
            float t, u, v;
            tests++;
            // correction 0.02 (SHADOW_OFFSET) for smoother transitions between the shadow and
            // the lighting model; ours: only occluders before the light count
            if (intersectTriangle(ro, rd, vertex[3 * i].xyz, vertex[3 * i + 1].xyz,
                                  vertex[3 * i + 2].xyz, t, u, v)
                && t > SHADOW_OFFSET && t < lightDistance)
                shadow = true;
        }
    }
    // ours: a loop cut short by the implementation is counted, never hidden
    if (!shadow && tests < testsInRange(firstTriangle, endTriangle, lastTriID)) truncated = 1u;
    return shadow;
}

#include "../common/intersect2_main.glsl"
