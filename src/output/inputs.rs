//! The files a scene was read from, which no output may replace: the scene file, its objects'
//! models (with an OBJ's material libraries) and its textures.

use std::path::{Path, PathBuf};

use super::check::{parent_of, Input};
use crate::scene::Scene;

/// The input files of `scene`.
pub fn scene_inputs(scene: &Scene) -> Vec<Input> {
    let input = |path: &Path, role: &str| Input {
        path: path.to_path_buf(),
        role: role.to_string(),
    };
    let mut inputs = vec![input(&scene.path, "the scene file")];
    for buffer in crate::scene::gltf::buffer_files(&scene.path) {
        inputs.push(input(&buffer, "a buffer of the scene's glTF file"));
    }
    for model in model_paths(&scene.path) {
        for buffer in crate::scene::gltf::buffer_files(&model) {
            inputs.push(input(&buffer, "a buffer of a glTF model of the scene"));
        }
        for mtl in material_libraries(&model) {
            inputs.push(input(&mtl, "a material library of the scene"));
        }
        inputs.push(input(&model, "a model of the scene"));
    }
    for (texture, _) in &scene.textures {
        inputs.push(input(texture, "a texture of the scene"));
    }
    inputs
}

/// The `path` of every `[[object]]` of the scene file, relative to its folder.
fn model_paths(scene_file: &Path) -> Vec<PathBuf> {
    let Ok(text) = crate::scene::file::read_text(scene_file) else {
        return Vec::new();
    };
    let Ok(doc) = text.parse::<toml::Table>() else {
        return Vec::new();
    };
    let objects = doc.get("object").and_then(|o| o.as_array());
    let paths = objects
        .into_iter()
        .flatten()
        .filter_map(|o| o.get("path")?.as_str());
    let dir = parent_of(scene_file);
    paths.map(|p| dir.join(p)).collect()
}

/// The files of an OBJ's `mtllib` lines, relative to its folder (none for other models).
fn material_libraries(model: &Path) -> Vec<PathBuf> {
    let is_obj = model
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    let text = is_obj
        .then(|| crate::scene::file::read_text(model).ok())
        .flatten()
        .unwrap_or_default();
    let dir = parent_of(model);
    let mut libs = Vec::new();
    for line in text.lines() {
        if let Some(names) = line.trim_start().strip_prefix("mtllib ") {
            libs.extend(names.split_whitespace().map(|n| dir.join(n)));
        }
    }
    libs
}
