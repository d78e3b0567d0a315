//! Triangle meshes in object space: OBJ files (tobj, with MTL colours and textures), Newell's
//! teapot tessellated from its Bézier patches, and the thesis' floor of quads.
//!
//! A mesh is a triangle soup, as the kernels read it (Müller 2015, Listing 12): the vertices of
//! triangle k are entries 3k, 3k+1, 3k+2 of every per-vertex array.

use glam::{DVec3, Vec2, Vec3};

/// Per-vertex attributes of a triangle soup plus a local material index per triangle.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub colors: Vec<Vec3>,
    pub texcoords: Vec<Vec2>,
    /// Index into the mesh's own material list ([`LoadedObj::materials`] for OBJ files, a
    /// single material otherwise), one entry per triangle.
    pub triangle_material: Vec<u32>,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.positions.len() / 3
    }

    pub(super) fn push_triangle(
        &mut self,
        p: [Vec3; 3],
        n: [Vec3; 3],
        c: [Vec3; 3],
        t: [Vec2; 3],
        m: u32,
    ) {
        self.positions.extend_from_slice(&p);
        self.normals.extend_from_slice(&n);
        self.colors.extend_from_slice(&c);
        self.texcoords.extend_from_slice(&t);
        self.triangle_material.push(m);
    }

    /// Axis-aligned bounds of the positions.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }
}

/// Area-weighted vertex normals of an indexed triangle list: unit length, or zero for a
/// vertex of degenerate triangles only.
/// Summed in f64: the cross product of f32 edges squares their length, which leaves f32 for
/// a model in units of 1e-12 or 1e10 (a normal of zero length, NaN once normalised).
pub(super) fn smooth_normals(pos: &[Vec3], triangles: &[[usize; 3]]) -> Vec<Vec3> {
    let mut acc = vec![DVec3::ZERO; pos.len()];
    for t in triangles {
        let n = face_cross([pos[t[0]], pos[t[1]], pos[t[2]]]);
        t.iter().for_each(|&k| acc[k] += n);
    }
    acc.into_iter()
        .map(|n| n.normalize_or_zero().as_vec3())
        .collect()
}

/// The cross product of a triangle's edges, in f64 (area-weighted normal).
fn face_cross(p: [Vec3; 3]) -> DVec3 {
    let [a, b, c] = p.map(|v| v.as_dvec3());
    (b - a).cross(c - a)
}

/// A triangle's unit geometric normal (zero for a degenerate one), computed in f64.
pub fn face_normal(p: [Vec3; 3]) -> Vec3 {
    face_cross(p).normalize_or_zero().as_vec3()
}

/// The normals at the corners `idx` (positions `p`) of a triangle; a zero vertex normal
/// (degenerate geometry) gives way to the triangle's geometric normal.
pub(super) fn corner_normals(p: [Vec3; 3], idx: [usize; 3], normals: &[Vec3]) -> [Vec3; 3] {
    let geo = face_normal(p);
    idx.map(|i| {
        if normals[i] == Vec3::ZERO {
            geo
        } else {
            normals[i]
        }
    })
}

/// The thesis' floor (ch. 5.1): `quads`×`quads` squares, two triangles each, in the xz plane
/// (y = 0) with side `size`, centred at the origin, normal +y. `checker` colours alternate
/// squares; texture coordinates run 0..quads.
pub fn floor(size: f32, quads: u32, checker: [Vec3; 2]) -> Mesh {
    let mut mesh = Mesh::default();
    let step = size / quads as f32;
    let half = size / 2.0;
    for i in 0..quads {
        for j in 0..quads {
            let x0 = -half + i as f32 * step;
            let z0 = -half + j as f32 * step;
            let corner =
                |di: u32, dj: u32| Vec3::new(x0 + di as f32 * step, 0.0, z0 + dj as f32 * step);
            let tc = |di: u32, dj: u32| Vec2::new((i + di) as f32, (j + dj) as f32);
            let q = [(0, 0), (0, 1), (1, 1), (1, 0)];
            let c = checker[((i + j) % 2) as usize];
            for tri in [[0, 1, 2], [0, 2, 3]] {
                let k = tri.map(|t| q[t]);
                mesh.push_triangle(
                    k.map(|(a, b)| corner(a, b)),
                    [Vec3::Y; 3],
                    [c; 3],
                    k.map(|(a, b)| tc(a, b)),
                    0,
                );
            }
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_has_the_thesis_triangle_count() {
        assert_eq!(floor(4.0, 64, [Vec3::ONE; 2]).triangle_count(), 8192);
    }
}
