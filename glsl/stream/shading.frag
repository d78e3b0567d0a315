// The shading kernel — the streaming tracer, ch. 3, Fig. 1, last kernel: "a simple per-pixel
// diffuse lighting with shadows and reflections". Its output is added into the colour texture by
// blending (GL_ONE, GL_ONE), one draw per term, so no kernel reads the colour it writes:
// term 0: the ambient light (or the background where the ray hit nothing)
// term 1: one point light, unless its shadow ray found a blocker (the shadow traversal's
//         result in the state textures) or the light lies behind the surface.
// Each term is weighted by the ray's weight (rayDirection.w) times (1 - reflectivity); the
// reflection ray carries weight times reflectivity to the next bounce (ray_generator.frag).
#include "grid.glsl"
#include "rays.glsl"
#include "state.glsl"

uniform int term;
uniform vec3 lightPosition;
uniform vec3 lightColor;
uniform vec3 ambientColor;
uniform vec3 backgroundColor;

layout(location = 0) out vec4 outColor;

vec3 lightTerm(ivec2 px, Surface s)
{
    vec3 l = normalize(lightPosition - s.position);
    float diffuse = dot(s.normal, l);
    if (diffuse <= 0.0 || resolvedHit(px).w != -1.0) return vec3(0.0);
    return lightColor * diffuse * s.diffuse;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 o = texelFetch(rayOrigin, px, 0), d = texelFetch(rayDirection, px, 0);
    vec4 hit = texelFetch(hitRecords, px, 0);
    outColor = vec4(0.0);
    if (d.w <= 0.0) return;
    if (hit.w < 0.0) {
        if (term == 0) outColor = vec4(d.w * backgroundColor, 0.0);
        return;
    }
    Surface s = surfaceAt(o.xyz, d.xyz, hit);
    vec3 local = term == 0 ? ambientColor * s.diffuse : lightTerm(px, s);
    outColor = vec4(d.w * (1.0 - s.reflectivity) * local, 0.0);
}
