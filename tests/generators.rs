//! What the generated meshes must be, beyond their triangle counts (the sphere and the square
//! are in `tests/wagner_scenes.rs`): the teapot's tessellation reaches every patch corner and
//! the patches that share a border curve meet along it (no cracks); the floor is a closed grid.

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;
use gpgpu_rt::scene::bpt::teapot;
use gpgpu_rt::scene::mesh::floor;

/// Newell's patches in the `.bpt` format, z up, as the generator reads them.
fn patches() -> Vec<[Vec3; 16]> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/teapot.bpt");
    let text = std::fs::read_to_string(path).unwrap();
    let nums: Vec<f32> = text
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    let count = nums[0] as usize;
    let mut out = Vec::new();
    let mut k = 1;
    for _ in 0..count {
        k += 2; // "3 3"
        let mut cp = [Vec3::ZERO; 16];
        for p in cp.iter_mut() {
            *p = Vec3::new(nums[k], nums[k + 1], nums[k + 2]);
            k += 3;
        }
        out.push(cp);
    }
    out
}

fn y_up(p: Vec3) -> Vec3 {
    Vec3::new(p.x, p.z, -p.y)
}

/// The cubic Bézier curve of four control points at t (a patch border), y up.
fn curve(c: [Vec3; 4], t: f32) -> Vec3 {
    let s = 1.0 - t;
    y_up(s * s * s * c[0] + 3.0 * t * s * s * c[1] + 3.0 * t * t * s * c[2] + t * t * t * c[3])
}

/// The four borders of a patch (control point (i, j) at 4i + j).
fn borders(cp: &[Vec3; 16]) -> [[Vec3; 4]; 4] {
    let at = |i: usize, j: usize| cp[4 * i + j];
    [
        [0, 1, 2, 3].map(|j| at(0, j)),
        [0, 1, 2, 3].map(|j| at(3, j)),
        [0, 1, 2, 3].map(|i| at(i, 0)),
        [0, 1, 2, 3].map(|i| at(i, 3)),
    ]
}

fn near(vertices: &[Vec3], p: Vec3) -> bool {
    vertices.iter().any(|v| (*v - p).length() < 1e-5)
}

#[test]
fn teapot_patches_reach_their_corners_and_shared_borders_meet() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/teapot.bpt");
    let patches = patches();
    assert_eq!(patches.len(), 32);
    for n in [10u32, 3] {
        let mesh = teapot(&path, n).unwrap();
        let per = (2 * n * n * 3) as usize;
        assert_eq!(mesh.positions.len(), per * 32);
        let verts: Vec<&[Vec3]> = mesh.positions.chunks(per).collect();
        let mut shared = 0;
        for (a, cp) in patches.iter().enumerate() {
            // the corners of every patch are vertices of its triangles
            for c in [0, 3, 12, 15] {
                assert!(
                    near(verts[a], y_up(cp[c])),
                    "n = {n}: patch {a}'s corner {c} is not on its mesh"
                );
            }
            // a border curve two patches share: both meshes have its points at t = k/n
            for (b, other) in patches.iter().enumerate().skip(a + 1) {
                for ba in borders(cp) {
                    for bb in borders(other) {
                        let mut rev = bb;
                        rev.reverse();
                        if ba != bb && ba != rev {
                            continue;
                        }
                        if ba.iter().all(|p| *p == ba[0]) {
                            continue; // a pole, not a border
                        }
                        shared += 1;
                        for k in 0..=n {
                            let p = curve(ba, k as f32 / n as f32);
                            for (who, v) in [(a, verts[a]), (b, verts[b])] {
                                assert!(
                                    near(v, p),
                                    "n = {n}: patches {a} and {b} share a border, patch \
                                     {who}'s mesh misses its point {k}/{n} ({p}): a crack"
                                );
                            }
                        }
                    }
                }
            }
        }
        // the body, lid, rim and bottom are sewn from many patches
        assert!(shared >= 30, "n = {n}: only {shared} shared borders");
    }
}

#[test]
fn floor_is_a_closed_grid_of_quads() {
    let (size, quads) = (4.0f32, 16u32);
    let mesh = floor(size, quads, [Vec3::ONE, Vec3::ZERO]);
    assert_eq!(mesh.triangle_count(), (2 * quads * quads) as usize);
    // vertices on the integer grid, the area exactly the square's
    let key = |p: Vec3| {
        let g = (p + size / 2.0) * quads as f32 / size;
        assert!(
            p.y == 0.0 && (g - g.round()).abs().max_element() < 1e-4,
            "{p} off the grid"
        );
        (g.x.round() as i32, g.z.round() as i32)
    };
    type Edge = ((i32, i32), (i32, i32));
    let mut edges: HashMap<Edge, i32> = HashMap::new();
    let mut area = 0.0f64;
    for t in mesh.positions.chunks(3) {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        assert!(n.y > 0.0, "every triangle faces up");
        area += 0.5 * n.length() as f64;
        for k in 0..3 {
            let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
            // +1 one way, -1 the other: a shared edge with opposite directions sums to 0
            let (e, s) = if a < b { ((a, b), 1) } else { ((b, a), -1) };
            *edges.entry(e).or_default() += s;
        }
    }
    assert!((area - (size * size) as f64).abs() < 1e-3, "area {area}");
    let q = quads as i32;
    for ((a, b), s) in edges {
        // an edge of the outer square: used once; every other edge twice, both ways round
        let outer = a.0 == b.0 && (a.0 == 0 || a.0 == q) || a.1 == b.1 && (a.1 == 0 || a.1 == q);
        assert_eq!(s.abs(), outer as i32, "edge {a:?}-{b:?}: used {s}");
    }
}
