//! The ray tracer of Müller 2015 (ch. 3.1, 4.1): four compute kernels — eye-ray generation,
//! intersect1, intersect2 and shading — that communicate through the ray-state textures, run in
//! the render loop of Fig. 8 (Fig. 15 with the uniform grid). The scene is transformed into
//! SSBOs at the start of every frame ([`gpu_scene`]); the closest-hit and any-hit searches are
//! the accelerator's ([`crate::accel`]), everything else is here.

pub mod gpu_scene;
pub mod images;
pub mod options;
pub mod records;

use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use glam::{Mat4, Vec3};
use serde_json::json;

pub use self::options::{RenderOptions, ShadowFlags, COUNTERS, TRIANGLE_TEST_COUNTERS};

use self::gpu_scene::GpuScene;
use self::images::{AovImages, RayImages};
use self::records::{Record, Records, FUSED_RECORDS};
use super::ray_kinds::{self, Bank, CounterBanks};
use super::renderer::Renderer;
use crate::accel::{
    Accel, Accelerator, BuildContext, Entry, FrameContext, FusedPasses, LightTarget, PassHost,
    PassRays,
};
use crate::frame::{flip_rows, Frame, FrameStats};
use crate::gl::resources::GpuTimers;
use crate::gl::{check_error, Defines, Gl, GlInfo, Kernel, PixelGrid, ShaderSource};
use crate::scene::{AreaLight, Camera, CameraRays, Scene};

/// `#define`s every kernel gets: counter slots, the shadow-flag layout, the scene's triangle
/// count (`glsl/common/scene.glsl`'s `triangleCount()`), the image size, whether AOVs are kept
/// and the scene has textures, whether the SAH BVH keeps the objects in their own space
/// (`BVH_INSTANCES`: its hit evaluation turns the normals into world space). (The SAH BVH's
/// other switches are its own: `accel::bvh`.)
pub fn kernel_defines(scene: &Scene, options: &RenderOptions) -> Defines {
    let mut d = Defines::new()
        .set(
            "SHADOW_BITS",
            (options.shadow_flags == ShadowFlags::Bits) as i32,
        )
        .set(
            "SHADOW_OFFSET",
            format!("{:?}", scene.settings.shadow_offset),
        )
        // the image size (bvh/records.glsl)
        .set("IMAGE_WIDTH", options.width)
        .set("IMAGE_HEIGHT", options.height)
        .set("SCENE_TRIANGLES", scene.triangle_count())
        // what the hit evaluation may skip (common/intersect1_hit.glsl): the first hits' store
        // when no AOVs are asked, the texture lookup in a scene without textures
        .set("STORE_AOVS", options.aovs as i32)
        .set("SCENE_TEXTURES", !scene.textures.is_empty() as i32)
        // the vertex normals and colours, the lights through image buffers: the SAH BVH's
        // evaluate_hit and shading only, where the GL has the units (GpuScene::vertex_images)
        .set("SCENE_IMAGES", 0)
        // the area lights' samples (common/light_target.glsl, shading.comp)
        .set("SAMPLES_U", options.light_samples.0)
        .set("SAMPLES_V", options.light_samples.1)
        .set("AREA_LIGHTS", scene.area_lights.len())
        // and the point lights (shading.comp, the fused pass): a constant, so that llvmpipe
        // unrolls the light loops (docs/design/frame.md)
        .set("POINT_LIGHTS", scene.lights.len())
        .set("BVH_INSTANCES", options.accel.instances() as i32)
        // and how many instances it has: one per object with triangles (accel::bvh::instances)
        .set(
            "BVH_INSTANCE_COUNT",
            crate::accel::bvh::instance_count(scene),
        );
    for (i, c) in COUNTERS.iter().enumerate() {
        d = d.set(&format!("COUNTER_{}", c.to_uppercase()), i);
    }
    d
}

/// The pipeline's own kernels (Listings 11 and 16).
struct Kernels {
    eye_ray_generation: Kernel,
    shading: Kernel,
}

