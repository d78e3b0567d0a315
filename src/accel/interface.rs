//! What an accelerator of Müller 2015's pipeline is and gets: the [`Accelerator`] trait and its
//! one optional hook's [`PassHost`], the contexts of its making and of a frame, the shadow
//! feelers' target, and its [`Entry`] in the registry. Below every accelerator, which all
//! implement it.

use std::any::Any;
use std::sync::Arc;

use super::options::Accel;
use anyhow::Result;
use glam::{Mat4, Vec3};

use crate::frame::FrameStats;
use crate::gl::resources::GpuTimers;
use crate::gl::{Defines, Gl, GlInfo, Kernel, PixelGrid, ShaderSource};
use crate::scene::{CameraRays, Scene};

/// Pixels each invocation of `glsl/bvh/pixel_counts.comp` sums (its `PIXELS_PER_INVOCATION`,
/// a #define of `pipeline::mueller2015::records`), for the accelerators whose kernels store
/// per-pixel counts ([`Accelerator::records`]).
pub const PIXELS_PER_INVOCATION: u32 = 16;
/// The most events one pixel's walk may count (node visits, triangle tests) so that the sums of
/// `pixels` pixels (one invocation of `pixel_counts.comp`: [`PIXELS_PER_INVOCATION`], or over
/// the fused pass' block lists an 8×8 block's) fit in 32 bits: such an accelerator checks its
/// structure against it. (A work group's sum of those sums carries into the counter's high
/// word: `glsl/common/counters.glsl`.)
pub const fn max_pixel_events(pixels: u32) -> u64 {
    (1 << 32) / pixels as u64 - 1
}

/// The GPU side of an accelerator.
pub trait Accelerator {
    /// Rebuild from the freshly transformed scene, before the eye rays (the grids: every
    /// frame, Fig. 15; brute force: nothing).
    fn build(&mut self, f: &mut FrameContext) -> Result<()>;
    /// Prepare intersect1 of reflection pass `pass` (0: primary rays): run any kernel that
    /// must come first, bind the design's buffers, put its intersect1 kernel in use with the
    /// design's uniforms set, and return it. The pipeline sets the shared uniforms and
    /// dispatches it over the image.
    fn closest_hit(&mut self, f: &mut FrameContext, pass: u32) -> &Kernel;
    /// The same for intersect2, the shadow feelers towards `target` (any hit): a point light,
    /// or one sample of an area light. A design that dispatches before returning (a traversal
    /// pass, the base tracer's split) sets the target's uniforms on its kernels first.
    fn occluded(&mut self, f: &mut FrameContext, target: &LightTarget) -> &Kernel;
    /// Add the design's facts (sizes, build time, settings) and events to the statistics.
    fn stats(&self, stats: &mut FrameStats);
    /// The one optional hook, ours: pass `pass` of Fig. 8 — the closest hit, the shadow
    /// feelers, the shading — in the accelerator's own kernels (the SAH BVH's fused pass),
    /// with the pipeline's part done through `host`; how it ran, for the pipeline to add its
    /// counts. `eye`: the camera where the pass computes its eye rays in place instead of
    /// loading the eye-ray kernel's texels. `None`: the accelerator has none (or was made
    /// without it), and the pipeline runs its four kernels.
    fn fused_pass(
        &mut self,
        _f: &mut FrameContext,
        _pass: u32,
        _eye: Option<&CameraRays>,
        _host: &dyn PassHost,
    ) -> Option<FusedRun> {
        None
    }
    /// For tests and inspection: the concrete type.
    fn as_any(&self) -> &dyn Any;
}

