//! Newell's teapot from its bicubic Bézier patches in the `.bpt` format: a line with the patch
//! count, then per patch a line `3 3` and 16 control points `x y z` (z up).
//!
//! The header's count is checked against the lines the file has before anything is allocated,
//! the triangles the patches give against [`super::MAX_PROCEDURAL_TRIANGLES`] and the host's
//! memory before they are tessellated, and every control point must be finite (file and line).

use std::path::Path;

use glam::{Vec2, Vec3};

use super::budget;
use super::mesh::Mesh;
use super::model::{SceneError, MAX_PROCEDURAL_TRIANGLES};

/// Non-empty lines of one patch: `3 3` and 16 control points.
const LINES_PER_PATCH: usize = 17;

/// Newell's teapot: its patches tessellated `n`×`n` quads per patch — patches·n·n·2
/// triangles, 6400 for the 32 patches of Newell's teapot and the thesis' n = 10 (ch. 5.1).
/// The result is y-up.
pub fn teapot(path: &Path, n: u32) -> Result<Mesh, SceneError> {
    let text = read_model_text(path, "teapot patches")?;
    let patches = parse_bpt(path, &text)?;
    let triangles = 2 * (n as u64).pow(2) * patches.len() as u64;
    let what = format!("{} patches at tessellation {n}", patches.len());
    if triangles > MAX_PROCEDURAL_TRIANGLES {
        let m = format!(
            "{what} give {triangles} triangles; a procedural object may have at most \
             {MAX_PROCEDURAL_TRIANGLES}"
        );
        return Err(SceneError::at(path, None, m));
    }
    budget::check_triangles(&what, triangles).map_err(|m| SceneError::at(path, None, m))?;
    let mut mesh = Mesh::default();
    for cp in &patches {
        tessellate(&mut mesh, cp, n);
    }
    Ok(mesh)
}

/// The patches a patch file's header claims (checked against its length when it is parsed).
pub fn patch_count(path: &Path) -> Result<u64, SceneError> {
    let text = read_model_text(path, "teapot patches")?;
    Ok(parse_bpt(path, &text)?.len() as u64)
}

/// A model file as text, its length checked against the host's memory first.
pub(super) fn read_model_text(path: &Path, what: &str) -> Result<String, SceneError> {
    super::file::read_text(path)
        .map_err(|e| SceneError::at(path, None, format!("cannot read {what}: {e}")))
}

/// One patch as `n`×`n` quads of two triangles each, y-up.
fn tessellate(mesh: &mut Mesh, cp: &[Vec3; 16], n: u32) {
    let y_up = |p: Vec3| Vec3::new(p.x, p.z, -p.y);
    let nf = n as f32;
    let grid: Vec<(Vec3, Vec3)> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let (u, v) = (i as f32 / nf, j as f32 / nf);
            let (p, normal) = bezier_point_normal(cp, u, v);
            (y_up(p), y_up(normal))
        })
        .collect();
    let at = |i: u32, j: u32| grid[(i * (n + 1) + j) as usize];
    let uv = |i: u32, j: u32| Vec2::new(i as f32 / nf, j as f32 / nf);
    for i in 0..n {
        for j in 0..n {
            let quad = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            for tri in [[0, 1, 2], [0, 2, 3]] {
                let c = tri.map(|k| quad[k]);
                let pts = c.map(|(a, b)| at(a, b));
                mesh.push_triangle(
                    pts.map(|x| x.0),
                    pts.map(|x| x.1),
                    [Vec3::ONE; 3],
                    c.map(|(a, b)| uv(a, b)),
                    0,
                );
            }
        }
    }
}

