//! The bench's only door to the library's GPU side: the GL context and kernel sources, Müller
//! 2015's ray tracer with an accelerator (`pipeline::mueller2015::RayTracer`, `RenderOptions`,
//! `GridOptions`) and Klee 2016's soft-shadow renderer (`SoftShadowRenderer`,
//! `SoftShadowOptions`), both driven through the `Renderer` interface. Everything
//! else in the bench speaks the bench's own terms: a [`Config`] and the command line in, a
//! [`FrameStats`] (and for soft shadows a [`ShadowFrame`]) out. When the library's renderer API
//! changes, this file is the one to adapt.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use glam::Mat4;

use super::args::BenchArgs;
use super::config::{BvhVariant, Config, Sizing};
use gpgpu_rt::accel::{Accel, ThesisGridOptions};
use gpgpu_rt::design::Design;
use gpgpu_rt::gl::{GlContext, GlInfo, ShaderSource};
use gpgpu_rt::pipeline::klee2016::{SoftShadowOptions, SoftShadowRenderer};
use gpgpu_rt::pipeline::mueller2015::{RenderOptions, ShadowFlags};
use gpgpu_rt::pipeline::stream::StreamOptions;
use gpgpu_rt::pipeline::wagner2018::WagnerOptions;
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::reference::linespace::LinespaceShadows;
use gpgpu_rt::scene::{Camera, Scene, ShadowMode};

pub use gpgpu_rt::frame::{Frame, FrameStats};

/// The GL context and where the kernels come from.
pub struct Gpu {
    ctx: GlContext,
    shaders: ShaderSource,
}

impl Gpu {
    /// Open EGL device `device` (`None`: the first with GL 4.5 core) with the kernels of
    /// `glsl_dir` (`None`: the copies built into the binary).
    pub fn open(device: Option<usize>, glsl_dir: Option<PathBuf>) -> Result<Gpu> {
        let shaders = ShaderSource::from_dir(glsl_dir)?;
        let ctx = GlContext::headless(device)?;
        Ok(Gpu { ctx, shaders })
    }

    /// The GL implementation: vendor, renderer, version, EGL device.
    pub fn info(&self) -> &GlInfo {
        &self.ctx.info
    }
}

/// The thesis grid's default list lengths: triangle ids per voxel, voxel ids per ray (`None`:
/// 3·N).
pub fn grid_list_defaults() -> (u32, Option<u32>) {
    let d = ThesisGridOptions::default();
    (d.voxel_array_length, d.ray_array_length)
}

/// The BVH variants the Wagner protocols measure (`bench wagner-a1`, `wagner-a2`, unless
/// `--bvh-variants` says otherwise): ours in Müller's pipeline and Wagner's megakernel.
pub const BVH_VARIANTS: &[BvhVariant] = &[BvhVariant::Sah, BvhVariant::Wagner];

/// The design of configuration `c` (its tracer's, each protocol's configuration pinned there)
/// at the configuration's size and reflection depth, with the command line's `--tile` and
/// list lengths, the thesis' RGBA shadow flags; the first hits kept where the configuration is
/// judged against the CPU reference.
fn design(c: &Config, args: &BenchArgs) -> Design {
    let (width, height, aovs) = (c.width, c.height, c.judge);
    match c.tracer.0.clone() {
        Design::Mueller2015(o) => Design::Mueller2015(RenderOptions {
            tile: args.tile,
            shadow_flags: ShadowFlags::Rgba,
            aovs,
            ..RenderOptions::new(with_lists(o.accel, args), width, height, c.refl_depth)
        }),
        Design::Wagner2018(_) => Design::Wagner2018(WagnerOptions {
            width,
            height,
            tile: args.tile,
            aovs,
        }),
        Design::Stream(o) => Design::Stream(StreamOptions {
            width,
            height,
            refl_depth: c.refl_depth,
            aovs,
            ..o
        }),
        Design::Klee2016(_) => unreachable!("the soft shadows are measured by their own protocols"),
    }
}

/// The thesis grid with the command line's list lengths, where it gives them.
fn with_lists(accel: Accel, args: &BenchArgs) -> Accel {
    match accel {
        Accel::ThesisGrid(o) => Accel::ThesisGrid(ThesisGridOptions {
            voxel_array_length: args.grid.voxel_array_length.unwrap_or(o.voxel_array_length),
            ray_array_length: args.grid.ray_array_length.or(o.ray_array_length),
            ..o
        }),
        other => other,
    }
}

