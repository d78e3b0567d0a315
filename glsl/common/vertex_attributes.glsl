// The hit triangle's vertex normals and colours for common/intersect1_hit.glsl (its hooks), read
// from the scene's buffers (common/scene.glsl) as the transform pass stored them, in world space
// — Müller 2015, Listing 13's normals[] and colors[]. For the base tracer and the grids; the SAH
// BVH reads them its own way (bvh/vertex_attributes.glsl).
vec3 hitVertexNormal(int k) { return normals[k].xyz; }
vec3 hitVertexColor(int k) { return colors[k].rgb; }
