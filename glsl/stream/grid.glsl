// The static grid and the triangles in texture memory — the streaming tracer, ch. 3, Fig. 3 ("grid
// data layout with two levels of indirection"), and the 3D-DDA of Amanatides and Woo that walks it.
// The grid is built in src/pipeline/stream/grid.rs; the CPU twin of every function here is in
// src/reference/stream_grid.rs (same f32 arithmetic, same order), the tests' oracle.
//
// The texels' layouts are #[repr(C)] records of src/pipeline/stream/grid_textures.rs, field by
// field:
// cells:      3D texture RGB32F, one CellTexel per grid cell: R `pointer` (the index in
//             references of the cell's first reference), G `count` (its references), B
//             `proximity` (the proximity-cloud distance, in cells, Chebyshev metric; 0 for a
//             non-empty cell)
// references: texture buffer R32F, the tightly packed lists, one ReferenceTexel per
//             reference: R `triangle`, an id, i.e. the (x, y) of the triangle's texels in the
//             two triangle textures
// triVertex:  3D texture RGB32F, 4 depth slices: slice k holds field k of the triangle's
//             TriangleVertexTexels, `v0`, `edge1`, `edge2`, `color` (diffuse)
// triNormal:  3D texture RGB32F, 4 depth slices: field k of TriangleNormalTexels, `n0`, `n1`,
//             `n2`, then (`reflectivity`, `unused`: 0, 0)
//             ("edge1 and edge2 are stored instead of v1 and v2, to save the GPU two vector
//             subtractions every ray-triangle intersection test", ch. 3)
#include "../common/intersect.glsl"

layout(binding = SAMPLER_STREAM_CELLS) uniform sampler3D cells;
layout(binding = SAMPLER_STREAM_REFS) uniform samplerBuffer references;
layout(binding = SAMPLER_STREAM_TRI_VERTEX) uniform sampler3D triVertex;
layout(binding = SAMPLER_STREAM_TRI_NORMAL) uniform sampler3D triNormal;

uniform vec3 gridMin;
uniform vec3 gridMax;
uniform vec3 cellSize;
uniform ivec3 gridSize;
// the width of the triangle textures: triangle id -> (x, y)
uniform int triTextureWidth;

// +infinity (GLSL has no literal for it)
#define INF uintBitsToFloat(0x7F800000u)

// the ray state in the w channel of Fig. 2's first texture
#define RAY_ACTIVE 1.0
#define RAY_DONE 2.0

ivec2 triTexel(int id)
{
    return ivec2(id % triTextureWidth, id / triTextureWidth);
}

vec3 triangleVertex(int id, int slice)
{
    return texelFetch(triVertex, ivec3(triTexel(id), slice), 0).rgb;
}

vec3 triangleNormal(int id, int slice)
{
    return texelFetch(triNormal, ivec3(triTexel(id), slice), 0).rgb;
}

// Möller and Trumbore (ch. 3: "the fastest known single sided algorithm") with the stored
// edges: the same arithmetic as Algorithm 1 of glsl/common/intersect.glsl given v1 - v0 and
// v2 - v0, so the distances equal the other tracers'. A deviation by default: the test is
// two-sided (a hit whatever the sign of det), as every tracer here, so that their hits compare
// pixel by pixel and models that are not consistently wound (the teapot's patches: 24 % of
// teapot1's first hits are back faces) render whole. SINGLE_SIDED (--stream-single-sided) is
// the paper's single-sided test: Möller and Trumbore's culling branch, a triangle seen from its
// back (det = edge1 · (rd × edge2) <= 0) is no hit and nothing after det is computed for it;
// a front face gets the same arithmetic, so the same distance. On the streaming tracer's own scenes
// no eye ray's first hit is a back face, so both find the same first hits; a few shadows near
// silhouettes differ (docs/results/backfaces.md).
bool intersectStored(vec3 r0, vec3 rd, int id, out float t, out float u, out float v)
{
    vec3 v0 = triangleVertex(id, 0);
    vec3 edge1 = triangleVertex(id, 1);
    vec3 edge2 = triangleVertex(id, 2);
#if SINGLE_SIDED
    if (dot(edge1, cross(rd, edge2)) <= 0.0) {
        t = 0.0; u = 0.0; v = 0.0;
        return false;
    }
#endif
    return intersectEdges(r0, rd, v0, edge1, edge2, t, u, v);
}

// clipToBox: (enter, exit) of o + t·d inside the grid's box; enter > exit when it misses.
vec2 clipToBox(vec3 o, vec3 d)
{
    float enter = -INF, exitT = INF;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
            if (o[a] < gridMin[a] || o[a] > gridMax[a]) return vec2(INF, -INF);
            continue;
        }
        float t0 = (gridMin[a] - o[a]) / d[a];
        float t1 = (gridMax[a] - o[a]) / d[a];
        enter = max(enter, min(t0, t1));
        exitT = min(exitT, max(t0, t1));
    }
    return vec2(enter, exitT);
}

// planeT: where o + t·d leaves cell column k of axis a (+inf for d = 0).
float planeT(vec3 o, vec3 d, int a, int k)
{
    if (d[a] == 0.0) return INF;
    int up = d[a] > 0.0 ? 1 : 0;
    return (gridMin[a] + float(k + up) * cellSize[a] - o[a]) / d[a];
}

vec3 tMaxOf(vec3 o, vec3 d, ivec3 c)
{
    return vec3(planeT(o, d, 0, c.x), planeT(o, d, 1, c.y), planeT(o, d, 2, c.z));
}

// cellOf: the cell of p, clamped into the grid.
ivec3 cellOf(vec3 p)
{
    return clamp(ivec3(floor((p - gridMin) / cellSize)), ivec3(0), gridSize - 1);
}

bool insideGrid(ivec3 c)
{
    return all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, gridSize));
}

// the axis of the smallest component (ties: x, then y, then z)
int minAxis(vec3 t)
{
    float m = min(t.x, min(t.y, t.z));
    return t.x == m ? 0 : (t.y == m ? 1 : 2);
}
