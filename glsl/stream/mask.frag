// The masking kernel — the streaming tracer, ch. 3, the optimisations: "During the execution of an
// additional kernel (right after the ray generator, but suppressed in figure 1) rays that are
// known not needing further processing (eg. rays missed the scene AABB, shadow rays for rays not
// intersecting any objects) are masked out as soon as possible, and excluded from further
// calculations."
// Writes the first state set of Fig. 2: a masked ray is RAY_DONE with an empty hit record (the
// early-Z pass then culls it from every traverse call); an active ray gets the start of its
// 3D-DDA (Amanatides and Woo): the cell where it enters the grid and tMax, no triangles
// processed, no hit yet.
// masking = 0 (--stream-no-mask, for measuring the optimisation): nothing is masked here — a
// ray that needs no work (no ray, or one that misses the grid's box) is started as active with
// -1 triangles processed, and the traverse kernel's first call finds it finished; a shadow
// ray's limit is |rayDirection.w| (ray_generator.frag negates it for a light behind the
// surface, a ray the masking would not have made).
#include "grid.glsl"
#include "rays.glsl"
#include "counters.glsl"

// 1: the rays are shadow rays (rayDirection.w is their limit, not a weight)
uniform int shadowRays;
uniform int masking;

layout(location = 0) out vec4 outTMax;
layout(location = 1) out vec4 outCell;
layout(location = 2) out vec4 outHit;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 o = texelFetch(rayOrigin, px, 0), d = texelFetch(rayDirection, px, 0);
    float limit = shadowRays != 0 ? abs(d.w) : INF;
    // masking off: a ray that needs no work stays active, marked for the traverse kernel
    outTMax = vec4(0.0, 0.0, 0.0, masking != 0 ? RAY_DONE : RAY_ACTIVE);
    outCell = vec4(0.0, 0.0, 0.0, masking != 0 ? 0.0 : -1.0);
    outHit = vec4(0.0, 0.0, INF, -1.0);
    if (masking != 0 ? d.w <= 0.0 : d.w == 0.0) return;
    vec2 span = clipToBox(o.xyz, d.xyz);
    float t0 = max(span.x, 0.0);
    if (t0 > min(span.y, limit)) return;
    ivec3 cell = cellOf(o.xyz + t0 * d.xyz);
    outTMax = vec4(tMaxOf(o.xyz, d.xyz, cell), RAY_ACTIVE);
    outCell = vec4(vec3(cell), 0.0);
    countAdd(COUNTER_VOXELS_VISITED, 1u);
}