/// The scene's lighting and background, as the kernels' uniforms take them.
struct Lighting {
    /// The point lights' positions, as the scene's `lightPos` buffer holds them (the feelers'
    /// targets: [`LightTarget::Point`]).
    lights: Vec<Vec3>,
    area_lights: Vec<AreaLight>,
    background: [f32; 3],
    ambient: [f32; 3],
}

impl Lighting {
    /// The shading kernel's `areaLight` array: corner, edge u, edge v, colour per area light.
    fn area_uniform(&self) -> Vec<[f32; 4]> {
        self.area_lights
            .iter()
            .flat_map(|a| [a.corner, a.edge_u, a.edge_v, a.color].map(|v| v.extend(0.0).into()))
            .collect()
    }
}

/// The shadow flags' bits (ours, after Klee 2016, for area lights): point light `l` has bit
/// `l` (Listing 15, the bitwise flags of ch. 5); then every area light U·V bits, one per
/// sample in Klee's sample order. The feelers of one intersect2 dispatch set one bit; the
/// shading kernel weights an area light by the share of its bits left unset.
pub fn shadow_slots(scene: &Scene, (su, sv): (u32, u32)) -> usize {
    scene.lights.len() + scene.area_lights.len() * (su * sv) as usize
}

/// The intersect2 dispatches of a pass, in order: each with the light it counts under
/// ([`Bank::occluded`]: point lights first, then the area lights) and its feelers' target.
pub fn light_targets(
    lights: &[Vec3],
    area_lights: &[AreaLight],
    (su, sv): (u32, u32),
) -> Vec<(usize, LightTarget)> {
    let samples = (su * sv) as usize;
    let points = lights
        .iter()
        .enumerate()
        .map(|(light, &position)| (light, LightTarget::Point { light, position }));
    let lights = lights.len();
    let areas = area_lights.iter().enumerate().flat_map(move |(a, area)| {
        (0..samples).map(move |r| {
            let target = LightTarget::AreaSample {
                slot: lights + a * samples + r,
                sample: r as u32,
                corner: area.corner,
                edges: [area.edge_u, area.edge_v],
            };
            (lights + a, target)
        })
    });
    points.chain(areas).collect()
}

/// The ray tracer: Müller 2015's pipeline with one accelerator.
pub struct RayTracer {
    gl: Arc<Gl>,
    scene: GpuScene,
    images: RayImages,
    aov_images: Option<AovImages>,
    kernels: Kernels,
    counters: CounterBanks,
    timers: GpuTimers,
    options: RenderOptions,
    pixels: PixelGrid,
    lighting: Lighting,
    renderer: String,
    /// Model matrix per object, applied by the transform pass when it changed.
    models: Vec<Mat4>,
    entry: &'static Entry,
    accel: Box<dyn Accelerator>,
    /// The hit records and per-pixel counts, for an accelerator that uses them.
    records: Option<Records>,
    /// with the fused pass: what its kernels were compiled for, which decides where its
    /// counts lie (`glsl/bvh/fused.glsl`)
    fused: Option<FusedPasses>,
    last: Option<FrameStats>,
}

/// Refuse options the pipeline cannot honour, before anything is allocated.
/// What shortens the loop that passed the implementation's limit, for the tracer `options`
/// choose (the refusal says it).
fn loop_limit_advice(options: &RenderOptions) -> &'static str {
    match options.accel {
        Accel::Bvh(_) if options.accel.instances() => {
            "The two-level BVH (--bvh-instances) walks every object whose box a ray enters, and \
             these overlap: render without --bvh-instances (one tree over all triangles)"
        }
        Accel::Bvh(_) => "A ray visits too many BVH nodes: a GPU driver runs the loop whole",
        Accel::ThesisGrid(_) | Accel::ExactGrid(_) => {
            "A ray walks too many voxels or tests too many triangles in one: change \
             --grid, or use --tracer bvh"
        }
        Accel::Base => "The base tracer tests every triangle in one loop: use --tracer bvh",
    }
}

