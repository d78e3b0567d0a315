// raytrace kernel — Wagner 2018 (B.Sc. thesis, "Potenzialanalyse der GPU-Beschleunigung beim
// Raytracing"), the CUDA kernel ported to a GLSL compute shader:
//   ch. 3.3.2   one thread per pixel, blocks of 16×16×1 (x_coord = blockIdx.x·blockDim.x + threadIdx.x)
//   ch. 4.1.1   Listing 4.1 createRay: the primary ray from the camera position
//   ch. 4.1.2   Listing 4.2 intersectTriangle: Möller–Trumbore with ε
//   ch. 4.2.2   Fig. 4.3: the BVH in three textures (boxes, node integers, triangle ids per leaf)
//   ch. 4.2.3   Listing 4.5 intersectAABB; the walk: the root first, then both children, the
//               nearer hit further until a leaf, all the leaf's triangles tested
//   ch. 4.3     the result stored in a texture (the CUDA surface) that a textured plane shows
//   ch. 5       one point light, hard shadows, no reflection or refraction
// The whole algorithm in one kernel ("megakernel"; the thesis' ch. 6 names this as one of its
// design decisions that turned out not to be optimal). Built on the CPU by Listings 4.3/4.4
// (src/pipeline/wagner2018/bvh.rs). CPU twin: src/reference/wagner2018.rs — the same functions,
// the same order, the same counts.
//
// Ours (the thesis does not say, or says otherwise):
// - rays through pixel centres, directions normalised (t is a distance); y counts image rows
//   from the top, as the thesis' image;
// - intersectTriangle: t = f(e2 · r) where the listing misprints f(e2 · q) (always 0), and only
//   t > 0 is a hit; equal distances go to the lower triangle id;
// - after a leaf the walk goes on with the farther children kept on a stack (the thesis
//   describes only the descent to the first leaf, which loses hits behind overlapping boxes),
//   and skips boxes entered beyond the closest hit (or beyond the light);
// - intersectAABB also gives the entry distance clamped to 0 (tNear): the listing's t is the
//   exit distance when the ray starts inside the box, which would skip boxes wrongly;
// - Lambert shading adds the scene's ambient light; the shadow ray starts at the hit point,
//   counts hits at SHADOW_OFFSET < t < the light, skips the hit triangle; a light behind the
//   surface (N·L <= 0) shadows without a ray; normals are turned towards the ray;
// - loopLimit: Mesa's llvmpipe ends an invocation's loops after 65535 iterations in total
//   (see common/intersect.glsl). Each walk is one loop whose iteration visits one node, tests
//   one triangle or pops one stack entry, bounded by LOOP_BUDGET (32000: two walks stay below
//   the limit); a walk that runs out, or finds its stack full, counts the ray as truncated and
//   the host refuses the frame.
layout(local_size_x = 16, local_size_y = 16) in;

#define COUNTER_SLOTS_PER_KERNEL 5
#include "../common/counters.glsl"

// Fig. 4.3, the #[repr(C)] records of src/pipeline/wagner2018/bvh.rs, field by field.
// Texture 1: one BoundsTexels per node, two texels: `centre` (xyz; w `centre_w` = 0), then
// `half`, the half extent (xyz; w `half_w` = 0)
layout(binding = SAMPLER_WAGNER_BVH_BOUNDS) uniform samplerBuffer bvhBounds;
// texture 2: one NodeTexel per node: x `leaf` (1 or 0), y `left_or_first` (an inner node's left
// child, a leaf's first triangle in texture 3), z `right_or_count` (the right child, the leaf's
// triangle count), w `unused` (0)
layout(binding = SAMPLER_WAGNER_BVH_NODES) uniform isamplerBuffer bvhNodes;
// texture 3: one TriangleTexel per leaf triangle: x `id`, the triangle ids grouped per leaf
layout(binding = SAMPLER_WAGNER_BVH_TRIANGLES) uniform isamplerBuffer bvhTriangles;
// the triangles (ch. 4.5: a vertex list), world space, 3 texels per triangle
layout(binding = SAMPLER_WAGNER_VERTICES) uniform samplerBuffer triVertices;
layout(binding = SAMPLER_WAGNER_NORMALS) uniform samplerBuffer triNormals;
layout(binding = SAMPLER_WAGNER_COLORS) uniform samplerBuffer triColors;

