//! The procedural test objects of Wagner 2018, ch. 5: the sphere of Fig. 5.2 (720 triangles)
//! and the subdivided square of ch. 5.1 / Table A.1 (8, 32, …, 32768 triangles).
//!
//! Both are built from a grid of vertices indexed by integers, and every vertex position is
//! computed from its indices alone, so two triangles that share a vertex share its exact
//! floating-point position: the meshes have no cracks (`tests/wagner_scenes.rs`).

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::mesh::Mesh;

/// The triangles of a sphere of `stacks` × `slices`: a fan of `slices` triangles at each
/// pole and two per quad in the `stacks − 2` bands between them.
pub fn sphere_triangles(stacks: u64, slices: u64) -> u64 {
    2u64.saturating_mul(slices)
        .saturating_mul(stacks.saturating_sub(1))
}

/// A UV sphere of `radius` about the origin, y up: `stacks` rings of latitude from pole to
/// pole (`stacks` ≥ 2) and `slices` meridians (`slices` ≥ 3); 2·slices·(stacks − 1) triangles,
/// wound counter-clockwise seen from outside, with the sphere's normals. The defaults of the
/// scene files, 16 stacks × 24 slices, give the 720 triangles of Wagner 2018's sphere
/// (ch. 5.2, Fig. 5.2): 24 + 24 in the two polar fans and 2·24·14 = 672 in the bands.
pub fn sphere(radius: f32, stacks: u32, slices: u32, color: Vec3) -> Mesh {
    let unit = |i: u32, j: u32| -> Vec3 {
        // the poles exactly, whatever sin(π) rounds to; the seam j = slices is j = 0
        if i == 0 {
            return Vec3::Y;
        }
        if i == stacks {
            return Vec3::NEG_Y;
        }
        let theta = PI * i as f32 / stacks as f32;
        let phi = 2.0 * PI * (j % slices) as f32 / slices as f32;
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            -theta.sin() * phi.sin(),
        )
    };
    let uv = |i: u32, j: u32| Vec2::new(j as f32 / slices as f32, 1.0 - i as f32 / stacks as f32);
    let mut mesh = Mesh::default();
    let mut push = |corners: [(u32, u32); 3]| {
        let n = corners.map(|(i, j)| unit(i, j));
        let p = n.map(|n| radius * n);
        mesh.push_triangle(p, n, [color; 3], corners.map(|(i, j)| uv(i, j)), 0);
    };
    for j in 0..slices {
        push([(0, j), (1, j), (1, j + 1)]);
        for i in 1..stacks - 1 {
            push([(i, j), (i + 1, j), (i + 1, j + 1)]);
            push([(i, j), (i + 1, j + 1), (i, j + 1)]);
        }
        push([(stacks - 1, j), (stacks, j), (stacks - 1, j + 1)]);
    }
    mesh
}

/// The triangles of the square at subdivision `level`: 2·4^level (8 at level 1).
pub fn square_triangles(level: u64) -> u64 {
    let quads = u32::try_from(level)
        .ok()
        .and_then(|l| 4u64.checked_pow(l))
        .unwrap_or(u64::MAX);
    quads.saturating_mul(2)
}

/// Wagner 2018's square (ch. 5.1, Table A.1): a square of side `size` centred at the origin in
/// the xz plane (facing +y), divided into 2^level × 2^level quads of two triangles each — four
/// quads (8 triangles) at level 1, four times as many at every further level (32768 at
/// level 7). Wound counter-clockwise seen from above; one colour.
pub fn square(size: f32, level: u32, color: Vec3) -> Mesh {
    let n = 1u32 << level;
    // from the integer grid index alone, so neighbouring quads share exact positions
    let coord = |k: u32| size * (k as f32 / n as f32 - 0.5);
    let corner = |(i, j): (u32, u32)| Vec3::new(coord(i), 0.0, coord(j));
    let uv = |(i, j): (u32, u32)| Vec2::new(i as f32 / n as f32, j as f32 / n as f32);
    let mut mesh = Mesh::default();
    for i in 0..n {
        for j in 0..n {
            let quad = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)];
            for tri in [[0, 1, 2], [0, 2, 3]] {
                let k = tri.map(|t| quad[t]);
                mesh.push_triangle(k.map(corner), [Vec3::Y; 3], [color; 3], k.map(uv), 0);
            }
        }
    }
    mesh
}
