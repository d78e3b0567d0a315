//! Triangle meshes in object space: OBJ files (tobj, with MTL colours and textures), Newell's
//! teapot tessellated from its Bézier patches, and the thesis' floor of quads.
//!
//! A mesh is a triangle soup, as the kernels read it (Müller 2015, Listing 12): the vertices of
//! triangle k are entries 3k, 3k+1, 3k+2 of every per-vertex array.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Ply, Property};

use super::SceneError;

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

/// A material found in an MTL file.
#[derive(Debug, Clone)]
pub struct ObjMaterial {
    pub name: String,
    pub diffuse: Option<Vec3>,
    pub texture: Option<PathBuf>,
    pub shininess: Option<f32>,
}

#[derive(Debug, Clone)]
pub struct LoadedObj {
    pub mesh: Mesh,
    pub materials: Vec<ObjMaterial>,
    /// true when the file gave per-vertex colours (`v x y z r g b`).
    pub has_vertex_colors: bool,
}

/// Load an OBJ file (triangulated) with its MTL materials. Material index
/// `materials.len()` in `triangle_material` means "no material".
pub fn load_obj(path: &Path) -> Result<LoadedObj, SceneError> {
    let (models, mtl) = read_obj(path)?;
    let materials = obj_materials(path, mtl)?;
    let mut mesh = Mesh::default();
    let mut has_vertex_colors = false;
    for model in &models {
        has_vertex_colors |= append_obj_model(&mut mesh, &model.mesh, &materials);
    }
    if mesh.positions.is_empty() {
        return Err(SceneError::at(
            path,
            None,
            "the OBJ file has no faces".into(),
        ));
    }
    check_obj_finite(path, &mesh)?;
    Ok(LoadedObj {
        mesh,
        materials,
        has_vertex_colors,
    })
}

/// The models and the MTL materials as tobj reads them; its errors name the file and, where
/// [`locate_obj_error`] finds it, the line.
fn read_obj(path: &Path) -> Result<(Vec<tobj::Model>, ObjMtl), SceneError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    tobj::load_obj(path, &opts).map_err(|e| {
        if !path.exists() {
            return SceneError::at(path, None, format!("cannot open OBJ file: {e}"));
        }
        let (line, what) = locate_obj_error(path);
        SceneError::at(path, line, format!("malformed OBJ file ({e}){what}"))
    })
}

/// tobj's result for the MTL file an OBJ file names.
type ObjMtl = Result<Vec<tobj::Material>, tobj::LoadError>;

/// The MTL materials, texture paths relative to the OBJ file; none when the MTL file is
/// missing (or none is named), an error when it is malformed.
fn obj_materials(path: &Path, mtl: ObjMtl) -> Result<Vec<ObjMaterial>, SceneError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    match mtl {
        Ok(ms) => Ok(ms
            .into_iter()
            .map(|m| ObjMaterial {
                name: m.name.clone(),
                diffuse: m.diffuse.map(Vec3::from),
                texture: m.diffuse_texture.as_ref().map(|t| dir.join(t)),
                shininess: m.shininess,
            })
            .collect()),
        Err(tobj::LoadError::OpenFileFailed) => Ok(Vec::new()),
        Err(e) => Err(SceneError::at(
            path,
            None,
            format!("cannot load its MTL file: {e}"),
        )),
    }
}