// ch. 4.3: the result (rgb, 1)
layout(rgba32f, binding = IMAGE_WAGNER_OUTPUT) uniform writeonly image2D outputImage;
// ours, for the AOVs: (t, triangle id as bits, u, v) of the first hit; the primary ray's
// direction; the normal at the hit with w = 1 lit, 0 in shadow (written with storeAovs)
layout(rgba32f, binding = IMAGE_WAGNER_HIT) uniform writeonly image2D hitImage;
layout(rgba32f, binding = IMAGE_WAGNER_RAY) uniform writeonly image2D rayImage;
layout(rgba32f, binding = IMAGE_WAGNER_NORMAL) uniform writeonly image2D normalImage;

// Listing 4.1's camera, computed on the CPU: direction to the image's upper-left corner, unit
// vectors right and down, the image's extent along them. A reading (docs/listings.md): the
// listing adds α·xDirection·xScale + β·yDirection·yScale with α, β in [0, 1] to
// camera.direction, so that points at the corner where α = β = 0, not along the view.
struct Camera {
    vec3 position;
    vec3 direction;
    vec3 xDirection;
    vec3 yDirection;
    float xScale;
    float yScale;
};
uniform Camera camera;
uniform ivec2 imageSize2;
uniform ivec2 tileOffset;
uniform vec3 lightPosition;
uniform vec3 lightColor;
uniform vec3 ambientColor;
uniform vec3 backgroundColor;
uniform int storeAovs;

struct Ray {
    vec3 origin;
    vec3 direction;
};

// work counts of this invocation, added to the 64-bit counters at the end
uint primaryTests = 0u;
uint shadowTests = 0u;
uint nodesVisited = 0u;
uint truncated = 0u;
uint raysTraced = 0u; // ours: the primary ray and the shadow ray if traced (accel-compare)

// Listing 4.1; x, y: pixel, y = 0 the top row
Ray createRay(Camera camera, int x, int y, int width, int height)
{
    float alpha = (float(x) + 0.5) / float(width);
    float beta = (float(y) + 0.5) / float(height);

    vec3 xDirection = camera.xDirection * alpha * camera.xScale;
    vec3 yDirection = camera.yDirection * beta * camera.yScale;

    vec3 direction = camera.direction + xDirection + yDirection;
    vec3 origin = camera.position;

    return Ray(origin, normalize(direction));
}

// Listing 4.2 with the triangle's vertices p0, p1, p2
bool intersectTriangle(Ray ray, int triangle, out float t, out float u, out float v)
{
    t = 0.0; u = 0.0; v = 0.0;
    vec3 p0 = texelFetch(triVertices, 3 * triangle).xyz;
    vec3 p1 = texelFetch(triVertices, 3 * triangle + 1).xyz;
    vec3 p2 = texelFetch(triVertices, 3 * triangle + 2).xyz;
    vec3 o = ray.origin, d = ray.direction;
    vec3 e1 = p1 - p0;
    vec3 e2 = p2 - p0;
    vec3 q = cross(d, e2);
    float a = dot(e1, q);
    if (a > -EPSILON && a < EPSILON) return false;
    float f = 1.0 / a;
    vec3 s = o - p0;
    u = f * dot(s, q);
    if (u < 0.0) return false;
    vec3 r = cross(s, e1);
    v = f * dot(d, r);
    if (v < 0.0 || u + v > 1.0) return false;
    // the listing prints t = f(e2 · q), which is 0 (q = d × e2 is normal to e2): a misprint of
    // Möller and Trumbore's t = f(e2 · r)
    t = f * dot(e2, r);
    return t > 0.0;
}