fn check_options(info: &GlInfo, scene: &Scene, options: &RenderOptions) -> Result<PixelGrid> {
    if scene.lights.len() > options.shadow_flags.max_lights() {
        bail!("{}", too_many_lights(scene, options.shadow_flags));
    }
    check_area_lights(scene, options)?;
    let max_tex = info.max_texture_size as u32;
    let (w, h) = (options.width, options.height);
    if w == 0 || h == 0 || w > max_tex || h > max_tex {
        bail!("image size {w}x{h} outside 1..={max_tex} (GL_MAX_TEXTURE_SIZE)");
    }
    PixelGrid::new(w, h, options.tile, info.profile.dispatch_threads)
}

/// Area lights need a flag bit per sample: the bitwise layout, with room for every sample.
fn check_area_lights(scene: &Scene, options: &RenderOptions) -> Result<()> {
    let areas = scene.area_lights.len();
    if areas == 0 {
        return Ok(());
    }
    let (su, sv) = options.light_samples;
    let path = scene.path.display();
    if options.shadow_flags != ShadowFlags::Bits {
        bail!(
            "{path}: {areas} [[area_light]](s) need --shadow-flags bits (a flag bit per light \
             sample); --shadow-flags rgba holds one flag per point light"
        );
    }
    let slots = shadow_slots(scene, options.light_samples);
    let most = ShadowFlags::Bits.max_lights();
    if slots > most {
        bail!(
            "{path}: {} point light(s) and {areas} area light(s) at --light-samples {su}x{sv} \
             need {slots} shadow flag bits, but --shadow-flags bits holds {most}: use fewer \
             samples or lights",
            scene.lights.len()
        );
    }
    Ok(())
}

/// The error for more lights than `flags` holds: it suggests the bitwise layout only where
/// that would hold them.
pub fn too_many_lights(scene: &Scene, flags: ShadowFlags) -> String {
    let layout = match flags {
        ShadowFlags::Rgba => "rgba",
        ShadowFlags::Bits => "bits",
    };
    let most = flags.max_lights();
    let lights = scene.lights.len();
    let bits = ShadowFlags::Bits.max_lights();
    let advice = if flags == ShadowFlags::Rgba && lights <= bits {
        "use --shadow-flags bits".to_string()
    } else {
        format!("no layout holds more than {bits}: use fewer lights")
    };
    format!(
        "{}: {lights} lights, but --shadow-flags {layout} holds at most {most} ({advice})",
        scene.path.display()
    )
}

