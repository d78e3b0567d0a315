// Both sets of the ping-ponged traversal state (the streaming tracer, Fig. 2), read after or
// between calls of the traverse-and-intersect kernel. A call reads one set and writes the other,
// and a ray that finished is culled from the later calls (early_z.frag), so exactly one set holds
// its final state: the one whose ray state says RAY_DONE. Before the first call the masking kernel
// wrote set A and the host cleared set B's ray state to 0.
layout(binding = SAMPLER_STREAM_STATE_A) uniform sampler2D stateA;
layout(binding = SAMPLER_STREAM_STATE_B) uniform sampler2D stateB;
layout(binding = SAMPLER_STREAM_HIT_A) uniform sampler2D hitA;
layout(binding = SAMPLER_STREAM_HIT_B) uniform sampler2D hitB;

// whether the ray of pixel px has finished (in either set)
bool rayFinished(ivec2 px)
{
    return texelFetch(stateA, px, 0).w == RAY_DONE || texelFetch(stateB, px, 0).w == RAY_DONE;
}

// the finished ray's hit record (u, v, t, triangle id; id -1: no hit); id -2 for a ray that
// has not finished (the host's bound on the calls was reached)
vec4 resolvedHit(ivec2 px)
{
    if (texelFetch(stateA, px, 0).w == RAY_DONE) return texelFetch(hitA, px, 0);
    if (texelFetch(stateB, px, 0).w == RAY_DONE) return texelFetch(hitB, px, 0);
    return vec4(0.0, 0.0, INF, -2.0);
}