/// A ray tracer made for one scene (Müller 2015's pipeline with the base tracer, the grid or
/// the SAH BVH).
pub struct RayTracer(Box<dyn Renderer>);

impl RayTracer {
    /// The tracer of configuration `c` (with the command line's `--tile` and list lengths):
    /// compile the kernels and upload `scene`.
    pub fn new(gpu: &Gpu, scene: &Scene, c: &Config, args: &BenchArgs) -> Result<RayTracer> {
        let (gl, info) = (gpu.ctx.gl.clone(), &gpu.ctx.info);
        let tracer = design(c, args).renderer(gl, info, scene, &gpu.shaders)?;
        Ok(RayTracer(tracer))
    }

    /// Place object `object` (index in the scene's objects) for the next frames.
    pub fn set_model(&mut self, object: usize, model: Mat4) -> Result<()> {
        self.0.set_model(object, model)
    }

    /// Render a frame seen from `camera` and read it back (with the first hits where the
    /// configuration is judged), its colour written to `png`.
    pub fn render_frame(&mut self, camera: &Camera, png: &Path) -> Result<Frame> {
        let frame = self.0.render(camera)?;
        gpgpu_rt::output::write_image(png, &frame)?;
        Ok(frame)
    }

    /// Render a frame seen from `camera`, write its colour to `png` if given, and return its
    /// statistics.
    pub fn render(&mut self, camera: &Camera, png: Option<&Path>) -> Result<FrameStats> {
        let Some(path) = png else {
            return self.0.draw(camera);
        };
        let frame = self.0.render(camera)?;
        gpgpu_rt::output::write_image(path, &frame)?;
        Ok(frame.stats)
    }
}

/// A frame of the soft-shadow renderer: its statistics and the G-buffer (row 0 = top).
pub struct ShadowFrame {
    pub stats: FrameStats,
    /// World-space position per pixel, w = 1 where geometry was hit.
    pub gbuffer_position: Vec<[f32; 4]>,
    /// Normal per pixel (xyz).
    pub gbuffer_normal: Vec<[f32; 4]>,
}

/// Klee 2016's soft-shadow renderer for one scene: the N-tree (N = 10, `levels` levels counting
/// the root: 3 or 4, the two readings of the thesis' "maximale Tiefe von 3") and its line spaces
/// built once; mode and light samples switchable.
pub struct SoftShadows(SoftShadowRenderer);

impl SoftShadows {
    /// Build the N-tree of `scene` and the renderer for the image size of `s`, 2×2 samples,
    /// dispatches of at most `tile`×`tile` pixels, an N-tree of `levels` levels (root included).
    pub fn new(gpu: &Gpu, scene: &Scene, s: Sizing, tile: u32, levels: u32) -> Result<Self> {
        let options = SoftShadowOptions {
            mode: ShadowMode::Linespace,
            samples_u: 2,
            samples_v: 2,
            ntree_n: 10,
            ntree_depth: levels,
            shading: Default::default(),
            linespace_build: Default::default(),
            width: s.width,
            height: s.height,
            tile,
        };
        let (gl, info) = (gpu.ctx.gl.clone(), &gpu.ctx.info);
        SoftShadowRenderer::new(gl, info, scene, &gpu.shaders, options)
            .map(SoftShadows)
            .with_context(|| format!("{}: soft-shadow renderer", scene.path.display()))
    }

    /// Switch the shadow mode and the light samples (su × sv shadow rays per pixel).
    pub fn configure(&mut self, gpu: &Gpu, mode: ShadowMode, su: u32, sv: u32) -> Result<()> {
        self.0.reconfigure(&gpu.shaders, mode, su, sv)
    }

    /// Render a frame seen from `camera`.
    pub fn render(&mut self, camera: &Camera) -> Result<ShadowFrame> {
        let stats = self.0.draw(camera)?;
        let (gbuffer_position, gbuffer_normal) = self.0.read_gbuffer();
        Ok(ShadowFrame {
            stats,
            gbuffer_position,
            gbuffer_normal,
        })
    }

    /// The CPU implementation over the same N-tree and light.
    pub fn cpu(&self) -> LinespaceShadows<'_> {
        self.0.cpu()
    }

    /// Bytes of the N-tree's node pool and of its line spaces.
    pub fn memory(&self) -> (usize, usize) {
        (self.0.ntree_bytes(), self.0.linespace_bytes())
    }
}
