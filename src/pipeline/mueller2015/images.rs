//! The ray-state textures of Müller 2015 ch. 3.1.2, bound to the image units of
//! `glsl/common/images.glsl` ([`crate::gl::slots::image`]) and cleared every frame — and the
//! copies of the primary rays, normals and shadow flags kept for the AOVs.

use std::sync::Arc;

use anyhow::Result;

use super::options::ShadowFlags;
use crate::frame::{flip_rows, flip_xyz, Aovs};
use crate::gl::resources::Image2d;
use crate::gl::slots::image;
use crate::gl::Gl;

/// The textures of ch. 3.1.2.
pub struct RayImages {
    pub ray_origin: Image2d,
    pub ray_dir: Image2d,
    pub normal: Image2d,
    pub color_buffer: Image2d,
    pub shadow: Image2d,
    pub final_color: Image2d,
    /// ours: (t, triangle id, u, v) of the first hit, written in the first pass (AOVs)
    pub primary_hit: Image2d,
}

impl RayImages {
    pub fn new(gl: &Arc<Gl>, w: u32, h: u32, flags: ShadowFlags) -> Result<RayImages> {
        let f = glow::RGBA32F;
        let shadow = flags.format();
        Ok(RayImages {
            ray_origin: Image2d::new(gl, w, h, f)?,
            ray_dir: Image2d::new(gl, w, h, f)?,
            normal: Image2d::new(gl, w, h, f)?,
            color_buffer: Image2d::new(gl, w, h, f)?,
            shadow: Image2d::new(gl, w, h, shadow)?,
            final_color: Image2d::new(gl, w, h, f)?,
            primary_hit: Image2d::new(gl, w, h, f)?,
        })
    }

    fn all(&self) -> [(&Image2d, u32); 7] {
        [
            (&self.ray_origin, image::RAY_ORIGIN),
            (&self.ray_dir, image::RAY_DIR),
            (&self.normal, image::NORMAL),
            (&self.color_buffer, image::COLOR_BUFFER),
            (&self.shadow, image::SHADOW),
            (&self.final_color, image::FINAL),
            (&self.primary_hit, image::PRIMARY_HIT),
        ]
    }

    pub fn bind(&self, gl: &Gl) {
        for (img, unit) in self.all() {
            img.bind_image(gl, unit);
        }
    }

    pub fn clear(&self, gl: &Gl) {
        for (img, _) in self.all() {
            img.clear(gl);
        }
    }
}

/// The primary rays, and the first hits' normals and shadow flags, copied on the GPU while a
/// frame runs (the ray-state textures are overwritten by the reflection passes), read back on
/// demand.
pub struct AovImages {
    ray_origin: Image2d,
    ray_dir: Image2d,
    normal: Image2d,
    shadow: Image2d,
    flags: ShadowFlags,
    /// Point lights, area lights, samples per area light (see [`super::shadow_slots`]).
    lights: (usize, usize, usize),
}

impl AovImages {
    pub fn new(
        gl: &Arc<Gl>,
        w: u32,
        h: u32,
        flags: ShadowFlags,
        lights: (usize, usize, usize),
    ) -> Result<AovImages> {
        Ok(AovImages {
            ray_origin: Image2d::new(gl, w, h, glow::RGBA32F)?,
            ray_dir: Image2d::new(gl, w, h, glow::RGBA32F)?,
            normal: Image2d::new(gl, w, h, glow::RGBA32F)?,
            shadow: Image2d::new(gl, w, h, flags.format())?,
            flags,
            lights,
        })
    }

    /// After the eye rays: keep them.
    pub fn keep_rays(&self, gl: &Gl, images: &RayImages) {
        self.ray_origin.copy_from(gl, &images.ray_origin);
        self.ray_dir.copy_from(gl, &images.ray_dir);
    }

    /// After the first pass: keep the normals and the shadow flags of the first hits.
    pub fn keep_first_hits(&self, gl: &Gl, images: &RayImages) {
        self.normal.copy_from(gl, &images.normal);
        self.shadow.copy_from(gl, &images.shadow);
    }

    /// Per pixel, the share of the lights whose shadow feeler of the first pass was not
    /// blocked (a light behind the surface counts as blocked, as Listing 15 treats it), an
    /// area light counting with the share of its samples' feelers unblocked; 1 where the
    /// primary ray missed (no feelers) or the scene has no lights. GL row order.
    fn lit_share(&self, gl: &Gl) -> Vec<f32> {
        let (n, areas, samples) = self.lights;
        match self.flags {
            ShadowFlags::Bits => self
                .shadow
                .read_u32(gl)
                .iter()
                .map(|f| lit_share_of_bits(f, n, areas, samples))
                .collect(),
            ShadowFlags::Rgba => self
                .shadow
                .read_f32(gl)
                .iter()
                .map(|f| {
                    let blocked = f[..n.min(4)].iter().filter(|&&c| c > 0.5).count();
                    if n == 0 {
                        1.0
                    } else {
                        (n - blocked) as f32 / n as f32
                    }
                })
                .collect(),
        }
    }

    /// The AOVs of the last frame, row 0 = the top image row.
    pub fn read(&self, gl: &Gl, primary_hit: &Image2d) -> Aovs {
        let (w, h) = (self.normal.width, self.normal.height);
        let hit = flip_rows(&primary_hit.read_f32(gl), w, h);
        Aovs {
            ray_origin: flip_xyz(&self.ray_origin.read_f32(gl), w, h),
            ray_direction: flip_xyz(&self.ray_dir.read_f32(gl), w, h),
            hit_t: hit.iter().map(|v| v[0]).collect(),
            triangle_id: hit.iter().map(|v| v[1].to_bits() as i32).collect(),
            normal: flip_xyz(&self.normal.read_f32(gl), w, h),
            shadow: Some(flip_rows(&self.lit_share(gl), w, h)),
        }
    }
}

/// The lit share of one pixel's bitwise flags: `lights` point lights with a bit each, then
/// `areas` area lights with `samples` bits each (`super::shadow_slots`).
pub fn lit_share_of_bits(flags: &[u32; 4], lights: usize, areas: usize, samples: usize) -> f32 {
    let set = |s: usize| flags[s >> 5] >> (s & 31) & 1 == 1;
    let points = (0..lights).filter(|&l| !set(l)).count() as f32;
    let area_share: f32 = (0..areas)
        .map(|a| {
            let first = lights + a * samples;
            let open = (first..first + samples).filter(|&s| !set(s)).count();
            open as f32 / samples as f32
        })
        .sum();
    match lights + areas {
        0 => 1.0,
        all => (points + area_share) / all as f32,
    }
}
