//! OBJ files through tobj, with their MTL materials. Before tobj reads the text, every line is
//! checked for what it would silently turn into something else: a face of fewer than 3 corners
//! (tobj makes it a degenerate triangle), `l` and `p` lines (not surfaces: dropped with a
//! warning; a file of nothing else is an error). The MTL files an OBJ file names must exist
//! (a missing one is an error naming it and the `mtllib` line: its colours and textures would
//! be lost silently) and parse, with finite numbers (file and line).

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::bpt::read_model_text;
use super::budget;
use super::mesh::Mesh;
use super::mesh::{corner_normals, smooth_normals};
use super::model::SceneError;

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
/// The triangles the OBJ file's faces give (a face of n corners: n − 2), counted from its `f`
/// lines without parsing the rest: a scene's total is checked before any model is built.
pub fn count_triangles(path: &Path) -> Result<u64, SceneError> {
    let text = read_model_text(path, "OBJ file")?;
    let corners = |l: &str| l.split_whitespace().count().saturating_sub(1) as u64;
    Ok(text
        .lines()
        .filter(|l| l.starts_with("f ") || l.starts_with("f\t"))
        .map(|l| corners(l).saturating_sub(2))
        .sum())
}

pub fn load_obj(path: &Path) -> Result<LoadedObj, SceneError> {
    let text = read_model_text(path, "OBJ file")?;
    let faces_only = check_elements(path, &text)?;
    let (models, mtl) = read_obj(path, &faces_only)?;
    let materials = obj_materials(path, mtl)?;
    check_usemtl(path, &faces_only, &materials)?;
    let triangles: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    budget::check_triangles("the OBJ file's faces", triangles as u64)
        .map_err(|m| SceneError::at(path, None, m))?;
    let mut mesh = Mesh::default();
    let mut has_vertex_colors = false;
    for model in &models {
        has_vertex_colors |= append_obj_model(&mut mesh, &model.mesh, &materials);
    }
    check_obj_finite(path, &text, &mesh)?;
    Ok(LoadedObj {
        mesh,
        materials,
        has_vertex_colors,
    })
}

/// The text with its `l` and `p` lines blanked (line numbers kept); an error for a face of
/// fewer than 3 corners and for a file without faces.
fn check_elements(path: &Path, text: &str) -> Result<String, SceneError> {
    let mut out = String::with_capacity(text.len());
    let (mut faces, mut dropped) = (0usize, Vec::new());
    for (i, line) in text.split_inclusive('\n').enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("f") => {
                let corners = words.count();
                if corners < 3 {
                    let m = format!(
                        "a face needs at least 3 vertices, this has {corners}: `{}`",
                        line.trim()
                    );
                    return Err(SceneError::at(path, Some(i + 1), m));
                }
                faces += 1;
            }
            Some(tag @ ("l" | "p")) => {
                dropped.push((i + 1, tag));
                out.push('\n');
                continue;
            }
            _ => {}
        }
        out.push_str(line);
    }
    if faces == 0 {
        let what = match dropped.first() {
            Some((l, tag)) => format!(
                " (only lines and points, `{tag}` on line {l}: they have no surface to render)"
            ),
            None => String::new(),
        };
        return Err(SceneError::at(
            path,
            None,
            format!("the OBJ file has no faces{what}"),
        ));
    }
    if let Some((l, tag)) = dropped.first() {
        log::warn!(
            "{}:{l}: `{tag}` and {} more `l`/`p` lines dropped: lines and points have no \
             surface to render",
            path.display(),
            dropped.len() - 1
        );
    }
    Ok(out)
}

/// The models and the MTL materials as tobj reads them from `text`; its errors name the file
/// and, where [`locate_obj_error`] finds it, the line. An MTL file's error is the second part.
fn read_obj(path: &Path, text: &str) -> Result<(Vec<tobj::Model>, ObjMtl), SceneError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let mtl_error = RefCell::new(None);
    let loader = |name: &Path| {
        load_mtl(path, text, name).unwrap_or_else(|e| {
            mtl_error.borrow_mut().get_or_insert(e);
            Err(tobj::LoadError::MaterialParseError)
        })
    };
    let (models, mtl) = tobj::load_obj_buf(&mut text.as_bytes(), &opts, loader).map_err(|e| {
        let (line, what) = locate_obj_error(text);
        SceneError::at(path, line, format!("malformed OBJ file ({e}){what}"))
    })?;
    match mtl_error.into_inner() {
        Some(e) => Ok((models, Err(e))),
        None => Ok((
            models,
            mtl.map_err(|e| SceneError::at(path, None, format!("cannot load its MTL file: {e}"))),
        )),
    }
}

