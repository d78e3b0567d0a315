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

uniform int lightSource;
uniform int lightSample;
uniform vec3 areaCorner;
uniform vec3 areaEdgeU;
uniform vec3 areaEdgeV;

vec3 feelerTarget()
{
    if (lightSample < 0) return lightPos[lightSource].xyz;
    return lightSamplePoint(areaCorner, areaEdgeU, areaEdgeV, lightSample, SAMPLES_U, SAMPLES_V);
}
