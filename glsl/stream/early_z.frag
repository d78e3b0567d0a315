// Early Z culling — the streaming tracer, ch. 3, the optimisations: "Early Z culling can be
// exploited, to skip a costly fragment program (esp. traverse and intersect) being executed on rays
// already terminated, this requires an additional pass initializing the Z buffer with proper depth
// values prior to executing the kernel."
// Run before every call of traverse_intersect.frag: depth 0 for a finished ray, 1 for an active
// one. The kernel's quad lies at depth 0.5 with the depth test LESS and early fragment tests,
// so finished rays are neither run nor counted by the occlusion query (the halting condition).
#include "grid.glsl"
#include "state.glsl"

void main()
{
    gl_FragDepth = rayFinished(ivec2(gl_FragCoord.xy)) ? 0.0 : 1.0;
}
