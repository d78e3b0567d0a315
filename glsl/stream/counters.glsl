// Exact 64-bit event counters of the streaming kernels (ours; the paper measured time only).
// Fragment programs have no work groups and no shared memory, so every fragment adds its own
// count with one atomic per counter and call: a pair of uints (low, high) with a carry,
// atomicAdd returning the old low word. The host clears the buffer every frame.
layout(std430, binding = SSBO_COUNTERS) coherent buffer CounterBuffer { uint counters[]; };

void countAdd(int slot, uint n)
{
    if (n == 0u) return;
    uint old = atomicAdd(counters[2 * slot], n);
    if (old > 0xFFFFFFFFu - n) atomicAdd(counters[2 * slot + 1], 1u);
}
