//! The CPU reference: the base tracer's camera, Algorithm 1, shadow feelers, reflections and
//! shading (Müller 2015, ch. 3.1 and 4.1) in plain Rust, pixel by pixel, with the same f32
//! arithmetic and the same pass structure as the kernels. It is the oracle of the tests: the
//! GPU's triangle ids, hit distances, colours and triangle-test counts are compared with it.

pub mod brute_force;
pub mod bvh;
pub mod exact_grid;
pub mod grid;
pub mod linespace;
pub mod proximity;
pub mod search;
pub mod stream_grid;
pub mod stream_shading;
pub mod thesis_grid;
pub mod wagner2018;

pub use search::{closest_among, intersect_triangle, CpuAccelerator, Feeler, Hit, MakeTwin};

use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;

use crate::frame::Aovs;
use crate::scene::{AreaLight, Camera, Scene, WorldAttributes};

/// The scene prepared for tracing on the CPU.
pub struct Reference {
    accel: Box<dyn CpuAccelerator>,
    attributes: WorldAttributes,
    materials: Vec<Vec4>,
    lights: Vec<(Vec3, Vec3)>,
    /// Per area light: its sample points (Klee's, [`linespace::light_samples`]), centre and
    /// colour; the samples as [`Reference::with_light_samples`] says.
    area_lights: Vec<(Vec<Vec3>, Vec3, Vec3)>,
    area_defs: Vec<AreaLight>,
    layers: (u32, u32, Vec<image::RgbaImage>),
    background: Vec3,
    ambient: Vec3,
    shadow_offset: f32,
}

/// What the reference computes for a frame: colour (row 0 = top), the AOVs and the test
/// counts of the two intersection kernels.
pub struct ReferenceFrame {
    pub width: u32,
    pub height: u32,
    pub color: Vec<[f32; 4]>,
    pub aovs: Aovs,
    pub intersect1_tests: u64,
    pub intersect2_tests: u64,
    /// Rays traced per kind, in [`crate::frame::RAY_KINDS`] order: primary rays, feelers
    /// towards the first light and the others (those with N·L > 0: the kernel traces no other),
    /// reflection rays.
    pub rays: [u64; 4],
}

/// GLSL's reflect(I, N).
fn reflect(i: Vec3, n: Vec3) -> Vec3 {
    i - 2.0 * n.dot(i) * n
}

impl Reference {
    /// The base tracer's reference: every ray against every triangle.
    pub fn new(scene: &Scene) -> Reference {
        Self::with_accelerator(
            scene,
            Box::new(brute_force::BruteForce::new(scene.world_triangles())),
        )
    }

    /// The reference with the closest-hit and any-hit searches of `accel`.
    pub fn with_accelerator(scene: &Scene, accel: Box<dyn CpuAccelerator>) -> Reference {
        Reference {
            accel,
            attributes: scene.world_attributes(),
            materials: scene
                .materials
                .iter()
                .map(|m| {
                    Vec4::new(
                        m.reflection,
                        m.specular,
                        m.shininess,
                        m.texture.map(|t| t as f32).unwrap_or(-1.0),
                    )
                })
                .collect(),
            lights: scene.lights.iter().map(|l| (l.position, l.color)).collect(),
            area_lights: Vec::new(),
            area_defs: scene.area_lights.clone(),
            layers: scene.texture_layers(16384),
            background: Vec3::from(scene.settings.background),
            ambient: Vec3::from(scene.settings.ambient),
            shadow_offset: scene.settings.shadow_offset,
        }
        .with_light_samples(crate::limits::defaults::LIGHT_SAMPLES)
    }

    /// The reference with `su`×`sv` feelers towards every area light (`--light-samples`).
    pub fn with_light_samples(mut self, (su, sv): (u32, u32)) -> Reference {
        self.area_lights = self
            .area_defs
            .iter()
            .map(|a| (linespace::light_samples(a, su, sv), a.center(), a.color))
            .collect();
        self
    }

