//! Scenes: a TOML scene file with a camera, background and ambient colour, point lights and
//! objects (OBJ and PLY files, or the procedural `teapot`, `floor`, `sphere` and `square`), each
//! with a transform and a material. See `scenes/*.toml` and `docs/scenes.md` for the format.

pub mod bpt;
pub mod budget;
pub mod camera;
pub mod file;
pub mod gltf;
pub mod magnitudes;
pub mod mesh;
pub mod model;
pub mod obj;
pub mod ply;
pub mod shadows;
pub mod shapes;
pub mod validate;

use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};
use serde::Deserialize;
use toml::Spanned;

pub use shadows::{parse_samples, ShadowMode};

pub use camera::{Camera, CameraRays};
pub use mesh::Mesh;
pub use model::{
    AreaLight, Light, Material, Object, RenderSettings, Scene, SceneError,
    MAX_PROCEDURAL_TRIANGLES, MAX_SCENE_TRIANGLES,
};

/// Whether a scene's textures are decoded or only their headers read ([`Scene::load_counts`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Textures {
    Decode,
    HeadersOnly,
}

/// Copies of a texture's RGBA8 texels the way to the GPU makes: the decoded image, its RGBA8
/// conversion, the flipped (and resized) layer, the upload's copy in the driver, and one for a
/// decoder that works in 16 bits a channel.
const TEXTURE_COPIES: u64 = 5;

/// Decode a texture within [`crate::limits::TEXTURE_SIDE`] texels a side and
/// [`crate::limits::TEXTURE_BYTES`] bytes of memory (a small file can claim a huge image). The
/// size is read from the header and checked, with the host memory its copies take, before
/// anything is decoded.
fn decode_texture(path: &Path, textures: Textures) -> Result<image::RgbaImage, String> {
    use crate::limits::{TEXTURE_BYTES, TEXTURE_SIDE};
    let bytes = file::read(path)?;
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(&bytes[..]))
            .with_guessed_format()
            .map_err(|e| e.to_string())
    };
    let (w, h) = reader()?.into_dimensions().map_err(|e| e.to_string())?;
    if w > TEXTURE_SIDE || h > TEXTURE_SIDE {
        return Err(format!(
            "its header gives {w}x{h} texels; textures may be at most \
             {TEXTURE_SIDE}x{TEXTURE_SIDE}"
        ));
    }
    let texels = u64::from(w) * u64::from(h);
    budget::check_host(
        &format!("its {w}x{h} texels (from the header)"),
        texels * 4 * TEXTURE_COPIES,
    )?;
    if textures == Textures::HeadersOnly {
        return Ok(image::RgbaImage::from_pixel(1, 1, image::Rgba([255; 4])));
    }
    let mut reader = reader()?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(TEXTURE_SIDE);
    limits.max_image_height = Some(TEXTURE_SIDE);
    limits.max_alloc = Some(TEXTURE_BYTES);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| match e {
        image::ImageError::Limits(_) => format!(
            "{e} (textures may be at most {TEXTURE_SIDE}x{TEXTURE_SIDE} texels and take at most \
             {} MiB to decode)",
            TEXTURE_BYTES >> 20
        ),
        e => e.to_string(),
    })?;
    Ok(img.to_rgba8())
}

/// Procedural sizes set from outside the scene file: each replaces its key in every object of
/// the type that takes it (`bench wagner-a1` renders one `square.toml` at every subdivision
/// level this way). An override that no object of the scene takes is an error.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Overrides {
    /// `level` of every object of type `square`.
    pub level: Option<u32>,
}

impl Overrides {
    /// Put the overrides into the objects' definitions (before they are built and checked).
    fn apply(&self, path: &Path, objects: &mut [ObjectDef]) -> Result<(), SceneError> {
        let Some(level) = self.level else {
            return Ok(());
        };
        let squares = objects.iter_mut().filter(|d| d.kind.get_ref() == "square");
        if squares.map(|d| d.shape.level = Some(level)).count() == 0 {
            return Err(SceneError::at(
                path,
                None,
                format!("level = {level} was set for the scene's squares, but it has no [[object]] of type \"square\""),
            ));
        }
        Ok(())
    }
}

