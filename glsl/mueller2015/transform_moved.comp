// The transform pass for a moved object — ours, beside Müller 2015's pass of ch. 3.1.2
// (Fig. 7, mueller2015/transform.vert), which still writes every attribute of every object
// and the lights in the first frame. Once the scene's SSBOs hold them, a frame in which an
// object's model matrix changed rewrites only what the matrix changes — the object's vertices
// and normals — in one invocation per vertex, from the object-space positions and normals of
// the transform pass' own VBOs (bound here as storage buffers: TRANSFORM_POSITIONS,
// TRANSFORM_NORMALS, tightly packed floats), with the vertex shader's arithmetic. Why a compute
// kernel: llvmpipe runs a draw's vertex shader on the calling thread, a dispatch on all of its
// threads (docs/design/bvh.md, "Moving objects"). Four storage blocks: GL 4.5 guarantees 8 to a
// compute shader.
layout(local_size_x = TRANSFORM_GROUP) in;

layout(std430, binding = SSBO_VERTEX) writeonly buffer VertexBuffer { vec4 vertex[]; };
layout(std430, binding = SSBO_NORMAL) writeonly buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = SSBO_TRANSFORM_POSITIONS) readonly buffer Positions { float objectPositions[]; };
layout(std430, binding = SSBO_TRANSFORM_NORMALS) readonly buffer Normals { float objectNormals[]; };

uniform mat4 modelMatrix;
uniform mat3 normalMatrix;
// the object's vertices: first, first + 1, … first + count − 1 (its range in the VBOs and SSBOs)
uniform int first;
uniform int count;

// The same floats as R32F image buffers over the VBOs (TRANSFORM_VIEWS, where the GL has the
// units and texels): llvmpipe loads a storage buffer lane by lane, which was three quarters of
// this kernel (docs/design/bvh.md, "Moving objects").
#if TRANSFORM_VIEWS
layout(r32f, binding = IMAGE_TRANSFORM_POSITIONS) readonly uniform imageBuffer positionTexels;
layout(r32f, binding = IMAGE_TRANSFORM_NORMALS) readonly uniform imageBuffer normalTexels;
vec3 objectVector(int i, bool normal)
{
    int k = 3 * i;
    return normal ? vec3(imageLoad(normalTexels, k).x, imageLoad(normalTexels, k + 1).x,
                         imageLoad(normalTexels, k + 2).x)
                  : vec3(imageLoad(positionTexels, k).x, imageLoad(positionTexels, k + 1).x,
                         imageLoad(positionTexels, k + 2).x);
}
#else
vec3 objectVector(int i, bool normal)
{
    return normal ? vec3(objectNormals[3 * i], objectNormals[3 * i + 1], objectNormals[3 * i + 2])
                  : vec3(objectPositions[3 * i], objectPositions[3 * i + 1],
                         objectPositions[3 * i + 2]);
}
#endif

void main()
{
    int k = int(gl_GlobalInvocationID.x);
    if (k >= count) return;
    int i = first + k;
    // transform.vert's two statements for a vertex of an object
    vertex[i] = modelMatrix * vec4(objectVector(i, false), 1.0);
    normals[i] = vec4(normalize(normalMatrix * objectVector(i, true)), 0.0);
}
