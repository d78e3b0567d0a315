// The ray textures of the streaming tracer, Fig. 1 ("rays are characterized by their origin and
// direction, this output stream of data is written into two textures") and the eye or reflection
// ray's hit record, with the surface at a hit as the shading and the ray generator see it.
// rayOrigin.w: the triangle the ray starts on (skipped by the traversal), -1 for none.
// rayDirection.w: an eye or reflection ray's weight in the pixel's colour (0: no ray), or a
// shadow ray's t limit, the distance to its light (0: no ray).
layout(binding = SAMPLER_STREAM_RAY_ORIGIN) uniform sampler2D rayOrigin;
layout(binding = SAMPLER_STREAM_RAY_DIR) uniform sampler2D rayDirection;
layout(binding = SAMPLER_STREAM_HIT) uniform sampler2D hitRecords;

struct Surface {
    vec3 position;
    // interpolated, turned towards the incoming ray (two-sided surfaces, as the other tracers)
    vec3 normal;
    vec3 diffuse;
    float reflectivity;
};

Surface surfaceAt(vec3 o, vec3 d, vec4 hit)
{
    int id = int(hit.w);
    float w = 1.0 - hit.x - hit.y;
    vec3 n = normalize(w * triangleNormal(id, 0) + hit.x * triangleNormal(id, 1)
                       + hit.y * triangleNormal(id, 2));
    if (dot(n, d) > 0.0) n = -n;
    return Surface(o + hit.z * d, n, triangleVertex(id, 3), triangleNormal(id, 3).r);
}