impl RayTracer {
    /// The pipeline for `scene` with the accelerator `options` selects, on the current context.
    pub fn new(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: RenderOptions,
    ) -> Result<RayTracer> {
        let pixels = check_options(info, scene, &options)?;
        let entry = options.accel.entry();
        let gpu_scene = GpuScene::new(&gl, info, scene, shaders)?;
        let defines = kernel_defines(scene, &options);
        let compute = |file, timer| Kernel::compute(&gl, shaders, file, &defines, timer);
        let images = defines
            .clone()
            .set("SCENE_IMAGES", gpu_scene.vertex_images() as i32);
        let kernels = Kernels {
            eye_ray_generation: compute(
                "mueller2015/eye_ray_generation.comp",
                "eye_ray_generation",
            )?,
            shading: Kernel::compute(&gl, shaders, "mueller2015/shading.comp", &images, "shading")?,
        };
        let (w, h) = (options.width, options.height);
        let build = BuildContext {
            gl: &gl,
            info,
            shaders,
            defines: &defines,
            width: w,
            height: h,
            triangles_per_dispatch: options.triangles_per_dispatch,
            fused: options.fused().then(|| FusedPasses {
                feelers: shadow_slots(scene, options.light_samples) as u32,
                lights: (scene.lights.len() + scene.area_lights.len()) as u32,
                first_light_point: !scene.lights.is_empty(),
                rays: PassRays {
                    eye_in_place: !options.aovs,
                    loaded: options.aovs || options.refl_depth > 0,
                    eye_pass_stores_rays: options.refl_depth > 0,
                },
            }),
            scene_images: gpu_scene.vertex_images(),
        };
        let accel = (entry.gpu)(&build, scene, &options.accel)?;
        let per_pixel = if options.fused() { FUSED_RECORDS } else { 1 };
        // the counts over block lists where the fused pass may run over them (FusedRun::lists)
        let lists = options.fused();
        let records = entry
            .records
            .then(|| Records::new(&gl, info, shaders, &images, (w, h), per_pixel, lists))
            .transpose()?;
        let counters = CounterBanks::new(&gl, info, COUNTERS.len())?;
        let t = RayTracer {
            images: RayImages::new(&gl, w, h, options.shadow_flags)?,
            aov_images: options
                .aovs
                .then(|| {
                    let samples = (options.light_samples.0 * options.light_samples.1) as usize;
                    let lights = (scene.lights.len(), scene.area_lights.len(), samples);
                    AovImages::new(&gl, w, h, options.shadow_flags, lights)
                })
                .transpose()?,
            scene: gpu_scene,
            kernels,
            counters,
            timers: GpuTimers::new(&gl),
            lighting: Lighting {
                lights: scene.lights.iter().map(|l| l.position).collect(),
                area_lights: scene.area_lights.clone(),
                background: scene.settings.background,
                ambient: scene.settings.ambient,
            },
            models: scene.objects.iter().map(|o| o.model).collect(),
            options,
            pixels,
            renderer: info.renderer.clone(),
            entry,
            accel,
            records,
            fused: build.fused,
            last: None,
            gl,
        };
        check_error(&t.gl, "creating the ray tracer")?;
        Ok(t)
    }

    pub fn options(&self) -> &RenderOptions {
        &self.options
    }

    /// The accelerator (for tests and inspection: downcast with `as_any`).
    pub fn accelerator(&self) -> &dyn Accelerator {
        self.accel.as_ref()
    }