/// Append the faces of one tobj model: normals from the file, or smooth (area weighted) when
/// it has none; colours per vertex, or the material's diffuse colour; texture coordinates
/// where the file has them. Returns whether the model has per-vertex colours.
fn append_obj_model(mesh: &mut Mesh, m: &tobj::Mesh, materials: &[ObjMaterial]) -> bool {
    let count = m.positions.len() / 3;
    let pos: Vec<Vec3> = (0..count).map(|i| vec3_at(&m.positions, i)).collect();
    let faces: Vec<[usize; 3]> = m
        .indices
        .chunks_exact(3)
        .map(|f| [f[0] as usize, f[1] as usize, f[2] as usize])
        .collect();
    let normals: Vec<Vec3> = if m.normals.len() == m.positions.len() {
        (0..count)
            .map(|i| vec3_at(&m.normals, i).normalize_or_zero())
            .collect()
    } else {
        smooth_normals(&pos, &faces)
    };
    let vcol = m.vertex_color.len() == m.positions.len();
    let has_texcoords = m.texcoords.len() >= 2 * count;
    let mat = m
        .material_id
        .map(|i| i as u32)
        .unwrap_or(materials.len() as u32);
    let diffuse = m
        .material_id
        .and_then(|i| materials.get(i))
        .and_then(|mm| mm.diffuse)
        .unwrap_or(Vec3::splat(0.8));
    for idx in faces {
        let p = idx.map(|i| pos[i]);
        let c = idx.map(|i| {
            if vcol {
                vec3_at(&m.vertex_color, i)
            } else {
                diffuse
            }
        });
        let t = idx.map(|i| {
            if has_texcoords {
                Vec2::new(m.texcoords[2 * i], m.texcoords[2 * i + 1])
            } else {
                Vec2::ZERO
            }
        });
        mesh.push_triangle(p, corner_normals(p, idx, &normals), c, t, mat);
    }
    vcol
}

/// Entry `i` of a flat `x y z x y z …` array.
fn vec3_at(v: &[f32], i: usize) -> Vec3 {
    Vec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2])
}

/// Area-weighted vertex normals of an indexed triangle list: unit length, or zero for a
/// vertex of degenerate triangles only.
fn smooth_normals(pos: &[Vec3], triangles: &[[usize; 3]]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; pos.len()];
    for t in triangles {
        let n = (pos[t[1]] - pos[t[0]]).cross(pos[t[2]] - pos[t[0]]);
        t.iter().for_each(|&k| acc[k] += n);
    }
    acc.into_iter().map(Vec3::normalize_or_zero).collect()
}

/// The normals at the corners `idx` (positions `p`) of a triangle; a zero vertex normal
/// (degenerate geometry) gives way to the triangle's geometric normal.
fn corner_normals(p: [Vec3; 3], idx: [usize; 3], normals: &[Vec3]) -> [Vec3; 3] {
    let geo = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
    idx.map(|i| {
        if normals[i] == Vec3::ZERO {
            geo
        } else {
            normals[i]
        }
    })
}

/// tobj reads `nan` and `inf`; a vertex with one is an error naming its line.
fn check_obj_finite(path: &Path, mesh: &Mesh) -> Result<(), SceneError> {
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    if finite(bytemuck::cast_slice(&mesh.positions))
        && finite(bytemuck::cast_slice(&mesh.normals))
        && finite(bytemuck::cast_slice(&mesh.texcoords))
    {
        return Ok(());
    }
    let (line, what) = locate_obj_error(path);
    Err(SceneError::at(
        path,
        line,
        format!("a vertex has a non-finite number (nan or inf){what}"),
    ))
}

/// Find the first line tobj could not have parsed: numbers of `v`/`vn`/`vt` lines and the
/// indices of `f` lines (tobj's errors do not carry a line number).
fn locate_obj_error(path: &Path) -> (Option<usize>, String) {
    let Ok(text) = std::fs::read_to_string(path) else {
        return (None, String::new());
    };
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    for (i, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        let Some(tag) = it.next() else { continue };
        let rest: Vec<&str> = it.collect();
        let floats_ok = |min: usize| {
            rest.len() >= min
                && rest
                    .iter()
                    .all(|s| s.parse::<f32>().is_ok_and(f32::is_finite))
        };
        let bad = match tag {
            "v" => {
                nv += 1;
                !floats_ok(3)
            }
            "vt" => {
                nt += 1;
                !floats_ok(1)
            }
            "vn" => {
                nn += 1;
                !floats_ok(3)
            }
            "f" => {
                rest.len() < 3
                    || rest.iter().any(|corner| {
                        corner.split('/').enumerate().any(|(k, s)| {
                            if s.is_empty() && k > 0 {
                                return false;
                            }
                            let limit = [nv, nt, nn][k.min(2)];
                            match s.parse::<i64>() {
                                Ok(v) => v == 0 || v > limit || -v > limit,
                                Err(_) => true,
                            }
                        })
                    })
            }
            _ => false,
        };
        if bad {
            return (Some(i + 1), format!(": `{}`", line.trim()));
        }
    }
    (None, String::new())
}