/// What the pipeline does in a fused pass ([`Accelerator::fused_pass`]) at the accelerator's
/// call: the part of the four kernels the pass stands for that is the pipeline's.
pub trait PassHost {
    /// Set the pipeline's uniforms of the pass (background, stores, camera position, ambient
    /// light, area lights) on `kernel`, in use.
    fn set_uniforms(&self, kernel: &Kernel);
    /// From here on the work is the frame's, not one ray kind's (a fused kernel traces every
    /// kind of the pass): its counters and time go to the frame.
    fn frame_work(&self, gl: &Gl, timers: &mut GpuTimers);
    /// Fill the pixels whose blocks' rays all miss as the miss kernel would, by a clear: the
    /// output colour the background at full weight (Listing 16's addToFinal on a miss).
    fn fill_misses(&self, gl: &Gl, timers: &mut GpuTimers);
}

/// How a fused pass ran ([`Accelerator::fused_pass`]), which decides where its counts lie.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FusedRun {
    /// over the block lists: the per-pixel records are summed a block at a time
    pub lists: bool,
    /// the blocks whose rays all miss were left to [`PassHost::fill_misses`]: their records
    /// were not written, each of their pixels counts one ray traced that visited nothing
    pub clears: bool,
}

/// The camera uniforms of Listing 11 (`glsl/common/eye_ray.glsl`) on `k`, the program in use.
pub fn set_camera(k: &Kernel, cam: &CameraRays) {
    k.set_vec4("camImgPosition", cam.cam_img_position.into(), 1.0);
    k.set_vec4("camImgOffset", cam.cam_img_offset.into(), 0.0);
    k.set_vec4("camWidth", cam.cam_width.into(), 0.0);
    k.set_vec4("camHeight", cam.cam_height.into(), 0.0);
}

/// What the shadow feelers of one intersect2 dispatch aim at (`glsl/common/light_target.glsl`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightTarget {
    /// Point light `light` at `position` (Listing 15): its flag is its index. Ours: the
    /// position as a uniform (`pointTarget`), where Listing 15 reads `lightPos[light]`, the
    /// scene's buffer in every invocation — on llvmpipe a storage-buffer load is a loop over
    /// the lanes (docs/design/bvh.md, "Shadow feelers").
    Point { light: usize, position: Vec3 },
    /// Ours, after Klee 2016: sample `sample` of the area light `corner`, `edges`; its flag is
    /// bit `slot` of the shadow flags.
    AreaSample {
        slot: usize,
        sample: u32,
        corner: Vec3,
        edges: [Vec3; 2],
    },
}

impl LightTarget {
    /// Its uniforms, on `kernel` (in use).
    pub fn set_uniforms(&self, kernel: &Kernel) {
        match *self {
            LightTarget::Point { light, position } => {
                kernel.set_i32("lightSource", light as i32);
                kernel.set_i32("lightSample", -1);
                kernel.set_vec3("pointTarget", position.to_array());
            }
            LightTarget::AreaSample {
                slot,
                sample,
                corner,
                edges,
            } => {
                kernel.set_i32("lightSource", slot as i32);
                kernel.set_i32("lightSample", sample as i32);
                kernel.set_vec3("areaCorner", corner.to_array());
                kernel.set_vec3("areaEdgeU", edges[0].to_array());
                kernel.set_vec3("areaEdgeV", edges[1].to_array());
            }
        }
    }
}

/// What an accelerator gets from the pipeline during a frame.
pub struct FrameContext<'a> {
    pub gl: &'a Arc<Gl>,
    pub timers: &'a mut GpuTimers,
    /// The image and its tiling, for per-pixel kernels.
    pub pixels: PixelGrid,
    /// The model matrix of every object this frame.
    pub models: &'a [Mat4],
}

