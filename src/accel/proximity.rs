//! Proximity clouds (Cohen and Sheffer, "Proximity clouds — an acceleration technique for 3D
//! grid traversal", The Visual Computer 11, 1994), as seed 004 uses them: per empty cell of a
//! uniform grid the Chebyshev (L∞) distance, in cells, to the nearest non-empty cell. Shared by
//! both grids that skip empty cells: the streaming tracer's static grid
//! (`reference::stream_grid`, `glsl/stream/`) and the exact grid rebuilt on the GPU every
//! frame (`reference::exact_grid`, `glsl/exact_grid/proximity.comp`).
//!
//! Why L∞ is safe for a 3D-DDA: a cell at distance d ≥ 2 is the centre of a cube of Chebyshev
//! radius d − 1 that holds no non-empty cell, so a walk may jump to where the ray leaves that
//! cube — the cells it passes inside the cube are all empty.

use glam::{IVec3, UVec3, Vec3};

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

/// The cells a 3D-DDA enters strictly between cells `a` and `b` of its walk: each of its
/// steps moves one cell along one axis, so it takes |b − a|₁ steps from `a` to `b`.
pub fn cells_between(a: IVec3, b: IVec3) -> u64 {
    ((b - a).abs().element_sum() as u64).saturating_sub(1)
}

/// A proximity-cloud jump (seed 004 ch. 3), shared by the streaming grid's walk
/// (`StreamGrid::jump`, `glsl/stream/traverse_intersect.frag` jumpCloud) and the exact grid's
/// (`grid::Walk::jump`, `glsl/exact_grid/dda.glsl` jumpWalk): `cell` is empty at distance
/// `dist` ≥ 2, so the cube of Chebyshev radius dist − 1 around it (clipped to the `dims`
/// grid) holds no non-empty cell; land in the cell where the ray leaves that cube. The exit
/// axis' cell is the first beyond the cube's face, the others the exit point's (within the
/// cube), as the DDA's plane parameters place it. `step`: the ray's direction signs;
/// `plane_t(a, k)`: the parameter of the face through which the ray leaves column `k` of axis
/// `a` (+∞ on an axis it does not move along); `cell_at(t)`: the cell of the point at `t`
/// (floor, unclamped). `None` when the cube is left beyond `limit` or the grid.
pub fn cloud_jump(
    cell: IVec3,
    dist: u32,
    dims: IVec3,
    step: IVec3,
    limit: f32,
    plane_t: impl Fn(usize, i32) -> f32,
    cell_at: impl Fn(f32) -> IVec3,
) -> Option<IVec3> {
    let rad = IVec3::splat(dist as i32 - 1);
    let lo = (cell - rad).max(IVec3::ZERO);
    let hi = (cell + rad).min(dims - 1);
    let far = IVec3::select(step.cmpgt(IVec3::ZERO), hi, lo);
    let t_box = Vec3::new(plane_t(0, far.x), plane_t(1, far.y), plane_t(2, far.z));
    let exit = t_box.min_element();
    if exit > limit {
        return None;
    }
    let a = if t_box.x == exit {
        0
    } else if t_box.y == exit {
        1
    } else {
        2
    };
    let mut v = cell_at(exit).clamp(lo, hi);
    for b in (0..3).filter(|&b| b != a && step[b] != 0) {
        // the exit point's cell as the plane parameters place it (floor() may round across a
        // plane the point lies on)
        let s = step[b];
        if plane_t(b, v[b] - s) > exit {
            v[b] -= s;
        } else if plane_t(b, v[b]) < exit {
            v[b] += s;
        }
        v[b] = v[b].clamp(lo[b], hi[b]);
    }
    v[a] = far[a] + step[a];
    let inside = v.cmpge(IVec3::ZERO).all() && v.cmplt(dims).all();
    inside.then_some(v)
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
