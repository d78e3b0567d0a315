// Exact 64-bit event counters (ours: the thesis counted triangle tests on the CPU side).
// GLSL 4.50 has no 64-bit atomics, so every counter is a pair of uints (low, high) with a
// carry: atomicAdd returns the old low word, and an addition that wraps it adds 1 to the high
// word. Each work group first sums its invocations' counts in shared memory, so there is one
// global atomic per work group and counter; that sum carries the same way (groupCarry: a work
// group's invocations may together count past 2^32 where each one's count fits in a uint, e.g.
// pixel_counts' sums of 64 pixels' records). The host clears the buffer every frame.
layout(std430, binding = SSBO_COUNTERS) coherent buffer CounterBuffer { uint counters[]; };

shared uint groupCount[COUNTER_SLOTS_PER_KERNEL];
shared uint groupCarry[COUNTER_SLOTS_PER_KERNEL];

void countersBegin()
{
    if (gl_LocalInvocationIndex < uint(COUNTER_SLOTS_PER_KERNEL)) {
        groupCount[gl_LocalInvocationIndex] = 0u;
        groupCarry[gl_LocalInvocationIndex] = 0u;
    }
    // GLSL 4.60 §8.16: barrier() orders shared-memory accesses in a compute shader;
    // memoryBarrierShared() first says so to compilers of earlier versions too
    memoryBarrierShared();
    barrier();
}

void countAdd(int local, uint n)
{
    if (n > 0u) {
        uint old = atomicAdd(groupCount[local], n);
        if (old > 0xFFFFFFFFu - n) atomicAdd(groupCarry[local], 1u);
    }
}

// local: the kernel's own counter 0..COUNTER_SLOTS_PER_KERNEL-1; slot: the global counter.
void countersEnd(int local, int slot)
{
    memoryBarrierShared();
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        uint n = groupCount[local];
        uint high = groupCarry[local];
        if (n > 0u) {
            uint old = atomicAdd(counters[2 * slot], n);
            if (old > 0xFFFFFFFFu - n) high++;
        }
        if (high > 0u) atomicAdd(counters[2 * slot + 1], high);
    }
}