    /// Bilinear lookup with repeat wrapping, as GL_LINEAR / GL_REPEAT on RGBA8 at level 0.
    fn sample(&self, layer: usize, uv: Vec2) -> Vec3 {
        let (w, h, layers) = (&self.layers.0, &self.layers.1, &self.layers.2);
        let img = &layers[layer.min(layers.len() - 1)];
        let x = uv.x * *w as f32 - 0.5;
        let y = uv.y * *h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let texel = |i: i64, j: i64| {
            let i = i.rem_euclid(*w as i64) as u32;
            let j = j.rem_euclid(*h as i64) as u32;
            let p = img.get_pixel(i, j).0;
            Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0
        };
        let (i, j) = (x0 as i64, y0 as i64);
        let top = texel(i, j).lerp(texel(i + 1, j), fx);
        let bottom = texel(i, j + 1).lerp(texel(i + 1, j + 1), fx);
        top.lerp(bottom, fy)
    }

    /// The shadow feeler of Listing 15: (in shadow, tests, whether it was traced — not when
    /// the light is behind the surface).
    fn shadowed(&self, p: Vec3, n: Vec3, last: usize, light: Vec3) -> (bool, u64, bool) {
        match Feeler::towards(p, n, last as i32, light, self.shadow_offset) {
            None => (true, 0, false),
            Some(feeler) => {
                let (shadow, tests) = self.accel.occluded(&feeler);
                (shadow, tests, true)
            }
        }
    }

    /// The shading kernel at a hit (Listing 16's loop), after the shadow feelers of
    /// intersect2 towards every point light and every sample of every area light: the colour
    /// and the lit share (the shadow AOV: an area light counts with its unblocked share).
    fn shade(&self, s: &Surface, out: &mut PixelResult) -> (Vec3, f32) {
        let phong = |l: Vec3| {
            let diffuse = s.n.dot(l).max(0.0);
            let r = reflect(-l, s.n);
            let specular = s.mat.y * r.dot(s.view).max(0.0).powf(s.mat.z);
            diffuse * s.color + Vec3::splat(specular)
        };
        let mut temp = self.ambient * s.color;
        let mut lit = 0.0;
        let mut feeler = |light: usize, target: Vec3| {
            let (shadow, tests, traced) = self.shadowed(s.p, s.n, s.id, target);
            out.tests2 += tests;
            if traced {
                out.rays[if light == 0 { 1 } else { 2 }] += 1;
            }
            shadow
        };
        for (light, &(lp, lc)) in self.lights.iter().enumerate() {
            if feeler(light, lp) {
                continue;
            }
            lit += 1.0;
            temp += lc * phong((lp - s.p).normalize());
        }
        for (a, (samples, centre, lc)) in self.area_lights.iter().enumerate() {
            let light = self.lights.len() + a;
            let open = samples.iter().filter(|&&q| !feeler(light, q)).count();
            let share = open as f32 / samples.len() as f32;
            lit += share;
            if share > 0.0 {
                temp += share * *lc * phong((*centre - s.p).normalize());
            }
        }
        let all = self.lights.len() + self.area_lights.len();
        (temp, if all == 0 { 1.0 } else { lit / all as f32 })
    }

    /// Trace one pixel through `refl_depth + 1` passes, as the kernels do.
    fn pixel(&self, camera_pos: Vec3, primary: (Vec3, Vec3), refl_depth: u32) -> PixelResult {
        let (mut ro, mut rd) = primary;
        let mut ray_state = 1.0f32;
        let mut last: i32 = -1;
        let mut final_color = Vec4::ZERO;
        let mut out = PixelResult {
            hit_t: f32::INFINITY,
            triangle_id: -1,
            normal: Vec3::ZERO,
            lit: 1.0,
            ..Default::default()
        };
        let a = &self.attributes;
        for pass in 0..=refl_depth {
            if ray_state <= 0.0 {
                break;
            }
            let (hit, tests) = self.accel.closest_hit(ro, rd, last);
            out.tests1 += tests;
            out.rays[if pass == 0 { 0 } else { 3 }] += 1;
            let (temp, weight_in) = match hit {
                None => {
                    ray_state = 0.0;
                    (self.background, 1.0)
                }
                Some(Hit { t, id, u, v }) => {
                    let w = 1.0 - u - v;
                    let k = 3 * id;
                    let mut n = (w * a.normals[k] + u * a.normals[k + 1] + v * a.normals[k + 2])
                        .normalize();
                    if n.dot(rd) > 0.0 {
                        n = -n;
                    }
                    let mat = self.materials[a.triangle_material[id] as usize];
                    let color = if mat.w >= 0.0 {
                        let uv =
                            w * a.texcoords[k] + u * a.texcoords[k + 1] + v * a.texcoords[k + 2];
                        self.sample(mat.w as usize, uv)
                    } else {
                        w * a.colors[k] + u * a.colors[k + 1] + v * a.colors[k + 2]
                    };
                    if pass == 0 {
                        out.hit_t = t;
                        out.triangle_id = id as i32;
                        out.normal = n;
                    }
                    let p = ro + t * rd;
                    let refl = mat.x;
                    if refl > 0.0 {
                        ray_state += 1.0;
                        rd = reflect(rd, n);
                    }
                    // shadow feelers and shading at p
                    let view = (camera_pos - p).normalize();
                    let surface = Surface {
                        p,
                        n,
                        id,
                        mat,
                        color,
                        view,
                    };
                    let (temp, lit) = self.shade(&surface, &mut out);
                    if pass == 0 {
                        out.lit = lit;
                    }
                    ro = p;
                    last = id as i32;
                    (temp, 1.0 - refl)
                }
            };
            // Listing 16
            let weight = final_color.w;
            let rgb = weight * final_color.truncate() + (1.0 - weight) * temp;
            final_color = rgb.extend(weight + (1.0 - weight) * weight_in);
            if ray_state > 0.0 {
                ray_state -= 1.0;
            }
        }
        out.color = final_color.to_array();
        out
    }

