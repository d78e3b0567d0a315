// intersect1 kernel of the base tracer — Müller 2015, ch. 3.1.1 (Fig. 6) and 4.1.2,
// Listings 12, 13 and 14.
// One invocation per pixel: the active ray (rayState > 0) is tested against every triangle
// of the scene with Algorithm 1 (Listing 12), skipping the triangle it starts on (lastTriID).
// The evaluation of the closest hit (Listings 13, 14) is in common/intersect1_main.glsl.
#include "../common/intersect_head.glsl"

// Listing 12's loop body: test triangle i (unless it is the one the ray starts on) and keep
// the closest hit.
void testTriangle(int i, int n, vec3 ro, vec3 rd, int lastTriID,
                  inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
    if (i < n && i != lastTriID) {
        // load the vertices of triangle #i
        vec3 v0 = vertex[3 * i].xyz, v1 = vertex[3 * i + 1].xyz, v2 = vertex[3 * i + 2].xyz;
        float t, u, v;
        tests++;
        // hit inside the triangle and closest so far? update the buffered results
        if (intersectTriangle(ro, rd, v0, v1, v2, t, u, v) && t < t_min) {
            t_min = t;
            triID = i;
            hit_u = u; hit_v = v;
        }
    }
}

// Listing 12: iteration over all triangles of the scene, TRIANGLES_PER_ITERATION at a time
// (see loopLimit in common/intersect.glsl). Listing 12 steps i by 3 over the vertices, so its
// triID is the index of the triangle's first vertex; ours counts triangles: triID = the
// triangle's index (its vertices are 3·triID + 0, 1, 2), as the AOVs and export-triangles
// number them.
void closestHit(ivec2 storePos, vec3 ro, vec3 rd, int lastTriID,
                inout float t_min, inout int triID, inout float hit_u, inout float hit_v)
{
    int n = triangleCount();
    int i = 0;
    for (; i < n; i += TRIANGLES_PER_ITERATION) {
        testTriangle(i, n, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
        testTriangle(i + 1, n, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
        testTriangle(i + 2, n, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
        testTriangle(i + 3, n, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
        testTriangle(i + 4, n, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
        testTriangle(i + 5, n, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
        testTriangle(i + 6, n, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
        testTriangle(i + 7, n, ro, rd, lastTriID, t_min, triID, hit_u, hit_v);
    }
    // a loop cut short by the implementation is counted, never hidden
    if (i < n) truncated = 1u;
}

#include "../common/intersect1_main.glsl"
