//! The CPU build of the line spaces, output-sensitive — Klee 2016, ch. 3.3, Fig. 5: "Dies
//! geschieht mittels einer Bitmaske, die für jeden gefüllten Unterknoten erstellt wird […]. Die
//! Binärmasken der einzelnen Unterknoten werden durch die binäre OR-Operation zusammengefügt",
//! after Keul et al. \[KLM\].
//!
//! A line space depends only on which of its node's N³ children hold geometry, and the shafts a
//! child cuts depend only on its position in the node. So the mask of every position that some
//! node fills is computed once (for all nodes of the tree) and OR-ed into the line spaces of the
//! nodes that fill it, as the thesis does per child. A mask is found output-sensitively: per pair
//! of sides and start cell, the end cells whose shaft can reach the child form a small rectangle
//! (bounded per axis over the shaft parameter t), and only its cells get the exact integer test
//! [`shaft_hits_cell`] — the test of the hierarchical build and of the GPU kernel, so the bits are
//! the same (`tests/linespace_cpu_build.rs` compares them with [`super::ntree::build_linespace`]).

use super::shaft::{entry_index, face_axes, linespace_words, shaft_hits_cell, FACES};
use rayon::prelude::*;

/// Widening of the t bounds and of the candidate ranges: the bounds are computed in f64 and only
/// need to hold a superset of the end cells (the exact test decides).
const MARGIN: f64 = 1e-9;

/// The lattice corners of cell (u, v) of side `f` (a flat box).
fn face_cell(n: i32, f: usize, u: i32, v: i32) -> ([i32; 3], [i32; 3]) {
    let axis = f / 2;
    let (ua, va) = face_axes(axis);
    let mut lo = [0; 3];
    lo[axis] = if f.is_multiple_of(2) { 0 } else { n };
    lo[ua] = u;
    lo[va] = v;
    let mut hi = lo;
    hi[ua] += 1;
    hi[va] += 1;
    (lo, hi)
}

/// Narrow the closed interval `t` to where α + β·t < γ can hold (closed: a superset of the
/// exact test's open interval); an empty interval has t.0 > t.1.
fn constrain(t: &mut (f64, f64), alpha: i32, beta: i32, gamma: i32) {
    let (alpha, beta, gamma) = (alpha as f64, beta as f64, gamma as f64);
    if beta == 0.0 {
        if alpha >= gamma {
            *t = (1.0, 0.0);
        }
    } else if beta > 0.0 {
        t.1 = t.1.min((gamma - alpha) / beta + MARGIN);
    } else {
        t.0 = t.0.max((gamma - alpha) / beta - MARGIN);
    }
}

/// The largest (`max`) or smallest value of base + num / t over t ∈ `t` (0 ≤ t.0 ≤ t.1): it is
/// monotone in t, so one of the ends; at t = 0 it is ±∞ by the sign of num.
fn extreme(base: i32, num: i32, t: (f64, f64), max: bool) -> f64 {
    let at = |t: f64| match (t > 0.0, num.signum()) {
        (true, _) => base as f64 + num as f64 / t,
        (false, 0) => base as f64,
        (false, 1) => f64::INFINITY,
        _ => f64::NEG_INFINITY,
    };
    let (v0, v1) = (at(t.0), at(t.1));
    if max {
        v0.max(v1)
    } else {
        v0.min(v1)
    }
}

/// The end cells on free axis `i` of the end side that a shaft from `a` through cell `c` may
/// reach for t ∈ `t`: x with alo + t·(x − alo) < c + 1 and ahi + t·(x + 1 − ahi) > c for some t,
/// i.e. x < alo + (c + 1 − alo)/t and x > ahi − 1 + (c − ahi)/t, bounded over t on their own.
fn end_range(n: i32, a: ([i32; 3], [i32; 3]), c: [i32; 3], i: usize, t: (f64, f64)) -> (i32, i32) {
    let (alo, ahi) = (a.0[i], a.1[i]);
    let below = extreme(alo, c[i] + 1 - alo, t, true) + MARGIN;
    let above = extreme(ahi - 1, c[i] - ahi, t, false) - MARGIN;
    let lo = above.floor().max(0.0);
    let hi = below.ceil().min((n - 1) as f64);
    (lo as i32, hi as i32)
}

/// The distinct mirror images of position `c` with the axes flipped for each (bit k: axis k);
/// a flip that leaves the middle cell of an odd N in place is left out.
fn mirrors(n: u32, c: [u32; 3]) -> impl Iterator<Item = (u32, [u32; 3])> {
    (0..8u32)
        .filter(move |fl| (0..3).all(|k| fl >> k & 1 == 0 || 2 * c[k] + 1 != n))
        .map(move |fl| {
            let flip = |k: usize| if fl >> k & 1 != 0 { n - 1 - c[k] } else { c[k] };
            (fl, [flip(0), flip(1), flip(2)])
        })
}

/// The masks of one position's mirror images (Fig. 5's mask per child, for the position and
/// its reflections in the node's middle planes): `flips` bit k set mirrors axis k.
struct Orbit {
    n: i32,
    masks: Vec<(u32, [u32; 3], Vec<u32>)>,
}