    /// Render a `width`×`height` frame with `refl_depth` reflection passes.
    pub fn render(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        refl_depth: u32,
    ) -> ReferenceFrame {
        let cam = camera.rays(width, height);
        let pixels: Vec<(PixelResult, (Vec3, Vec3))> = (0..height)
            .into_par_iter()
            .flat_map_iter(|row| {
                // row 0 = top: GL row height-1-row
                let y = height - 1 - row;
                (0..width).map(move |x| (x, y))
            })
            .map(|(x, y)| {
                let primary = cam.primary_ray(x, y);
                (self.pixel(cam.cam_position, primary, refl_depth), primary)
            })
            .collect();
        let mut frame = ReferenceFrame {
            width,
            height,
            color: Vec::with_capacity(pixels.len()),
            aovs: Aovs {
                shadow: Some(Vec::with_capacity(pixels.len())),
                ..Default::default()
            },
            intersect1_tests: 0,
            intersect2_tests: 0,
            rays: [0; 4],
        };
        for (p, (o, d)) in pixels {
            frame.color.push(p.color);
            frame.aovs.ray_origin.push(o.to_array());
            frame.aovs.ray_direction.push(d.to_array());
            frame.aovs.hit_t.push(p.hit_t);
            frame.aovs.triangle_id.push(p.triangle_id);
            frame.aovs.normal.push(p.normal.to_array());
            frame.aovs.shadow.as_mut().unwrap().push(p.lit);
            frame.intersect1_tests += p.tests1;
            frame.intersect2_tests += p.tests2;
            for (all, r) in frame.rays.iter_mut().zip(p.rays) {
                *all += r;
            }
        }
        frame
    }
}

/// A hit point as the shading kernel sees it.
struct Surface {
    p: Vec3,
    n: Vec3,
    id: usize,
    mat: Vec4,
    color: Vec3,
    view: Vec3,
}

#[derive(Default)]
struct PixelResult {
    color: [f32; 4],
    hit_t: f32,
    triangle_id: i32,
    normal: Vec3,
    /// the share of the lights whose feeler of the first hit is unblocked (the shadow AOV)
    lit: f32,
    tests1: u64,
    tests2: u64,
    /// rays traced per kind (see `ReferenceFrame::rays`)
    rays: [u64; 4],
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn algorithm1_hits_inside_and_misses_outside() {
        let (v0, v1, v2) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let (t, u, v) =
            intersect_triangle(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, v0, v1, v2).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (u - 0.25).abs() < 1e-6 && (v - 0.25).abs() < 1e-6);
        assert!(intersect_triangle(Vec3::new(0.75, 0.75, 1.0), -Vec3::Z, v0, v1, v2).is_none());
        // behind the origin: t < 0 is no hit
        assert!(intersect_triangle(Vec3::new(0.25, 0.25, -1.0), -Vec3::Z, v0, v1, v2).is_none());
        // parallel: det = 0
        assert!(intersect_triangle(Vec3::new(0.25, 0.25, 1.0), Vec3::X, v0, v1, v2).is_none());
    }
}