    /// The accelerator's registry entry.
    pub fn entry(&self) -> &'static Entry {
        self.entry
    }

    pub fn gl(&self) -> &Gl {
        &self.gl
    }

    /// The pixels the last pass' hit list held (the SAH BVH's four kernels: pixel indices
    /// `y · width + x`, GL rows, in the order `evaluate_hit` appended them); `None` for an
    /// accelerator without one. For tests and inspection, after a frame.
    pub fn hit_list(&self) -> Option<Vec<u32>> {
        match (&self.records, self.options.fused()) {
            (Some(r), false) => Some(r.hit_list_entries(&self.gl)),
            _ => None,
        }
    }

    /// The eye rays (Listing 11).
    fn eye_rays(&mut self, cam: &CameraRays) {
        let k = &self.kernels.eye_ray_generation;
        k.use_program();
        crate::accel::set_camera(k, cam);
        k.dispatch_pixels(&mut self.timers, self.pixels);
    }

    /// One pass of Fig. 8's loop: intersect1, intersect2 per light, shading — or with
    /// the accelerator's fused pass (the SAH BVH's default).
    fn pass(&mut self, cam: &CameraRays, pass: u32) {
        if self.options.fused() {
            return self.fused_pass(cam, pass);
        }
        let mut f = FrameContext {
            gl: &self.gl,
            timers: &mut self.timers,
            pixels: self.pixels,
            models: &self.models,
        };
        self.counters.bind(f.gl, f.timers, Bank::closest_hit(pass));
        let k = self.accel.closest_hit(&mut f, pass);
        k.set_vec4("backgroundColor", self.lighting.background, 1.0);
        k.set_i32("storePrimaryHit", (pass == 0) as i32);
        k.dispatch_pixels(f.timers, f.pixels);
        if let Some(r) = &self.records {
            r.after_closest_hit(f.timers, f.pixels, self.lighting.background, pass == 0);
        }
        // the shadow flags of this pass: cleared before every pass (the thesis, ch. 3.1.3,
        // clears the textures once a frame; intersect2 only sets flags, so a reflection pass
        // would inherit the flags of the pass before it)
        self.images.shadow.clear(&self.gl);
        let l = &self.lighting;
        for (light, target) in light_targets(&l.lights, &l.area_lights, self.options.light_samples)
        {
            self.counters.bind(f.gl, f.timers, Bank::occluded(light));
            let k = self.accel.occluded(&mut f, &target);
            target.set_uniforms(k);
            match &self.records {
                Some(r) => r.trace_feelers(k, f.timers, f.pixels.threads),
                None => k.dispatch_pixels(f.timers, f.pixels),
            }
        }
        self.counters.bind(&self.gl, &mut self.timers, Bank::Frame);
        let k = &self.kernels.shading;
        k.use_program();
        k.set_vec4("camPosition", cam.cam_position.into(), 1.0);
        k.set_vec4("ambientColor", self.lighting.ambient, 1.0);
        k.set_vec4_slice("areaLight", &self.lighting.area_uniform());
        k.dispatch_pixels(&mut self.timers, self.pixels);
    }

    /// The frame's clear of the ray-state images (Müller 2015, ch. 3.1.3: once a frame), timed
    /// as `image_clear` — on llvmpipe a memset of every texel, 5–9 ms for the seven images at
    /// 512². Ours: the fused pass with its eye rays in place writes every pixel's output colour
    /// in its first pass, and the ray state of every pixel a reflection pass reads but those of
    /// the blocks left to clears (`fused_misses_apart`, [`RayTracer::fused_pass`]), which an
    /// inactive ray origin must mark; it reads no other image before writing it (the AOVs'
    /// images are only written where the host keeps AOVs, and then no eye ray is in place) —
    /// so it clears the ray origins where a reflection pass follows, and nothing else.
    fn clear_images(&mut self) {
        let (gl, images) = (&self.gl, &self.images);
        let origins_only = self.eye_in_place(0);
        let reflections = self.options.refl_depth > 0;
        self.timers.time(gl, "image_clear", || match origins_only {
            false => images.clear(gl),
            true if reflections => images.ray_origin.clear(gl),
            true => {}
        });
    }

    /// Whether pass `pass` computes its eye rays in place (the fused pass' first, where no
    /// AOVs keep the rays: `glsl/bvh/pass_ray.glsl`), so no eye-ray kernel runs.
    fn eye_in_place(&self, pass: u32) -> bool {
        self.options.fused() && pass == 0 && self.aov_images.is_none()
    }

    /// One pass in the accelerator's fused kernel (ours, the SAH BVH's default:
    /// `glsl/bvh/fused.glsl`), the pipeline's part through [`FusedHost`]; then the
    /// counts of its three records, each under the bank intersect1 and intersect2 count under.
    fn fused_pass(&mut self, cam: &CameraRays, pass: u32) {
        let eye = self.eye_in_place(pass);
        let mut f = FrameContext {
            gl: &self.gl,
            timers: &mut self.timers,
            pixels: self.pixels,
            models: &self.models,
        };
        // the entry pass is the closest-hit search's set-up
        self.counters.bind(f.gl, f.timers, Bank::closest_hit(pass));
        let host = FusedHost {
            counters: &self.counters,
            lighting: &self.lighting,
            final_color: &self.images.final_color,
            cam,
            pass,
            refl_depth: self.options.refl_depth,
        };
        let run = self
            .accel
            .fused_pass(&mut f, pass, eye.then_some(cam), &host)
            .expect("the fused pass runs with an accelerator made with it");
        let r = self
            .records
            .as_ref()
            .expect("the fused pass stores records");
        let feelers = feeler_records(self.fused.expect("made with the fused pass"));
        let kinds = [(Bank::closest_hit(pass), "intersect1", Record::Packed(0))].into_iter();
        let feelers = feelers.into_iter().map(|(b, r)| (b, "intersect2", r));
        for (bank, tests, record) in kinds.chain(feelers) {
            self.counters.bind(&self.gl, &mut self.timers, bank);
            match run.lists {
                // the records over the block lists: only the hit blocks' where the clears
                // stood for the miss kernel
                true => r.add_block_counts(&mut self.timers, tests, record, run.clears),
                false => r.add_record_counts(&mut self.timers, tests, record),
            }
        }
        self.counters.bind(&self.gl, &mut self.timers, Bank::Frame);
    }

    /// The area lights and their samples, for the settings (none without area lights).
    fn area_settings(&self) -> Vec<(&'static str, serde_json::Value)> {
        let areas = self.lighting.area_lights.len();
        let (su, sv) = self.options.light_samples;
        match areas {
            0 => vec![],
            _ => vec![
                ("area_lights", json!(areas)),
                ("light_samples", json!(format!("{su}x{sv}"))),
            ],
        }
    }

    /// The counters and timers of the frame, with the accelerator's facts.
    fn frame_stats(&mut self) -> FrameStats {
        let banks = self.counters.read(&self.gl);
        let gpu_ms = self.timers.resolve(&self.gl);
        let kind_ms = self.timers.take_ray_kind_ms();
        let mut stats = FrameStats {
            gpu_ms,
            ray_kinds: ray_kinds::ray_kind_stats(&banks, COUNTERS, TRIANGLE_TEST_COUNTERS, kind_ms),
            ..Default::default()
        };
        for (i, name) in COUNTERS.iter().enumerate() {
            let v = banks.iter().map(|b| b[i]).sum();
            if TRIANGLE_TEST_COUNTERS.contains(name) {
                stats.triangle_tests.insert(name.to_string(), v);
            } else if *name == "truncated_rays" {
                stats.truncated_rays = v;
            } else {
                stats.events.insert(name.to_string(), v);
            }
        }
        if !self.options.accel.proximity_clouds() {
            for k in ["cloud_jumps", "empty_cells_skipped"] {
                stats.events.remove(k);
            }
        }
        self.accel.stats(&mut stats);
        if let (Some(r), false) = (&self.records, self.options.fused()) {
            let pixels = r.hit_list_pixels(&self.gl);
            stats.facts.insert("hit_list_pixels".into(), json!(pixels));
        }
        stats
    }
}

