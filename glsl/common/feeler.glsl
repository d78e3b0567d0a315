// One shadow feeler of Listing 15 (Müller 2015, ch. 4.1.2): from the hit point ro (normal n,
// triangle lastTriID) towards `target`; true if the light is blocked there — behind the
// surface (N·L <= 0: shadow without a test) or a triangle other than lastTriID lies on the
// segment (the design's occluded, which the including kernel defines). Ours: a function of its
// own, shared by common/intersect2_main.glsl and the SAH BVH's fused pass
// (bvh/fused_pass.comp), which traces all of a pixel's feelers in one invocation; it adds
// the feeler to raysTraced (ours: the feelers traced, per ray kind).
bool occluded(ivec2 storePos, vec3 ro, vec3 rd, float lightDistance, int lastTriID);

bool feelerBlocked(ivec2 storePos, vec3 ro, vec3 n, int lastTriID, vec3 target)
{
    vec3 toLight = target - ro;
    float lightDistance = length(toLight);
    vec3 rd = toLight / lightDistance;

    // light in the back half-space of the hit point: shadow without a test
    if (dot(n, rd) <= 0.0) return true;
    raysTraced += uint(COUNTS_RAY);
    return occluded(storePos, ro, rd, lightDistance, lastTriID);
}
