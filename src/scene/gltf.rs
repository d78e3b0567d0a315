//! glTF 2.0 scenes and models (Khronos, glTF 2.0 specification): `gltf-rs` parses the JSON or
//! GLB; the buffers are read here, each file through the bounded reader ([`super::file`]) and
//! each data URI decoded, and every accessor's extent is checked against its buffer view and
//! buffer before a value is read, so a malformed file is an error naming it, never a panic.
//!
//! What is taken, and how (`docs/scenes.md`, "glTF"):
//! - the default scene (else the first), its node hierarchy's transforms (matrix or TRS) applied
//!   to the meshes: one triangle soup in the glTF's world space, a mirroring transform's
//!   triangles turned back to counter-clockwise;
//! - every primitive of mode TRIANGLES, indexed or not (other modes are refused, named);
//!   normals from the file or flat; `TEXCOORD_0` with v flipped (glTF's v runs down);
//! - materials: `baseColorFactor` as the colour, `baseColorTexture` (an external image) as the
//!   texture, whose texels are the colour where it is given, as for OBJ's `map_Kd`; metallic
//!   and roughness mapped to the thesis' terms by [`material_terms`];
//! - the first perspective camera (`yfov`; the aspect follows the image);
//! - `KHR_lights_punctual`: point and spot lights as point lights at their position (a spot's
//!   cone is not modelled), a directional light as a point light far along its reverse
//!   direction; the colour is the light's, its intensity is not used (the thesis' lights have
//!   no falloff).

use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Vec2, Vec3};

use super::camera::Camera;
use super::mesh::Mesh;
use super::model::{Light, SceneError};
use super::{budget, file};

/// A glTF file's default scene, flattened.
pub struct LoadedGltf {
    /// Every triangle in the glTF's world space; `triangle_material` indexes `materials`.
    pub mesh: Mesh,
    pub materials: Vec<GltfMaterial>,
    pub camera: Option<Camera>,
    pub lights: Vec<Light>,
}

/// A glTF material in the thesis' terms.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfMaterial {
    pub color: Vec3,
    /// The base colour texture's image file.
    pub texture: Option<PathBuf>,
    pub reflection: f32,
    pub specular: f32,
    pub shininess: f32,
}

/// The thesis' reflection, specular weight and Phong exponent for glTF's metallic-roughness
/// model: a polished metal mirrors (reflection = metallic · (1 − roughness)), a smooth surface
/// has a sharp, strong highlight (specular = 1 − roughness, and the exponent 2/α² − 2 of the
/// Blinn-Phong lobe that matches a Beckmann lobe of width α = roughness², within 1…1000).
pub fn material_terms(metallic: f32, roughness: f32) -> (f32, f32, f32) {
    let (m, r) = (metallic.clamp(0.0, 1.0), roughness.clamp(0.0, 1.0));
    let alpha = (r * r).max(0.03);
    let shininess = (2.0 / (alpha * alpha) - 2.0).clamp(1.0, 1000.0);
    (m * (1.0 - r), 1.0 - r, shininess)
}

/// Is `path` a glTF file by its extension (`.gltf`, `.glb`)?
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

fn err(path: &Path, m: impl Into<String>) -> SceneError {
    SceneError::at(path, None, m.into())
}

/// The file parsed (JSON or GLB) and validated by gltf-rs.
fn parse(path: &Path) -> Result<gltf::Gltf, SceneError> {
    let bytes = file::read(path).map_err(|e| err(path, format!("cannot read glTF file: {e}")))?;
    gltf::Gltf::from_slice(&bytes).map_err(|e| err(path, format!("malformed glTF: {e}")))
}

/// The scene a viewer shows: the default one, else the first.
fn main_scene<'a>(path: &Path, doc: &'a gltf::Document) -> Result<gltf::Scene<'a>, SceneError> {
    doc.default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| err(path, "the glTF file has no scene"))
}

