// The hit triangle's vertex normals and colours for common/intersect1_hit.glsl (its hooks), as
// the SAH BVH's hit evaluations read them (ours: bvh/evaluate_hit.comp and the fused pass,
// bvh/fused.glsl); the thesis' reads are common/vertex_attributes.glsl.
//
// With SCENE_IMAGES (where the GL has the image units: GpuScene::vertex_images) the scene's
// buffers (common/scene.glsl) are read as image buffers — llvmpipe loads a storage-buffer vector
// lane by lane and component by component, an image texel for all lanes at once
// (docs/design/frame.md).
#if SCENE_IMAGES
layout(rgba32f, binding = IMAGE_SCENE_NORMAL) readonly uniform imageBuffer normalImage;
layout(rgba32f, binding = IMAGE_SCENE_COLOR) readonly uniform imageBuffer colorImage;
vec3 vertexNormal(int k) { return imageLoad(normalImage, k).xyz; }
vec3 hitVertexColor(int k) { return imageLoad(colorImage, k).rgb; }
#else
vec3 vertexNormal(int k) { return normals[k].xyz; }
vec3 hitVertexColor(int k) { return colors[k].rgb; }
#endif

// The two levels (BVH_INSTANCES, ours; src/accel/bvh/instances.rs): the scene's vertex normals
// stay in object space, and the hit's instance turns each into world space and normalises it,
// as the transform pass does with its normalMatrix (the transpose of the inverse of the model
// matrix' 3×3 part), before Listing 13 interpolates them — the same normal under any scale;
// bvh/hit_record.glsl sets it for the hit's instance.
#if BVH_INSTANCES
mat3 hitNormalMatrix = mat3(1.0);
vec3 hitVertexNormal(int k) { return normalize(hitNormalMatrix * vertexNormal(k)); }
#else
vec3 hitVertexNormal(int k) { return vertexNormal(k); }
#endif
