// G-buffer pass, fragment stage — Klee 2016, ch. 4.1 (Fig. 7, first phase): position,
// normal and diffuse colour of the closest fragment into three textures of an FBO (the
// depth test keeps the closest). Ours: position.w = 1 marks geometry (0: background),
// normal.w = the triangle id (gl_PrimitiveID of the single draw of all triangles) for the
// triangle_id AOV, and the normal is turned towards the camera (two-sided surfaces, as the
// ray tracers do).
in vec3 worldPosition;
in vec3 worldNormal;
in vec3 diffuseColor;

uniform vec3 cameraPosition;

layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;
layout(location = 2) out vec4 outDiffuse;

void main()
{
    vec3 n = normalize(worldNormal);
    if (dot(n, cameraPosition - worldPosition) < 0.0) n = -n;
    outPosition = vec4(worldPosition, 1.0);
    outNormal = vec4(n, float(gl_PrimitiveID));
    outDiffuse = vec4(diffuseColor, 1.0);
}
