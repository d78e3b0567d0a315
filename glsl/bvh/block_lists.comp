// The fused pass' block lists' two steps around the entry pass (ours; bvh/block_lists.glsl),
// one work group, an invocation per list: before it (finish 0) both lists emptied — a kernel
// rather than a glBufferSubData, so that its stores are ordered after the last pass' reads and
// atomics by the barrier between passes, as every pass is (src/gl/sync.rs); after it
// (finish 1) each list's dispatch command written from its count, within GL's limit on work
// groups per dimension (common/work_lists.glsl).
#include "block_lists.glsl"

layout(local_size_x = 2) in;

uniform int finish;

void main()
{
    uint k = gl_GlobalInvocationID.x; // list k, its command at word 4k
    if (finish == 0) blockWords[BLOCK_LIST_COUNTS + k] = 0u;
    uvec4 command = groupsCommand(finish != 0 ? blockListCount(k) : 0u);
    for (uint w = 0u; w < 4u; w++) blockWords[4u * k + w] = command[w];
}
