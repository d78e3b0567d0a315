// intersect1 kernel of the base tracer — Müller 2015, ch. 3.1.1 (Fig. 6) and 4.1.2,
// Listings 12, 13 and 14.
// One invocation per pixel: the active ray (rayState > 0) is tested against every triangle
// of the scene with Algorithm 1 (Listing 12, below), skipping the triangle it starts on
// (lastTriID); then the closest hit is evaluated (Listings 13 and 14: evaluateHit in
// common/intersect1_hit.glsl).
// Ours: the host may split the triangles over several dispatches of this kernel, each testing
// firstTriangle <= i < endTriangle — only where the GL implementation ends long loops (Mesa
// llvmpipe, see loopLimit in common/intersect.glsl; src/accel/brute_force.rs). The closest hit
// so far goes from one dispatch to the next in the colour buffer (which only the last one
// writes otherwise); the dispatch that ends with the last triangle evaluates it.
// the first of the dispatches counts the ray (raysTraced, common/intersect_head.glsl)
#define COUNTS_RAY (firstTriangle == 0)
#include "../common/intersect_head.glsl"
#include "../common/count_work.glsl"
#include "../common/vertex_attributes.glsl"
#include "../common/intersect1_hit.glsl"

// this dispatch's triangles (ours): firstTriangle <= i < endTriangle; one dispatch: 0 and
// triangleCount()
uniform int firstTriangle;
uniform int endTriangle;

void trace(ivec2 storePos)
{
    vec4 originState = imageLoad(rayOriginTexture, storePos);
    vec4 dirTri = imageLoad(rayDirTexture, storePos);
    float rayState = originState.w;
    if (rayState <= 0.0) {
        emptyColorBuffer(storePos);
        return;
    }
    raysTraced = uint(COUNTS_RAY);
    vec3 ro = originState.xyz;
    vec3 rd = dirTri.xyz;
    int lastTriID = int(dirTri.w);

    // the closest hit so far (ch. 4.1.2: t_min, triID, hit_u, hit_v): none before the first
    // triangle, else the one the dispatch before carried over
    float t_min = 1.0 / 0.0; // +inf
    int triID = -1;
    float hit_u = 0.0, hit_v = 0.0;
    if (firstTriangle > 0) {
        vec4 carried = imageLoad(colorBufferTexture, storePos);
        t_min = carried.x;
        triID = int(carried.y);
        hit_u = carried.z; hit_v = carried.w;
    }

    // Listing 12: iteration over all triangles of the scene (of this dispatch). Listing 12
    // steps i by 3 over the vertices, so its triID is the index of the triangle's first vertex;
    // ours counts triangles: triID = the triangle's index (its vertices are 3·triID + 0, 1, 2),
    // as the AOVs and export-triangles number them.
    for (int i = firstTriangle; i < endTriangle; i++)
    {
        if (i != lastTriID)
        { // load the vertices of triangle #i
            vec3 v0 = vertex[3 * i].xyz,
                 v1 = vertex[3 * i + 1].xyz,
                 v2 = vertex[3 * i + 2].xyz;
            // the intersection test after Purcell et al. (Algorithm 1)
            float t, u, v;
            tests++;
            // hit inside the triangle and closest so far?
            if (intersectTriangle(ro, rd, v0, v1, v2, t, u, v) && t < t_min)
            { // update the buffered results
                t_min = t;
                triID = i;
                hit_u = u; hit_v = v;
            }
        }
    }
    // ours: a loop cut short by the implementation is counted, never hidden
    if (tests < testsInRange(firstTriangle, endTriangle, lastTriID)) truncated = 1u;

    if (endTriangle < triangleCount()) {
        // not the last dispatch: carry the closest hit so far to the next one
        imageStore(colorBufferTexture, storePos, vec4(t_min, float(triID), hit_u, hit_v));
        return;
    }
    // Listings 13 and 14
    evaluateHit(storePos, ro, rd, rayState, t_min, triID, hit_u, hit_v);
}

void main()
{
    traceAndCount(COUNTER_INTERSECT1);
}
