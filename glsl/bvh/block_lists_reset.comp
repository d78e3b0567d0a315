// The fused pass' block lists emptied before each pass' entry pass (ours; bvh/block_lists.glsl):
// both dispatch commands set to (0, 1, 1, 0), one invocation a command. A kernel rather than a
// glBufferSubData: its stores are ordered after the last pass' reads and atomics, and before
// the entry pass' atomics, by the barrier between passes, as every other pass is
// (src/gl/sync.rs).
#include "block_lists.glsl"

layout(local_size_x = 2) in;

void main()
{
    uint c = gl_GlobalInvocationID.x; // one work group: commands 0 and 1
    blockWords[4u * c] = 0u;
    blockWords[4u * c + 1u] = 1u;
    blockWords[4u * c + 2u] = 1u;
    blockWords[4u * c + 3u] = 0u;
}
