//! Scenes: a TOML scene file with a camera, background and ambient colour, point lights and
//! objects (OBJ files, or the procedural `teapot` and `floor`), each with a transform and a
//! material. See `scenes/*.toml` and the README for the format.

pub mod camera;
pub mod mesh;
pub mod shadows;

use std::fmt;
use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Quat, Vec2, Vec3};
use serde::Deserialize;
use toml::Spanned;

pub use shadows::{parse_samples, ShadowMode};

pub use camera::{Camera, CameraRays};
pub use mesh::Mesh;

/// A scene error that names the file and, where known, the line.
#[derive(Debug, Clone)]
pub struct SceneError {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub message: String,
}

impl SceneError {
    pub fn at(file: &Path, line: Option<usize>, message: String) -> Self {
        SceneError {
            file: file.to_path_buf(),
            line,
            message,
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}", self.file.display(), l, self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for SceneError {}

/// Surface properties of a triangle, as the kernels read them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Reflection coefficient (Listing 14): the share of the reflected ray in the colour.
    pub reflection: f32,
    pub specular: f32,
    pub shininess: f32,
    /// Layer of the texture array, if textured.
    pub texture: Option<u32>,
}

#[derive(Debug, Clone)]
pub struct Light {
    pub position: Vec3,
    pub color: Vec3,
}

/// A rectangular area light (Klee 2016): the points `corner + s·edge_u + t·edge_v`,
/// s, t ∈ [0, 1], emitting `color`.
#[derive(Debug, Clone, Copy)]
pub struct AreaLight {
    pub corner: Vec3,
    pub edge_u: Vec3,
    pub edge_v: Vec3,
    pub color: Vec3,
}

impl AreaLight {
    /// The centre of the rectangle.
    pub fn center(&self) -> Vec3 {
        self.corner + 0.5 * (self.edge_u + self.edge_v)
    }
}

#[derive(Debug, Clone)]
pub struct Object {
    pub name: String,
    /// Object-space triangle soup; `triangle_material` holds scene material ids.
    pub mesh: Mesh,
    pub model: Mat4,
}

impl Object {
    /// The normal matrix: inverse transpose of the model matrix' upper 3×3.
    pub fn normal_matrix(&self) -> Mat3 {
        Mat3::from_mat4(self.model).inverse().transpose()
    }
}

/// Rendering settings a scene file may give; the command line overrides them.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// REFL_DEPTH of Fig. 8: the number of reflection passes after the primary pass.
    pub refl_depth: u32,
    pub background: [f32; 3],
    pub ambient: [f32; 3],
    /// The thesis' 0.02 offset of shadow feelers (Listing 15), in scene units.
    pub shadow_offset: f32,
    /// Soft shadows from the `[[area_light]]` by default (`render --shadows` overrides):
    /// `exact`, `linespace` or `linespace-dda`.
    pub shadows: Option<ShadowMode>,
    /// Light samples `UxV` for the soft shadows (`--light-samples` overrides).
    #[serde(deserialize_with = "light_samples")]
    pub light_samples: Option<(u32, u32)>,
}

fn light_samples<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<(u32, u32)>, D::Error> {
    let s = String::deserialize(d)?;
    parse_samples(&s)
        .map(Some)
        .map_err(serde::de::Error::custom)
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 512,
            height: 512,
            refl_depth: 1,
            background: [0.1, 0.1, 0.15],
            ambient: [0.15, 0.15, 0.15],
            shadow_offset: 0.02,
            shadows: None,
            light_samples: None,
        }
    }
}

/// A loaded scene: everything the tracers and the CPU reference need.
#[derive(Debug, Clone)]
pub struct Scene {
    pub path: PathBuf,
    pub camera: Camera,
    pub settings: RenderSettings,
    pub lights: Vec<Light>,
    /// Rectangular area lights (`[[area_light]]`), used by the soft-shadow pipeline.
    pub area_lights: Vec<AreaLight>,
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    /// Texture images, one layer each; paths for messages.
    pub textures: Vec<(PathBuf, image::RgbaImage)>,
}

