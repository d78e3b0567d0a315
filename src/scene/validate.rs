//! One validation step over everything the GPU receives (issue 14, class 2): world-space
//! positions (the model matrix applied, as the transform pass applies it), normals (through
//! the normal matrix), colours, texture coordinates and material ids of every object, the
//! materials, the point and area lights and the render colours. NaN or inf in any of them is
//! refused with the object and the array that has it. The loaders refuse what they read with
//! file and line first; this step catches what arises later (a transform that overflows, a
//! `fit` of a tiny object) and scenes built by code.

use glam::{Vec2, Vec3};

use super::model::{Object, Scene};

/// The first index of a non-finite vector, if any.
fn first_bad3(v: impl IntoIterator<Item = Vec3>) -> Option<usize> {
    v.into_iter().position(|x| !x.is_finite())
}

fn first_bad2(v: &[Vec2]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}

/// The first vertex of a triangle with a world-space area whose world-space normal has no
/// direction (a degenerate triangle is never hit, so its normals do not matter).
fn first_zero_normal(o: &Object) -> Option<usize> {
    let m = &o.mesh;
    let nm = o.normal_matrix();
    let triangles = m.positions.chunks_exact(3).zip(m.normals.chunks_exact(3));
    for (t, (p, n)) in triangles.enumerate() {
        let world = [0, 1, 2].map(|k| o.model.transform_point3(p[k]));
        if super::mesh::face_normal(world) == Vec3::ZERO {
            continue; // no area
        }
        if let Some(k) = (0..3).find(|&k| (nm * n[k]).normalize_or_zero() == Vec3::ZERO) {
            return Some(3 * t + k);
        }
    }
    None
}

/// An object's uploaded arrays, world space, all finite, normals with a direction; material
/// ids below `materials`.
pub fn object(o: &Object, materials: usize) -> Result<(), String> {
    let m = &o.mesh;
    let nm = o.normal_matrix();
    let world = m.positions.iter().map(|p| o.model.transform_point3(*p));
    let normals = m.normals.iter().map(|n| nm * *n);
    let checks = [
        ("world-space position", first_bad3(world)),
        ("world-space normal", first_bad3(normals)),
        ("colour", first_bad3(m.colors.iter().copied())),
        ("texture coordinate", first_bad2(&m.texcoords)),
    ];
    for (what, bad) in checks {
        if let Some(i) = bad {
            return Err(format!(
                "object `{}`: vertex {i} has a non-finite {what} (nan or inf) after its \
                 transform; the numbers or the transform overflow f32",
                o.name
            ));
        }
    }
    if let Some(i) = first_zero_normal(o) {
        return Err(format!(
            "object `{}`: vertex {i} of a triangle with an area has a normal of zero length \
             after its transform (the numbers leave f32 on the way: a model in units near \
             1e-20 or 1e20?); the kernels would normalise it to NaN",
            o.name
        ));
    }
    if let Some(t) = m
        .triangle_material
        .iter()
        .position(|&k| k as usize >= materials)
    {
        return Err(format!(
            "object `{}`: triangle {t} has material {} of {materials}",
            o.name, m.triangle_material[t]
        ));
    }
    Ok(())
}

/// Everything of `scene` that is uploaded, as [`object`] for each object.
pub fn scene(s: &Scene) -> Result<(), String> {
    for o in &s.objects {
        object(o, s.materials.len())?;
    }
    for (i, m) in s.materials.iter().enumerate() {
        if ![m.reflection, m.specular, m.shininess]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(format!("material {i} has a non-finite number: {m:?}"));
        }
    }
    let lights = s.lights.iter().flat_map(|l| [l.position, l.color]);
    if let Some(i) = first_bad3(lights) {
        return Err(format!(
            "light {} has a non-finite position or colour",
            i / 2
        ));
    }
    let area = s
        .area_lights
        .iter()
        .flat_map(|a| [a.corner, a.edge_u, a.edge_v, a.color]);
    if let Some(i) = first_bad3(area) {
        return Err(format!("area light {} has a non-finite number", i / 4));
    }
    let colours = [s.settings.background, s.settings.ambient].map(Vec3::from);
    if first_bad3(colours).is_some() {
        return Err("render.background or render.ambient is not finite".into());
    }
    Ok(())
}
