// linespace_build kernel — Klee 2016, ch. 3.3 (Fig. 4: a line space's entry per pair of
// boundary cells on different sides of a node; Fig. 5: the entry set when a child with geometry
// lies in the shaft between the two cells) and ch. 4.2 (Listing 3: the entries packed 32 to a
// uint into the 3D R32UI texture the shadow kernel reads). The thesis builds the line spaces on
// the CPU; this GPU build is ours, and so is everything below that the thesis does not print:
// - One invocation per 32-bit word of a line space (32 shafts, one after the other): the word
//   is stored whole with imageStore, so no atomics are needed; its bits past the line space's
//   last entry come out 0 like the CPU's (the host zeroes the texels after the last one).
// - The entry layout of src/pipeline/klee2016/ntree.rs (`entry_index`): the 15 pairs of sides
//   s < e, `entry = pair(s, e)·N⁴ + cell_s·N² + cell_e`, cells u + N·v.
// - The shaft test is exact in integers: every box involved (the two boundary cells, the
//   children) lies on the node's integer lattice [0, N]³, so the t-interval test of
//   `shaft_hits_box` (ntree.rs, f64) becomes a comparison of fractions with numerators and
//   denominators within ±N — the same bits as the f64 test, not a rounding of it
//   (`shaft_hits_cell` in ntree.rs is this function's twin; tests/linespace_build.rs).
// - Which children to test: the shaft is the union over t ∈ [0, 1] of the boxes
//   lerp(A, B, t), each at most one cell wide per axis; for t in [j/N, (j+1)/N] those boxes
//   lie in the bounding box of the two at the ends (lo and hi move linearly), so the filled
//   children in those N boxes of cells — found in the node's occupancy rows, one N-bit mask
//   per (y, z) — are all that can lie in the shaft, and each is tested exactly.
layout(local_size_x = 64) in;

#define N NTREE_N
#define NN (N * N)
#define N4 (NN * NN)
#define ENTRIES (15 * N4)

// occupancy[ls · N² + y + N·z]: bit x set when child (x, y, z) of line space ls's node has
// geometry (made on the host from the node pool)
layout(std430, binding = SSBO_LS_OCCUPANCY) readonly buffer Occupancy { uint occupancy[]; };
// sat[ls · (N+1)³ + x + (N+1)·(y + (N+1)·z)]: the filled children with all coordinates below
// (x, y, z) (a summed-volume table of the same flags), to skip boxes of cells without any
layout(std430, binding = SSBO_LS_SAT) readonly buffer Sat { uint sat[]; };
layout(r32ui, binding = IMAGE_LINESPACE) uniform writeonly uimage3D linespaceTexture;

uniform int lsBegin;         // this dispatch's line spaces: lsBegin <= ls < lsEnd
uniform int lsEnd;
uniform int wordsPerLs;      // linespace_words(N)
uniform int tex_x_res;       // Listing 3's texture layout
uniform int tex_y_res;
uniform int ls_y_size;

// The pair of sides s < e with index p (lexicographic, as ntree.rs's pair_index).
ivec2 pairSides(int p)
{
    int s = 0;
    int first = 0;
    while (s < 5 && p >= first + (5 - s)) { first += 5 - s; s++; }
    return ivec2(s, s + 1 + (p - first));
}

// The boundary cell (u, v) of side f (2·axis + (0 at 0, 1 at N)) as a flat box [lo, hi].
void faceCell(int f, int u, int v, out ivec3 lo, out ivec3 hi)
{
    int axis = f / 2;
    int c = (f % 2 == 0) ? 0 : N;
    int ua = axis == 0 ? 1 : 0;
    int va = axis == 2 ? 1 : 2;
    lo = ivec3(0);
    lo[axis] = c;
    lo[ua] = u;
    lo[va] = v;
    hi = lo + ivec3(1);
    hi[axis] = c;
}

// t < num/den (den > 0) tightens the upper bound (thn/thd); t > num/den the lower (tln/tld).
// Returns false when a constraint α + β·t < γ with β = 0 fails outright.
bool constrain(int alpha, int beta, int gamma, inout ivec4 t)
{
    if (beta == 0) return alpha < gamma;
    if (beta > 0) {
        int num = gamma - alpha;
        if (num * t.w < t.z * beta) t.zw = ivec2(num, beta);
    } else {
        int num = alpha - gamma;
        if (num * t.y > t.x * (-beta)) t.xy = ivec2(num, -beta);
    }
    return true;
}