impl Scene {
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError::at(path, None, format!("cannot read scene file: {e}")))?;
        Self::parse(path, &text)
    }

    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.mesh.triangle_count()).sum()
    }

    pub fn vertex_count(&self) -> usize {
        3 * self.triangle_count()
    }

    /// World-space triangles in triangle-id order, transformed exactly as the transform pass
    /// does (f32 model matrix times (p, 1)).
    pub fn world_triangles(&self) -> Vec<[Vec3; 3]> {
        let mut out = Vec::with_capacity(self.triangle_count());
        for o in &self.objects {
            for t in o.mesh.positions.chunks_exact(3) {
                out.push([0, 1, 2].map(|k| o.model.transform_point3(t[k])));
            }
        }
        out
    }

    /// World-space per-vertex data (normals, colours, texture coordinates) and per-triangle
    /// material ids, in the order of [`Scene::world_triangles`].
    pub fn world_attributes(&self) -> WorldAttributes {
        let mut a = WorldAttributes::default();
        for o in &self.objects {
            let nm = o.normal_matrix();
            a.normals
                .extend(o.mesh.normals.iter().map(|n| (nm * *n).normalize_or_zero()));
            a.colors.extend_from_slice(&o.mesh.colors);
            a.texcoords.extend_from_slice(&o.mesh.texcoords);
            a.triangle_material
                .extend_from_slice(&o.mesh.triangle_material);
        }
        a
    }

    /// The textures as equally sized layers for a 2D array texture: every image resized
    /// (bilinear) to the largest width and height among them, at most `max_size`, and flipped
    /// so that layer row 0 is the image's bottom row (OBJ texture coordinate v = 0). A scene
    /// without textures gets a single white texel. The CPU reference samples the same layers.
    pub fn texture_layers(&self, max_size: u32) -> (u32, u32, Vec<image::RgbaImage>) {
        if self.textures.is_empty() {
            return (
                1,
                1,
                vec![image::RgbaImage::from_pixel(1, 1, image::Rgba([255; 4]))],
            );
        }
        let w = self
            .textures
            .iter()
            .map(|(_, t)| t.width())
            .max()
            .unwrap_or(1)
            .min(max_size);
        let h = self
            .textures
            .iter()
            .map(|(_, t)| t.height())
            .max()
            .unwrap_or(1)
            .min(max_size);
        let layers = self
            .textures
            .iter()
            .map(|(_, t)| {
                let img = if t.dimensions() == (w, h) {
                    t.clone()
                } else {
                    image::imageops::resize(t, w, h, image::imageops::FilterType::Triangle)
                };
                image::imageops::flip_vertical(&img)
            })
            .collect();
        (w, h, layers)
    }

    /// Bounds of the world-space geometry.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.world_triangles().iter().flatten().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }

    fn parse(path: &Path, text: &str) -> Result<Scene, SceneError> {
        let file: SceneFile = toml::from_str(text).map_err(|e| {
            let line = e.span().map(|s| line_of(text, s.start));
            SceneError::at(path, line, e.message().to_string())
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let at = |span: std::ops::Range<usize>, msg: String| {
            SceneError::at(path, Some(line_of(text, span.start)), msg)
        };
        let cam_span = file.camera.span();
        let camera = file.camera.into_inner();
        camera.validate().map_err(|m| at(cam_span.clone(), m))?;
        let (settings, render_line) = match file.render {
            Some(r) => (*r.get_ref(), Some(line_of(text, r.span().start))),
            None => (RenderSettings::default(), None),
        };
        if settings.width == 0 || settings.height == 0 {
            return Err(SceneError::at(
                path,
                render_line,
                "render.width and render.height must be positive".into(),
            ));
        }
        if !settings
            .background
            .iter()
            .chain(&settings.ambient)
            .all(|v| v.is_finite())
        {
            return Err(SceneError::at(
                path,
                render_line,
                "render.background and render.ambient must be finite".into(),
            ));
        }
        if !settings.shadow_offset.is_finite() || settings.shadow_offset < 0.0 {
            return Err(SceneError::at(
                path,
                render_line,
                "render.shadow_offset must be finite and >= 0".into(),
            ));
        }
        let mut lights = Vec::new();
        for l in file.light {
            let span = l.span();
            let l = l.into_inner();
            if !l.position.iter().chain(&l.color).all(|v| v.is_finite()) {
                return Err(at(span, "light: position and color must be finite".into()));
            }
            lights.push(Light {
                position: Vec3::from(l.position),
                color: Vec3::from(l.color),
            });
        }
        let mut area_lights = Vec::new();
        for l in file.area_light {
            let span = l.span();
            let l = l.into_inner();
            let a = AreaLight {
                corner: Vec3::from(l.corner),
                edge_u: Vec3::from(l.edge_u),
                edge_v: Vec3::from(l.edge_v),
                color: Vec3::from(l.color),
            };
            let finite = [a.corner, a.edge_u, a.edge_v, a.color]
                .iter()
                .all(|v| v.is_finite());
            if !finite || a.edge_u.cross(a.edge_v).length() <= 1e-12 {
                return Err(at(
                    span,
                    "area_light: corner, edge_u, edge_v and color must be finite, and edge_u and \
                     edge_v must span a rectangle (non-zero, not parallel)"
                        .into(),
                ));
            }
            area_lights.push(a);
        }
        if settings.shadows.is_some() && area_lights.is_empty() {
            return Err(SceneError::at(
                path,
                render_line,
                "render.shadows needs an [[area_light]] in the scene".into(),
            ));
        }
        let mut scene = Scene {
            path: path.to_path_buf(),
            camera,
            settings,
            lights,
            area_lights,
            objects: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
        };
        if file.object.is_empty() {
            return Err(SceneError::at(
                path,
                None,
                "the scene has no [[object]]".into(),
            ));
        }
        for (k, def) in file.object.into_iter().enumerate() {
            let span = def.kind.span();
            let object = scene.build_object(dir, k, def).map_err(|e| match e {
                // errors about the object itself point at its `type` line
                ObjectError::Here(m) => at(span.clone(), m),
                ObjectError::File(e) => e,
            })?;
            scene.objects.push(object);
        }
        Ok(scene)
    }

    fn load_texture(&mut self, path: &Path) -> Result<u32, ObjectError> {
        if let Some(i) = self.textures.iter().position(|(p, _)| p == path) {
            return Ok(i as u32);
        }
        let img = image::open(path)
            .map_err(|e| ObjectError::Here(format!("cannot load texture {}: {e}", path.display())))?
            .to_rgba8();
        self.textures.push((path.to_path_buf(), img));
        Ok(self.textures.len() as u32 - 1)
    }

    fn add_material(&mut self, m: Material) -> u32 {
        if let Some(i) = self.materials.iter().position(|x| *x == m) {
            return i as u32;
        }
        self.materials.push(m);
        self.materials.len() as u32 - 1
    }

    fn build_object(
        &mut self,
        dir: &Path,
        index: usize,
        def: ObjectDef,
    ) -> Result<Object, ObjectError> {
        let kind = def.kind.get_ref().as_str();
        let base = Material {
            reflection: def.reflection,
            specular: def.specular,
            shininess: def.shininess,
            texture: None,
        };
        if !(0.0..=1.0).contains(&def.reflection) {
            return Err(ObjectError::Here(format!(
                "reflection = {} must lie in [0, 1]",
                def.reflection
            )));
        }
        let color = def.color.map(Vec3::from);
        let texture = match &def.texture {
            Some(t) => Some(self.load_texture(&dir.join(t.get_ref()))?),
            None => None,
        };
        let need_path = |what: &str| {
            def.path
                .as_ref()
                .map(|p| dir.join(p.get_ref()))
                .ok_or_else(|| {
                    ObjectError::Here(format!(
                        "an object of type \"{kind}\" needs path = \"{what}\""
                    ))
                })
        };
        let mut mesh = match kind {
            "obj" => {
                let path = need_path("model.obj")?;
                let obj = mesh::load_obj(&path).map_err(ObjectError::File)?;
                // one scene material per MTL material, plus one for faces without
                let mut ids = Vec::new();
                for m in &obj.materials {
                    let tex = match (&texture, &m.texture) {
                        (Some(t), _) => Some(*t),
                        (None, Some(p)) => Some(self.load_texture(p)?),
                        (None, None) => None,
                    };
                    ids.push(self.add_material(Material { texture: tex, ..base }));
                }
                ids.push(self.add_material(Material { texture, ..base }));
                let mut mesh = obj.mesh;
                for m in mesh.triangle_material.iter_mut() {
                    *m = ids[*m as usize];
                }
                if let Some(c) = color {
                    mesh.colors.iter_mut().for_each(|x| *x = c);
                }
                mesh
            }
            "ply" => {
                let path = need_path("model.ply.gz")?;
                let mut mesh = mesh::load_ply(&path).map_err(ObjectError::File)?;
                let c = color.unwrap_or(Vec3::splat(0.8));
                mesh.colors.iter_mut().for_each(|x| *x = c);
                let id = self.add_material(Material { texture, ..base });
                mesh.triangle_material.iter_mut().for_each(|m| *m = id);
                mesh
            }
            "teapot" => {
                let path = need_path("models/teapot.bpt")?;
                let n = def.tessellation.unwrap_or(10);
                if n == 0 {
                    return Err(ObjectError::Here("tessellation must be positive".into()));
                }
                // 32 patches in Newell's teapot (a .bpt with more patches gives more)
                procedural_limit("tessellation", n, 32 * 2 * n as u64 * n as u64)?;
                let mut mesh = mesh::teapot(&path, n).map_err(ObjectError::File)?;
                let c = color.unwrap_or(Vec3::new(0.8, 0.3, 0.2));
                mesh.colors.iter_mut().for_each(|x| *x = c);
                let id = self.add_material(Material { texture, ..base });
                mesh.triangle_material.iter_mut().for_each(|m| *m = id);
                mesh
            }
            "floor" => {
                let quads = def.quads.unwrap_or(64);
                if quads == 0 {
                    return Err(ObjectError::Here("quads must be positive".into()));
                }
                procedural_limit("quads", quads, 2 * quads as u64 * quads as u64)?;
                let checker = match (def.checker, color) {
                    (Some([a, b]), _) => [Vec3::from(a), Vec3::from(b)],
                    (None, Some(c)) => [c, c],
                    (None, None) => [Vec3::splat(0.75), Vec3::splat(0.35)],
                };
                let mut mesh = mesh::floor(def.size.unwrap_or(4.0), quads, checker);
                let id = self.add_material(Material { texture, ..base });
                mesh.triangle_material.iter_mut().for_each(|m| *m = id);
                mesh
            }
            other => {
                return Err(ObjectError::Here(format!(
                    "unknown object type \"{other}\" (expected \"obj\", \"ply\", \"teapot\" or \"floor\")"
                )))
            }
        };
        if let Some(fit) = def.fit {
            let (lo, hi) = mesh.bounds();
            let extent = (hi - lo).max_element();
            let center = Vec3::new((lo.x + hi.x) / 2.0, lo.y, (lo.z + hi.z) / 2.0);
            let s = fit / extent;
            mesh.positions
                .iter_mut()
                .for_each(|p| *p = (*p - center) * s);
        }
        let scale = match def.scale {
            Scale::Uniform(s) => Vec3::splat(s),
            Scale::Axes(a) => Vec3::from(a),
        };
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        let scale_values: Vec<f32> = match def.scale {
            Scale::Uniform(s) => vec![s],
            Scale::Axes(a) => a.to_vec(),
        };
        if !(finite(&def.translate)
            && finite(&def.rotate)
            && finite(&scale_values)
            && def.fit.is_none_or(|f| f.is_finite() && f > 0.0)
            && def.size.is_none_or(|s| s.is_finite() && s > 0.0))
        {
            return Err(ObjectError::Here(
                "translate, rotate and scale must be finite, fit and size finite and positive"
                    .into(),
            ));
        }
        if !(finite(&def.color.unwrap_or_default())
            && finite(def.checker.unwrap_or_default().as_flattened())
            && finite(&[def.specular, def.shininess]))
        {
            return Err(ObjectError::Here(
                "color, checker, specular and shininess must be finite".into(),
            ));
        }
        let r = def.rotate.map(f32::to_radians);
        let model = Mat4::from_scale_rotation_translation(
            scale,
            Quat::from_euler(glam::EulerRot::YXZ, r[1], r[0], r[2]),
            Vec3::from(def.translate),
        );
        if Mat3::from_mat4(model).determinant().abs() < 1e-12 {
            return Err(ObjectError::Here(
                "the transform is singular (a zero scale)".into(),
            ));
        }
        Ok(Object {
            name: def.name.unwrap_or_else(|| format!("{kind}#{index}")),
            mesh,
            model,
        })
    }
}

/// The most triangles a procedural object (`teapot`, `floor`) may have: far beyond what the GL
/// buffers of any device hold (those limits are checked when the scene is uploaded), but it
/// keeps a mistyped `quads` or `tessellation` from exhausting the memory first.
pub const MAX_PROCEDURAL_TRIANGLES: u64 = 1 << 26;

fn procedural_limit(key: &str, value: u32, triangles: u64) -> Result<(), ObjectError> {
    if triangles > MAX_PROCEDURAL_TRIANGLES {
        return Err(ObjectError::Here(format!(
            "{key} = {value} gives {triangles} triangles; a procedural object may have at most \
             {MAX_PROCEDURAL_TRIANGLES}"
        )));
    }
    Ok(())
}

/// World-space vertex attributes of the whole scene.
#[derive(Debug, Clone, Default)]
pub struct WorldAttributes {
    pub normals: Vec<Vec3>,
    pub colors: Vec<Vec3>,
    pub texcoords: Vec<Vec2>,
    pub triangle_material: Vec<u32>,
}

enum ObjectError {
    Here(String),
    File(SceneError),
}

fn line_of(text: &str, byte: usize) -> usize {
    text[..byte.min(text.len())].matches('\n').count() + 1
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: Spanned<Camera>,
    render: Option<Spanned<RenderSettings>>,
    #[serde(default)]
    light: Vec<Spanned<LightDef>>,
    #[serde(default)]
    area_light: Vec<Spanned<AreaLightDef>>,
    #[serde(default)]
    object: Vec<ObjectDef>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightDef {
    position: [f32; 3],
    #[serde(default = "white")]
    color: [f32; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AreaLightDef {
    corner: [f32; 3],
    edge_u: [f32; 3],
    edge_v: [f32; 3],
    #[serde(default = "white")]
    color: [f32; 3],
}

fn white() -> [f32; 3] {
    [1.0, 1.0, 1.0]
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Scale {
    Uniform(f32),
    Axes([f32; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectDef {
    #[serde(rename = "type")]
    kind: Spanned<String>,
    name: Option<String>,
    path: Option<Spanned<String>>,
    #[serde(default)]
    translate: [f32; 3],
    /// Degrees about x, y and z (applied y, then x, then z).
    #[serde(default)]
    rotate: [f32; 3],
    #[serde(default = "unit_scale")]
    scale: Scale,
    /// Centre the model (bottom at y = 0) and scale its largest extent to this size first.
    fit: Option<f32>,
    color: Option<[f32; 3]>,
    checker: Option<[[f32; 3]; 2]>,
    texture: Option<Spanned<String>>,
    #[serde(default)]
    reflection: f32,
    #[serde(default = "default_specular")]
    specular: f32,
    #[serde(default = "default_shininess")]
    shininess: f32,
    size: Option<f32>,
    quads: Option<u32>,
    tessellation: Option<u32>,
}

fn unit_scale() -> Scale {
    Scale::Uniform(1.0)
}
fn default_specular() -> f32 {
    0.3
}
fn default_shininess() -> f32 {
    32.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_file_and_line() {
        let text = "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n\n[[object]]\ntype = \"sphere\"\n";
        let e = Scene::parse(Path::new("x.toml"), text).unwrap_err();
        assert_eq!(e.line, Some(6), "{e}");
        assert!(e.to_string().contains("unknown object type"), "{e}");
        let text = "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\nfov = 3\n";
        let e = Scene::parse(Path::new("x.toml"), text).unwrap_err();
        assert_eq!(e.line, Some(4), "{e}");
    }
}