impl Orbit {
    /// The mirror images of position `c` ([`mirrors`]), their masks empty.
    fn new(n: u32, c: [u32; 3]) -> Orbit {
        let words = linespace_words(n);
        let masks = mirrors(n, c)
            .map(|(fl, cell)| (fl, cell, vec![0u32; words]))
            .collect();
        Orbit { n: n as i32, masks }
    }

    /// Cell (u, v) of side `f` mirrored by `fl`.
    fn flip(&self, fl: u32, f: usize, u: i32, v: i32) -> (usize, u32, u32) {
        let axis = f / 2;
        let (ua, va) = face_axes(axis);
        let m = |k: usize, x: i32| if fl >> k & 1 != 0 { self.n - 1 - x } else { x } as u32;
        (f ^ (fl as usize >> axis & 1), m(ua, u), m(va, v))
    }

    /// The shaft from cell `a` of side `s` to cell `b` of side `e` cuts the position: so its
    /// mirror image cuts each mirrored position.
    fn hit(&mut self, s: usize, a: (i32, i32), e: usize, b: (i32, i32)) {
        for i in 0..self.masks.len() {
            let fl = self.masks[i].0;
            let (s, su, sv) = self.flip(fl, s, a.0, a.1);
            let (e, eu, ev) = self.flip(fl, e, b.0, b.1);
            let idx = entry_index(self.n as u32, s, su, sv, e, eu, ev).expect("s ≠ e");
            self.masks[i].2[idx / 32] |= 1 << (idx % 32);
        }
    }
}

/// Every shaft between a start cell of side `s` and an end cell of side `e > s` that cuts
/// cell `c` (the orbit's first position), recorded in `orbit`.
fn pair_mask(orbit: &mut Orbit, s: usize, e: usize, c: [i32; 3]) {
    let n = orbit.n;
    let m = e / 2;
    let end = if e.is_multiple_of(2) { 0 } else { n };
    let (ua, va) = face_axes(m);
    for sv in 0..n {
        for su in 0..n {
            let a = face_cell(n, s, su, sv);
            // the end side's axis: the box at t is flat there, a range of t meets the cell
            let mut t = (0.0f64, 1.0f64);
            constrain(&mut t, a.0[m], end - a.0[m], c[m] + 1);
            constrain(&mut t, -a.1[m], -(end - a.1[m]), -c[m]);
            if t.0 > t.1 {
                continue;
            }
            let (u0, u1) = end_range(n, a, c, ua, t);
            let (v0, v1) = end_range(n, a, c, va, t);
            for ev in v0..=v1 {
                for eu in u0..=u1 {
                    if shaft_hits_cell(a, face_cell(n, e, eu, ev), c) {
                        orbit.hit(s, (su, sv), e, (eu, ev));
                    }
                }
            }
        }
    }
}

/// The masks of position `c` (lower corner, each coordinate in 0..N) and of its mirror images:
/// per position every entry whose shaft cuts the child's interior, `linespace_words(n)` words.
fn orbit_masks(n: u32, c: [u32; 3]) -> Vec<([u32; 3], Vec<u32>)> {
    let mut orbit = Orbit::new(n, c);
    let ci = c.map(|v| v as i32);
    for s in 0..FACES {
        for e in s + 1..FACES {
            pair_mask(&mut orbit, s, e, ci);
        }
    }
    orbit.masks.into_iter().map(|(_, c, m)| (c, m)).collect()
}

/// The mask of child position `c`: every entry whose shaft cuts the child's interior.
pub fn cell_mask(n: u32, c: [u32; 3]) -> Vec<u32> {
    let canon = c.map(|v| v.min(n - 1 - v));
    let orbit = orbit_masks(n, canon);
    orbit
        .into_iter()
        .find(|(cell, _)| *cell == c)
        .expect("c is in its orbit")
        .1
}

/// The line spaces of nodes whose children's geometry flags (N³ each, index x + N(y + Nz)) are
/// `filled`, concatenated in that order: per position the mask once (computed for the positions
/// of one octant, mirrored to the others), OR-ed into every node that fills it. Two mirrored
/// layers of positions (z and N − 1 − z) at a time, so at most 2N² masks are held.
pub fn build_linespaces(n: u32, filled: &[Vec<bool>]) -> Vec<u32> {
    let words = linespace_words(n);
    let nn = n as usize;
    let half = n.div_ceil(2);
    let index = |c: [u32; 3]| c[0] as usize + nn * (c[1] as usize + nn * c[2] as usize);
    let used: Vec<bool> = (0..nn * nn * nn)
        .map(|i| filled.iter().any(|f| f[i]))
        .collect();
    let mut out = vec![0u32; filled.len() * words];
    for z in 0..half {
        let masks: Vec<(usize, Vec<u32>)> = (0..half * half)
            .into_par_iter()
            .flat_map_iter(|j| {
                let c = [j % half, j / half, z];
                let any = mirrors(n, c).any(|(_, cell)| used[index(cell)]);
                let masks = if any { orbit_masks(n, c) } else { Vec::new() };
                masks
                    .into_iter()
                    .map(|(c, m)| (index(c), m))
                    .filter(|(i, _)| used[*i])
            })
            .collect();
        out.par_chunks_mut(words)
            .zip(filled.par_iter())
            .for_each(|(ls, f)| {
                for (i, mask) in &masks {
                    if f[*i] {
                        ls.iter_mut().zip(mask).for_each(|(w, m)| *w |= m);
                    }
                }
            });
    }
    out
}
