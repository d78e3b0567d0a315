// The hit record of a finished traversal — the streaming tracer, Fig. 2's third texture
// (barycentric u, v, ray parameter t, triangle id), copied out of whichever state set holds the
// ray's final state (state.glsl), so the shadow rays' traversal may reuse the state textures while
// the shading and ray-generator kernels still read the eye or reflection ray's hit.
#include "grid.glsl"
#include "state.glsl"

layout(location = 0) out vec4 hitRecord;

void main()
{
    hitRecord = resolvedHit(ivec2(gl_FragCoord.xy));
}
