// order kernel of the thesis grid — ours, not in Müller 2015 (the thesis' build, Listing 20,
// ends with the lists as the atomics left them). Listing 20 claims list entries with
// atomicCompSwap, so a voxel's list comes out in whatever order the triangles won their race.
// Listing 22's closest hit does not care, but a shadow feeler (intersect2) stops at the first
// occluder of a list, so its triangle-test count would differ from run to run (e.g. 489,744
// and 491,409 on one frame). This pass puts every list in ascending triangle id, the order the
// CPU twin's sequential build gives, so the counts are reproducible and equal the twin's.
// One invocation per voxel sorts its list in place with heapsort (n·log n steps, no second
// buffer), then checks the order: a list that is not ascending afterwards (a loop cut short by
// the GL implementation's loop limit) is counted in truncated_rays, never used silently.
layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

#define COUNTER_SLOTS_PER_KERNEL 1
#include "../common/counters.glsl"

layout(std430, binding = SSBO_VOXELSLIST) coherent buffer VerticesInVoxel { int voxelslist[]; };
layout(std430, binding = SSBO_VOXELCONTAINS) readonly buffer ContainedVertices { int voxelcontains[]; };

uniform int voxelTotal;

void swapEntries(int a, int b)
{
    int x = voxelslist[a];
    voxelslist[a] = voxelslist[b];
    voxelslist[b] = x;
}

// the heap [first, first + end) below `root` restored: at most log2(end) + 1 levels
void siftDown(int first, int root, int end)
{
    for (int level = 0; level < 32; level++) {
        int child = 2 * root + 1;
        if (child >= end) return;
        if (child + 1 < end && voxelslist[first + child] < voxelslist[first + child + 1]) child++;
        if (voxelslist[first + root] >= voxelslist[first + child]) return;
        swapEntries(first + root, first + child);
        root = child;
    }
}

void heapSort(int first, int n)
{
    for (int start = n / 2 - 1; start >= 0; start--) siftDown(first, start, n);
    for (int end = n - 1; end > 0; end--) {
        swapEntries(first, first + end);
        siftDown(first, 0, end);
    }
}

void main()
{
    countersBegin();
    uint truncated = 0u;
    int v = int(gl_GlobalInvocationID.x);
    if (v < voxelTotal) {
        int first = v * voxel_array_length;
        int n = voxelcontains[v];
        heapSort(first, n);
        int j = 1;
        for (; j < n; j++)
            if (voxelslist[first + j - 1] > voxelslist[first + j]) break;
        if (j < n) truncated = 1u;
    }
    countAdd(0, truncated);
    countersEnd(0, COUNTER_TRUNCATED_RAYS);
}
