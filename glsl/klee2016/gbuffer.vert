// G-buffer pass, vertex stage — Klee 2016, ch. 4.1 (Fig. 7, first phase; after [Rob09]):
// the scene is rasterised instead of ray traced for the primary rays. The world-space
// triangles are drawn with the camera's view-projection matrix (the same pinhole camera as the
// ray tracers' eye rays: pixel centres, image plane at `near`).
layout(location = 0) in vec3 inPosition;   // world space
layout(location = 1) in vec3 inNormal;     // world space
layout(location = 2) in vec3 inColor;      // diffuse colour

uniform mat4 viewProjection;

out vec3 worldPosition;
out vec3 worldNormal;
out vec3 diffuseColor;

void main()
{
    worldPosition = inPosition;
    worldNormal = inNormal;
    diffuseColor = inColor;
    gl_Position = viewProjection * vec4(inPosition, 1.0);
}