/// Every node of `scene` with its world matrix, parents before children.
fn world_nodes<'a>(scene: &gltf::Scene<'a>) -> Vec<(gltf::Node<'a>, Mat4)> {
    let mut out = Vec::new();
    let mut stack: Vec<(gltf::Node<'a>, Mat4)> =
        scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    // a node may appear under one parent only and the hierarchy is a forest (the
    // specification; gltf-rs does not check it): each node is taken once, so a cycle or a
    // shared child cannot run forever or multiply the work
    let mut seen = std::collections::HashSet::new();
    while let Some((node, parent)) = stack.pop() {
        if !seen.insert(node.index()) {
            continue;
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        let children: Vec<_> = node.children().map(|c| (c, world)).collect();
        stack.extend(children.into_iter().rev());
        out.push((node, world));
    }
    out
}

/// The triangles a primitive gives: its index count, else its vertex count, over 3.
fn primitive_triangles(
    path: &Path,
    mesh: &gltf::Mesh,
    p: &gltf::Primitive,
) -> Result<u64, SceneError> {
    let name = mesh_name(mesh);
    if p.mode() != gltf::mesh::Mode::Triangles {
        return Err(err(
            path,
            format!(
                "{name}, primitive {}: mode {:?}; only TRIANGLES (4) is rendered",
                p.index(),
                p.mode()
            ),
        ));
    }
    let count = match (p.indices(), p.get(&gltf::Semantic::Positions)) {
        (Some(i), _) => i.count(),
        (None, Some(pos)) => pos.count(),
        (None, None) => {
            return Err(err(
                path,
                format!("{name}, primitive {}: no POSITION", p.index()),
            ))
        }
    };
    if count % 3 != 0 {
        return Err(err(
            path,
            format!(
                "{name}, primitive {}: {count} vertices are no whole triangles",
                p.index()
            ),
        ));
    }
    Ok(count as u64 / 3)
}

fn mesh_name(mesh: &gltf::Mesh) -> String {
    match mesh.name() {
        Some(n) => format!("mesh {} ({n:?})", mesh.index()),
        None => format!("mesh {}", mesh.index()),
    }
}

/// The triangles of the file's scene, from its JSON alone (nothing else is read).
pub fn count_triangles(path: &Path) -> Result<u64, SceneError> {
    let doc = parse(path)?.document;
    let scene = main_scene(path, &doc)?;
    nodes_triangles(path, &world_nodes(&scene))
}

/// The triangles the meshes of `nodes` give (each primitive checked by
/// [`primitive_triangles`]).
fn nodes_triangles(path: &Path, nodes: &[(gltf::Node, Mat4)]) -> Result<u64, SceneError> {
    let mut total = 0u64;
    for (node, _) in nodes {
        if let Some(mesh) = node.mesh() {
            for p in mesh.primitives() {
                total = total.saturating_add(primitive_triangles(path, &mesh, &p)?);
            }
        }
    }
    Ok(total)
}

/// The external files the glTF file reads besides its images: its `.bin` buffers.
pub fn buffer_files(path: &Path) -> Vec<PathBuf> {
    if !is_gltf(path) {
        return Vec::new();
    }
    let Ok(g) = parse(path) else {
        return Vec::new();
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    g.document
        .buffers()
        .filter_map(|b| match b.source() {
            gltf::buffer::Source::Uri(u) if !u.starts_with("data:") => {
                percent_decoded(u).map(|u| dir.join(u))
            }
            _ => None,
        })
        .collect()
}

/// A relative URI's path with its %XX escapes decoded; `None` for an absolute URI (a scheme or
/// a leading `/`: a file may only name files beside it).
fn percent_decoded(uri: &str) -> Option<String> {
    let scheme = uri.split_once(':').is_some_and(|(s, _)| {
        !s.is_empty()
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    if scheme || uri.starts_with('/') {
        return None;
    }
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |k: usize| b.get(k).and_then(|c| (*c as char).to_digit(16));
        match (b[i], hex(i + 1), hex(i + 2)) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8(out).ok()
}

/// The bytes of every buffer, in index order: the GLB's binary chunk, a data URI decoded, or an
/// external file read whole; each at least as long as its declared `byteLength`.
fn buffers(path: &Path, g: &gltf::Gltf) -> Result<Vec<Vec<u8>>, SceneError> {
    use base64::Engine as _;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for b in g.document.buffers() {
        let what = format!("buffer {}", b.index());
        let data = match b.source() {
            gltf::buffer::Source::Bin => g.blob.clone().ok_or_else(|| {
                err(
                    path,
                    format!("{what} is the GLB's binary chunk, which it lacks"),
                )
            })?,
            gltf::buffer::Source::Uri(u) if u.starts_with("data:") => {
                let (_, payload) = u
                    .split_once(";base64,")
                    .ok_or_else(|| err(path, format!("{what}: a data URI that is not base64")))?;
                base64::engine::general_purpose::STANDARD
                    .decode(payload)
                    .map_err(|e| err(path, format!("{what}: its data URI does not decode: {e}")))?
            }
            gltf::buffer::Source::Uri(u) => {
                let rel = percent_decoded(u).ok_or_else(|| {
                    err(
                        path,
                        format!("{what}: {u:?} is not a relative path to a file beside it"),
                    )
                })?;
                let file_path = dir.join(rel);
                file::read(&file_path).map_err(|e| {
                    err(
                        path,
                        format!("{what}: cannot read {}: {e}", file_path.display()),
                    )
                })?
            }
        };
        if (data.len() as u64) < b.length() as u64 {
            return Err(err(
                path,
                format!(
                    "{what} holds {} bytes, less than its byteLength {}",
                    data.len(),
                    b.length()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// The accessor's bytes lie inside its buffer view and the view inside its buffer (gltf-rs
/// reads what is there and stops early otherwise: a short file would lose triangles silently).
fn check_accessor(path: &Path, a: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<(), SceneError> {
    let what = format!("accessor {}", a.index());
    if a.sparse().is_some() {
        return Err(err(
            path,
            format!("{what} is sparse, which is not supported"),
        ));
    }
    let view = a
        .view()
        .ok_or_else(|| err(path, format!("{what} has no buffer view")))?;
    let size = a.size() as u64;
    let stride = view.stride().map_or(size, |s| s as u64);
    let count = a.count() as u64;
    if count == 0 {
        return Err(err(path, format!("{what} has no elements")));
    }
    let need = (a.offset() as u64)
        .saturating_add(stride.saturating_mul(count - 1))
        .saturating_add(size);
    if need > view.length() as u64 {
        return Err(err(
            path,
            format!(
                "{what}: {count} elements of {size} bytes every {stride} need {need} bytes, more \
                 than its buffer view's {}",
                view.length()
            ),
        ));
    }
    let end = (view.offset() as u64).saturating_add(view.length() as u64);
    let have = buffers
        .get(view.buffer().index())
        .map_or(0, |b| b.len() as u64);
    if end > have {
        return Err(err(
            path,
            format!(
                "buffer view {} ends at byte {end}, past its buffer's {have}",
                view.index()
            ),
        ));
    }
    Ok(())
}

/// Load the glTF file's scene: its triangles are counted from the JSON and checked against
/// [`super::model::MAX_SCENE_TRIANGLES`] and the host's memory before any buffer is read.
pub fn load(path: &Path) -> Result<LoadedGltf, SceneError> {
    let g = parse(path)?;
    let doc = &g.document;
    let scene = main_scene(path, doc)?;
    let nodes = world_nodes(&scene);
    let triangles = nodes_triangles(path, &nodes)?;
    if triangles > super::model::MAX_SCENE_TRIANGLES {
        let most = super::model::MAX_SCENE_TRIANGLES;
        let m = format!("{triangles} triangles, more than the {most} a scene may have");
        return Err(err(path, m));
    }
    budget::check_triangles("the glTF file's scene", triangles).map_err(|m| err(path, m))?;
    let buffers = buffers(path, &g)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut out = LoadedGltf {
        mesh: Mesh::default(),
        materials: Vec::new(),
        camera: None,
        lights: Vec::new(),
    };
    let mut material_ids: Vec<(Option<usize>, u32)> = Vec::new();
    for (node, world) in &nodes {
        let Some(mesh) = node.mesh() else { continue };
        for p in mesh.primitives() {
            primitive_triangles(path, &mesh, &p)?;
            let key = p.material().index();
            let id = match material_ids.iter().find(|(k, _)| *k == key) {
                Some((_, id)) => *id,
                None => {
                    out.materials.push(material(path, dir, &p.material())?);
                    let id = out.materials.len() as u32 - 1;
                    material_ids.push((key, id));
                    id
                }
            };
            let color = out.materials[id as usize].color;
            append_primitive(path, &mut out.mesh, &p, *world, &buffers, color, id)?;
        }
    }
    if out.mesh.triangle_count() == 0 {
        return Err(err(path, "the glTF file's scene has no triangles"));
    }
    out.camera = camera(path, &nodes)?;
    out.lights = lights(&nodes, &out.mesh);
    Ok(out)
}

/// The primitive's triangles, in world space, appended to `mesh` with material `id`.
fn append_primitive(
    path: &Path,
    mesh: &mut Mesh,
    p: &gltf::Primitive,
    world: Mat4,
    buffers: &[Vec<u8>],
    color: Vec3,
    id: u32,
) -> Result<(), SceneError> {
    use gltf::accessor::{DataType, Dimensions};
    let what = |s: &str| format!("primitive {} of a mesh: {s}", p.index());
    let check_type = |sem: gltf::Semantic, dims: Dimensions, float_only: bool| {
        let Some(a) = p.get(&sem) else {
            return Ok(false);
        };
        check_accessor(path, &a, buffers)?;
        let ok = a.dimensions() == dims && (!float_only || a.data_type() == DataType::F32);
        match ok {
            true => Ok(true),
            false => Err(err(
                path,
                what(&format!(
                    "{sem:?} is {:?} {:?}",
                    a.dimensions(),
                    a.data_type()
                )),
            )),
        }
    };
    check_type(gltf::Semantic::Positions, Dimensions::Vec3, true)?;
    let has_normals = check_type(gltf::Semantic::Normals, Dimensions::Vec3, true)?;
    let has_uv = check_type(gltf::Semantic::TexCoords(0), Dimensions::Vec2, false)?;
    if let Some(i) = p.indices() {
        check_accessor(path, &i, buffers)?;
    }
    let reader = p.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
    let positions: Vec<Vec3> = reader
        .read_positions()
        .ok_or_else(|| err(path, what("no POSITION")))?
        .map(Vec3::from)
        .collect();
    let normals: Option<Vec<Vec3>> = has_normals
        .then(|| reader.read_normals().map(|n| n.map(Vec3::from).collect()))
        .flatten();
    let uvs: Option<Vec<Vec2>> = has_uv
        .then(|| {
            reader
                .read_tex_coords(0)
                .map(|t| t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect())
        })
        .flatten();
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(err(
            path,
            what(&format!(
                "index {bad} past its {} vertices",
                positions.len()
            )),
        ));
    }
    let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
    let mirrored = Mat3::from_mat4(world).determinant() < 0.0;
    for t in indices.chunks_exact(3) {
        let mut t = [t[0], t[1], t[2]].map(|i| i as usize);
        if mirrored {
            t.swap(1, 2);
        }
        let pos = t.map(|i| world.transform_point3(positions[i]));
        let flat = (pos[1] - pos[0]).cross(pos[2] - pos[0]).normalize_or_zero();
        let n = match &normals {
            Some(n) => t.map(|i| (normal_matrix * n[i]).normalize_or(flat)),
            None => [flat; 3],
        };
        let uv = match &uvs {
            Some(u) => t.map(|i| u[i]),
            None => [Vec2::ZERO; 3],
        };
        if pos.iter().any(|p| !p.is_finite()) || uv.iter().any(|u| !u.is_finite()) {
            return Err(err(path, what("a vertex that is not finite")));
        }
        mesh.push_triangle(pos, n, [color; 3], uv, id);
    }
    Ok(())
}

/// A glTF material (the default material where a primitive has none).
fn material(path: &Path, dir: &Path, m: &gltf::Material) -> Result<GltfMaterial, SceneError> {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let texture = match pbr.base_color_texture() {
        None => None,
        Some(info) => match info.texture().source().source() {
            gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
                let rel = percent_decoded(uri).ok_or_else(|| {
                    err(
                        path,
                        format!("image {uri:?} is not a relative path to a file beside it"),
                    )
                })?;
                Some(dir.join(rel))
            }
            _ => {
                return Err(err(
                    path,
                    format!(
                        "material {}: its base colour image is embedded in the file; export the \
                         images as separate files (Blender: glTF Separate)",
                        m.index().map_or("default".to_string(), |i| i.to_string())
                    ),
                ))
            }
        },
    };
    let (reflection, specular, shininess) =
        material_terms(pbr.metallic_factor(), pbr.roughness_factor());
    Ok(GltfMaterial {
        color: Vec3::new(r, g, b),
        texture,
        reflection,
        specular,
        shininess,
    })
}

/// The first perspective camera of the scene's nodes, looking down its node's −z with +y up.
fn camera(path: &Path, nodes: &[(gltf::Node, Mat4)]) -> Result<Option<Camera>, SceneError> {
    let Some((node, world, cam)) = nodes
        .iter()
        .find_map(|(n, w)| n.camera().map(|c| (n, *w, c)))
    else {
        return Ok(None);
    };
    let gltf::camera::Projection::Perspective(p) = cam.projection() else {
        return Err(err(
            path,
            format!(
                "node {}: an orthographic camera; only perspective ones are rendered",
                node.index()
            ),
        ));
    };
    let eye = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
    let fov = p.yfov().to_degrees();
    if forward == Vec3::ZERO
        || up == Vec3::ZERO
        || !(eye.is_finite() && (1.0..179.0).contains(&fov))
    {
        return Err(err(
            path,
            format!("node {}: a camera that cannot be used", node.index()),
        ));
    }
    let near = super::camera::default_near_for(Some(p.znear()));
    Ok(Some(Camera {
        position: eye.to_array(),
        look_at: (eye + forward).to_array(),
        up: up.to_array(),
        fov_y: fov,
        near,
    }))
}

/// The scene's punctual lights as point lights (module documentation).
fn lights(nodes: &[(gltf::Node, Mat4)], mesh: &Mesh) -> Vec<Light> {
    let (lo, hi) = mesh.bounds();
    let far = 100.0 * (hi - lo).length().max(1e-3);
    nodes
        .iter()
        .filter_map(|(n, w)| n.light().map(|l| (l, *w)))
        .map(|(l, w)| {
            let at = w.transform_point3(Vec3::ZERO);
            let position = match l.kind() {
                gltf::khr_lights_punctual::Kind::Directional => {
                    let dir = w.transform_vector3(Vec3::NEG_Z).normalize_or(Vec3::NEG_Y);
                    0.5 * (lo + hi) - far * dir
                }
                _ => at,
            };
            Light {
                position,
                color: Vec3::from(l.color()),
            }
        })
        .collect()
}

/// A camera that frames `mesh` when the file has none: from the front (+z) and a little above,
/// at the distance where its bounding sphere fills the 45° field of view.
pub fn framing_camera(mesh: &Mesh) -> Camera {
    let (lo, hi) = mesh.bounds();
    let center = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    let fov = 45.0f32;
    let distance = radius / (fov.to_radians() / 2.0).sin();
    let dir = Vec3::new(0.0, 0.35, 1.0).normalize();
    let eye = center + distance * dir;
    Camera {
        position: eye.to_array(),
        look_at: center.to_array(),
        up: [0.0, 1.0, 0.0],
        fov_y: fov,
        near: super::camera::default_near_for(Some(distance * 1e-3)),
    }
}

/// A light for a file that has none: above and behind the camera, white.
pub fn default_light(camera: &Camera, mesh: &Mesh) -> Light {
    let (lo, hi) = mesh.bounds();
    let up = (hi - lo).length().max(1e-3);
    Light {
        position: Vec3::from(camera.position) + Vec3::new(0.0, up, 0.0),
        color: Vec3::ONE,
    }
}
