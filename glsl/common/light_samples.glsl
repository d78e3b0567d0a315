// The sample points of a rectangular area light — Klee 2016, ch. 4.1 (the shadow rays of a
// surface point go to SAMPLES_U × SAMPLES_V uniformly spaced points of the light): sample
// r = i·sv + j lies at corner + (i + ½)/su · edgeU + (j + ½)/sv · edgeV. One definition for
// Klee 2016's shadow kernel (klee2016/linespace_shadow.comp) and the area-light feelers of
// Müller 2015's intersect2 (common/light_target.glsl); the CPU twin is
// reference::linespace::light_samples.

vec3 lightSamplePoint(vec3 corner, vec3 edgeU, vec3 edgeV, int r, int su, int sv)
{
    int i = r / sv;
    int j = r - i * sv;
    return corner + (float(i) + 0.5) / float(su) * edgeU
                  + (float(j) + 0.5) / float(sv) * edgeV;
}
