//! The base ray tracer of Müller 2015 (ch. 3.1, 4.1): four compute kernels — eye-ray
//! generation, intersect1, intersect2 and shading — that communicate through the ray-state
//! textures, run in the render loop of Fig. 8. Every ray is tested against every triangle.

use std::sync::Arc;

use anyhow::Result;
use glam::Mat4;

use super::pipeline::{RayPipeline, Stages};
use super::{Frame, RenderOptions, Tracer};
use crate::gl::{Gl, GlInfo, ShaderSource};
use crate::scene::{Camera, Scene};

/// The brute-force intersection kernels (Listings 12–15).
struct BaseStages {
    intersect1: glow::Program,
    intersect2: glow::Program,
}

impl Stages for BaseStages {
    fn prepare_frame(&mut self, _p: &mut RayPipeline) -> Result<()> {
        Ok(())
    }

    fn intersect1(&mut self, p: &mut RayPipeline, pass: u32) {
        let prog = self.intersect1;
        p.use_program(prog);
        p.uniform_vec4(prog, "backgroundColor", p.background, 1.0);
        p.uniform_i32(prog, "storePrimaryHit", (pass == 0) as i32);
        p.uniform_i32(prog, "textures", 0);
        p.dispatch_pixels(prog, "intersect1");
    }

    fn intersect2(&mut self, p: &mut RayPipeline, light: usize) {
        let prog = self.intersect2;
        p.use_program(prog);
        p.uniform_i32(prog, "lightSource", light as i32);
        p.dispatch_pixels(prog, "intersect2");
    }
}

/// The base tracer: the shared pipeline plus the brute-force intersection kernels.
pub struct BaseTracer {
    pipeline: RayPipeline,
    stages: BaseStages,
}

impl BaseTracer {
    pub fn new(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: RenderOptions,
    ) -> Result<BaseTracer> {
        let pipeline = RayPipeline::new(gl, info, scene, shaders, options)?;
        let stages = BaseStages {
            intersect1: pipeline.compute_program("intersect1.comp", &[])?,
            intersect2: pipeline.compute_program("intersect2.comp", &[])?,
        };
        Ok(BaseTracer { pipeline, stages })
    }

    pub fn options(&self) -> &RenderOptions {
        &self.pipeline.options
    }
}

impl Tracer for BaseTracer {
    fn name(&self) -> &'static str {
        "base"
    }

    fn set_model(&mut self, object: usize, model: Mat4) {
        self.pipeline.models[object] = model;
    }

    fn output_texture(&self) -> glow::Texture {
        self.pipeline.images.final_color.texture
    }

    fn render(&mut self, camera: &Camera) -> Result<Frame> {
        self.pipeline.render(camera, &mut self.stages)
    }
}

impl Drop for BaseTracer {
    fn drop(&mut self) {
        self.pipeline.delete_program(self.stages.intersect1);
        self.pipeline.delete_program(self.stages.intersect2);
    }
}
