// Transformation pass — Müller 2015, ch. 3.1.2 (Fig. 7): a vertex-shader program, drawn as
// points with the rasterizer discarded, transforms every object's vertices and normals with
// the object's model and normal matrices into world space and writes them, with the unchanged
// attributes, into the SSBOs the kernels read. A second draw (transformLights = 1) writes the
// light positions and colours. Moving an object only changes its modelMatrix uniform: the
// object-space data stays in its VBOs and is never uploaded again.
#define SCENE_QUALIFIER writeonly
#include "../common/scene.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;   // lights: unused
layout(location = 2) in vec3 inColor;
layout(location = 3) in vec2 inTexCoord; // lights: unused
layout(location = 4) in int inMaterial;  // material id of the vertex's triangle

uniform mat4 modelMatrix;
uniform mat3 normalMatrix;
uniform int transformLights;

void main()
{
    int i = gl_VertexID; // glDrawArrays' first is the object's offset in the scene
    if (transformLights != 0) {
        lightPos[i] = modelMatrix * vec4(inPosition, 1.0);
        lightColor[i] = vec4(inColor, 1.0);
    } else {
        vertex[i] = modelMatrix * vec4(inPosition, 1.0);
        normals[i] = vec4(normalize(normalMatrix * inNormal), 0.0);
        colors[i] = vec4(inColor, 1.0);
        texcoords[i] = inTexCoord;
        if (i % 3 == 0) triMaterial[i / 3] = inMaterial;
    }
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
