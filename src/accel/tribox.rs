//! Triangle/box overlap, the registration test of the grids that store a triangle in every cell
//! its surface touches: the streaming tracer's static grid, built here on the CPU
//! (`pipeline::stream::grid`), and the exact grid, whose kernels run the same test in
//! `glsl/exact_grid/tribox.glsl` (its CPU twin: `reference::grid`).

use glam::Vec3;

fn axis_separates(axis: Vec3, v: [Vec3; 3], half: Vec3) -> bool {
    let p = v.map(|x| x.dot(axis));
    let r = half.dot(axis.abs());
    p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r
}

/// Triangle/box overlap by separating axes (Akenine-Möller 2001), boundary included — as
/// `glsl/exact_grid/tribox.glsl`.
pub fn tri_box_overlap(center: Vec3, half: Vec3, tri: [Vec3; 3]) -> bool {
    let v = tri.map(|p| p - center);
    let lo = v[0].min(v[1]).min(v[2]);
    let hi = v[0].max(v[1]).max(v[2]);
    if lo.cmpgt(half).any() || hi.cmplt(-half).any() {
        return false;
    }
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let n = e[0].cross(e[1]);
    if n.dot(v[0]).abs() > half.dot(n.abs()) {
        return false;
    }
    for e in e {
        for axis in [
            Vec3::new(0.0, -e.z, e.y),
            Vec3::new(e.z, 0.0, -e.x),
            Vec3::new(-e.y, e.x, 0.0),
        ] {
            if axis_separates(axis, v, half) {
                return false;
            }
        }
    }
    true
}
