// Scene data in shader storage buffers (Müller 2015, ch. 3.1.2 "GPU-Datenverwaltung", Fig. 7).
// The transform.vert pass writes the world-space vertex attributes, the per-triangle material
// and the lights; the kernels only read them. Triangles are stored as a triangle soup:
// the vertices of triangle k are vertex[3k], vertex[3k+1], vertex[3k+2] (Listing 12).

layout(std430, binding = SSBO_VERTEX) SCENE_QUALIFIER buffer VertexBuffer { vec4 vertex[]; };
layout(std430, binding = SSBO_NORMAL) SCENE_QUALIFIER buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = SSBO_COLOR) SCENE_QUALIFIER buffer ColorBuffer { vec4 colors[]; };
layout(std430, binding = SSBO_TEXCOORD) SCENE_QUALIFIER buffer TexCoordBuffer { vec2 texcoords[]; };
// Material id of every triangle (written by the transform pass from the object's materials).
layout(std430, binding = SSBO_TRI_MATERIAL) SCENE_QUALIFIER buffer TriMaterialBuffer { int triMaterial[]; };
// Per material: x = reflection coefficient (refl), y = specular, z = shininess,
// w = texture layer in the sampler2DArray (-1: vertex colours).
layout(std430, binding = SSBO_MATERIAL) readonly buffer MaterialBuffer { vec4 material[]; };
layout(std430, binding = SSBO_LIGHT_POS) SCENE_QUALIFIER buffer LightPosBuffer { vec4 lightPos[]; };
layout(std430, binding = SSBO_LIGHT_COLOR) SCENE_QUALIFIER buffer LightColorBuffer { vec4 lightColor[]; };

// Number of triangles in the scene: SCENE_TRIANGLES, a #define of the host
// (pipeline::raytrace::kernel_defines). Deviation: Listings 12 and 15 loop to vertex.length() - 2;
// GLSL 4.60 §4.1.9 and GL 4.6 §7.8 make length() of a runtime-sized array the size of the buffer
// bound to that block's binding, but Mesa 22.3's zink returns the size of another bound buffer
// when the program declares a shader storage block it does not use (every kernel that includes
// this file does), so the grids' build kernels registered 278 of 22,146 references
// (docs/drivers.md). The host knows the count; no kernel asks a buffer for it.
#ifndef SCENE_TRIANGLES
#error "SCENE_TRIANGLES (the scene's triangle count) must be #defined by the host"
#endif
int triangleCount() { return SCENE_TRIANGLES; }
