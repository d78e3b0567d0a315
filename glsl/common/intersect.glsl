// Ray/triangle intersection, Algorithm 1 of Müller 2015 (ch. 2.1, after Purcell et al.):
// intersectTriangle (two misprints of the printed algorithm corrected, see below);
// the Möller–Trumbore test. No determinant epsilon, as in the thesis: a ray parallel to the
// triangle gives det = 0, 1/det = inf and comparisons that fail, i.e. no hit.
// Returns true for a hit with t > 0 and the barycentric (u, v).
// intersectEdges is the algorithm after its first two lines (edge1 = v1 − v0, edge2 = v2 − v0),
// for the accelerators that store the edges (the SAH BVH's leaves, the streaming tracer's triangle
// textures): the same operations on the same values, so every tracer finds the same distances.
bool intersectEdges(vec3 r0, vec3 rd, vec3 v0, vec3 edge1, vec3 edge2,
                    out float t, out float u, out float v)
{
    vec3 pvec = cross(rd, edge2);
    float det = dot(edge1, pvec);
    float invDet = 1.0 / det;
    vec3 tvec = r0 - v0;
    // the thesis prints u = det⁻¹ · (tvec × pvec), a cross product where a scalar is meant:
    // Möller and Trumbore's dot product
    u = invDet * dot(tvec, pvec);
    // the thesis prints qvec = tvec × pvec; with that qvec, v and t are not the barycentric
    // coordinate and the distance (qvec ⊥ pvec). Möller and Trumbore's qvec = tvec × edge1
    // makes v = det⁻¹ · (rd · qvec) and t = det⁻¹ · (edge2 · qvec) right (Cramer's rule)
    vec3 qvec = cross(tvec, edge1);
    v = invDet * dot(rd, qvec);
    t = invDet * dot(edge2, qvec);
    return (u >= 0.0) && (v >= 0.0) && (u + v <= 1.0) && (t > 0.0);
}

bool intersectTriangle(vec3 r0, vec3 rd, vec3 v0, vec3 v1, vec3 v2,
                       out float t, out float u, out float v)
{
    vec3 edge1 = v1 - v0;
    vec3 edge2 = v2 - v0;
    return intersectEdges(r0, rd, v0, edge1, edge2, t, u, v);
}

// loopLimit: Mesa's llvmpipe ends every loop of an invocation after 65535 iterations in total
// (its guard against endless loops), which would silently cut the base tracer's loop over the
// 69451-triangle bunny short. The loops stay as Listings 12 and 15 print them (one triangle per
// iteration); the host instead splits the triangles over several dispatches of the kernel where
// the implementation needs it (at most TRIANGLES_PER_DISPATCH in src/accel/brute_force.rs).
// A loop that still ends early is counted (the truncated_rays statistic; the host refuses such
// a frame): it tested fewer triangles than testsInRange, the triangles first <= i < end other
// than skip (the triangle the ray starts on).
uint testsInRange(int first, int end, int skip)
{
    return uint(end - first) - ((skip >= first && skip < end) ? 1u : 0u);
}