/// The pipeline's part of a fused pass ([`PassHost`]): the uniforms of the four kernels it
/// stands for, the frame's counters, the miss blocks' clear.
struct FusedHost<'a> {
    counters: &'a CounterBanks,
    lighting: &'a Lighting,
    final_color: &'a crate::gl::resources::Image2d,
    cam: &'a CameraRays,
    pass: u32,
    refl_depth: u32,
}

impl PassHost for FusedHost<'_> {
    fn set_uniforms(&self, k: &Kernel) {
        let (l, pass) = (self.lighting, self.pass);
        k.set_vec4("backgroundColor", l.background, 1.0);
        k.set_i32("storePrimaryHit", (pass == 0) as i32);
        k.set_i32("storeRayState", (pass < self.refl_depth) as i32);
        k.set_i32("firstPass", (pass == 0) as i32);
        k.set_vec4("camPosition", self.cam.cam_position.into(), 1.0);
        k.set_vec4("ambientColor", l.ambient, 1.0);
        k.set_vec4_slice("areaLight", &l.area_uniform());
    }

    /// Timed as the frame's, not one ray kind's: the kernel traces every kind of the pass (and
    /// the colour's clear stands for the miss kernel).
    fn frame_work(&self, gl: &Gl, timers: &mut GpuTimers) {
        self.counters.bind(gl, timers, Bank::Frame);
    }

    fn fill_misses(&self, gl: &Gl, timers: &mut GpuTimers) {
        let bg = self.lighting.background;
        let c = self.final_color;
        timers.time(gl, "fused_miss", || {
            c.fill_f32(gl, [bg[0], bg[1], bg[2], 1.0])
        });
    }
}

