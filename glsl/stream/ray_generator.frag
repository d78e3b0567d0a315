// The ray generator — the streaming tracer, ch. 3, Fig. 1, first kernel: "The first kernel is
// responsible for generating either primary, shadow or reflection rays. Rays are characterized by
// their origin and direction, this output stream of data is written into two textures."
// generate = 0: primary rays through the pixel centres (the camera of Müller 2015, Listing 11,
//               so all tracers cast the same rays: the direction from camImgOffset, the image
//               plane relative to the camera, as mueller2015/eye_ray_generation.comp); weight 1
// generate = 1: shadow rays from the eye or reflection ray's hit towards lightPosition, with
//               the light's distance as their limit; none where the ray hit nothing or the
//               light lies behind the surface (it is then in shadow: shading.frag). Without
//               masking (masking = 0, --stream-no-mask), the paper's optimisation switched off
//               for measuring it: the rays towards a light behind the surface are made too,
//               their limit negated (-distance) so that the shadow AOV still leaves them out;
//               the shading ignores their verdict (the cosine is not positive)
// generate = 2: reflection rays (mirror direction) from hits on reflective surfaces, weight
//               times reflectivity; none elsewhere
#include "grid.glsl"
#include "rays.glsl"
#include "counters.glsl"

uniform int generate;
uniform vec3 camImgPosition;
uniform vec3 camImgOffset;
uniform vec3 camWidth;
uniform vec3 camHeight;
uniform vec2 imageSize2;
uniform vec3 lightPosition;
uniform int masking;

layout(location = 0) out vec4 outOrigin;
layout(location = 1) out vec4 outDirection;

void primaryRay(vec2 px)
{
    vec3 across = (px.x + 0.5) * camWidth + (imageSize2.y - px.y - 0.5) * camHeight;
    outOrigin = vec4(camImgPosition + across, -1.0);
    outDirection = vec4(normalize(camImgOffset + across), 1.0);
    countAdd(COUNTER_RAYS, 1u); // ours: rays generated, for rays per second (accel-compare)
}

void secondaryRay(ivec2 px)
{
    vec4 o = texelFetch(rayOrigin, px, 0), d = texelFetch(rayDirection, px, 0);
    vec4 hit = texelFetch(hitRecords, px, 0);
    outOrigin = vec4(0.0, 0.0, 0.0, -1.0);
    outDirection = vec4(0.0);
    if (d.w <= 0.0 || hit.w < 0.0) return;
    Surface s = surfaceAt(o.xyz, d.xyz, hit);
    outOrigin = vec4(s.position, hit.w);
    if (generate == 1) {
        vec3 toLight = lightPosition - s.position;
        float distance = length(toLight);
        vec3 l = toLight / distance;
        if (dot(s.normal, l) > 0.0) outDirection = vec4(l, distance);
        else if (masking == 0) outDirection = vec4(l, -distance);
    } else if (s.reflectivity > 0.0) {
        outDirection = vec4(reflect(d.xyz, s.normal), d.w * s.reflectivity);
    }
    if (outDirection.w != 0.0) countAdd(COUNTER_RAYS, 1u);
}

void main()
{
    if (generate == 0) primaryRay(floor(gl_FragCoord.xy));
    else secondaryRay(ivec2(gl_FragCoord.xy));
}
