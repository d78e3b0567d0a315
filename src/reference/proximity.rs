//! The proximity-cloud jump of the CPU twins' walks (the streaming tracer ch. 3; the distances they
//! jump by: `accel::proximity`), shared by the streaming grid's (`reference::stream_grid`) and the
//! exact grid's (`reference::grid`).

use glam::{IVec3, Vec3};

/// The cells a 3D-DDA enters strictly between cells `a` and `b` of its walk: each of its
/// steps moves one cell along one axis, so it takes |b − a|₁ steps from `a` to `b`.
pub fn cells_between(a: IVec3, b: IVec3) -> u64 {
    ((b - a).abs().element_sum() as u64).saturating_sub(1)
}

/// A proximity-cloud jump (the streaming tracer ch. 3), shared by the streaming grid's walk
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