/// The materials of the MTL file `name` (relative to the OBJ file's folder) that `obj` names;
/// an error names the MTL file and line, or the OBJ file's `mtllib` line when it is missing.
fn load_mtl(obj: &Path, obj_text: &str, name: &Path) -> Result<tobj::MTLLoadResult, SceneError> {
    let file = obj.parent().unwrap_or(Path::new(".")).join(name);
    let text = read_model_text(&file, "MTL file").map_err(|e| {
        let line = obj_text.lines().position(|l| {
            l.trim_start().starts_with("mtllib") && l.contains(&*name.to_string_lossy())
        });
        SceneError::at(
            obj,
            line.map(|l| l + 1),
            format!("its MTL file {}: {}", file.display(), e.message),
        )
    })?;
    check_mtl(&file, &text)?;
    match tobj::load_mtl_buf(&mut text.as_bytes()) {
        Ok(m) => Ok(Ok(m)),
        Err(e) => Err(SceneError::at(
            &file,
            None,
            format!("malformed MTL file: {e}"),
        )),
    }
}

/// Every number of an MTL line tobj reads (colours, exponents, opacity) must parse and be
/// finite: the first line where one does not is the error.
fn check_mtl(file: &Path, text: &str) -> Result<(), SceneError> {
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else { continue };
        let min = match key {
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => 3,
            "Ns" | "Ni" | "d" | "Tr" | "illum" => 1,
            "newmtl" if words.clone().next().is_none() => {
                return Err(SceneError::at(
                    file,
                    Some(i + 1),
                    "`newmtl` without a name".into(),
                ));
            }
            _ => continue,
        };
        let nums: Vec<&str> = words.collect();
        let ok = nums.len() >= min
            && nums
                .iter()
                .all(|s| s.parse::<f32>().is_ok_and(f32::is_finite));
        if !ok {
            let m = format!("`{key}` needs {min} finite number(s): `{}`", line.trim());
            return Err(SceneError::at(file, Some(i + 1), m));
        }
    }
    Ok(())
}

/// tobj's result for the MTL file an OBJ file names, or our error for it.
type ObjMtl = Result<Vec<tobj::Material>, SceneError>;

/// Every `usemtl NAME` of the OBJ text names a material of its MTL files: tobj gives the faces
/// of an unknown name no material, which would lose its colour and texture without a word. An
/// error names the OBJ file, the `usemtl` line and the name.
fn check_usemtl(path: &Path, text: &str, materials: &[ObjMaterial]) -> Result<(), SceneError> {
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("usemtl") {
            continue;
        }
        let name = words.collect::<Vec<_>>().join(" ");
        if !materials.iter().any(|m| m.name == name) {
            let known = materials
                .iter()
                .map(|m| m.name.as_str())
                .collect::<Vec<_>>();
            return Err(SceneError::at(
                path,
                Some(k + 1),
                format!(
                    "usemtl {name}: no material of that name in its MTL files (they define: {})",
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            ));
        }
    }
    Ok(())
}

/// The MTL materials, texture paths relative to the OBJ file; an error when an MTL file is
/// missing or malformed.
fn obj_materials(path: &Path, mtl: ObjMtl) -> Result<Vec<ObjMaterial>, SceneError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    Ok(mtl?
        .into_iter()
        .map(|m| ObjMaterial {
            name: m.name.clone(),
            diffuse: m.diffuse.map(Vec3::from),
            texture: m.diffuse_texture.as_ref().map(|t| dir.join(t)),
            shininess: m.shininess,
        })
        .collect())
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

/// tobj reads `nan` and `inf`; a vertex with one is an error naming its line.
fn check_obj_finite(path: &Path, text: &str, mesh: &Mesh) -> Result<(), SceneError> {
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    if finite(bytemuck::cast_slice(&mesh.positions))
        && finite(bytemuck::cast_slice(&mesh.normals))
        && finite(bytemuck::cast_slice(&mesh.colors))
        && finite(bytemuck::cast_slice(&mesh.texcoords))
    {
        return Ok(());
    }
    let (line, what) = locate_obj_error(text);
    Err(SceneError::at(
        path,
        line,
        format!("a vertex has a non-finite number (nan or inf){what}"),
    ))
}

/// Find the first line tobj could not have parsed: numbers of `v`/`vn`/`vt` lines and the
/// indices of `f` lines (tobj's errors do not carry a line number).
fn locate_obj_error(text: &str) -> (Option<usize>, String) {
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
