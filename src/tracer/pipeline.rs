//! The render loop of Müller 2015, Fig. 8 (base tracer) and Fig. 15 (with the uniform grid):
//! the ray-state textures, the eye-ray-generation and shading kernels, the 64-bit counters and
//! timers — everything the tracer designs share. A design plugs in its intersection stages
//! (and, for the grid, the per-frame build) through [`Stages`].

use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use glam::Mat4;
use glow::HasContext;

use super::gpu_scene::{binding, GpuScene};
use super::{
    flip_rows, Aovs, Frame, FrameStats, RenderOptions, ShadowFlags, COUNTERS,
    TRIANGLE_TEST_COUNTERS,
};
use crate::gl::resources::{GpuTimers, Image2d, Ssbo};
use crate::gl::{check_error, compile_program, Defines, Gl, GlInfo, ShaderSource};
use crate::scene::{Camera, Scene};

/// Image units of the ray-state textures, shared with `glsl/common/images.glsl`.
mod unit {
    pub const RAY_ORIGIN: u32 = 0;
    pub const RAY_DIR: u32 = 1;
    pub const NORMAL: u32 = 2;
    pub const COLOR_BUFFER: u32 = 3;
    pub const SHADOW: u32 = 4;
    pub const FINAL: u32 = 5;
    pub const PRIMARY_HIT: u32 = 6;
}

/// The textures of ch. 3.1.2, cleared every frame.
pub struct RayImages {
    pub ray_origin: Image2d,
    pub ray_dir: Image2d,
    pub normal: Image2d,
    pub color_buffer: Image2d,
    pub shadow: Image2d,
    pub final_color: Image2d,
    pub primary_hit: Image2d,
}

impl RayImages {
    fn new(gl: &Gl, w: u32, h: u32, flags: ShadowFlags) -> Result<RayImages> {
        let f = glow::RGBA32F;
        let shadow = match flags {
            ShadowFlags::Rgba => glow::RGBA32F,
            ShadowFlags::Bits => glow::RGBA32UI,
        };
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
            (&self.ray_origin, unit::RAY_ORIGIN),
            (&self.ray_dir, unit::RAY_DIR),
            (&self.normal, unit::NORMAL),
            (&self.color_buffer, unit::COLOR_BUFFER),
            (&self.shadow, unit::SHADOW),
            (&self.final_color, unit::FINAL),
            (&self.primary_hit, unit::PRIMARY_HIT),
        ]
    }

    fn bind(&self, gl: &Gl) {
        for (img, u) in self.all() {
            img.bind_image(gl, u);
        }
    }

    fn clear(&self, gl: &Gl) {
        for (img, _) in self.all() {
            img.clear(gl);
        }
    }

    fn delete(&self, gl: &Gl) {
        for (img, _) in self.all() {
            img.delete(gl);
        }
    }
}

/// What a tracer design adds to the render loop.
pub trait Stages {
    /// Before the eye rays: e.g. rebuild the grid from the freshly transformed scene.
    fn prepare_frame(&mut self, p: &mut RayPipeline) -> Result<()>;
    /// The intersect1 stage of reflection pass `pass` (0: primary rays).
    fn intersect1(&mut self, p: &mut RayPipeline, pass: u32);
    /// The intersect2 stage for light `light`.
    fn intersect2(&mut self, p: &mut RayPipeline, light: usize);
    /// Add design-specific facts to the frame's statistics.
    fn finish_stats(&mut self, _stats: &mut FrameStats) {}
}

/// The shared part of every tracer: scene on the GPU, ray-state textures, eye-ray generation,
/// shading, counters and timers.
pub struct RayPipeline {
    pub gl: Arc<Gl>,
    pub scene: GpuScene,
    pub images: RayImages,
    eye_ray_generation: glow::Program,
    shading: glow::Program,
    counters: Ssbo,
    pub timers: GpuTimers,
    pub options: RenderOptions,
    pub lights: usize,
    pub background: [f32; 3],
    ambient: [f32; 3],
    renderer: String,
    /// Model matrix per object, applied by the transform pass every frame.
    pub models: Vec<Mat4>,
    /// `#define`s every kernel of this tracer gets.
    pub defines: Defines,
    pub shaders: ShaderSource,
}

/// `#define`s every kernel gets: counter slots and the shadow-flag layout.
pub fn kernel_defines(scene: &Scene, options: &RenderOptions) -> Defines {
    let mut d = Defines::new()
        .set(
            "SHADOW_BITS",
            (options.shadow_flags == ShadowFlags::Bits) as i32,
        )
        .set(
            "SHADOW_OFFSET",
            format!("{:?}", scene.settings.shadow_offset),
        );
    for (i, c) in COUNTERS.iter().enumerate() {
        d = d.set(&format!("COUNTER_{}", c.to_uppercase()), i);
    }
    d
}

