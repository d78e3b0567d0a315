// intersect2 kernel of the BVH — ours, after Wagner 2018 ch. 4.2 (hard shadows: a shadow ray
// towards the one light through the same BVH): the shadow feeler walks the BVH
// (bvh/traverse.glsl, nodes beyond the light and those it leaves before the shadow offset
// pruned) and tests the triangles of each leaf until the first occluder (any hit).
// Deviations: see traverse.glsl; any number of lights.
// Feeler set-up, N·L early out and flags: common/intersect2_main.glsl (Müller 2015, Listing 15).
// Ours: an invocation per pixel of the pass' hit list (bvh/hit_list.glsl), not per pixel.
#include "int64.glsl"
#include "hit_list.glsl"
#include "../common/intersect_head.glsl"
#include "records.glsl"
// the work counts stored per pixel (storePixelRecord), not added to the counters
#include "record_work.glsl"
#include "traverse.glsl"

// the feelers of the pixels in the pass' hit list, not of every pixel (bvh/hit_list.glsl): an
// invocation per entry, its work in the record of its list position
bool workItem(out ivec2 storePos, out int record)
{
    uint k = listGroup() * HIT_LIST_GROUP + gl_LocalInvocationIndex;
    record = int(k);
    storePos = ivec2(0);
    bool listed = k < hitCount();
    if (listed) storePos = hitPixel(k);
    return listed;
}

// the feeler's last triangle and the light's distance, for triangleHit (the feeler itself:
// rayO, rayD of bvh/traverse.glsl)
int rayLast = -1;
float rayLight = 0.0;

bool triangleHit(int at, int tri, vec3 v0, vec3 edge1, vec3 edge2, inout float limit)
{
    float t, u, v;
    bool hit = intersectEdges(rayO, rayD, v0, edge1, edge2, t, u, v);
    if (tri == rayLast) return false;
    tests++;
    return hit && t > SHADOW_OFFSET && t < rayLight;
}

bool occluded(ivec2 storePos, vec3 ro, vec3 rd, float lightDistance, int lastTriID)
{
    rayLast = lastTriID; rayLight = lightDistance;
    return traverseScene(ro, rd, SHADOW_OFFSET, lightDistance, uvec4(0u)); // from the root
}

#include "../common/intersect2_main.glsl"
