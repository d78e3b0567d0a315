// The point the shadow feelers of one intersect2 dispatch aim at (Müller 2015, Listing 15:
// the light lightSource; ours beside it: one sample of an area light, after Klee 2016).
// Shared by common/intersect2_main.glsl and the thesis grid's traversal kernel in shadow mode.
//   lightSource: the shadow flag the feelers set — a point light's index (lightPos), or for an
//                area light the slot of this sample's bit (after the point lights' bits, U·V
//                bits per area light: pipeline::mueller2015::ShadowSlots).
//   lightSample: < 0 for a point light; else the sample r of the area light in the uniforms
//                areaCorner/areaEdgeU/areaEdgeV, at Klee's sample position
//                (common/light_samples.glsl, SAMPLES_U × SAMPLES_V).
#include "light_samples.glsl"

// pointTarget: a point light's position, lightPos[lightSource], set by the host for each
// dispatch (LightTarget::set_uniforms). Ours: Listing 15 reads lightPos[lightSource] from the
// scene's buffer in every invocation; llvmpipe makes that storage-buffer load a loop over the
// lanes even with a uniform index (docs/design/bvh.md, "Shadow feelers").
uniform vec3 pointTarget;
uniform int lightSource;
uniform int lightSample;
uniform vec3 areaCorner;
uniform vec3 areaEdgeU;
uniform vec3 areaEdgeV;

vec3 feelerTarget()
{
    if (lightSample < 0) return pointTarget;
    return lightSamplePoint(areaCorner, areaEdgeU, areaEdgeV, lightSample, SAMPLES_U, SAMPLES_V);
}