// One axis of Listing 4.5 (lines 6-16): e = p_i, f = d_i, h = h_i; false: the box is missed.
// (Written out per axis rather than as a loop: see loopLimit above.)
bool slab(float e, float f, float h, inout float tmin, inout float tmax)
{
    if (abs(f) > EPSILON) {
        float t1 = (e + h) / f;
        float t2 = (e - h) / f;
        if (t1 > t2) { float s = t1; t1 = t2; t2 = s; }
        if (t1 > tmin) tmin = t1;
        if (t2 < tmax) tmax = t2;
        if (tmin > tmax) return false;
        if (tmax < 0.0) return false;
    } else if (-e - h > 0.0 || -e + h < 0.0) return false;
    return true;
}

// Listing 4.5 for node `node`'s box (centre ac, half extents h). t: as the listing returns it;
// tNear: ours, the entry distance clamped to 0.
bool intersectAABB(Ray ray, int node, out float t, out float tNear)
{
    t = 0.0; tNear = 0.0;
    vec3 ac = texelFetch(bvhBounds, 2 * node).xyz;
    vec3 h = texelFetch(bvhBounds, 2 * node + 1).xyz;
    float tmin = -1.0 / 0.0;
    float tmax = 1.0 / 0.0;
    vec3 p = ac - ray.origin;
    vec3 d = ray.direction;
    if (!slab(p.x, d.x, h.x, tmin, tmax)) return false;
    if (!slab(p.y, d.y, h.y, tmin, tmax)) return false;
    if (!slab(p.z, d.z, h.z, tmin, tmax)) return false;
    if (tmin > 0.0) { t = tmin; tNear = tmin; return true; }
    t = tmax;
    return true;
}

// the box of `node` entered at a distance <= limit?
bool enter(Ray ray, int node, float limit, out float t, out float tNear)
{
    return intersectAABB(ray, node, t, tNear) && tNear <= limit;
}

// The walk through the BVH. anyHit = false: the closest hit (limit +inf); anyHit = true: the
// first triangle other than `skip` at offset < t < limit (a shadow ray). Returns the triangle
// found (-1: none) with its t, u, v.
int traverse(Ray ray, bool anyHit, float offset, float limit, int skip,
             out float hitT, out float hitU, out float hitV)
{
    hitT = 1.0 / 0.0; hitU = 0.0; hitV = 0.0;
    int hitID = -1;
    float t, tNear;
    // the root first: a miss of its box is a miss of the scene
    if (!enter(ray, 0, limit, t, tNear)) return -1;
    int stackNode[WAGNER_STACK];
    float stackNear[WAGNER_STACK];
    int sp = 0;
    int node = 0;         // the node to visit next (-1: none)
    int tri = 0, triEnd = 0; // the leaf triangles still to test
    for (int it = 0; it < LOOP_BUDGET; it++) {
        if (tri < triEnd) {
            // one triangle of the leaf (Listing 4.2)
            int id = texelFetch(bvhTriangles, tri).x;
            tri++;
            if (anyHit && id == skip) continue;
            if (anyHit) shadowTests++; else primaryTests++;
            float tt, u, v;
            if (!intersectTriangle(ray, id, tt, u, v)) continue;
            if (anyHit) {
                if (tt > offset && tt < limit) {
                    hitT = tt; hitU = u; hitV = v;
                    return id;
                }
            } else if (hitID < 0 || tt < hitT || (tt == hitT && id < hitID)) {
                hitT = tt; hitU = u; hitV = v; hitID = id;
                limit = tt;
            }
        } else if (node >= 0) {
            nodesVisited++;
            ivec4 n = texelFetch(bvhNodes, node);
            if (n.x != 0) {
                // a leaf: its triangles next
                tri = n.y;
                triEnd = n.y + n.z;
                node = -1;
                continue;
            }
            // both children (Listing 4.5); the nearer hit next, the other onto the stack
            float tl, nl, tr, nr;
            bool hl = enter(ray, n.y, limit, tl, nl);
            bool hr = enter(ray, n.z, limit, tr, nr);
            if (hl && hr) {
                bool leftFirst = tl <= tr;
                if (sp < WAGNER_STACK) {
                    stackNode[sp] = leftFirst ? n.z : n.y;
                    stackNear[sp] = leftFirst ? nr : nl;
                    sp++;
                } else truncated = 1u;
                node = leftFirst ? n.y : n.z;
            } else if (hl) node = n.y;
            else if (hr) node = n.z;
            else node = -1;
        } else {
            // nothing to visit: the next node from the stack, unless beyond the limit
            if (sp == 0) return hitID;
            sp--;
            if (stackNear[sp] <= limit) node = stackNode[sp];
        }
    }
    truncated = 1u;
    return hitID;
}

