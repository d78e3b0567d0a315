//! The pinhole camera of Müller 2015, ch. 4.1.1: an image plane at the near distance in front
//! of the camera, described to the eye-ray-generation kernel by its upper-left corner
//! (`camImgPosition`) and the spacing of neighbouring pixels (`camWidth`, `camHeight`).

use glam::{Mat4, Vec3};
use serde::Deserialize;

/// Camera of a scene file: position, look-at point, up vector, vertical field of view.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub position: [f32; 3],
    pub look_at: [f32; 3],
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    #[serde(default = "default_fov")]
    pub fov_y: f32,
    /// Distance of the image plane (the thesis' near-clipping factor); rays start there.
    #[serde(default = "default_near")]
    pub near: f32,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f32 {
    45.0
}
fn default_near() -> f32 {
    0.05
}

/// The image plane's distance for a camera from elsewhere (a glTF file's `znear`): that
/// distance where it is finite and positive, else the default. Rays start there, so a scene
/// that reaches closer to the eye is cut as by a near clipping plane.
pub fn default_near_for(znear: Option<f32>) -> f32 {
    znear
        .filter(|z| z.is_finite() && *z > 0.0)
        .unwrap_or_else(default_near)
}

/// The kernel uniforms of Listing 11, in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraRays {
    pub cam_position: Vec3,
    pub cam_img_position: Vec3,
    /// `cam_img_position − cam_position`, computed in f64 and rounded once: the rays'
    /// directions are built from it, not from the difference of two rounded world positions
    /// (which loses the image plane entirely once the camera's coordinates exceed about
    /// `near / 2⁻²³`, e.g. 0.05 / 1.2e-7 ≈ 4e5 with the default near distance).
    pub cam_img_offset: Vec3,
    pub cam_width: Vec3,
    pub cam_height: Vec3,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// Every key usable; an error names the key it is about (for its line) and says why.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let p = Vec3::from(self.position);
        let l = Vec3::from(self.look_at);
        let up = Vec3::from(self.up);
        for (key, finite) in [
            ("position", p.is_finite()),
            ("look_at", l.is_finite()),
            ("up", up.is_finite()),
            ("fov_y", self.fov_y.is_finite()),
            ("near", self.near.is_finite()),
        ] {
            if !finite {
                return Err((key, format!("camera.{key} must be finite")));
            }
        }
        if (l - p).length() <= 0.0 {
            return Err(("look_at", "camera.look_at equals camera.position".into()));
        }
        if up.length() <= 0.0 {
            return Err(("up", "camera.up is the zero vector".into()));
        }
        if (l - p).normalize().cross(up.normalize_or_zero()).length() < 1e-6 {
            return Err((
                "up",
                "camera.up is parallel to the viewing direction".into(),
            ));
        }
        if !(self.fov_y > 0.0 && self.fov_y < 180.0) {
            let m = format!("camera.fov_y = {} must lie in (0, 180) degrees", self.fov_y);
            return Err(("fov_y", m));
        }
        if self.near <= 0.0 {
            return Err((
                "near",
                format!("camera.near = {} must be positive", self.near),
            ));
        }
        Ok(())
    }

    /// The camera turned about the vertical axis through `center` by `degrees` (the thesis'
    /// ch. 5.1 protocol rotates the scene, which is the same as orbiting the camera).
    pub fn orbited(&self, center: Vec3, degrees: f32) -> Camera {
        let r = Mat4::from_rotation_y(degrees.to_radians());
        let p = center + r.transform_vector3(Vec3::from(self.position) - center);
        let l = center + r.transform_vector3(Vec3::from(self.look_at) - center);
        Camera {
            position: p.into(),
            look_at: l.into(),
            ..*self
        }
    }

    /// Image-plane vectors for a `width`×`height` image, computed in f64 and rounded once.
    pub fn rays(&self, width: u32, height: u32) -> CameraRays {
        let v = |a: [f32; 3]| glam::DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
        let pos = v(self.position);
        let forward = (v(self.look_at) - pos).normalize();
        let right = forward.cross(v(self.up)).normalize();
        let up = right.cross(forward);
        let near = self.near as f64;
        let half_h = near * (self.fov_y as f64 / 2.0).to_radians().tan();
        let half_w = half_h * width as f64 / height as f64;
        let center = pos + near * forward;
        let top_left = center - right * half_w + up * half_h;
        let f = |d: glam::DVec3| d.as_vec3();
        CameraRays {
            cam_position: f(pos),
            cam_img_position: f(top_left),
            cam_img_offset: f(top_left - pos),
            cam_width: f(right * (2.0 * half_w / width as f64)),
            cam_height: f(-up * (2.0 * half_h / height as f64)),
            width,
            height,
        }
    }
}

impl CameraRays {
    /// The primary ray of pixel (x, y), y = 0 the bottom row, exactly as the eye-ray kernel
    /// computes it in f32 (the CPU reference uses this): the origin on the image plane as
    /// Listing 11, the direction from the camera-relative offset (see `cam_img_offset`).
    pub fn primary_ray(&self, x: u32, y: u32) -> (Vec3, Vec3) {
        let xf = x as f32;
        let yf = y as f32;
        let across =
            (xf + 0.5) * self.cam_width + (self.height as f32 - yf - 0.5) * self.cam_height;
        let pixel = self.cam_img_position + across;
        (pixel, (self.cam_img_offset + across).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_corners_span_fov() {
        let cam = Camera {
            position: [0.0, 0.0, 5.0],
            look_at: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y: 90.0,
            near: 1.0,
        };
        let r = cam.rays(2, 2);
        // with 2x2 pixels the centre of the image is the shared corner of the four pixels
        let (o, d) = r.primary_ray(1, 1);
        assert!((o - Vec3::new(0.5, 0.5, 4.0)).length() < 1e-5, "{o}");
        assert!(d.z < 0.0);
        // fov 90°: the top edge of the image plane lies at height near·tan(45°) = 1
        assert!((r.cam_img_position - Vec3::new(-1.0, 1.0, 4.0)).length() < 1e-5);
        assert!((r.cam_height - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6);
    }
}