/// Load a PLY file (ASCII or binary; gzip-compressed when the name ends in `.gz`) with
/// `vertex` x/y/z and `face` vertex_indices (polygons are fanned into triangles). Vertex
/// normals are the area-weighted face normals.
pub fn load_ply(path: &Path) -> Result<Mesh, SceneError> {
    let ply = read_ply(path)?;
    let empty = Vec::new();
    let pos = ply_positions(path, ply.payload.get("vertex").unwrap_or(&empty))?;
    let faces = ply.payload.get("face").unwrap_or(&empty);
    let tris = ply_triangles(path, faces, pos.len())?;
    if tris.is_empty() {
        return Err(SceneError::at(
            path,
            None,
            "the PLY file has no faces".into(),
        ));
    }
    let normals = smooth_normals(&pos, &tris);
    let mut mesh = Mesh::default();
    for t in tris {
        let p = t.map(|k| pos[k]);
        let n = corner_normals(p, t, &normals);
        mesh.push_triangle(p, n, [Vec3::splat(0.8); 3], [Vec2::ZERO; 3], 0);
    }
    Ok(mesh)
}

fn read_ply(path: &Path) -> Result<Ply<DefaultElement>, SceneError> {
    let file = std::fs::File::open(path)
        .map_err(|e| SceneError::at(path, None, format!("cannot open PLY file: {e}")))?;
    let mut reader: Box<dyn std::io::Read> = if path.extension().is_some_and(|e| e == "gz") {
        Box::new(std::io::BufReader::new(flate2::read::GzDecoder::new(file)))
    } else {
        Box::new(std::io::BufReader::new(file))
    };
    Parser::<DefaultElement>::new()
        .read_ply(&mut reader)
        .map_err(|e| SceneError::at(path, None, format!("malformed PLY file: {e}")))
}

/// The `x y z` of every vertex element, each finite.
fn ply_positions(path: &Path, vertices: &[DefaultElement]) -> Result<Vec<Vec3>, SceneError> {
    let mut pos = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let c = ["x", "y", "z"].map(|k| ply_scalar(v.get(k)));
        match c {
            [Some(x), Some(y), Some(z)] if [x, y, z].iter().all(|c| (*c as f32).is_finite()) => {
                pos.push(Vec3::new(x as f32, y as f32, z as f32))
            }
            _ => {
                return Err(SceneError::at(
                    path,
                    None,
                    format!("vertex {i} lacks finite numeric x, y, z"),
                ))
            }
        }
    }
    Ok(pos)
}

/// A scalar property as f64; `None` for a missing property or a list.
fn ply_scalar(p: Option<&Property>) -> Option<f64> {
    Some(match p? {
        Property::Float(v) => *v as f64,
        Property::Double(v) => *v,
        Property::Int(v) => *v as f64,
        Property::UInt(v) => *v as f64,
        Property::Short(v) => *v as f64,
        Property::UShort(v) => *v as f64,
        Property::Char(v) => *v as f64,
        Property::UChar(v) => *v as f64,
        _ => return None,
    })
}

/// The faces fanned into triangles, every index checked against the `vertices` count.
fn ply_triangles(
    path: &Path,
    faces: &[DefaultElement],
    vertices: usize,
) -> Result<Vec<[usize; 3]>, SceneError> {
    let mut tris: Vec<[usize; 3]> = Vec::with_capacity(faces.len());
    for (i, f) in faces.iter().enumerate() {
        let idx = ply_face_indices(f).ok_or_else(|| {
            SceneError::at(path, None, format!("face {i} lacks a vertex_indices list"))
        })?;
        if idx.len() < 3 || idx.iter().any(|&k| k < 0 || k as usize >= vertices) {
            return Err(SceneError::at(
                path,
                None,
                format!(
                    "face {i} has indices {idx:?}: needs at least 3, each below {vertices} vertices"
                ),
            ));
        }
        for k in 1..idx.len() - 1 {
            tris.push([idx[0] as usize, idx[k] as usize, idx[k + 1] as usize]);
        }
    }
    Ok(tris)
}