// Lambert shading with one hard shadow ray (ch. 5): ambient · c + lightColor · c · N·L where
// the light is seen. Writes the normal (w: lit) for the AOVs.
vec3 shade(ivec2 storePos, Ray ray, int id, float t, float u, float v)
{
    vec3 p = ray.origin + t * ray.direction;
    float w = 1.0 - u - v;
    vec3 n = normalize(w * texelFetch(triNormals, 3 * id).xyz
                       + u * texelFetch(triNormals, 3 * id + 1).xyz
                       + v * texelFetch(triNormals, 3 * id + 2).xyz);
    if (dot(n, ray.direction) > 0.0) n = -n;
    vec3 c = w * texelFetch(triColors, 3 * id).rgb
           + u * texelFetch(triColors, 3 * id + 1).rgb
           + v * texelFetch(triColors, 3 * id + 2).rgb;
    vec3 toLight = lightPosition - p;
    float lightDistance = length(toLight);
    vec3 dir = toLight / lightDistance;
    float lambert = dot(n, dir);
    bool lit = false;
    if (lambert > 0.0) {
        raysTraced++; // ours: the shadow ray is traced
        float st, su, sv;
        lit = traverse(Ray(p, dir), true, SHADOW_OFFSET, lightDistance, id, st, su, sv) < 0;
    }
    vec3 color = ambientColor * c;
    if (lit) color += lightColor * c * lambert;
    if (storeAovs != 0) imageStore(normalImage, storePos, vec4(n, lit ? 1.0 : 0.0));
    return color;
}

void raytrace(ivec2 storePos)
{
    int width = imageSize2.x, height = imageSize2.y;
    // GL's row 0 is the bottom row; createRay counts rows from the top
    Ray ray = createRay(camera, storePos.x, height - 1 - storePos.y, width, height);
    raysTraced++; // ours: the primary ray
    float t, u, v;
    int id = traverse(ray, false, 0.0, 1.0 / 0.0, -1, t, u, v);
    vec3 color = backgroundColor;
    if (id >= 0) color = shade(storePos, ray, id, t, u, v);
    else if (storeAovs != 0) imageStore(normalImage, storePos, vec4(0.0, 0.0, 0.0, 1.0));
    imageStore(outputImage, storePos, vec4(color, 1.0));
    imageStore(hitImage, storePos, vec4(t, intBitsToFloat(id), u, v));
    if (storeAovs != 0) imageStore(rayImage, storePos, vec4(ray.direction, 0.0));
}

void main()
{
    countersBegin();
    // ch. 3.3.2: the thread's pixel (x_coord, y_coord), here within the tile
    ivec2 storePos = ivec2(gl_GlobalInvocationID.xy) + tileOffset;
    if (all(lessThan(storePos, imageSize2))) raytrace(storePos);
    countAdd(0, primaryTests);
    countAdd(1, shadowTests);
    countAdd(2, nodesVisited);
    countAdd(3, truncated);
    countAdd(4, raysTraced);
    countersEnd(0, COUNTER_PRIMARY_TESTS);
    countersEnd(1, COUNTER_SHADOW_TESTS);
    countersEnd(2, COUNTER_NODES_VISITED);
    countersEnd(3, COUNTER_TRUNCATED_RAYS);
    countersEnd(4, COUNTER_RAYS);
}