impl Scene {
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Self::load_with(path, &Overrides::default())
    }

    /// Load a scene file with some of its procedural sizes replaced by `overrides`.
    pub fn load_with(path: &Path, overrides: &Overrides) -> Result<Scene, SceneError> {
        if gltf::is_gltf(path) {
            if *overrides != Overrides::default() {
                return Err(SceneError::at(
                    path,
                    None,
                    "a glTF file has no procedural objects to size".into(),
                ));
            }
            return Self::from_gltf(path, Textures::Decode);
        }
        let text = file::read_text(path)
            .map_err(|e| SceneError::at(path, None, format!("cannot read scene file: {e}")))?;
        Self::parse(path, &text, overrides, Textures::Decode)
    }

    /// The triangles the scene file's objects will give, counted from the file, the models'
    /// headers and face lines and the procedural sizes, before any mesh is built (a PLY face
    /// counts as one triangle: a lower bound). Checked against [`MAX_SCENE_TRIANGLES`] and the
    /// host's memory as [`Scene::load`] does first.
    /// Also gives the file's render settings (unchecked: [`Scene::load`] checks them).
    pub fn count_triangles(path: &Path) -> Result<(u64, RenderSettings), SceneError> {
        if gltf::is_gltf(path) {
            return Ok((gltf::count_triangles(path)?, RenderSettings::default()));
        }
        let text = file::read_text(path)
            .map_err(|e| SceneError::at(path, None, format!("cannot read scene file: {e}")))?;
        let src = SceneText { path, text: &text };
        let file = src.deserialize()?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let triangles = predict_triangles(&src, dir, &file.object)?;
        let settings = file.render.map(|r| *r.get_ref()).unwrap_or_default();
        Ok((triangles, settings))
    }

    /// The scene for its counts (`info`): every file read and checked as [`Scene::load`] does,
    /// but each texture only from its header (its size checked, nothing decoded), so
    /// `textures` holds 1×1 white placeholders. Not for rendering.
    pub fn load_counts(path: &Path) -> Result<Scene, SceneError> {
        if gltf::is_gltf(path) {
            return Self::from_gltf(path, Textures::HeadersOnly);
        }
        let text = file::read_text(path)
            .map_err(|e| SceneError::at(path, None, format!("cannot read scene file: {e}")))?;
        Self::parse(path, &text, &Overrides::default(), Textures::HeadersOnly)
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
        transform_triangles(
            self.objects
                .iter()
                .map(|o| (o.mesh.positions.as_slice(), o.model)),
        )
    }

    /// World-space per-vertex data (positions, normals, colours, texture coordinates) and
    /// per-triangle material ids, in the order of [`Scene::world_triangles`].
    pub fn world_attributes(&self) -> WorldAttributes {
        let mut a = WorldAttributes::default();
        for o in &self.objects {
            let nm = o.normal_matrix();
            a.positions.extend(
                o.mesh
                    .positions
                    .iter()
                    .map(|p| o.model.transform_point3(*p)),
            );
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
        let largest = |side: fn(&image::RgbaImage) -> u32| {
            let most = self.textures.iter().map(|(_, t)| side(t)).max();
            most.unwrap_or(1).min(max_size)
        };
        let (w, h) = (largest(|t| t.width()), largest(|t| t.height()));
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

    fn parse(
        path: &Path,
        text: &str,
        overrides: &Overrides,
        textures: Textures,
    ) -> Result<Scene, SceneError> {
        let src = SceneText { path, text };
        let mut file = src.deserialize()?;
        overrides.apply(path, &mut file.object)?;
        let camera = *file.camera.get_ref();
        camera
            .validate()
            .map_err(|(key, m)| src.key_error("camera", file.camera.span().start, key, m))?;
        let (settings, render_at) = match file.render {
            Some(r) => (*r.get_ref(), Some(r.span().start)),
            None => (RenderSettings::default(), None),
        };
        let render_line = render_at.map(|at| line_of(text, at));
        let render_error = |m: &str| SceneError::at(path, render_line, m.into());
        settings.validate().map_err(|(key, m)| match render_at {
            Some(at) => src.key_error("render", at, key, m),
            None => render_error(&m),
        })?;
        let lights = src.check_all(file.light, LightDef::light)?;
        let area_lights = src.check_all(file.area_light, AreaLightDef::area_light)?;
        if settings.shadows.is_some() && area_lights.is_empty() {
            return Err(render_error(
                "render.shadows needs an [[area_light]] in the scene",
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
        let dir = path.parent().unwrap_or(Path::new("."));
        predict_triangles(&src, dir, &file.object)?;
        for (k, def) in file.object.into_iter().enumerate() {
            let type_line = def.kind.span().start;
            if let Some(key) = def.unknown.keys().next() {
                return Err(src.unknown_object_key(type_line, key));
            }
            let object = scene
                .build_object(dir, k, def, textures)
                .map_err(|e| match e {
                    // errors about the object itself point at its `type` line
                    ObjectError::Here(m) => src.error_at(type_line, m),
                    ObjectError::File(e) => e,
                })?;
            validate::object(&object, scene.materials.len())
                .map_err(|m| src.error_at(type_line, m))?;
            scene.objects.push(object);
        }
        let triangles = scene.triangle_count() as u64;
        if triangles > MAX_SCENE_TRIANGLES {
            let m = format!(
                "{triangles} triangles, more than the {MAX_SCENE_TRIANGLES} a scene may have"
            );
            return Err(SceneError::at(path, None, m));
        }
        validate::scene(&scene).map_err(|m| SceneError::at(path, None, m))?;
        magnitudes::check(&scene)?;
        Ok(scene)
    }

    fn load_texture(&mut self, path: &Path, textures: Textures) -> Result<u32, ObjectError> {
        if let Some(i) = self.textures.iter().position(|(p, _)| p == path) {
            return Ok(i as u32);
        }
        let img = decode_texture(path, textures).map_err(|e| {
            ObjectError::Here(format!("cannot load texture {}: {e}", path.display()))
        })?;
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
        textures: Textures,
    ) -> Result<Object, ObjectError> {
        let base = def.base_material()?;
        def.check_type_keys()?;
        def.check_numbers()?;
        let texture = match &def.texture {
            Some(t) => Some(self.load_texture(&dir.join(t.get_ref()), textures)?),
            None => None,
        };
        let material = Material { texture, ..base };
        let mut mesh = self.object_mesh(dir, &def, material, textures)?;
        if let Some(size) = def.fit {
            fit(&mut mesh, size)?;
        }
        let model = def.model_matrix()?;
        let kind = def.kind.get_ref();
        Ok(Object {
            name: def.name.unwrap_or_else(|| format!("{kind}#{index}")),
            mesh,
            model,
        })
    }

    /// The object's mesh by its type, its triangles with the scene material id of `material`
    /// (an OBJ file's: one per MTL material).
    fn object_mesh(
        &mut self,
        dir: &Path,
        def: &ObjectDef,
        material: Material,
        textures: Textures,
    ) -> Result<Mesh, ObjectError> {
        let mut mesh = match def.kind.get_ref().as_str() {
            "obj" => {
                let path = def.model_path(dir, "model.obj")?;
                return self.obj_mesh(&path, material, def, textures);
            }
            "gltf" => {
                let path = def.model_path(dir, "model.gltf")?;
                let loaded = gltf::load(&path).map_err(ObjectError::File)?;
                let mut mesh = self.gltf_mesh(loaded.mesh, &loaded.materials, textures)?;
                if let Some(c) = def.color {
                    mesh.colors.fill(Vec3::from(c));
                }
                return Ok(mesh);
            }
            "ply" => def.ply_mesh(dir)?,
            "teapot" => def.teapot_mesh(dir)?,
            "floor" => def.floor_mesh()?,
            "sphere" => def.sphere_mesh()?,
            "square" => def.square_mesh()?,
            other => {
                return Err(ObjectError::Here(format!(
                    "unknown object type \"{other}\" (expected one of {})",
                    quoted(OBJECT_TYPES)
                )))
            }
        };
        let id = self.add_material(material);
        mesh.triangle_material.fill(id);
        Ok(mesh)
    }

    /// A glTF file's triangles with their materials made scene materials (textures loaded).
    fn gltf_mesh(
        &mut self,
        mut mesh: Mesh,
        materials: &[gltf::GltfMaterial],
        textures: Textures,
    ) -> Result<Mesh, ObjectError> {
        let mut ids = Vec::with_capacity(materials.len());
        for m in materials {
            let texture = match &m.texture {
                Some(p) => Some(self.load_texture(p, textures)?),
                None => None,
            };
            ids.push(self.add_material(Material {
                reflection: m.reflection,
                specular: m.specular,
                shininess: m.shininess,
                texture,
            }));
        }
        for m in mesh.triangle_material.iter_mut() {
            *m = ids[*m as usize];
        }
        Ok(mesh)
    }

    /// A glTF file as the whole scene (`render model.glb`): its camera, or one that frames it;
    /// its lights, or one above the camera; default render settings.
    fn from_gltf(path: &Path, textures: Textures) -> Result<Scene, SceneError> {
        let loaded = gltf::load(path)?;
        let camera = loaded
            .camera
            .unwrap_or_else(|| gltf::framing_camera(&loaded.mesh));
        let lights = match loaded.lights.is_empty() {
            true => vec![gltf::default_light(&camera, &loaded.mesh)],
            false => loaded.lights,
        };
        let mut scene = Scene {
            path: path.to_path_buf(),
            camera,
            settings: RenderSettings::default(),
            lights,
            area_lights: Vec::new(),
            objects: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
        };
        let on_file = |e: ObjectError| match e {
            ObjectError::Here(m) => SceneError::at(path, None, m),
            ObjectError::File(e) => e,
        };
        let mesh = scene
            .gltf_mesh(loaded.mesh, &loaded.materials, textures)
            .map_err(on_file)?;
        let name = path
            .file_name()
            .map_or("gltf".into(), |n| n.to_string_lossy().into_owned());
        scene.objects.push(Object {
            name,
            mesh,
            model: Mat4::IDENTITY,
        });
        scene
            .camera
            .validate()
            .map_err(|(_, m)| SceneError::at(path, None, m))?;
        validate::scene(&scene).map_err(|m| SceneError::at(path, None, m))?;
        magnitudes::check(&scene)?;
        Ok(scene)
    }

    /// An OBJ model with one scene material per MTL material (with the MTL texture unless
    /// `material` has one) plus `material` for faces without; the object's `color`, if given,
    /// replaces the file's colours.
    fn obj_mesh(
        &mut self,
        path: &Path,
        material: Material,
        def: &ObjectDef,
        textures: Textures,
    ) -> Result<Mesh, ObjectError> {
        let obj = obj::load_obj(path).map_err(ObjectError::File)?;
        let mut ids = Vec::new();
        for m in &obj.materials {
            let texture = match (material.texture, &m.texture) {
                (Some(t), _) => Some(t),
                (None, Some(p)) => Some(self.load_texture(p, textures)?),
                (None, None) => None,
            };
            ids.push(self.add_material(Material {
                texture,
                ..material
            }));
        }
        ids.push(self.add_material(material));
        let mut mesh = obj.mesh;
        for m in mesh.triangle_material.iter_mut() {
            *m = ids[*m as usize];
        }
        if let Some(c) = def.color {
            mesh.colors.fill(Vec3::from(c));
        }
        Ok(mesh)
    }
}

/// The scene's triangles counted before anything is built ([`Scene::count_triangles`]): a
/// total over [`MAX_SCENE_TRIANGLES`] or the host's memory names the object that passes it. A
/// model file named by several objects is read once.
///
/// An object that is wrong or too large on its own stops the count there: building it gives
/// the error that names its file, key or header (checked, like this count, before its memory
/// is taken), and [`Scene::parse`] checks the built total again.
fn predict_triangles(src: &SceneText, dir: &Path, defs: &[ObjectDef]) -> Result<u64, SceneError> {
    let mut models: std::collections::HashMap<PathBuf, u64> = Default::default();
    let mut total = 0u64;
    // (the host's memory read once for the whole scene, not twice an object)
    let limit = budget::host_limit();
    for (k, def) in defs.iter().enumerate() {
        let Ok(n) = def.predicted_triangles(dir, &mut models) else {
            return Ok(total);
        };
        let alone = n > MAX_SCENE_TRIANGLES.min(MAX_PROCEDURAL_TRIANGLES)
            || budget::check_triangles_against("", n, limit).is_err();
        if alone {
            return Ok(total);
        }
        total = total.saturating_add(n);
        let upto = format!(
            "the scene's objects up to #{} ({})",
            k + 1,
            def.kind.get_ref()
        );
        if total > MAX_SCENE_TRIANGLES {
            let m = format!(
                "{upto} give {total} triangles, more than the {MAX_SCENE_TRIANGLES} a scene may \
                 have"
            );
            return Err(src.error_at(def.kind.span().start, m));
        }
        budget::check_triangles_against(&upto, total, limit)
            .map_err(|m| src.error_at(def.kind.span().start, m))?;
    }
    Ok(total)
}

/// Centre the mesh (its bottom at y = 0) and scale its largest extent to `size`; an error for
/// an object without extent (all vertices in one point) or one whose scale overflows f32.
fn fit(mesh: &mut Mesh, size: f32) -> Result<(), ObjectError> {
    let (lo, hi) = mesh.bounds();
    let extent = (hi - lo).max_element();
    let center = Vec3::new((lo.x + hi.x) / 2.0, lo.y, (lo.z + hi.z) / 2.0);
    let s = size / extent;
    if !(extent > 0.0 && s.is_finite() && center.is_finite()) {
        return Err(ObjectError::Here(format!(
            "fit = {size} needs an object that extends in some direction; this one's largest \
             extent is {extent} (from {lo} to {hi})"
        )));
    }
    mesh.positions
        .iter_mut()
        .for_each(|p| *p = (*p - center) * s);
    Ok(())
}

impl ObjectDef {
    /// The material the object gives, without a texture.
    fn base_material(&self) -> Result<Material, ObjectError> {
        if !(0.0..=1.0).contains(&self.reflection) {
            return Err(ObjectError::Here(format!(
                "reflection = {} must lie in [0, 1]",
                self.reflection
            )));
        }
        Ok(Material {
            reflection: self.reflection,
            specular: self.specular,
            shininess: self.shininess,
            texture: None,
        })
    }

    /// `path` relative to the scene file's folder; `example` shows it in the error when the
    /// object has none.
    fn model_path(&self, dir: &Path, example: &str) -> Result<PathBuf, ObjectError> {
        let path = self.path.as_ref().map(|p| dir.join(p.get_ref()));
        path.ok_or_else(|| {
            ObjectError::Here(format!(
                "an object of type \"{}\" needs path = \"{example}\"",
                self.kind.get_ref()
            ))
        })
    }

    /// The triangles this object will give ([`predict_triangles`]); `models` caches a model
    /// file's count by path. Sizes out of range are the errors building it gives.
    fn predicted_triangles(
        &self,
        dir: &Path,
        models: &mut std::collections::HashMap<PathBuf, u64>,
    ) -> Result<u64, ObjectError> {
        let mut model = |example: &str, count: fn(&Path) -> Result<u64, SceneError>| {
            let path = self.model_path(dir, example)?;
            if let Some(&n) = models.get(&path) {
                return Ok(n);
            }
            let n = count(&path).map_err(ObjectError::File)?;
            models.insert(path, n);
            Ok(n)
        };
        let s = &self.shape;
        Ok(match self.kind.get_ref().as_str() {
            "obj" => model("model.obj", obj::count_triangles)?,
            "gltf" => model("model.gltf", gltf::count_triangles)?,
            "ply" => model("model.ply.gz", ply::count_faces)?,
            "teapot" => {
                let n = procedural_size("tessellation", s.tessellation, 10, 1, |n| 2 * n * n)?;
                let patches = model("models/teapot.bpt", bpt::patch_count)?;
                patches.saturating_mul(2 * u64::from(n).pow(2))
            }
            "floor" => {
                2 * u64::from(procedural_size("quads", s.quads, 64, 1, |q| 2 * q * q)?).pow(2)
            }
            "sphere" => {
                let stacks = procedural_size("stacks", s.stacks, 16, 2, |_| 0)?;
                let slices = procedural_size("slices", s.slices, 24, 3, |_| 0)?;
                shapes::sphere_triangles(stacks.into(), slices.into())
            }
            "square" => shapes::square_triangles(
                procedural_size("level", s.level, 1, 1, shapes::square_triangles)?.into(),
            ),
            _ => 0, // an unknown type: its error comes when it is built
        })
    }

    fn ply_mesh(&self, dir: &Path) -> Result<Mesh, ObjectError> {
        let path = self.model_path(dir, "model.ply.gz")?;
        let mut mesh = ply::load_ply(&path).map_err(ObjectError::File)?;
        mesh.colors.fill(self.color_or(Vec3::splat(0.8)));
        Ok(mesh)
    }

    fn teapot_mesh(&self, dir: &Path) -> Result<Mesh, ObjectError> {
        let path = self.model_path(dir, "models/teapot.bpt")?;
        // here one patch's triangles: the file's patch count, and with it the whole mesh's
        // size and memory, is checked when the file is read (bpt::teapot) — a memory check for
        // Newell's 32 patches here would refuse a file of 64 for the wrong reason, and only
        // where the host has less memory
        let n = procedural_size("tessellation", self.shape.tessellation, 10, 1, |n| {
            2 * n * n
        })?;
        let mut mesh = bpt::teapot(&path, n).map_err(ObjectError::File)?;
        mesh.colors.fill(self.color_or(Vec3::new(0.8, 0.3, 0.2)));
        Ok(mesh)
    }

    fn floor_mesh(&self) -> Result<Mesh, ObjectError> {
        let quads = procedural_size("quads", self.shape.quads, 64, 1, |q| 2 * q * q)?;
        let checker = match (self.shape.checker, self.color) {
            (Some([a, b]), _) => [Vec3::from(a), Vec3::from(b)],
            (None, Some(c)) => [Vec3::from(c); 2],
            (None, None) => [Vec3::splat(0.75), Vec3::splat(0.35)],
        };
        Ok(mesh::floor(self.shape.size.unwrap_or(4.0), quads, checker))
    }

    /// Wagner 2018's sphere (Fig. 5.2): 16 stacks × 24 slices = 720 triangles by default, blue.
    fn sphere_mesh(&self) -> Result<Mesh, ObjectError> {
        let stacks = procedural_size("stacks", self.shape.stacks, 16, 2, |_| 0)?;
        let slices = procedural_size("slices", self.shape.slices, 24, 3, |_| 0)?;
        at_most_triangles(
            &format!("stacks = {stacks} with slices = {slices}"),
            shapes::sphere_triangles(stacks as u64, slices as u64),
        )?;
        let radius = self.shape.radius.unwrap_or(1.0);
        if !(radius.is_finite() && radius > 0.0) {
            return Err(ObjectError::Here(format!(
                "radius = {radius} must be finite and positive"
            )));
        }
        let blue = Vec3::new(0.15, 0.3, 0.9);
        Ok(shapes::sphere(radius, stacks, slices, self.color_or(blue)))
    }

    /// Wagner 2018's square (ch. 5.1, Table A.1): 2·4^level triangles, level 1 (8) by default.
    fn square_mesh(&self) -> Result<Mesh, ObjectError> {
        let level = procedural_size("level", self.shape.level, 1, 1, shapes::square_triangles)?;
        let size = self.shape.size.unwrap_or(1.0);
        Ok(shapes::square(size, level, self.color_or(Vec3::splat(0.8))))
    }

    /// Keys that only some object types take are refused on the others, rather than ignored.
    fn check_type_keys(&self) -> Result<(), ObjectError> {
        let kind = self.kind.get_ref().as_str();
        if !OBJECT_TYPES.contains(&kind) {
            return Ok(()); // the unknown type is the error, reported when the mesh is built
        }
        let given: [(&str, bool, &[&str]); 8] = [
            ("size", self.shape.size.is_some(), &["floor", "square"]),
            ("quads", self.shape.quads.is_some(), &["floor"]),
            ("checker", self.shape.checker.is_some(), &["floor"]),
            (
                "tessellation",
                self.shape.tessellation.is_some(),
                &["teapot"],
            ),
            ("radius", self.shape.radius.is_some(), &["sphere"]),
            ("stacks", self.shape.stacks.is_some(), &["sphere"]),
            ("slices", self.shape.slices.is_some(), &["sphere"]),
            ("level", self.shape.level.is_some(), &["square"]),
        ];
        match given
            .iter()
            .find(|(_, set, types)| *set && !types.contains(&kind))
        {
            Some((key, _, types)) => Err(ObjectError::Here(format!(
                "{key} applies to objects of type {}, not \"{kind}\"",
                quoted(types)
            ))),
            None => Ok(()),
        }
    }

    fn color_or(&self, default: Vec3) -> Vec3 {
        self.color.map(Vec3::from).unwrap_or(default)
    }

    /// Every number finite, `fit` and `size` also positive.
    fn check_numbers(&self) -> Result<(), ObjectError> {
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        if !(finite(&self.translate)
            && finite(&self.rotate)
            && self.scale.vector().is_finite()
            && self.fit.is_none_or(|f| f.is_finite() && f > 0.0)
            && self.shape.size.is_none_or(|s| s.is_finite() && s > 0.0))
        {
            return Err(ObjectError::Here(
                "translate, rotate and scale must be finite, fit and size finite and positive"
                    .into(),
            ));
        }
        if !(finite(&self.color.unwrap_or_default())
            && finite(self.shape.checker.unwrap_or_default().as_flattened())
            && finite(&[self.specular, self.shininess]))
        {
            return Err(ObjectError::Here(
                "color, checker, specular and shininess must be finite".into(),
            ));
        }
        Ok(())
    }

    /// Scale, then rotate (y, then x, then z), then translate; an error when singular.
    fn model_matrix(&self) -> Result<Mat4, ObjectError> {
        let r = self.rotate.map(f32::to_radians);
        let model = Mat4::from_scale_rotation_translation(
            self.scale.vector(),
            Quat::from_euler(glam::EulerRot::YXZ, r[1], r[0], r[2]),
            Vec3::from(self.translate),
        );
        // the rotation is orthonormal: the matrix is singular exactly when a scale is zero (a
        // small determinant is no test: a uniform scale of 1e-4 has 1e-12 and is fine)
        let scale = self.scale.vector();
        if scale.cmpeq(Vec3::ZERO).any() {
            return Err(ObjectError::Here(format!(
                "the transform is singular: scale = {scale} has a zero component"
            )));
        }
        Ok(model)
    }
}

/// The keys of an `[[object]]`.
const OBJECT_KEYS: &[&str] = &[
    "type",
    "name",
    "path",
    "translate",
    "rotate",
    "scale",
    "fit",
    "color",
    "texture",
    "reflection",
    "specular",
    "shininess",
    "checker",
    "size",
    "quads",
    "tessellation",
    "radius",
    "stacks",
    "slices",
    "level",
];

/// The object types of a scene file.
const OBJECT_TYPES: &[&str] = &["obj", "ply", "gltf", "teapot", "floor", "sphere", "square"];

/// "\"a\", \"b\" or \"c\"".
fn quoted(names: &[&str]) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
    match q.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => q.join(""),
    }
}

/// The size `key` of a procedural object (`default` when not given): at least `min`, and
/// giving at most [`MAX_PROCEDURAL_TRIANGLES`] by `triangles`.
fn procedural_size(
    key: &str,
    value: Option<u32>,
    default: u32,
    min: u32,
    triangles: impl Fn(u64) -> u64,
) -> Result<u32, ObjectError> {
    let value = value.unwrap_or(default);
    if value < min {
        let what = if min == 1 {
            "must be positive".to_string()
        } else {
            format!("must be at least {min}")
        };
        return Err(ObjectError::Here(format!("{key} = {value} {what}")));
    }
    at_most_triangles(&format!("{key} = {value}"), triangles(value as u64))?;
    Ok(value)
}

/// `triangles`, which the sizes `sizes` give, must be at most [`MAX_PROCEDURAL_TRIANGLES`] and
/// fit the host's memory ([`budget::check_triangles`]), checked before the mesh is built.
fn at_most_triangles(sizes: &str, triangles: u64) -> Result<(), ObjectError> {
    if triangles > MAX_PROCEDURAL_TRIANGLES {
        return Err(ObjectError::Here(format!(
            "{sizes} gives {triangles} triangles; a procedural object may have at most \
             {MAX_PROCEDURAL_TRIANGLES}"
        )));
    }
    budget::check_triangles(sizes, triangles).map_err(ObjectError::Here)
}

/// World-space vertex attributes of the whole scene: one triangle soup whose
/// `triangle_material` holds scene material ids.
pub type WorldAttributes = Mesh;

enum ObjectError {
    Here(String),
    File(SceneError),
}

fn line_of(text: &str, byte: usize) -> usize {
    text[..byte.min(text.len())].matches('\n').count() + 1
}

/// A scene file's path and text, for errors that name a line.
struct SceneText<'a> {
    path: &'a Path,
    text: &'a str,
}

impl SceneText<'_> {
    fn deserialize(&self) -> Result<SceneFile, SceneError> {
        toml::from_str(self.text).map_err(|e| {
            let line = e.span().map(|s| line_of(self.text, s.start));
            SceneError::at(self.path, line, e.message().to_string())
        })
    }

    /// An error at the line of byte `byte`.
    fn error_at(&self, byte: usize, message: String) -> SceneError {
        SceneError::at(self.path, Some(line_of(self.text, byte)), message)
    }

    /// The byte where `key = …` starts in the table whose header `header` (e.g. `[camera]`)
    /// is the last that starts before byte `inside`.
    fn key_at(&self, header: &str, inside: usize, key: &str) -> Option<usize> {
        let end = (inside + header.len()).min(self.text.len());
        let start = self.text.get(..end)?.rfind(header)?;
        let mut offset = start;
        for line in self.text[start..].split_inclusive('\n') {
            let t = line.trim_start();
            if offset > start && t.starts_with('[') {
                break; // the next table
            }
            if let Some((name, _)) = t.split_once('=') {
                if name.trim().trim_matches('"') == key {
                    return Some(offset);
                }
            }
            offset += line.len();
        }
        None
    }

    /// An error about `key` of the `[table]` around byte `inside`, at the key's line (the
    /// table's when the key is not written: a default).
    fn key_error(&self, table: &str, inside: usize, key: &str, message: String) -> SceneError {
        let at = self.key_at(&format!("[{table}]"), inside, key);
        self.error_at(at.unwrap_or(inside), message)
    }

    /// The error for the unknown `key` of the `[[object]]` whose `type` is at byte `type_at`,
    /// naming the key's line (found in the text of that object's table).
    fn unknown_object_key(&self, type_at: usize, key: &str) -> SceneError {
        let at = self.key_at("[[object]]", type_at, key).unwrap_or(type_at);
        self.error_at(
            at,
            format!(
                "unknown field `{key}` of an [[object]], expected one of {}",
                quoted(OBJECT_KEYS)
            ),
        )
    }

    /// `item` through `convert`; its error names the line where the item starts.
    fn check<T, U>(
        &self,
        item: Spanned<T>,
        convert: impl FnOnce(T) -> Result<U, String>,
    ) -> Result<U, SceneError> {
        let start = item.span().start;
        convert(item.into_inner()).map_err(|m| self.error_at(start, m))
    }

    /// Every item through `convert`, as [`SceneText::check`].
    fn check_all<T, U>(
        &self,
        items: Vec<Spanned<T>>,
        convert: impl Fn(T) -> Result<U, String>,
    ) -> Result<Vec<U>, SceneError> {
        items.into_iter().map(|i| self.check(i, &convert)).collect()
    }
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

impl LightDef {
    fn light(self) -> Result<Light, String> {
        if !self
            .position
            .iter()
            .chain(&self.color)
            .all(|v| v.is_finite())
        {
            return Err("light: position and color must be finite".into());
        }
        Ok(Light {
            position: Vec3::from(self.position),
            color: Vec3::from(self.color),
        })
    }
}

impl AreaLightDef {
    fn area_light(self) -> Result<AreaLight, String> {
        let a = AreaLight {
            corner: Vec3::from(self.corner),
            edge_u: Vec3::from(self.edge_u),
            edge_v: Vec3::from(self.edge_v),
            color: Vec3::from(self.color),
        };
        let finite = [a.corner, a.edge_u, a.edge_v, a.color]
            .iter()
            .all(|v| v.is_finite());
        if !finite || a.edge_u.cross(a.edge_v).length() <= 1e-12 {
            return Err(
                "area_light: corner, edge_u, edge_v and color must be finite, and edge_u and \
                 edge_v must span a rectangle (non-zero, not parallel)"
                    .into(),
            );
        }
        Ok(a)
    }
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

impl Scale {
    fn vector(&self) -> Vec3 {
        match *self {
            Scale::Uniform(s) => Vec3::splat(s),
            Scale::Axes(a) => Vec3::from(a),
        }
    }
}

/// An `[[object]]`. Its keys are checked by hand (`unknown`): serde's `deny_unknown_fields`
/// does not combine with `flatten`.
#[derive(Deserialize)]
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
    texture: Option<Spanned<String>>,
    #[serde(default)]
    reflection: f32,
    #[serde(default = "default_specular")]
    specular: f32,
    #[serde(default = "default_shininess")]
    shininess: f32,
    /// The keys of the procedural types.
    #[serde(flatten)]
    shape: ShapeKeys,
    /// Every other key: an error.
    #[serde(flatten)]
    unknown: std::collections::BTreeMap<String, toml::Value>,
}

/// The keys of the procedural object types, each taken by some of them only
/// ([`ObjectDef::check_type_keys`]).
#[derive(Deserialize, Default)]
struct ShapeKeys {
    /// floor: two colours of the checkerboard.
    checker: Option<[[f32; 3]; 2]>,
    /// floor: side length (4); square: side length (1).
    size: Option<f32>,
    /// floor: quads per side (64).
    quads: Option<u32>,
    /// teapot: quads per patch side (10).
    tessellation: Option<u32>,
    /// sphere: radius (1), rings of latitude pole to pole (16), meridians (24).
    radius: Option<f32>,
    stacks: Option<u32>,
    slices: Option<u32>,
    /// square: subdivision level (1: 2×2 quads, 8 triangles; each level ×4).
    level: Option<u32>,
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

/// The triangles of objects given as (object-space positions, 3 per triangle; model matrix),
/// in world space, in object order: the scene's triangle ids.
pub fn transform_triangles<'a>(
    objects: impl IntoIterator<Item = (&'a [Vec3], Mat4)>,
) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for (positions, m) in objects {
        for t in positions.chunks_exact(3) {
            out.push([0, 1, 2].map(|k| m.transform_point3(t[k])));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_file_and_line() {
        let parse = |text: &str| {
            let none = Overrides::default();
            Scene::parse(Path::new("x.toml"), text, &none, Textures::Decode).unwrap_err()
        };
        let e = parse(
            "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n\n[[object]]\ntype = \"cube\"\n",
        );
        assert_eq!(e.line, Some(6), "{e}");
        assert!(e.to_string().contains("unknown object type"), "{e}");
        let e = parse("[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\nfov = 3\n");
        assert_eq!(e.line, Some(4), "{e}");
    }
}