// Does the shaft between the flat boxes A and B (their convex hull) overlap the interior of
// the unit cell c? Is there a t in [0, 1] where lerp(A, B, t) overlaps it on every axis —
// ntree.rs's shaft_hits_box with the bounds kept as fractions t = (tln/tld, thn/thd).
bool shaftHitsCell(ivec3 alo, ivec3 ahi, ivec3 blo, ivec3 bhi, ivec3 c)
{
    ivec4 t = ivec4(0, 1, 1, 1);
    for (int i = 0; i < 3; i++) {
        if (!constrain(alo[i], blo[i] - alo[i], c[i] + 1, t)) return false;
        if (!constrain(-ahi[i], -(bhi[i] - ahi[i]), -c[i], t)) return false;
    }
    return t.x * t.w < t.z * t.y;
}

#define M1 (N + 1)
// Filled children in the cells c0..c1 (inclusive; c0 <= c1) of the node whose table starts at
// satBase.
uint filledIn(uint satBase, ivec3 c0, ivec3 c1)
{
    ivec3 h = c1 + ivec3(1);
#define S(x, y, z) sat[satBase + uint(x + M1 * (y + M1 * (z)))]
    return S(h.x, h.y, h.z) - S(c0.x, h.y, h.z) - S(h.x, c0.y, h.z) - S(h.x, h.y, c0.z)
        + S(c0.x, c0.y, h.z) + S(c0.x, h.y, c0.z) + S(h.x, c0.y, c0.z) - S(c0.x, c0.y, c0.z);
#undef S
}

// Fig. 5: is there a child with geometry in the shaft between A and B? (See the header for
// the candidates.)
bool shaftBlocked(uint base, ivec3 alo, ivec3 ahi, ivec3 blo, ivec3 bhi)
{
    uint satBase = base / uint(NN) * uint(M1 * M1 * M1);
    for (int j = 0; j < N; j++) {
        // the boxes at t = j/N and (j+1)/N, scaled by N: integers
        ivec3 lo0 = (N - j) * alo + j * blo;
        ivec3 lo1 = (N - j - 1) * alo + (j + 1) * blo;
        ivec3 hi0 = (N - j) * ahi + j * bhi;
        ivec3 hi1 = (N - j - 1) * ahi + (j + 1) * bhi;
        // cells m with m < max(hi)/N and m + 1 > min(lo)/N (interiors; all values >= 0)
        ivec3 c0 = min(lo0, lo1) / N;
        ivec3 c1 = min((max(hi0, hi1) + (N - 1)) / N - 1, ivec3(N - 1));
        if (any(lessThan(c1, c0)) || filledIn(satBase, c0, c1) == 0u) continue;
        uint xs = ((1u << uint(c1.x - c0.x + 1)) - 1u) << uint(c0.x);
        for (int z = c0.z; z <= c1.z; z++) {
            for (int y = c0.y; y <= c1.y; y++) {
                uint row = occupancy[base + uint(y + N * z)] & xs;
                while (row != 0u) {
                    int x = findLSB(row);
                    row &= row - 1u;
                    if (shaftHitsCell(alo, ahi, blo, bhi, ivec3(x, y, z))) return true;
                }
            }
        }
    }
    return false;
}

// Entry `entry` of a line space: the shaft of its pair of boundary cells.
bool entryBit(uint base, int entry)
{
    ivec2 se = pairSides(entry / N4);
    int cs = (entry % N4) / NN;
    int ce = entry % NN;
    ivec3 alo, ahi, blo, bhi;
    faceCell(se.x, cs % N, cs / N, alo, ahi);
    faceCell(se.y, ce % N, ce / N, blo, bhi);
    return shaftBlocked(base, alo, ahi, blo, bhi);
}

void main()
{
    uint id = gl_GlobalInvocationID.x;
    uint ls = uint(lsBegin) + id / uint(wordsPerLs);
    if (ls >= uint(lsEnd)) return;
    uint w = id % uint(wordsPerLs);
    uint base = ls * uint(NN);
    uint word = 0u;
    for (int b = 0; b < 32; b++) {
        int entry = int(w) * 32 + b;
        if (entry < ENTRIES && entryBit(base, entry)) word |= 1u << uint(b);
    }
    // Listing 3: the texel of word w of line space ls
    int y_position = int(ls) * ls_y_size + int(w) / tex_x_res;
    ivec3 texel = ivec3(int(w) % tex_x_res, y_position % tex_y_res, y_position / tex_y_res);
    imageStore(linespaceTexture, texel, uvec4(word, 0u, 0u, 0u));
}
