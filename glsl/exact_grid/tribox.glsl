// Triangle/box overlap test (separating axes: the box's 3 axes, the triangle's normal and the
// 9 cross products of edges and axes; Akenine-Möller 2001). Not in Müller 2015: the thesis
// registers triangles only along their edges (build.comp); the exact grid registers every
// triangle in every voxel it overlaps.
// precise (ours; GLSL 4.60 §4.7.1): the count and fill passes are two programs that must reach
// the same verdict for every (triangle, voxel) pair — a compiler may otherwise contract a·b + c
// into a fused multiply-add in one and not the other, and fill would find more overlaps than
// count reserved (counted as truncated) or fewer (list slots left unwritten). Every value the
// verdict depends on is precise, so both programs compute it in the order written, unfused.

bool axisSeparates(vec3 axis, vec3 v0, vec3 v1, vec3 v2, vec3 halfSize)
{
    precise float p0 = dot(v0, axis), p1 = dot(v1, axis), p2 = dot(v2, axis);
    precise float r = dot(halfSize, abs(axis));
    return min(p0, min(p1, p2)) > r || max(p0, max(p1, p2)) < -r;
}

// Does the triangle (a, b, c) overlap the box center ± halfSize (boundary included)?
bool triBoxOverlap(vec3 center, vec3 halfSize, vec3 a, vec3 b, vec3 c)
{
    precise vec3 v0 = a - center, v1 = b - center, v2 = c - center;
    // the box's axes: the triangle's bounds
    precise vec3 lo = min(v0, min(v1, v2)), hi = max(v0, max(v1, v2));
    if (any(greaterThan(lo, halfSize)) || any(lessThan(hi, -halfSize))) return false;
    precise vec3 e0 = v1 - v0, e1 = v2 - v1, e2 = v0 - v2;
    // the triangle's plane
    precise vec3 n = cross(e0, e1);
    precise float d = dot(n, v0), rn = dot(halfSize, abs(n));
    if (abs(d) > rn) return false;
    // the nine edge × axis directions
    vec3 edges[3] = vec3[3](e0, e1, e2);
    for (int i = 0; i < 3; i++) {
        vec3 e = edges[i];
        if (axisSeparates(vec3(0.0, -e.z, e.y), v0, v1, v2, halfSize)) return false;
        if (axisSeparates(vec3(e.z, 0.0, -e.x), v0, v1, v2, halfSize)) return false;
        if (axisSeparates(vec3(-e.y, e.x, 0.0), v0, v1, v2, halfSize)) return false;
    }
    return true;
}
