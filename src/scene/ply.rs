//! PLY files (ASCII or binary; gzip-compressed when the name ends in `.gz`) through
//! `ply-rs-bw`. The file is read whole first (a compressed one at most as far as the host's
//! memory allows) and the header's element counts are checked against the length of the data
//! and the host's memory before the parser allocates anything for them.

use std::io::Read;
use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Ply, Property};

use super::budget;
use super::mesh::Mesh;
use super::mesh::{corner_normals, smooth_normals};
use super::model::SceneError;

/// Host bytes of one parsed element (ply-rs keeps a map of named properties per element):
/// this much per element plus [`ELEMENT_PROPERTY_BYTES`] per property.
const ELEMENT_BYTES: u64 = 64;
const ELEMENT_PROPERTY_BYTES: u64 = 96;

/// Load a PLY file with `vertex` x/y/z and `face` vertex_indices (polygons are fanned into
/// triangles). Vertex normals are the area-weighted face normals.
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
    let what = format!("{} faces", faces.len());
    budget::check_triangles(&what, tris.len() as u64).map_err(|m| SceneError::at(path, None, m))?;
    let normals = smooth_normals(&pos, &tris);
    let mut mesh = Mesh::default();
    for t in tris {
        let p = t.map(|k| pos[k]);
        let n = corner_normals(p, t, &normals);
        mesh.push_triangle(p, n, [Vec3::splat(0.8); 3], [Vec2::ZERO; 3], 0);
    }
    Ok(mesh)
}

/// The faces the PLY header claims (each at least one triangle), read from the header only: a
/// scene's total is checked before any model is built.
pub fn count_faces(path: &Path) -> Result<u64, SceneError> {
    let bytes = read_ply_bytes(path)?;
    let faces = header_elements(&bytes)
        .and_then(|(_, elements, _)| elements.into_iter().find(|e| e.name == "face"));
    Ok(faces.map_or(0, |e| e.count))
}

fn read_ply(path: &Path) -> Result<Ply<DefaultElement>, SceneError> {
    let bytes = read_ply_bytes(path)?;
    check_header(&bytes).map_err(|m| SceneError::at(path, None, m))?;
    Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::Cursor::new(&bytes))
        .map_err(|e| SceneError::at(path, None, format!("malformed PLY file: {e}")))
}

/// The file's bytes, decompressed when it ends in `.gz`; each within the host's memory
/// ([`budget::check_file`]: the compressed length first, then the decompressed bytes as
/// they come).
fn read_ply_bytes(path: &Path) -> Result<Vec<u8>, SceneError> {
    let err = |m: String| SceneError::at(path, None, m);
    let gz = path.extension().is_some_and(|e| e == "gz");
    if !gz {
        return super::file::read(path).map_err(|e| err(format!("cannot read PLY file: {e}")));
    }
    let (file, len) =
        super::file::open_regular(path).map_err(|e| err(format!("cannot open PLY file: {e}")))?;
    budget::check_file(len).map_err(err)?;
    let cap = budget::host_limit().map_or(u64::MAX, |(b, _)| b / budget::FILE_FACTOR);
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(std::io::BufReader::new(file))
        .take(cap.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| err(format!("cannot decompress PLY file: {e}")))?;
    if bytes.len() as u64 > cap {
        budget::check_file(bytes.len() as u64).map_err(|m| err(format!("decompressed, {m}")))?;
    }
    Ok(bytes)
}

/// An element of the header: its name, count and the smallest size of one in the data.
struct ElementDef {
    name: String,
    count: u64,
    min_bytes: u64,
    properties: u64,
}

/// The header's elements, when it parses (otherwise the parser reports the error).
fn header_elements(bytes: &[u8]) -> Option<(bool, Vec<ElementDef>, usize)> {
    let end = bytes.windows(10).position(|w| w == b"end_header")?;
    let data = end + bytes[end..].iter().position(|&b| b == b'\n')? + 1;
    let text = std::str::from_utf8(&bytes[..end]).ok()?;
    let mut ascii = false;
    let mut elements: Vec<ElementDef> = Vec::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["format", f, ..] => ascii = *f == "ascii",
            ["element", name, count] => elements.push(ElementDef {
                name: name.to_string(),
                count: count.parse().ok()?,
                min_bytes: 0,
                properties: 0,
            }),
            ["property", "list", count_type, _, _] => {
                let e = elements.last_mut()?;
                e.min_bytes += if ascii { 2 } else { scalar_bytes(count_type) };
                e.properties += 1;
            }
            ["property", ty, _] => {
                let e = elements.last_mut()?;
                e.min_bytes += if ascii { 2 } else { scalar_bytes(ty) };
                e.properties += 1;
            }
            _ => {}
        }
    }
    Some((ascii, elements, data))
}

/// Bytes of a PLY scalar type in binary data (1 for a type the parser will refuse).
fn scalar_bytes(ty: &str) -> u64 {
    match ty {
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        _ => 1,
    }
}

/// The header's counts must fit the data that follows it (every element at least its
/// smallest size) and the host's memory once parsed.
fn check_header(bytes: &[u8]) -> Result<(), String> {
    let Some((ascii, elements, data)) = header_elements(bytes) else {
        return Ok(());
    };
    let have = (bytes.len() - data) as u64;
    let mut need = 0u64;
    let mut parsed = 0u64;
    for e in &elements {
        let this = e.count.saturating_mul(e.min_bytes);
        need = need.saturating_add(this);
        if need > have {
            let form = if ascii { "ASCII" } else { "binary" };
            return Err(format!(
                "the header claims {} elements `{}`, which need at least {} bytes of {form} \
                 data ({} each), but the file has {have} bytes after the header",
                e.count, e.name, this, e.min_bytes
            ));
        }
        let each = ELEMENT_BYTES + ELEMENT_PROPERTY_BYTES * e.properties;
        parsed = parsed.saturating_add(e.count.saturating_mul(each));
    }
    budget::check_host("parsing this PLY file", parsed)
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