impl RayPipeline {
    pub fn new(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: RenderOptions,
    ) -> Result<RayPipeline> {
        if scene.lights.len() > options.shadow_flags.max_lights() {
            bail!(
                "{}: {} lights, but --shadow-flags {} holds at most {} (use --shadow-flags bits)",
                scene.path.display(),
                scene.lights.len(),
                match options.shadow_flags {
                    ShadowFlags::Rgba => "rgba",
                    ShadowFlags::Bits => "bits",
                },
                options.shadow_flags.max_lights()
            );
        }
        let max_tex = info.max_texture_size as u32;
        if options.width == 0
            || options.height == 0
            || options.width > max_tex
            || options.height > max_tex
        {
            bail!(
                "image size {}x{} outside 1..={} (GL_MAX_TEXTURE_SIZE)",
                options.width,
                options.height,
                max_tex
            );
        }
        if !options.tile.is_multiple_of(8) {
            bail!(
                "--tile {} must be a multiple of 8 (the kernels' work group size)",
                options.tile
            );
        }
        let gpu_scene = GpuScene::new(&gl, info, scene, shaders)?;
        let defines = kernel_defines(scene, &options);
        let compute =
            |name: &str| compile_program(&gl, shaders, &[(glow::COMPUTE_SHADER, name)], &defines);
        let counters = Ssbo::new(
            &gl,
            "counters",
            8 * COUNTERS.len(),
            None,
            info.max_ssbo_block_size,
        )?;
        let p = RayPipeline {
            eye_ray_generation: compute("eye_ray_generation.comp")?,
            shading: compute("shading.comp")?,
            images: RayImages::new(&gl, options.width, options.height, options.shadow_flags)?,
            scene: gpu_scene,
            counters,
            timers: GpuTimers::default(),
            lights: scene.lights.len(),
            background: scene.settings.background,
            ambient: scene.settings.ambient,
            models: scene.objects.iter().map(|o| o.model).collect(),
            options,
            renderer: info.renderer.clone(),
            defines,
            shaders: shaders.clone(),
            gl,
        };
        check_error(&p.gl, "creating the ray pipeline")?;
        Ok(p)
    }

    /// Compile a compute kernel of this tracer with the shared defines plus `extra`.
    pub fn compute_program(&self, name: &str, extra: &[(&str, String)]) -> Result<glow::Program> {
        let mut d = self.defines.clone();
        for (k, v) in extra {
            d = d.set(k, v);
        }
        compile_program(&self.gl, &self.shaders, &[(glow::COMPUTE_SHADER, name)], &d)
    }

    pub fn uniform_vec4(&self, program: glow::Program, name: &str, v: [f32; 3], w: f32) {
        // SAFETY: setting a uniform of the program in use.
        unsafe {
            let loc = self.gl.get_uniform_location(program, name);
            self.gl.uniform_4_f32(loc.as_ref(), v[0], v[1], v[2], w);
        }
    }

    pub fn uniform_i32(&self, program: glow::Program, name: &str, v: i32) {
        // SAFETY: setting a uniform of the program in use.
        unsafe {
            let loc = self.gl.get_uniform_location(program, name);
            self.gl.uniform_1_i32(loc.as_ref(), v);
        }
    }

    pub fn use_program(&self, p: glow::Program) {
        // SAFETY: binding one of our programs.
        unsafe { self.gl.use_program(Some(p)) };
    }

    /// Dispatch `program` (in use) over the image in tiles, timed under `name`, followed by a
    /// barrier.
    pub fn dispatch_pixels(&mut self, program: glow::Program, name: &'static str) {
        let (w, h) = (self.options.width, self.options.height);
        let tile = if self.options.tile == 0 {
            w.max(h)
        } else {
            self.options.tile
        };
        let gl = self.gl.clone();
        // SAFETY: uniform lookup on our program.
        let loc = unsafe { gl.get_uniform_location(program, "tileOffset") };
        for ty in (0..h).step_by(tile as usize) {
            for tx in (0..w).step_by(tile as usize) {
                let (tw, th) = (tile.min(w - tx), tile.min(h - ty));
                self.timers.time(&gl, name, || unsafe {
                    // SAFETY: dispatch of the program in use.
                    gl.uniform_2_i32(loc.as_ref(), tx as i32, ty as i32);
                    gl.dispatch_compute(tw.div_ceil(8), th.div_ceil(8), 1);
                });
            }
        }
        barrier(&gl);
    }

    /// Dispatch `program` (in use) with `groups` one-dimensional work groups, timed under
    /// `name`, followed by a barrier.
    pub fn dispatch_1d(&mut self, name: &'static str, groups: u32) {
        let gl = self.gl.clone();
        if groups > 0 {
            // SAFETY: dispatch of the program in use.
            self.timers
                .time(&gl, name, || unsafe { gl.dispatch_compute(groups, 1, 1) });
        }
        barrier(&gl);
    }