/// The fused pass' feeler records a pass sums, each under its bank: the first light's (packed
/// in record 0 beside the closest hit's where it is a point light, else record 1) and the
/// other lights' (record 2) — `glsl/bvh/fused.glsl`.
fn feeler_records(fused: FusedPasses) -> Vec<(Bank, Record)> {
    let first = match fused.first_light_point {
        true => Record::PackedHigh(0),
        false => Record::Plain(1),
    };
    let kinds = [
        (Bank::occluded(0), first),
        (Bank::occluded(1), Record::Plain(2)),
    ];
    kinds
        .into_iter()
        .take(fused.lights.min(2) as usize)
        .collect()
}

impl Renderer for RayTracer {
    fn name(&self) -> &'static str {
        self.options.accel.tracer()
    }

    fn size(&self) -> (u32, u32) {
        (self.options.width, self.options.height)
    }

    /// The render loop of Fig. 8 / Fig. 15.
    fn draw(&mut self, camera: &Camera) -> Result<FrameStats> {
        let start = Instant::now();
        let gl = self.gl.clone();
        // the objects that moved are transformed into the SSBOs at the start of the frame; with
        // --bvh-instances the SSBOs keep object space (the instances place the objects, the
        // hit evaluation turns the normals), so nothing is transformed after the first frame
        let identity;
        let scene_models = if self.options.accel.instances() {
            identity = vec![Mat4::IDENTITY; self.models.len()];
            &identity
        } else {
            &self.models
        };
        self.scene.transform(&gl, &mut self.timers, scene_models);
        self.scene.bind(&gl);
        self.counters.clear(&gl, &mut self.timers);
        self.accel.build(&mut FrameContext {
            gl: &self.gl,
            timers: &mut self.timers,
            pixels: self.pixels,
            models: &self.models,
        })?;
        self.clear_images();
        self.images.bind(&gl);
        if let Some(r) = &self.records {
            r.bind(&gl);
        }
        let cam = camera.rays(self.options.width, self.options.height);
        if !self.eye_in_place(0) {
            self.eye_rays(&cam);
        }
        if let Some(a) = &self.aov_images {
            a.keep_rays(&gl, &self.images);
        }
        for pass in 0..=self.options.refl_depth {
            crate::progress::pass(pass, self.options.refl_depth + 1);
            self.pass(&cam, pass);
            if let (0, Some(a)) = (pass, &self.aov_images) {
                a.keep_first_hits(&gl, &self.images);
            }
        }
        let mut stats = self.frame_stats();
        if stats.truncated_rays > 0 {
            bail!(
                "{} shader loops stopped early: this GL implementation ({}) ends long shader loops \
                 (Mesa llvmpipe: 65535 iterations per invocation); the frame would be wrong. {}",
                stats.truncated_rays,
                self.renderer,
                loop_limit_advice(&self.options)
            );
        }
        super::renderer::end_of_frame(&gl, &mut stats, start)?;
        self.last = Some(stats.clone());
        Ok(stats)
    }

    fn read_back(&mut self) -> Result<Frame> {
        let stats = super::renderer::last_drawn(&self.last)?;
        let (w, h) = self.size();
        Ok(Frame {
            width: w,
            height: h,
            color: flip_rows(&self.images.final_color.read_f32(&self.gl), w, h),
            aovs: self
                .aov_images
                .as_ref()
                .map(|a| a.read(&self.gl, &self.images.primary_hit)),
            stats,
        })
    }

    fn output_texture(&self) -> glow::Texture {
        self.images.final_color.texture.raw()
    }

    fn set_model(&mut self, object: usize, model: Mat4) -> Result<()> {
        let n = self.models.len();
        *self
            .models
            .get_mut(object)
            .ok_or_else(|| anyhow!("no object {object}: the scene has {n} objects"))? = model;
        Ok(())
    }

    fn settings(&self) -> serde_json::Map<String, serde_json::Value> {
        let o = &self.options;
        [
            ("lights", json!(self.lighting.lights.len())),
            ("refl_depth", json!(o.refl_depth)),
            ("shadow_flags", json!(o.shadow_flags)),
            ("tile", json!(o.tile)),
        ]
        .into_iter()
        .chain(o.accel.settings())
        .chain(self.area_settings())
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }
}
