//! Camera control of the viewer: orbit about the look-at point, pan, zoom.
//!
//! The thesis' scene object hands every camera change to the kernels with
//! `passCameraUpdates()` (Müller 2015, ch. 3.3); here the camera is a plain
//! [`Camera`] value that the next `Tracer::render` turns into the kernel uniforms of
//! Listing 11. The operations below return a new camera and never touch an untouched one,
//! so a viewer that was not moved renders exactly the scene file's camera (bit for bit the
//! same image as `render`).

use glam::{Quat, Vec3};

use gpgpu_rt::scene::Camera;

/// The smallest angle, in degrees, between the viewing direction and the up axis that orbiting
/// keeps (looking straight up or down would leave the image orientation undefined).
pub const MIN_POLAR_DEGREES: f32 = 1.0;

/// Orbit `camera` about its look-at point: `yaw` degrees about the up axis, `pitch` degrees
/// about the camera's horizontal axis (positive: the camera moves up). The polar angle is
/// clamped to [MIN_POLAR_DEGREES, 180° − MIN_POLAR_DEGREES].
pub fn orbit(camera: &Camera, yaw: f32, pitch: f32) -> Camera {
    let target = Vec3::from(camera.look_at);
    let up = Vec3::from(camera.up).normalize();
    let offset = Vec3::from(camera.position) - target;
    let distance = offset.length();
    let dir = offset / distance;
    // yaw about the up axis
    let dir = Quat::from_axis_angle(up, yaw.to_radians()) * dir;
    // pitch: change the polar angle (angle between dir and up), clamped
    let polar = dir.dot(up).clamp(-1.0, 1.0).acos();
    let lo = MIN_POLAR_DEGREES.to_radians();
    let hi = std::f32::consts::PI - lo;
    let new_polar = (polar - pitch.to_radians()).clamp(lo, hi);
    let horizontal = (dir - up * dir.dot(up)).normalize_or_zero();
    let horizontal = if horizontal == Vec3::ZERO {
        // looking along the up axis (possible only in a scene file): pick any horizontal
        up.any_orthonormal_vector()
    } else {
        horizontal
    };
    let dir = up * new_polar.cos() + horizontal * new_polar.sin();
    Camera {
        position: (target + dir * distance).into(),
        ..*camera
    }
}

/// The camera's right and (image-)up unit vectors, as in `Camera::rays`.
fn basis(camera: &Camera) -> (Vec3, Vec3, Vec3) {
    let forward = (Vec3::from(camera.look_at) - Vec3::from(camera.position)).normalize();
    let right = forward.cross(Vec3::from(camera.up)).normalize();
    let up = right.cross(forward);
    (forward, right, up)
}

/// Move camera and look-at point sideways by `dx`, `dy` in units of the image height (a drag
/// over the whole window height moves the look-at point by the height the image plane covers
/// at the look-at distance, so the point under the cursor follows the cursor).
pub fn pan(camera: &Camera, dx: f32, dy: f32) -> Camera {
    let (_, right, up) = basis(camera);
    let distance = (Vec3::from(camera.look_at) - Vec3::from(camera.position)).length();
    let height = 2.0 * distance * (camera.fov_y.to_radians() / 2.0).tan();
    let shift = (-dx * right + dy * up) * height;
    Camera {
        position: (Vec3::from(camera.position) + shift).into(),
        look_at: (Vec3::from(camera.look_at) + shift).into(),
        ..*camera
    }
}

/// Scale the distance to the look-at point by `factor` (< 1: closer). The camera stays at
/// least twice the image-plane distance (`near`) from the look-at point.
pub fn zoom(camera: &Camera, factor: f32) -> Camera {
    if !(factor.is_finite() && factor > 0.0) {
        return *camera;
    }
    let target = Vec3::from(camera.look_at);
    let offset = Vec3::from(camera.position) - target;
    let distance = offset.length();
    let new_distance = (distance * factor).max(2.0 * camera.near);
    Camera {
        position: (target + offset * (new_distance / distance)).into(),
        ..*camera
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera {
            position: [0.0, 2.2, 4.2],
            look_at: [0.0, 0.5, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y: 45.0,
            near: 0.05,
        }
    }

    fn dist(c: &Camera) -> f32 {
        (Vec3::from(c.position) - Vec3::from(c.look_at)).length()
    }

    #[test]
    fn orbit_keeps_distance_and_target_and_full_turn_returns() {
        let c = cam();
        let o = orbit(&c, 90.0, 0.0);
        assert_eq!(o.look_at, c.look_at);
        assert!((dist(&o) - dist(&c)).abs() < 1e-5);
        // a quarter turn about +y takes +z to +x
        assert!(
            o.position[0] > 4.0 && o.position[2].abs() < 1e-4,
            "{:?}",
            o.position
        );
        assert!((o.position[1] - c.position[1]).abs() < 1e-5);
        let mut back = c;
        for _ in 0..4 {
            back = orbit(&back, 90.0, 0.0);
        }
        for k in 0..3 {
            assert!((back.position[k] - c.position[k]).abs() < 1e-4);
        }
    }

    #[test]
    fn pitch_is_clamped_short_of_the_pole() {
        let c = cam();
        let top = orbit(&c, 0.0, 500.0);
        let dir = (Vec3::from(top.position) - Vec3::from(top.look_at)).normalize();
        let polar = dir.dot(Vec3::Y).acos().to_degrees();
        assert!((polar - MIN_POLAR_DEGREES).abs() < 1e-3, "{polar}");
        assert!(top.validate().is_ok());
        let bottom = orbit(&c, 0.0, -500.0);
        let dir = (Vec3::from(bottom.position) - Vec3::from(bottom.look_at)).normalize();
        assert!((dir.dot(Vec3::Y).acos().to_degrees() - (180.0 - MIN_POLAR_DEGREES)).abs() < 1e-3);
        // pitching up moves the camera up
        assert!(orbit(&c, 0.0, 10.0).position[1] > c.position[1]);
    }

    #[test]
    fn pan_moves_camera_and_target_together_sideways() {
        let c = cam();
        let p = pan(&c, 0.5, 0.0);
        let shift = Vec3::from(p.position) - Vec3::from(c.position);
        assert_eq!(shift, Vec3::from(p.look_at) - Vec3::from(c.look_at));
        // dragging right moves the camera to the left (-x when looking down -z)
        assert!(shift.x < 0.0 && shift.y.abs() < 1e-6 && shift.z.abs() < 1e-6);
        let expected = 0.5 * 2.0 * dist(&c) * 22.5f32.to_radians().tan();
        assert!((shift.length() - expected).abs() < 1e-4);
    }

    #[test]
    fn zoom_scales_distance_and_stops_before_the_target() {
        let c = cam();
        assert!((dist(&zoom(&c, 0.5)) - 0.5 * dist(&c)).abs() < 1e-5);
        let close = zoom(&c, 1e-9);
        assert!((dist(&close) - 2.0 * c.near).abs() < 1e-5);
        assert!(close.validate().is_ok());
        assert_eq!(zoom(&c, f32::NAN), c);
    }
}