    /// Render one frame with the render loop of Fig. 8 / Fig. 15.
    pub fn render(&mut self, camera: &Camera, stages: &mut dyn Stages) -> Result<Frame> {
        let start = Instant::now();
        let gl = self.gl.clone();
        let (w, h) = (self.options.width, self.options.height);
        let cam = camera.rays(w, h);
        // the scene data is transformed into the SSBOs at the start of every frame
        self.scene.transform(&gl, &mut self.timers, &self.models);
        self.scene.bind(&gl);
        self.counters.bind(&gl, binding::COUNTERS);
        self.counters.clear_u32(&gl, 0);
        stages.prepare_frame(self)?;
        self.images.clear(&gl);
        self.images.bind(&gl);

        let p = self.eye_ray_generation;
        self.use_program(p);
        self.uniform_vec4(p, "camPosition", cam.cam_position.into(), 1.0);
        self.uniform_vec4(p, "camImgPosition", cam.cam_img_position.into(), 1.0);
        self.uniform_vec4(p, "camWidth", cam.cam_width.into(), 0.0);
        self.uniform_vec4(p, "camHeight", cam.cam_height.into(), 0.0);
        self.dispatch_pixels(p, "eye_ray_generation");

        let mut aovs = None;
        if self.options.aovs {
            let o = self.images.ray_origin.read_f32(&gl);
            let d = self.images.ray_dir.read_f32(&gl);
            aovs = Some(Aovs {
                ray_origin: flip_rows(&o, w, h)
                    .iter()
                    .map(|v| [v[0], v[1], v[2]])
                    .collect(),
                ray_direction: flip_rows(&d, w, h)
                    .iter()
                    .map(|v| [v[0], v[1], v[2]])
                    .collect(),
                ..Default::default()
            });
        }

        for pass in 0..=self.options.refl_depth {
            stages.intersect1(self, pass);
            // the shadow flags of this pass
            self.images.shadow.clear(&gl);
            for light in 0..self.lights {
                stages.intersect2(self, light);
            }
            let p = self.shading;
            self.use_program(p);
            self.uniform_vec4(p, "camPosition", cam.cam_position.into(), 1.0);
            self.uniform_vec4(p, "ambientColor", self.ambient, 1.0);
            self.uniform_i32(p, "lightCount", self.lights as i32);
            self.dispatch_pixels(p, "shading");

            if pass == 0 {
                if let Some(a) = aovs.as_mut() {
                    let hit = flip_rows(&self.images.primary_hit.read_f32(&gl), w, h);
                    let n = flip_rows(&self.images.normal.read_f32(&gl), w, h);
                    a.hit_t = hit.iter().map(|v| v[0]).collect();
                    a.triangle_id = hit.iter().map(|v| v[1].to_bits() as i32).collect();
                    a.normal = n.iter().map(|v| [v[0], v[1], v[2]]).collect();
                }
            }
        }

        let color = flip_rows(&self.images.final_color.read_f32(&gl), w, h);
        let raw = self.counters.read_u32(&gl);
        let mut stats = FrameStats {
            gpu_ms: self.timers.resolve(&gl),
            ..Default::default()
        };
        for (i, name) in COUNTERS.iter().enumerate() {
            let v = raw[2 * i] as u64 | ((raw[2 * i + 1] as u64) << 32);
            if TRIANGLE_TEST_COUNTERS.contains(name) {
                stats.triangle_tests.insert(name.to_string(), v);
            } else if *name == "truncated_rays" {
                stats.truncated_rays = v;
            } else {
                stats.events.insert(name.to_string(), v);
            }
        }
        stages.finish_stats(&mut stats);
        if stats.truncated_rays > 0 {
            bail!(
                "{} shader loops stopped early: this GL implementation ({}) ends long shader loops \
                 (Mesa llvmpipe: 65535 iterations per invocation); the frame would be wrong",
                stats.truncated_rays,
                self.renderer
            );
        }
        check_error(&gl, "rendering a frame").map_err(|e| anyhow!("{e:#}"))?;
        stats.wall_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(Frame {
            width: w,
            height: h,
            color,
            aovs,
            stats,
        })
    }

    /// Delete a program of a stage.
    pub fn delete_program(&self, p: glow::Program) {
        // SAFETY: deleting a program we made.
        unsafe { self.gl.delete_program(p) };
    }
}

/// A barrier so the next kernel sees this kernel's image and buffer writes.
pub fn barrier(gl: &Gl) {
    // SAFETY: glMemoryBarrier on a current context.
    unsafe {
        gl.memory_barrier(
            glow::SHADER_IMAGE_ACCESS_BARRIER_BIT
                | glow::SHADER_STORAGE_BARRIER_BIT
                | glow::BUFFER_UPDATE_BARRIER_BIT,
        )
    };
}

impl Drop for RayPipeline {
    fn drop(&mut self) {
        let gl = self.gl.clone();
        self.scene.delete(&gl);
        self.images.delete(&gl);
        self.counters.delete(&gl);
        self.timers.delete(&gl);
        self.delete_program(self.eye_ray_generation);
        self.delete_program(self.shading);
    }
}