/// A face's `vertex_indices` (or `vertex_index`) list of any integer type.
fn ply_face_indices(f: &DefaultElement) -> Option<Vec<i64>> {
    fn widen<T: Copy + Into<i64>>(v: &[T]) -> Vec<i64> {
        v.iter().map(|x| (*x).into()).collect()
    }
    match f.get("vertex_indices").or_else(|| f.get("vertex_index"))? {
        Property::ListInt(v) => Some(widen(v)),
        Property::ListUInt(v) => Some(widen(v)),
        Property::ListShort(v) => Some(widen(v)),
        Property::ListUShort(v) => Some(widen(v)),
        Property::ListUChar(v) => Some(widen(v)),
        _ => None,
    }
}

/// Newell's teapot: 32 bicubic Bézier patches in the `.bpt` format (a line with the patch
/// count, then per patch a line `3 3` and 16 control points `x y z`, z up), tessellated
/// `n`×`n` quads per patch — 32·n·n·2 triangles, 6400 for the thesis' n = 10 (ch. 5.1).
/// The result is y-up.
pub fn teapot(path: &Path, n: u32) -> Result<Mesh, SceneError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::at(path, None, format!("cannot read teapot patches: {e}")))?;
    let patches = parse_bpt(path, &text)?;
    let mut mesh = Mesh::default();
    let y_up = |p: Vec3| Vec3::new(p.x, p.z, -p.y);
    let nf = n as f32;
    for cp in &patches {
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
    Ok(mesh)
}

fn parse_bpt(path: &Path, text: &str) -> Result<Vec<[Vec3; 16]>, SceneError> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let err = |line: usize, msg: String| SceneError::at(path, Some(line + 1), msg);
    let (l0, first) = lines
        .next()
        .ok_or_else(|| SceneError::at(path, None, "empty patch file".into()))?;
    let count: usize = first.trim().parse().map_err(|_| {
        err(
            l0,
            format!("expected the patch count, found `{}`", first.trim()),
        )
    })?;
    let mut patches = Vec::with_capacity(count);
    for _ in 0..count {
        let (ln, deg) = lines.next().ok_or_else(|| {
            SceneError::at(
                path,
                None,
                format!("file ends before patch {} of {count}", patches.len() + 1),
            )
        })?;
        if deg.split_whitespace().collect::<Vec<_>>() != ["3", "3"] {
            return Err(err(
                ln,
                format!("expected `3 3` (bicubic patch), found `{}`", deg.trim()),
            ));
        }
        let mut cp = [Vec3::ZERO; 16];
        for p in cp.iter_mut() {
            let (ln, l) = lines
                .next()
                .ok_or_else(|| SceneError::at(path, None, "file ends inside a patch".into()))?;
            let v: Vec<f32> = l
                .split_whitespace()
                .filter_map(|s| s.parse().ok())
                .collect();
            if v.len() != 3 || l.split_whitespace().count() != 3 {
                return Err(err(
                    ln,
                    format!("expected a control point `x y z`, found `{}`", l.trim()),
                ));
            }
            *p = Vec3::new(v[0], v[1], v[2]);
        }
        patches.push(cp);
    }
    Ok(patches)
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

    fn teapot_path() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/teapot.bpt")
    }

    #[test]
    fn teapot_has_the_thesis_triangle_count() {
        let m = teapot(&teapot_path(), 10).unwrap();
        assert_eq!(m.triangle_count(), 6400);
        assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3));
    }

    #[test]
    fn floor_has_the_thesis_triangle_count() {
        assert_eq!(floor(4.0, 64, [Vec3::ONE; 2]).triangle_count(), 8192);
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