/// What an accelerator gets when it is made: the GL context, the kernels' sources and the
/// pipeline's `#define`s, the image size.
pub struct BuildContext<'a> {
    pub gl: &'a Arc<Gl>,
    pub info: &'a GlInfo,
    pub shaders: &'a ShaderSource,
    /// The `#define`s every kernel of the pipeline gets (counters, shadow flags, offset).
    pub defines: &'a Defines,
    pub width: u32,
    pub height: u32,
    /// The base tracer: the most triangles one dispatch of its intersect1/intersect2 tests
    /// (the rest in further dispatches); `None`: [`brute_force::triangles_per_dispatch`] —
    /// split only where the GL implementation ends long loops.
    pub triangles_per_dispatch: Option<u32>,
    /// The SAH BVH's fused pass (its default): the pass in one kernel
    /// ([`Accelerator::fused_pass`]).
    pub fused: Option<FusedPasses>,
    /// The scene's vertex attributes and lights are bound as image buffers too
    /// (`SCENE_IMAGES`, `GpuScene::vertex_images`).
    pub scene_images: bool,
}

/// What a fused pass kernel (`glsl/bvh/fused.glsl` under its entry files) needs to know at
/// compile time.
#[derive(Debug, Clone, Copy)]
pub struct FusedPasses {
    /// The shadow feelers of a hit: one per point light and area-light sample. A pixel's
    /// feeler records sum their counts (`glsl/bvh/pixel_counts.comp`), so the structure must
    /// keep that many walks' events under [`max_pixel_events`].
    pub feelers: u32,
    /// The lights (point and area lights): their feelers count under the first light's kind
    /// and, past the first, the other lights' (`pipeline::ray_kinds::Bank::occluded`).
    pub lights: u32,
    /// Whether the first light is a point light (one feeler a hit: its counts packed beside
    /// the closest hit's).
    pub first_light_point: bool,
    /// Which passes' rays the kernels take (`PASS_EYE_RAYS`, `glsl/bvh/pass_ray.glsl`):
    /// eye rays computed in place (the first pass, where no AOVs keep the rays), and the
    /// ray-state images (a first pass with AOVs, or reflection passes). Each is a variant of
    /// the kernels of its own, compiled only where some pass needs it.
    pub rays: PassRays,
}

/// The kind of rays the passes of a frame take (see [`FusedPasses::rays`]).
#[derive(Debug, Clone, Copy)]
pub struct PassRays {
    pub eye_in_place: bool,
    pub loaded: bool,
    /// Whether a reflection pass follows the first: the eye-ray variant, always the first
    /// pass, then stores the ray state (`EYE_PASS_STORES_RAYS`, with `firstPass` a constant;
    /// the loaded variant takes both as uniforms).
    pub eye_pass_stores_rays: bool,
}

impl BuildContext<'_> {
    /// Compile one of the accelerator's compute kernels with the pipeline's defines plus
    /// `extra`, timed under `timer`.
    pub fn kernel(
        &self,
        file: &str,
        extra: &[(&str, String)],
        timer: &'static str,
    ) -> Result<Kernel> {
        let mut d = self.defines.clone();
        for (k, v) in extra {
            d = d.set(k, v);
        }
        Kernel::compute(self.gl, self.shaders, file, &d, timer)
    }
}

/// Makes the GPU side of an accelerator from its options (always its own variant of [`Accel`]).
pub type MakeGpu = fn(&BuildContext, &Scene, &Accel) -> Result<Box<dyn Accelerator>>;

/// One accelerator of Müller 2015's pipeline: its name, its options where the command line
/// gives none, and how its GPU side is made (its row in `design::REGISTRY` says what else
/// belongs to it, its CPU twin included).
pub struct Entry {
    /// Its row's name in `design::REGISTRY`: "base", "grid-thesis", "grid-exact", "bvh".
    pub label: &'static str,
    /// It with the command line's defaults.
    pub plain: Accel,
    /// Whether its intersect1 stores hit records and its intersection kernels store per-pixel
    /// counts (`glsl/bvh/records.glsl`), for the pipeline to evaluate the hits and add the
    /// counts after them (`pipeline::mueller2015::records`); the thesis' accelerators evaluate
    /// and count in the kernel.
    pub records: bool,
    /// Its variants whose frames equal its CPU twin's, hits and counts (the tests walk them):
    /// a label ("grid exact pc") and the options.
    pub variants: &'static [(&'static str, Accel)],
    pub gpu: MakeGpu,
}
