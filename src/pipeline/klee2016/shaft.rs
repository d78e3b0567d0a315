//! A line space's addressing and its shaft test (Klee 2016, ch. 3.3, Fig. 4–5): the sides of a
//! node and their pairs, the entry of a pair of boundary cells, and whether the shaft between
//! two cells — their convex hull — meets a box. Below the N-tree and the line-space builds on
//! the CPU (`ntree.rs`'s hierarchical one, `linespace_cpu.rs`'s by child position), which
//! both import it, so that they set the same bits.

/// Sides of a node, numbered 2·axis + (0 at coordinate 0, 1 at coordinate N). The thesis
/// numbers them ±1, ±2, ±3 (positive at 0, negative at N): face f here is thesis side
/// `(f / 2 + 1)·(f % 2 == 0 ? 1 : −1)`.
pub const FACES: usize = 6;
/// Number of pairs of different sides (s < e).
pub const FACE_PAIRS: usize = 15;

/// Index of the pair of sides s < e in 0..15 (lexicographic order).
pub fn pair_index(s: usize, e: usize) -> usize {
    debug_assert!(s < e && e < FACES);
    s * (11 - s) / 2 + (e - s - 1)
}

/// The two axes of a side's cells (increasing order) for a side on `axis`.
pub fn face_axes(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// Number of line-space entries (bits) of one node.
pub fn linespace_entries(n: u32) -> usize {
    FACE_PAIRS * (n as usize).pow(4)
}

/// Number of u32 words of one line space.
pub fn linespace_words(n: u32) -> usize {
    linespace_entries(n).div_ceil(32)
}

/// The entry of the shaft from cell (su, sv) of side `s` to cell (eu, ev) of side `e`
/// (s ≠ e; the symmetric entry is the same). `None` for two cells of the same side (no shaft).
pub fn entry_index(
    n: u32,
    s: usize,
    su: u32,
    sv: u32,
    e: usize,
    eu: u32,
    ev: u32,
) -> Option<usize> {
    if s == e {
        return None;
    }
    let n = n as usize;
    let (s, cs, e, ce) = {
        let cs = su as usize + n * sv as usize;
        let ce = eu as usize + n * ev as usize;
        if s < e {
            (s, cs, e, ce)
        } else {
            (e, ce, s, cs)
        }
    };
    Some(pair_index(s, e) * n * n * n * n + cs * n * n + ce)
}

/// An axis-aligned box in node-local coordinates ([0, N]³, children are unit cells).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

impl Aabb {
    pub fn cell(i: u32, j: u32, k: u32) -> Aabb {
        let (i, j, k) = (i as f64, j as f64, k as f64);
        Aabb {
            lo: [i, j, k],
            hi: [i + 1.0, j + 1.0, k + 1.0],
        }
    }
}

/// The rectangle of side `f` covering cells [u0, u1) × [v0, v1), as a flat box.
pub fn face_rect(n: u32, f: usize, u0: u32, u1: u32, v0: u32, v1: u32) -> Aabb {
    let axis = f / 2;
    let c = if f.is_multiple_of(2) { 0.0 } else { n as f64 };
    let (ua, va) = face_axes(axis);
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    lo[axis] = c;
    hi[axis] = c;
    lo[ua] = u0 as f64;
    hi[ua] = u1 as f64;
    lo[va] = v0 as f64;
    hi[va] = v1 as f64;
    Aabb { lo, hi }
}

/// Does the shaft between the flat boxes `a` and `b` — their convex hull — overlap the
/// interior of box `c`? The hull is the union over t ∈ [0, 1] of the boxes (1−t)·a + t·b
/// (axis-aligned), so the test is: is there a t in [0, 1] where that box overlaps `c`
/// on every axis? Every axis gives a linear inequality in t; the open interval of t that
/// satisfies all of them must be non-empty. (Exact; interior overlap, so a shaft that only
/// touches a child's boundary does not count.)
pub fn shaft_hits_box(a: &Aabb, b: &Aabb, c: &Aabb) -> bool {
    let (mut tl, mut th) = (0.0f64, 1.0f64);
    // α + β t < γ
    let mut constrain = |alpha: f64, beta: f64, gamma: f64| -> bool {
        if beta == 0.0 {
            alpha < gamma
        } else if beta > 0.0 {
            th = th.min((gamma - alpha) / beta);
            true
        } else {
            tl = tl.max((gamma - alpha) / beta);
            true
        }
    };
    for i in 0..3 {
        // lo_i(t) < c.hi_i
        if !constrain(a.lo[i], b.lo[i] - a.lo[i], c.hi[i]) {
            return false;
        }
        // hi_i(t) > c.lo_i  ⇔  −hi_i(t) < −c.lo_i
        if !constrain(-a.hi[i], -(b.hi[i] - a.hi[i]), -c.lo[i]) {
            return false;
        }
    }
    tl < th
}

/// [`shaft_hits_box`] for the unit cell `c` (lower corner) with every coordinate on the
/// integer lattice, in integers: the bounds of t kept as fractions (numerator, denominator > 0)
/// and compared crosswise — the twin of `shaftHitsCell` in glsl/klee2016/linespace_build.comp.
/// The same answers as the f64 test: its quotients are of integers within ±(N + 1), which f64
/// rounds monotonically and keeps apart (two different ones differ by at least 1/(N + 1)²), so
/// every comparison comes out as it does for the fractions (`tests/linespace_build.rs` checks
/// every shaft and cell for small N).
pub fn shaft_hits_cell(a: ([i32; 3], [i32; 3]), b: ([i32; 3], [i32; 3]), c: [i32; 3]) -> bool {
    // (tl, th) as (numerator, denominator) pairs
    let (mut tl, mut th) = ((0i32, 1i32), (1i32, 1i32));
    // α + β t < γ
    let mut constrain = |alpha: i32, beta: i32, gamma: i32| -> bool {
        if beta == 0 {
            return alpha < gamma;
        }
        if beta > 0 {
            let num = gamma - alpha;
            if num * th.1 < th.0 * beta {
                th = (num, beta);
            }
        } else {
            let num = alpha - gamma;
            if num * tl.1 > tl.0 * -beta {
                tl = (num, -beta);
            }
        }
        true
    };
    let ((alo, ahi), (blo, bhi)) = (a, b);
    for i in 0..3 {
        if !constrain(alo[i], blo[i] - alo[i], c[i] + 1) {
            return false;
        }
        if !constrain(-ahi[i], -(bhi[i] - ahi[i]), -c[i]) {
            return false;
        }
    }
    tl.0 * th.1 < th.0 * tl.1
}
