//! Magnitudes f32 can shade: a scene is refused, with the object, its extent and the limit,
//! before anything is uploaded, when its coordinates are too large for the kernels' f32
//! arithmetic to give a right image.
//!
//! Two bounds, both on world-space coordinates (after the objects' transforms):
//! - **Dynamic range.** Every vertex and the camera's position lie within
//!   [`MAX_RANGE`] = 2²⁰ times the viewing distance (camera position to look-at) of the
//!   origin. Möller–Trumbore's `t` and the hit point carry an error of about 2⁻²³ times the
//!   coordinates of the triangle's vertices relative to the ray origin, so a floor scaled far
//!   beyond the viewing distance puts its hit points above or below itself and shadows itself
//!   (measured on `teapot1.toml` with a one-colour floor at 96²: floor sizes 5e3 … 5e8, up to
//!   1.1e8 viewing distances, render the same image as size 5e3; sizes 5e9 and 5e10 leave
//!   62–65 % of the pixels wrong, flat ambient). 2²⁰ keeps two decades below the first failure.
//! - **Overflow and underflow.** Every coordinate, lights included, is at most [`MAX_COORD`] =
//!   2⁶⁰ ≈ 1.2e18 in magnitude (the kernels square distances — `det`, `length` — and f32 ends at
//!   3.4e38, so a light at 3e19 was ignored), and the viewing distance is at least
//!   [`MIN_VIEW`] = 2⁻⁴⁰ ≈ 9.1e-13 (below, the products of edge lengths fall under f32's
//!   smallest normal number, 1.2e-38, and every `det` becomes 0: no hits).
//!
//! Lights take only the second bound: their positions enter only as directions and distances,
//! so a distant light (a sun) shades right.

use std::path::Path;

use glam::Vec3;

use super::model::{Scene, SceneError};

/// Largest ratio of a coordinate (vertex or camera) to the viewing distance.
pub const MAX_RANGE: f32 = 1048576.0; // 2^20
/// Largest magnitude of any coordinate.
pub const MAX_COORD: f32 = 1.152_921_5e18; // 2^60
/// Smallest viewing distance.
pub const MIN_VIEW: f32 = 9.094_947e-13; // 2^-40

/// The largest coordinate magnitude of a set of points.
fn largest(points: impl IntoIterator<Item = Vec3>) -> f32 {
    points
        .into_iter()
        .fold(0.0f32, |m, p| m.max(p.abs().max_element()))
}

/// Refuse a scene whose magnitudes f32 cannot shade (see the module's comment).
pub fn check(scene: &Scene) -> Result<(), SceneError> {
    let at = |m: String| SceneError::at(&scene.path, None, m);
    let view = viewing_distance(scene);
    if view.is_nan() || view < MIN_VIEW {
        return Err(at(format!(
            "the camera looks {view:.3e} ahead (camera.position to look_at); at least {MIN_VIEW:.3e} \
             (2^-40) is needed, below that the kernels' f32 products underflow: scale the scene up"
        )));
    }
    let camera = largest([Vec3::from(scene.camera.position)]);
    check_one(&scene.path, "camera.position", camera, view)?;
    for o in &scene.objects {
        let m = largest(
            o.mesh
                .positions
                .iter()
                .map(|p| o.model.transform_point3(*p)),
        );
        check_one(&scene.path, &format!("object '{}'", o.name), m, view)?;
    }
    for (k, l) in scene.lights.iter().enumerate() {
        let m = largest([l.position]);
        if m > MAX_COORD {
            return Err(at(format!(
                "light {} lies at {m:.3e}, beyond {MAX_COORD:.3e} (2^60): the kernels' f32 distances \
                 to it overflow",
                k + 1
            )));
        }
    }
    Ok(())
}

fn viewing_distance(scene: &Scene) -> f32 {
    let c = &scene.camera;
    let d =
        glam::DVec3::from(c.look_at.map(f64::from)) - glam::DVec3::from(c.position.map(f64::from));
    d.length() as f32
}

/// One object's (or the camera's) largest coordinate `m` against both bounds.
fn check_one(path: &Path, what: &str, m: f32, view: f32) -> Result<(), SceneError> {
    let limit = (MAX_RANGE * view).min(MAX_COORD);
    if m <= limit {
        return Ok(());
    }
    let why = if limit == MAX_COORD {
        format!("{MAX_COORD:.3e} (2^60), beyond which the kernels' f32 products overflow")
    } else {
        format!(
            "2^20 × the viewing distance {view:.3e} (camera.position to look_at) = {limit:.3e}: \
             f32 hit points that far out err by more than the image can hide"
        )
    };
    Err(SceneError::at(
        path,
        None,
        format!(
            "{what} reaches a coordinate of {m:.3e} in world space, beyond {why}; scale the \
             scene down or move the camera back"
        ),
    ))
}
