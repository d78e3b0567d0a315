// The hit list's two steps around bvh/evaluate_hit.comp (ours; bvh/hit_list.glsl), one
// invocation: before it (finish 0) the list emptied — a kernel rather than a glBufferSubData,
// so that its stores are ordered after the last pass' reads by the barrier between passes, as
// every pass is (src/gl/sync.rs); after it (finish 1) the dispatch commands of the pass'
// intersect2 (a work group per HIT_LIST_GROUP entries) and of its counts (bvh/pixel_counts.comp:
// PIXELS_PER_INVOCATION entries an invocation, COUNT_GROUP invocations a work group) written
// from the count, within GL's limit on work groups per dimension (common/work_lists.glsl), and
// the count added to the frame's.
#include "hit_list.glsl"

layout(local_size_x = 1) in;

uniform int finish;
// 1 in the first pass of a frame: the frame's sum of entries starts again
uniform int firstPass;

void setCommand(uint word, uint groups)
{
    uvec4 command = groupsCommand(groups);
    for (uint w = 0u; w < 4u; w++) hitWords[word + w] = command[w];
}

void main()
{
    uint n = finish != 0 ? hitCount() : 0u;
    if (finish == 0) hitWords[HIT_LIST_COUNT] = 0u;
    if (finish == 0 && firstPass != 0) hitWords[HIT_LIST_FRAME_ENTRIES] = 0u;
    if (finish != 0) hitWords[HIT_LIST_FRAME_ENTRIES] += n;
    uint perCountGroup = uint(PIXELS_PER_INVOCATION * COUNT_GROUP);
    setCommand(0u, (n + HIT_LIST_GROUP - 1u) / HIT_LIST_GROUP);
    setCommand(4u, (n + perCountGroup - 1u) / perCountGroup);
}
