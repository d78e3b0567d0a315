//! Proximity clouds (Cohen and Sheffer, "Proximity clouds — an acceleration technique for 3D
//! grid traversal", The Visual Computer 11, 1994), as the streaming tracer uses them: per empty
//! cell of a uniform grid the Chebyshev (L∞) distance, in cells, to the nearest non-empty cell. The
//! streaming tracer's static grid takes them from here when it is built
//! (`pipeline::stream::grid`); the exact grid, rebuilt on the GPU every frame, computes them in
//! `glsl/exact_grid/proximity.comp` and its CPU twin here (`reference::exact_grid`). The jump
//! the walks make with them is their CPU twins' (`reference::proximity`).
//!
//! Why L∞ is safe for a 3D-DDA: a cell at distance d ≥ 2 is the centre of a cube of Chebyshev
//! radius d − 1 that holds no non-empty cell, so a walk may jump to where the ray leaves that
//! cube — the cells it passes inside the cube are all empty.

use glam::{IVec3, UVec3};

use crate::progress::Progress;

/// The 26 neighbour offsets (dz, dy, dx) before a cell in x-fastest scan order.
fn causal_neighbours() -> Vec<IVec3> {
    let mut v = Vec::new();
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let o = IVec3::new(dx, dy, dz);
                if (dz, dy, dx) < (0, 0, 0) {
                    v.push(o);
                }
            }
        }
    }
    v
}

/// Proximity clouds (Cohen and Sheffer 1994) in the Chebyshev (L∞) metric: for every cell the
/// distance, in cells, to the nearest cell with `filled` set — by the two-pass chamfer
/// transform with unit weights over the 26-neighbourhood (Rosenfeld and Pfaltz), which is
/// exact for L∞. An empty grid gets the largest side everywhere.
pub fn chebyshev_distances(dims: UVec3, filled: &[bool]) -> Vec<u32> {
    let d = dims.as_ivec3();
    let far = dims.max_element();
    let mut dist: Vec<u32> = filled.iter().map(|&f| if f { 0 } else { far }).collect();
    let idx = |c: IVec3| ((c.z * d.y + c.y) * d.x + c.x) as usize;
    let inside = |c: IVec3| c.cmpge(IVec3::ZERO).all() && c.cmplt(d).all();
    let back = causal_neighbours();
    // a grid of 2^24 cells or more has long passes: their progress is shown by slices
    let cells = filled.len() as u64;
    let worth = if cells >= 1 << 24 { 0 } else { u64::MAX };
    let progress = Progress::new("proximity clouds", 2 * d.z as u64, worth);
    let mut relax = |c: IVec3, offsets: &mut dyn Iterator<Item = IVec3>| {
        let mut best = dist[idx(c)];
        for o in offsets {
            if inside(c + o) {
                best = best.min(dist[idx(c + o)] + 1);
            }
        }
        dist[idx(c)] = best;
    };
    // forward in x-fastest scan order, then backward (no list of the cells: a 512³ grid would
    // need 1.6 GB for it)
    for z in 0..d.z {
        for y in 0..d.y {
            for x in 0..d.x {
                relax(IVec3::new(x, y, z), &mut back.iter().copied());
            }
        }
        progress.inc(1);
    }
    for z in (0..d.z).rev() {
        for y in (0..d.y).rev() {
            for x in (0..d.x).rev() {
                relax(IVec3::new(x, y, z), &mut back.iter().map(|o| -*o));
            }
        }
        progress.inc(1);
    }
    dist.into_iter().map(|v| v.min(far)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance field against its definition, on a small grid with a few filled cells.
    #[test]
    fn chebyshev_transform_equals_brute_force() {
        let dims = UVec3::new(7, 5, 6);
        let n = (dims.x * dims.y * dims.z) as usize;
        let mut filled = vec![false; n];
        for i in [3usize, 77, 150, 151, 209] {
            filled[i] = true;
        }
        let d = dims.as_ivec3();
        let pos = |i: usize| {
            let i = i as i32;
            IVec3::new(i % d.x, (i / d.x) % d.y, i / (d.x * d.y))
        };
        let got = chebyshev_distances(dims, &filled);
        for (i, g) in got.iter().enumerate() {
            let want = (0..n)
                .filter(|&j| filled[j])
                .map(|j| (pos(i) - pos(j)).abs().max_element() as u32)
                .min()
                .unwrap();
            assert_eq!(*g, want, "cell {:?}", pos(i));
        }
    }
}
