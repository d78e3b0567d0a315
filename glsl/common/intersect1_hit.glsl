// The evaluation of the closest hit in the intersect1 kernel of every tracer design — Müller
// 2015, ch. 4.1.2, Listings 13 and 14, and the stores that end the kernel. The kernel calls
// emptyColorBuffer for an inactive ray, else evaluateHit with the closest hit its search found
// (triID -1: none).
//
// At the closest hit the vertex normal is interpolated with (u, v) (Listing 13), the colour
// is taken from the texture through the sampler or interpolated from the vertex colours, and
// on a reflecting triangle the rayState is raised, the colour weighted and the direction
// reflected (Listing 14). A miss writes the background colour and ends the ray.

uniform vec4 backgroundColor;
// 1 in the first pass (primary rays): the first hit is also stored for the AOVs (ours; only
// where the host keeps AOVs: STORE_AOVS).
uniform int storePrimaryHit;
layout(binding = SAMPLER_TEXTURES) uniform sampler2DArray textures;

// The hit triangle's vertex attributes, which the including kernel defines before including
// this file (a hook, as closestHit is): common/vertex_attributes.glsl reads the scene's buffers
// as the transform pass stored them (the base tracer, the grids); the SAH BVH reads them its
// own way (bvh/vertex_attributes.glsl, ours: as image buffers, and with two levels turned into
// world space by the hit's instance).
//     vec3 hitVertexNormal(int k)   the world-space normal of vertex k, for Listing 13 to interpolate
//     vec3 hitVertexColor(int k)    the colour of vertex k

// inactive ray: an empty colour buffer, nothing for shading to add. Ours: weight -1 marks it;
// the thesis' shading skips an empty colour buffer (ch. 4.1.3, "sofern dieser nicht leer
// ist") without saying how it is marked, and a weight of 0 is a real one (a perfect mirror)
void emptyColorBuffer(ivec2 storePos)
{
    imageStore(colorBufferTexture, storePos, vec4(0.0, 0.0, 0.0, -1.0));
}

// The four texels Listings 13 and 14 leave for the hit (t_min, triID, hit_u, hit_v; triID −1: a
// miss) of the ray (ro, rd, rayState): rayOrigin (hit point, rayState), rayDir (direction,
// triangle), normal and colorBuffer; and the hit triangle's material (0 for a miss). Ours: a function of its own so that the SAH BVH's fused
// pass (bvh/fused_pass.comp) computes the same values without storing them.
void hitTexels(vec3 ro, vec3 rd, float rayState, float t_min, int triID, float hit_u,
               float hit_v, out vec4 hitPoint, out vec4 dirTri, out vec4 normal,
               out vec4 colorWeight, out vec4 mat)
{
    // Ours: a hit and a miss compute the same four texels and share one store per texture —
    // llvmpipe runs both sides of a branch that any lane takes, and every store is a loop over
    // the lanes (docs/design/frame.md). A miss: the background colour with full weight, and the
    // ray leaves the scene (rayState 0); its direction is stored with triangle −1, which no kernel
    // reads for an ended ray.
    vec3 direction = rd;
    vec3 interpolated_normal = vec3(0.0);
    hitPoint = vec4(ro, 0.0);
    colorWeight = vec4(backgroundColor.rgb, 1.0);
    mat = vec4(0.0);
    if (triID >= 0) {
        // Listing 13: interpolation of the vertex normals with the (u, v) of the hit
        float w = 1.0 - hit_u - hit_v;
        interpolated_normal = normalize(w * hitVertexNormal(3 * triID)
                                        + hit_u * hitVertexNormal(3 * triID + 1)
                                        + hit_v * hitVertexNormal(3 * triID + 2));
        // ours: the normal faces the incoming ray (two-sided surfaces)
        if (dot(interpolated_normal, direction) > 0.0) interpolated_normal = -interpolated_normal;

        mat = material[triMaterial[triID]];
        vec3 color = w * hitVertexColor(3 * triID) + hit_u * hitVertexColor(3 * triID + 1)
                   + hit_v * hitVertexColor(3 * triID + 2);
#if SCENE_TEXTURES
        if (mat.w >= 0.0) {
            // textured triangle: interpolated texture coordinates, sampled through the sampler
            vec2 uv = w * texcoords[3 * triID] + hit_u * texcoords[3 * triID + 1]
                    + hit_v * texcoords[3 * triID + 2];
            color = textureLod(textures, vec3(uv, mat.w), 0.0).rgb;
        }
#endif

        // Listing 14: reflection on the hit triangle?
        float refl = mat.x;
        if (refl > 0.0) {
            rayState += 1.0;
            direction = reflect(direction, interpolated_normal);
        }
        hitPoint = vec4(ro + t_min * rd, rayState);
        // weight of the hit colour; the reflection gets the rest
        colorWeight = vec4(color, 1.0 - refl);
    }
    dirTri = vec4(direction, float(triID));
    normal = vec4(interpolated_normal, 0.0);
}

// The first hit for the AOVs (ours; only where the host keeps AOVs: STORE_AOVS).
void storeFirstHit(ivec2 storePos, float t_min, int triID, float hit_u, float hit_v)
{
#if STORE_AOVS
    if (storePrimaryHit != 0)
        imageStore(primaryHitTexture, storePos, vec4(t_min, intBitsToFloat(triID), hit_u, hit_v));
#endif
}

void evaluateHit(ivec2 storePos, vec3 ro, vec3 rd, float rayState,
                 float t_min, int triID, float hit_u, float hit_v)
{
    storeFirstHit(storePos, t_min, triID, hit_u, hit_v);
    vec4 hitPoint, dirTri, normal, colorWeight, mat;
    hitTexels(ro, rd, rayState, t_min, triID, hit_u, hit_v, hitPoint, dirTri, normal, colorWeight,
              mat);
    imageStore(rayOriginTexture, storePos, hitPoint);
    imageStore(rayDirTexture, storePos, dirTri);
    imageStore(normalTexture, storePos, normal);
    imageStore(colorBufferTexture, storePos, colorWeight);
}
