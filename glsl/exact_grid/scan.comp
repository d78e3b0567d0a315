// Exact grid, pass 2 of 4: exclusive prefix sum of the voxel counts — ours. The start of every
// voxel's compact list: voxelStart[v] = sum of voxelCount[u] for u < v. Three phases:
//   scanPhase 0: every work group scans 1024 counts in shared memory, its total -> blockSums
//   scanPhase 1: one invocation scans the block totals (<= 2048 of them) and writes the total
//                number of triangle references to gridTotal
//   scanPhase 2: every voxel's start gets its block's offset added
layout(local_size_x = 512, local_size_y = 1, local_size_z = 1) in;

layout(std430, binding = SSBO_VOXEL_COUNT) readonly buffer VoxelCount { uint voxelCount[]; };
layout(std430, binding = SSBO_VOXEL_START) buffer VoxelStart { uint voxelStart[]; };
layout(std430, binding = SSBO_BLOCK_SUMS) buffer BlockSums { uint blockSums[]; };
layout(std430, binding = SSBO_GRID_TOTAL) buffer GridTotal { uint gridTotal[]; };

uniform int scanPhase;
uniform int voxelTotal; // N³
uniform int blockCount;

shared uint temp[1024];

void main()
{
    uint local = gl_LocalInvocationID.x;
    uint block = gl_WorkGroupID.x;
    if (scanPhase == 0) {
        uint base = block * 1024u;
        uint a = base + 2u * local, b = a + 1u;
        temp[2u * local] = a < uint(voxelTotal) ? voxelCount[a] : 0u;
        temp[2u * local + 1u] = b < uint(voxelTotal) ? voxelCount[b] : 0u;
        // Blelloch scan: up-sweep
        uint offset = 1u;
        for (uint d = 512u; d > 0u; d >>= 1u) {
            memoryBarrierShared(); barrier();
            if (local < d) {
                uint ai = offset * (2u * local + 1u) - 1u;
                uint bi = offset * (2u * local + 2u) - 1u;
                temp[bi] += temp[ai];
            }
            offset <<= 1u;
        }
        memoryBarrierShared(); barrier();
        if (local == 0u) {
            blockSums[block] = temp[1023];
            temp[1023] = 0u;
        }
        // down-sweep
        for (uint d = 1u; d < 1024u; d <<= 1u) {
            offset >>= 1u;
            memoryBarrierShared(); barrier();
            if (local < d) {
                uint ai = offset * (2u * local + 1u) - 1u;
                uint bi = offset * (2u * local + 2u) - 1u;
                uint t = temp[ai];
                temp[ai] = temp[bi];
                temp[bi] += t;
            }
        }
        memoryBarrierShared(); barrier();
        if (a < uint(voxelTotal)) voxelStart[a] = temp[2u * local];
        if (b < uint(voxelTotal)) voxelStart[b] = temp[2u * local + 1u];
    } else if (scanPhase == 1) {
        if (gl_GlobalInvocationID.x == 0u) {
            uint sum = 0u;
            for (int i = 0; i < blockCount; i++) {
                uint s = blockSums[i];
                blockSums[i] = sum;
                sum += s;
            }
            gridTotal[0] = sum;
        }
    } else {
        uint a = block * 1024u + 2u * local;
        uint offset = blockSums[block];
        if (a < uint(voxelTotal)) voxelStart[a] += offset;
        if (a + 1u < uint(voxelTotal)) voxelStart[a + 1u] += offset;
    }
}
