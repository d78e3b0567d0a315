// Voxel traversal of a segment — Müller 2015, ch. 3.2.2, Algorithms 2 and 3 with the special
// cases of Fig. 13, as the build kernel walks triangle edges (traverseConnection, ch. 4.2.1)
// and the traversal kernel walks rays (ch. 4.2.2).
// The including kernel defines, before including this file:
//     void storeVoxel(ivec3 voxel)   // called for every voxel the segment passes, in order
// and a global `uint truncated` (set when a walk does not end in its end voxel).

// at most N crossings per axis
#define MAX_CROSSINGS (3 * voxel_amount + 3)

// Walk the grid-space segment p0 -> p1 (the thesis' r0 and r(t_max); t_max = 1), starting in
// voxel vox_min and ending in vox_max (both inside the grid). The start voxel is stored first,
// as the thesis does separately. Algorithm 2's `a` (2 / voxel_amount, the voxel edge) is
// vx_edge here (Listing 19's name).
void traverseConnection(vec3 p0, vec3 p1, ivec3 vox_min, ivec3 vox_max)
{
    float t_list[MAX_CROSSINGS];
    int dimension[MAX_CROSSINGS];
    int count = 0;
    vec3 rd = p1 - p0;
    const float t_max = 1.0;

    // Algorithm 2, once per coordinate axis: the parameters t of the crossings with the voxel
    // planes x = i·a - 1 (a = vx_edge) between the start and the end voxel
    for (int d = 0; d < 3; d++) {
        // ours: `!(x > 0 || x < 0)` skips a NaN component as well as 0 (the loop below ends
        // because i moves towards j, which holds for every finite rd; a NaN would walk i away)
        if (!(rd[d] > 0.0 || rd[d] < 0.0)) continue;
        int direction = rd[d] > 0.0 ? 1 : -1;
        int i = vox_min[d];
        int j = vox_max[d];
        if (rd[d] > 0.0) { i++; j++; }
        while (i != j && count < MAX_CROSSINGS) {
            // Algorithm 2 prints t = (i·a − 1 − rd_x) / rd_x: the ray's origin, not its
            // direction, is subtracted (solving r0_x + t·rd_x = i·a − 1 for t, Fig. 11)
            float t = (float(i) * vx_edge - 1.0 - p0[d]) / rd[d];
            // Algorithm 2 keeps t <= t_max; the planes between the start and the end voxel
            // are all crossed, so a t rounded just above t_max is clamped, not dropped (else
            // the walk would end one voxel short)
            if (i >= 0) {
                t_list[count] = min(t, t_max);
                dimension[count] = d;
                count++;
            }
            // Algorithm 2 prints i = i + direction·a; i counts planes, a is a length: the next
            // plane is i + direction
            i += direction;
        }
    }

    // BubbleSort of t_list, dimension kept in step (ch. 4.2.1)
    for (int n = count; n > 1; n--) {
        bool swapped = false;
        for (int k = 0; k + 1 < n; k++) {
            if (t_list[k] > t_list[k + 1]) {
                float tt = t_list[k]; t_list[k] = t_list[k + 1]; t_list[k + 1] = tt;
                int dd = dimension[k]; dimension[k] = dimension[k + 1]; dimension[k + 1] = dd;
                swapped = true;
            }
        }
        if (!swapped) break;
    }

    // Algorithm 3: from the start voxel, one move per crossing. Equal parameters (Fig. 13):
    // the segment passes exactly through a voxel edge or corner; the moves of the axes with
    // positive direction are made together first, then those with negative direction.
    ivec3 current = vox_min;
    storeVoxel(current);
    int k = 0;
    while (k < count) {
        int g = k;
        while (g + 1 < count && t_list[g + 1] == t_list[k]) g++;
        ivec3 positive = ivec3(0), negative = ivec3(0);
        for (int m = k; m <= g; m++) {
            int d = dimension[m];
            if (rd[d] > 0.0) positive[d] = 1; else negative[d] = -1;
        }
        if (positive != ivec3(0)) { current += positive; storeVoxel(current); }
        if (negative != ivec3(0)) { current += negative; storeVoxel(current); }
        k = g + 1;
    }
    // the walk ends in the end voxel unless a loop was cut short
    if (current != vox_max) truncated = 1u;
}
