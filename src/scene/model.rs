//! What a loaded scene is — its objects, lights, materials, settings and camera — and the error
//! that names a scene file's line: the types the loaders (`obj`, `ply`, `gltf`, `bpt`) build
//! and the checks (`validate`, `magnitudes`) read, below them and below `scene/mod.rs`, which
//! parses a scene file and loads it through them.

use std::fmt;
use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Vec3};
use serde::Deserialize;

use super::camera::Camera;
use super::mesh::Mesh;
use super::shadows::{parse_samples, ShadowMode};

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
    /// The normal matrix: inverse transpose of the model matrix' upper 3×3. Normals are
    /// normalised after it, so its scale is free: where the f32 inverse leaves a safe range
    /// (a model matrix that scales by 1e-13 or 1e13 overflows it: NaN normals) it is computed
    /// in f64 and divided by its largest element; ordinary transforms keep the f32 inverse.
    pub fn normal_matrix(&self) -> Mat3 {
        let m = Mat3::from_mat4(self.model).inverse().transpose();
        let largest = m.to_cols_array().iter().fold(0.0f32, |a, v| a.max(v.abs()));
        if (1e-15..=1e15).contains(&largest) {
            return m;
        }
        let m = glam::DMat3::from_mat4(self.model.as_dmat4())
            .inverse()
            .transpose();
        let largest = m.to_cols_array().iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if largest > 0.0 && largest.is_finite() {
            (m * (1.0 / largest)).as_mat3()
        } else {
            m.as_mat3() // singular: refused by the scene's validation
        }
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

impl RenderSettings {
    /// Sizes and the reflection depth within [`crate::limits`], colours finite, the shadow
    /// offset finite and >= 0.
    /// An error names the key it is about (for its line).
    pub(super) fn validate(&self) -> Result<(), (&'static str, String)> {
        use crate::limits::{check, IMAGE_SIDE, REFL_DEPTH};
        for (key, value, range) in [
            ("width", self.width, &IMAGE_SIDE),
            ("height", self.height, &IMAGE_SIDE),
            ("refl_depth", self.refl_depth, &REFL_DEPTH),
        ] {
            check(&format!("render.{key}"), value, range).map_err(|m| (key, m))?;
        }
        for (key, c) in [("background", self.background), ("ambient", self.ambient)] {
            if !c.iter().all(|v| v.is_finite()) {
                return Err((key, format!("render.{key} must be finite")));
            }
        }
        if !self.shadow_offset.is_finite() || self.shadow_offset < 0.0 {
            let m = "render.shadow_offset must be finite and >= 0".to_string();
            return Err(("shadow_offset", m));
        }
        Ok(())
    }
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

/// The most triangles a procedural object (`teapot`, `floor`, `sphere`, `square`) may have:
/// far beyond what the GL buffers of any device hold (those limits are checked when the scene
/// is uploaded), but it keeps a mistyped `quads`, `tessellation`, `stacks` or `level` from
/// exhausting the memory first (a square's `level` may be at most 12).
pub const MAX_PROCEDURAL_TRIANGLES: u64 = 1 << 26;

/// The most triangles a scene may have: Müller 2015's kernels carry a triangle id in a float
/// channel of the ray state, exact up to 2^24, and the other designs are measured far below.
pub const MAX_SCENE_TRIANGLES: u64 = 1 << 24;