/// The patches of a `.bpt` text; the header's count must fit the lines the file has.
fn parse_bpt(path: &Path, text: &str) -> Result<Vec<[Vec3; 16]>, SceneError> {
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| (i + 1, l.trim()))
        .collect();
    let err = |line: usize, msg: String| SceneError::at(path, Some(line), msg);
    let &(l0, first) = lines
        .first()
        .ok_or_else(|| SceneError::at(path, None, "empty patch file".into()))?;
    let count: usize = first
        .parse()
        .map_err(|_| err(l0, format!("expected the patch count, found `{first}`")))?;
    let room = (lines.len() - 1) / LINES_PER_PATCH;
    if count > room {
        return Err(err(
            l0,
            format!(
                "the header claims {count} patches, but the file's {} lines hold at most \
                 {room} ({LINES_PER_PATCH} lines a patch)",
                lines.len()
            ),
        ));
    }
    let mut patches = Vec::with_capacity(count);
    for chunk in lines[1..].chunks(LINES_PER_PATCH).take(count) {
        patches.push(parse_patch(path, chunk)?);
    }
    Ok(patches)
}

/// `3 3` and 16 finite control points `x y z`, as (line number, text).
fn parse_patch(path: &Path, lines: &[(usize, &str)]) -> Result<[Vec3; 16], SceneError> {
    let err = |line: usize, msg: String| SceneError::at(path, Some(line), msg);
    let (ln, deg) = lines[0];
    if deg.split_whitespace().collect::<Vec<_>>() != ["3", "3"] {
        let m = format!("expected `3 3` (bicubic patch), found `{deg}`");
        return Err(err(ln, m));
    }
    let mut cp = [Vec3::ZERO; 16];
    for (p, &(ln, l)) in cp.iter_mut().zip(&lines[1..]) {
        let v: Vec<f32> = l
            .split_whitespace()
            .filter_map(|s| s.parse().ok())
            .collect();
        if v.len() != 3 || l.split_whitespace().count() != 3 {
            let m = format!("expected a control point `x y z`, found `{l}`");
            return Err(err(ln, m));
        }
        *p = Vec3::new(v[0], v[1], v[2]);
        if !p.is_finite() {
            let m = format!("a control point has a non-finite number (nan or inf): `{l}`");
            return Err(err(ln, m));
        }
    }
    Ok(cp)
}

fn bernstein(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

fn bernstein_d(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}

/// Point and unit normal of a bicubic patch (control point (i, j) at index 4i + j).
fn bezier_point_normal(cp: &[Vec3; 16], u: f32, v: f32) -> (Vec3, Vec3) {
    let eval = |bu: [f32; 4], bv: [f32; 4]| {
        let mut p = Vec3::ZERO;
        for i in 0..4 {
            for j in 0..4 {
                p += bu[i] * bv[j] * cp[4 * i + j];
            }
        }
        p
    };
    let p = eval(bernstein(u), bernstein(v));
    let normal_at = |u: f32, v: f32| {
        eval(bernstein_d(u), bernstein(v)).cross(eval(bernstein(u), bernstein_d(v)))
    };
    let mut n = normal_at(u, v);
    if n.length() < 1e-6 {
        // degenerate corner (the lid's and the bottom's poles): step inwards a little
        let nudge = |t: f32| if t < 0.5 { t + 1e-3 } else { t - 1e-3 };
        n = normal_at(nudge(u), nudge(v));
    }
    (p, n.normalize_or_zero())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn teapot_has_the_thesis_triangle_count() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/teapot.bpt");
        let m = teapot(&path, 10).unwrap();
        assert_eq!(m.triangle_count(), 6400);
        assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3));
    }

    #[test]
    fn bezier_corners_interpolate_control_points() {
        let cp: [Vec3; 16] = std::array::from_fn(|k| {
            Vec3::new((k / 4) as f32, (k % 4) as f32, ((k * 7) % 5) as f32)
        });
        assert!((bezier_point_normal(&cp, 0.0, 0.0).0 - cp[0]).length() < 1e-6);
        assert!((bezier_point_normal(&cp, 1.0, 1.0).0 - cp[15]).length() < 1e-6);
        assert!((bezier_point_normal(&cp, 1.0, 0.0).0 - cp[12]).length() < 1e-6);
    }
}
