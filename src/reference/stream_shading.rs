//! CPU twin of the streaming tracer's shading (the streaming tracer, Fig. 1's last kernel and the
//! ray generator's shadow and reflection rays: `glsl/stream/shading.frag`,
//! `glsl/stream/ray_generator.frag`): per pixel the ambient term or the background, the
//! Lambert term of every point light whose shadow ray is unblocked, and the reflection
//! bounces, each weighted as the kernels weigh them.

use glam::{Vec3, Vec4};

use super::stream_grid::{Rule, StreamRay};
use crate::pipeline::stream::grid::StreamGrid;
use crate::scene::{Scene, WorldAttributes};

/// The scene as the shading reads it.
pub struct StreamShading<'a> {
    pub grid: &'a StreamGrid,
    attributes: WorldAttributes,
    reflectivity: Vec<f32>,
    lights: Vec<(Vec3, Vec3)>,
    ambient: Vec3,
    background: Vec3,
    shadow_offset: f32,
    pub proximity_clouds: bool,
    /// shadow rays as the naive closest-hit search (`--stream-naive-shadows`): the same
    /// verdicts, more work
    pub naive_shadows: bool,
}

/// GLSL's reflect(I, N).
fn reflect(i: Vec3, n: Vec3) -> Vec3 {
    i - 2.0 * n.dot(i) * n
}

impl<'a> StreamShading<'a> {
    pub fn new(scene: &Scene, grid: &'a StreamGrid, proximity_clouds: bool) -> Self {
        let attributes = scene.world_attributes();
        let reflectivity = attributes
            .triangle_material
            .iter()
            .map(|&m| scene.materials[m as usize].reflection)
            .collect();
        StreamShading {
            grid,
            attributes,
            reflectivity,
            lights: scene.lights.iter().map(|l| (l.position, l.color)).collect(),
            ambient: Vec3::from(scene.settings.ambient),
            background: Vec3::from(scene.settings.background),
            shadow_offset: scene.settings.shadow_offset,
            proximity_clouds,
            naive_shadows: false,
        }
    }

    /// surfaceAt: position, normal turned towards the ray, diffuse colour, reflectivity.
    fn surface(&self, r: &StreamRay, t: f32, id: usize, u: f32, v: f32) -> (Vec3, Vec3, Vec3, f32) {
        let (a, k) = (&self.attributes, 3 * id);
        let w = 1.0 - u - v;
        let mut n = (w * a.normals[k] + u * a.normals[k + 1] + v * a.normals[k + 2]).normalize();
        if n.dot(r.d) > 0.0 {
            n = -n;
        }
        (r.o + t * r.d, n, a.colors[k], self.reflectivity[id])
    }

    /// The light terms at p (normal n, on triangle id): shadow rays as the ray generator makes
    /// them, the diffuse term as shading.frag.
    fn lights_at(&self, p: Vec3, n: Vec3, id: usize) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for &(position, color) in &self.lights {
            let to_light = position - p;
            let distance = to_light.length();
            if n.dot(to_light / distance) <= 0.0 {
                continue;
            }
            let feeler = StreamRay {
                o: p,
                d: to_light / distance,
                skip: id as i32,
                limit: distance,
            };
            let rule = match self.naive_shadows {
                true => Rule::NaiveShadow(self.shadow_offset),
                false => Rule::AnyHit(self.shadow_offset),
            };
            if self
                .grid
                .trace(&feeler, rule, self.proximity_clouds)
                .0
                .is_some()
            {
                continue;
            }
            let diffuse = n.dot((position - p).normalize());
            if diffuse > 0.0 {
                sum += color * diffuse;
            }
        }
        sum
    }

    /// The colour of the pixel whose primary ray is `primary`, after `refl_depth` reflection
    /// bounces (rgb, 1).
    pub fn pixel(&self, primary: StreamRay, refl_depth: u32) -> Vec4 {
        let (mut ray, mut weight, mut color) = (primary, 1.0f32, Vec3::ZERO);
        for bounce in 0..=refl_depth {
            let Some(h) = self
                .grid
                .trace(&ray, Rule::Closest, self.proximity_clouds)
                .0
            else {
                color += weight * self.background;
                break;
            };
            let (p, n, kd, refl) = self.surface(&ray, h.t, h.id, h.u, h.v);
            let local = self.ambient * kd + self.lights_at(p, n, h.id) * kd;
            color += weight * (1.0 - refl) * local;
            if refl <= 0.0 || bounce == refl_depth {
                break;
            }
            ray = StreamRay {
                o: p,
                d: reflect(ray.d, n),
                skip: h.id as i32,
                limit: f32::INFINITY,
            };
            weight *= refl;
        }
        color.extend(1.0)
    }
}
