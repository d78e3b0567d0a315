//! The streaming tracer (a Purcell-style GPU ray tracer with a uniform grid and
//! proximity clouds), `--tracer stream`: every kernel is a **fragment program** drawn over a
//! viewport-sized quad into multiple render targets; rays are fragments, their state lives in
//! textures (Fig. 1, Fig. 2).
//!
//! A frame, per bounce (the primary rays, then `refl_depth` reflection bounces):
//! 1. the ray generator (`glsl/stream/ray_generator.frag`) writes the rays' origin and
//!    direction textures;
//! 2. the masking kernel (`mask.frag`) starts the 3D-DDA of every ray that needs work and marks
//!    the others finished;
//! 3. the traverse-and-intersect kernel (`traverse_intersect.frag`) is called again and again,
//!    each call after the early-Z pass (`early_z.frag`) that culls the finished rays, with a
//!    bounded amount of work per call, reading one state set and writing the other, until an
//!    occlusion query (`GL_SAMPLES_PASSED`) counts no fragment ([`StreamRenderer::traverse`]);
//! 4. `hit_record.frag` keeps the hit; shading (`shading.frag`) adds the ambient term, then per
//!    point light: shadow rays (1.–3. with any-hit traversal) and the light's diffuse term;
//!    the reflection rays of the next bounce come from the ray generator.
//!
//! The grid is static, built once on the CPU ([`grid`]; its walk's CPU twin and oracle:
//! `reference::stream_grid`), and lives in the textures of Fig. 3 ([`grid_textures`]).

pub mod grid;
pub mod grid_textures;
pub mod targets;

use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use glam::{Mat4, UVec3, Vec3};
use glow::HasContext;
use serde_json::json;

use self::grid::{auto_dims, StreamGrid};
use self::grid_textures::GridTextures;
use self::targets::{AovTargets, Targets};
use super::ray_kinds::{self, Bank, CounterBanks};
use super::renderer::Renderer;
use crate::frame::{flip_rows, flip_xyz, Aovs, Frame, FrameStats};
use crate::gl::resources::{GpuTimers, Owned};
use crate::gl::{check_error, Defines, Gl, GlInfo, Kernel, ShaderSource};
use crate::scene::{Camera, Scene};

/// The 64-bit counters of the kernels (`#define COUNTER_*`).
pub const COUNTERS: &[&str] = &[
    "closest_tests",
    "shadow_tests",
    "voxels_visited",
    "cloud_jumps",
    "empty_cells_skipped",
    // rays generated (primary, shadow, reflection; ours: rays per second in accel-compare)
    "rays",
];

/// Options of the streaming tracer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamOptions {
    pub width: u32,
    pub height: u32,
    /// reflection bounces after the primary rays (the paper's Table 3: 2)
    pub refl_depth: u32,
    /// gx, gy, gz (`None`: the paper's ∛n per axis)
    pub dims: Option<[u32; 3]>,
    pub proximity_clouds: bool,
    /// steps (triangle tests or cell moves) per traverse call
    pub steps_per_call: u32,
    /// traverse calls per traversal at most
    pub max_calls: u32,
    /// shadow rays as a naive closest-hit search (`--stream-naive-shadows`)
    pub naive_shadows: bool,
    /// without the masking kernel's optimisation (`--stream-no-mask`)
    pub no_mask: bool,
    /// the paper's single-sided ray–triangle test (`--stream-single-sided`)
    pub single_sided: bool,
    pub aovs: bool,
}

impl StreamOptions {
    /// Steps per traverse call unless `--stream-steps` says otherwise.
    pub const STEPS_PER_CALL: u32 = 64;
    /// Traverse calls per traversal at most unless `--stream-max-calls` says otherwise.
    pub const MAX_CALLS: u32 = 10_000;

    /// A `width`×`height` image with `refl_depth` bounces and the command line's defaults: the
    /// paper's ∛n grid, no proximity clouds, the paper's shadow optimisations,
    /// [`Self::STEPS_PER_CALL`] steps per call and at most [`Self::MAX_CALLS`] calls.
    pub fn new(width: u32, height: u32, refl_depth: u32) -> StreamOptions {
        StreamOptions {
            width,
            height,
            refl_depth,
            dims: None,
            proximity_clouds: false,
            steps_per_call: Self::STEPS_PER_CALL,
            max_calls: Self::MAX_CALLS,
            naive_shadows: false,
            no_mask: false,
            single_sided: false,
            aovs: false,
        }
    }
}

/// The kernels of Fig. 1 (and the two passes the paper's optimisations add).
struct Kernels {
    ray_generator: Kernel,
    mask: Kernel,
    early_z: Kernel,
    traverse: Kernel,
    hit_record: Kernel,
    shading: Kernel,
}

fn compile(gl: &Arc<Gl>, shaders: &ShaderSource, defines: &Defines) -> Result<Kernels> {
    let k = |file: &str, timer: &'static str| {
        Kernel::program(
            gl,
            shaders,
            &[
                (glow::VERTEX_SHADER, "stream/quad.vert"),
                (glow::FRAGMENT_SHADER, file),
            ],
            defines,
            timer,
        )
    };
    Ok(Kernels {
        ray_generator: k("stream/ray_generator.frag", "ray_generator")?,
        mask: k("stream/mask.frag", "mask")?,
        early_z: k("stream/early_z.frag", "early_z")?,
        traverse: k("stream/traverse_intersect.frag", "traverse_intersect")?,
        hit_record: k("stream/hit_record.frag", "hit_record")?,
        shading: k("stream/shading.frag", "shading")?,
    })
}

/// What the traversals of a frame counted beyond the counters.
#[derive(Debug, Clone, Copy, Default)]
struct Calls {
    /// traverse calls, the last of each traversal (the one the query found idle) included
    total: u64,
    traversals: u64,
    /// the most calls one traversal took
    max: u64,
    /// rays still walking when a traversal hit `max_calls`
    unfinished: u64,
}

/// The streaming ray tracer.
pub struct StreamRenderer {
    gl: Arc<Gl>,
    options: StreamOptions,
    scene: Scene,
    grid: StreamGrid,
    grid_ms: f64,
    textures: GridTextures,
    targets: Targets,
    kernels: Kernels,
    counters: CounterBanks,
    timers: GpuTimers,
    query: Owned<glow::Query>,
    calls: Calls,
    /// for the shadow AOV: per pixel (GL row order), the lights whose first-bounce shadow ray
    /// found no blocker
    unblocked: Vec<u32>,
    last: Option<(Camera, FrameStats)>,
}

/// Refuse what the renderer cannot do, before anything is allocated.
fn check(info: &GlInfo, scene: &Scene, o: &StreamOptions) -> Result<()> {
    if scene.triangle_count() == 0 {
        bail!("{}: the scene has no triangles", scene.path.display());
    }
    let max_tex = info.max_texture_size as u32;
    if o.width > max_tex || o.height > max_tex {
        bail!(
            "image size {}x{} outside 1..={max_tex} (GL_MAX_TEXTURE_SIZE)",
            o.width,
            o.height
        );
    }
    use crate::limits::{check, GRID_RES, STREAM_CALLS, STREAM_STEPS};
    let msg = anyhow::Error::msg;
    for (axis, n) in ["x", "y", "z"].iter().zip(o.dims.unwrap_or([1; 3])) {
        check(&format!("the grid's {axis} resolution"), n, &GRID_RES).map_err(msg)?;
    }
    check(
        "the steps per traverse call",
        o.steps_per_call,
        &STREAM_STEPS,
    )
    .map_err(msg)?;
    check("the traverse calls", o.max_calls, &STREAM_CALLS).map_err(msg)?;
    Ok(())
}

fn defines(scene: &Scene, o: &StreamOptions) -> Defines {
    let mut d = Defines::new()
        .set("STEPS_PER_CALL", o.steps_per_call)
        .set(
            "SHADOW_OFFSET",
            format!("{:?}", scene.settings.shadow_offset),
        )
        .set("SINGLE_SIDED", o.single_sided as u32);
    for (i, c) in COUNTERS.iter().enumerate() {
        d = d.set(&format!("COUNTER_{}", c.to_uppercase()), i);
    }
    d
}

impl StreamRenderer {
    /// Build the grid of `scene` on the CPU, upload it, compile the kernels.
    pub fn new(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: StreamOptions,
    ) -> Result<StreamRenderer> {
        check(info, scene, &options)?;
        let kernels = compile(&gl, shaders, &defines(scene, &options))?;
        let scene = Scene {
            textures: Vec::new(),
            ..scene.clone()
        };
        let start = Instant::now();
        let dims = options
            .dims
            .map(UVec3::from)
            .unwrap_or_else(|| auto_dims(scene.triangle_count()));
        let grid = StreamGrid::build(scene.world_triangles(), scene.bounds(), dims)
            .map_err(|e| anyhow!("{}: {e}", scene.path.display()))?;
        let grid_ms = start.elapsed().as_secs_f64() * 1e3;
        let textures = GridTextures::upload(&gl, &grid, &scene)?;
        let targets = Targets::new(&gl, options.width, options.height, options.aovs)?;
        let counters = CounterBanks::new(&gl, info, COUNTERS.len())?;
        // SAFETY: query creation on a current context.
        let query = Owned::new(&gl, unsafe { gl.create_query().map_err(|e| anyhow!(e))? });
        let r = StreamRenderer {
            scene,
            grid,
            grid_ms,
            textures,
            targets,
            kernels,
            counters,
            timers: GpuTimers::new(&gl),
            query,
            calls: Calls::default(),
            unblocked: match options.aovs {
                true => vec![0; options.width as usize * options.height as usize],
                false => vec![],
            },
            last: None,
            options,
            gl,
        };
        check_error(&r.gl, "creating the streaming ray tracer")?;
        Ok(r)
    }

    /// The grid the kernels walk (the CPU twin).
    pub fn grid(&self) -> &StreamGrid {
        &self.grid
    }

    /// Put `k` in use with the grid's uniforms.
    fn use_kernel(&self, k: &Kernel) {
        k.use_program();
        self.textures.set_uniforms(k, &self.grid);
    }

    /// The ray generator into `into` (0/1: the eye or reflection rays; 2: the shadow rays),
    /// reading the rays of bounce texture `from`.
    fn generate(&mut self, camera: &Camera, generate: i32, from: usize, into: usize, light: usize) {
        let (gl, t) = (&self.gl, &self.targets);
        let k = &self.kernels.ray_generator;
        self.use_kernel(k);
        t.bind_rays(gl, &t.rays[from]);
        let cam = camera.rays(t.width, t.height);
        k.set_i32("generate", generate);
        k.set_i32("masking", !self.options.no_mask as i32);
        k.set_vec3("camImgPosition", cam.cam_img_position.to_array());
        k.set_vec3("camImgOffset", cam.cam_img_offset.to_array());
        k.set_vec3("camWidth", cam.cam_width.to_array());
        k.set_vec3("camHeight", cam.cam_height.to_array());
        k.set_vec2("imageSize2", [t.width as f32, t.height as f32]);
        if let Some(l) = self.scene.lights.get(light) {
            k.set_vec3("lightPosition", l.position.to_array());
        }
        let fbo = if into == 2 {
            t.fbo.shadow.raw()
        } else {
            t.fbo.rays[into].raw()
        };
        t.draw(gl, &mut self.timers, k, fbo);
        t.unbind(gl);
    }

    /// Mask the rays of [`Targets::ray_set`] `rays` into state set A and clear set B's ray
    /// state; then traverse.
    fn trace(&mut self, rays: usize, shadow: bool) {
        let (gl, t) = (&self.gl, &self.targets);
        let k = &self.kernels.mask;
        self.use_kernel(k);
        t.bind_rays(gl, t.ray_set(rays));
        k.set_i32("shadowRays", shadow as i32);
        k.set_i32("masking", !self.options.no_mask as i32);
        t.draw(gl, &mut self.timers, k, t.fbo.state[0].raw());
        t.unbind(gl);
        t.state[1].tmax.clear(gl);
        self.traverse(rays, shadow);
    }

    /// The early-Z pass, then one traverse call reading set `read` inside the occlusion query;
    /// the query's count of fragments that ran.
    fn traverse_call(&mut self, read: usize, shadow: bool) -> u64 {
        let (gl, t) = (&self.gl, &self.targets);
        t.bind_state(gl, read);
        self.use_kernel(&self.kernels.early_z);
        // SAFETY: depth state of our own passes on a current context.
        unsafe {
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::ALWAYS);
            gl.depth_mask(true);
        }
        t.draw(
            gl,
            &mut self.timers,
            &self.kernels.early_z,
            t.fbo.depth_only.raw(),
        );
        let k = &self.kernels.traverse;
        self.use_kernel(k);
        let naive = shadow && self.options.naive_shadows;
        k.set_i32("anyHit", (shadow && !naive) as i32);
        k.set_i32("naiveShadow", naive as i32);
        k.set_f32("shadowOffset", self.scene.settings.shadow_offset);
        k.set_i32("proximityClouds", self.options.proximity_clouds as i32);
        k.set_i32("testCounter", if shadow { 1 } else { 0 });
        // SAFETY: as above, and the query around the draw.
        unsafe {
            gl.depth_func(glow::LESS);
            gl.depth_mask(false);
            gl.begin_query(glow::SAMPLES_PASSED, self.query.raw());
        }
        t.draw(gl, &mut self.timers, k, t.fbo.state[1 - read].raw());
        // SAFETY: ending the query and reading its result (waits for the call).
        unsafe {
            gl.end_query(glow::SAMPLES_PASSED);
            gl.disable(glow::DEPTH_TEST);
            gl.depth_mask(true);
            gl.get_query_parameter_u32(self.query.raw(), glow::QUERY_RESULT) as u64
        }
    }

    /// Call traverse-and-intersect until the occlusion query counts no fragment (the paper's
    /// halting condition), at most `max_calls` times.
    fn traverse(&mut self, rays: usize, shadow: bool) {
        let gl = self.gl.clone();
        let (mut read, mut calls) = (0, 0u64);
        loop {
            self.targets.bind_rays(&gl, self.targets.ray_set(rays));
            let passed = self.traverse_call(read, shadow);
            calls += 1;
            read = 1 - read;
            if passed == 0 {
                break;
            }
            if calls == self.options.max_calls as u64 {
                // the rays that ran in the last call may still be walking
                self.calls.unfinished += passed;
                break;
            }
        }
        self.targets.unbind(&gl);
        self.calls.total += calls;
        self.calls.traversals += 1;
        self.calls.max = self.calls.max.max(calls);
    }

    /// Copy the finished traversal's hit records out of the state sets.
    fn keep_hits(&mut self) {
        self.hit_records_into(self.targets.fbo.hit.raw());
    }

    /// The hit-record pass over state set 0 into `fbo`.
    fn hit_records_into(&mut self, fbo: glow::Framebuffer) {
        let (gl, t) = (&self.gl, &self.targets);
        t.bind_state(gl, 0);
        self.use_kernel(&self.kernels.hit_record);
        t.draw(gl, &mut self.timers, &self.kernels.hit_record, fbo);
        t.unbind(gl);
    }

    /// One shading term (0: ambient or background, 1: light `light`) added into the colour.
    fn shade(&mut self, bounce: usize, term: i32, light: usize) {
        let (gl, t) = (&self.gl, &self.targets);
        let k = &self.kernels.shading;
        self.use_kernel(k);
        t.bind_rays(gl, &t.rays[bounce]);
        t.bind_state(gl, 0);
        let s = &self.scene.settings;
        k.set_i32("term", term);
        k.set_vec3("ambientColor", s.ambient);
        k.set_vec3("backgroundColor", s.background);
        if let Some(l) = self.scene.lights.get(light) {
            k.set_vec3("lightPosition", l.position.to_array());
            k.set_vec3("lightColor", l.color.to_array());
        }
        // SAFETY: additive blending of our own pass.
        unsafe {
            gl.enable(glow::BLEND);
            gl.blend_func(glow::ONE, glow::ONE);
        }
        t.draw(gl, &mut self.timers, k, t.fbo.color.raw());
        // SAFETY: as above.
        unsafe { gl.disable(glow::BLEND) };
        t.unbind(gl);
    }

    /// Keep the primary rays and hits for the AOVs.
    fn keep_primary(&self) {
        if let Some(a) = &self.targets.primary {
            let gl = &self.gl;
            a.rays.origin.copy_from(gl, &self.targets.rays[0].origin);
            a.rays
                .direction
                .copy_from(gl, &self.targets.rays[0].direction);
            a.hit.copy_from(gl, &self.targets.hit);
        }
    }

    /// For the shadow AOV: count the pixels whose primary hit's shadow ray (the traversal just
    /// finished) found no blocker. A pixel without a shadow ray (no hit, or the light behind
    /// the surface: the ray generator leaves its weight 0) is not counted.
    fn count_unblocked(&mut self) {
        let Some(fbo) = self.targets.primary.as_ref().map(|a| a.shadow_fbo.raw()) else {
            return;
        };
        self.hit_records_into(fbo);
        let (gl, t) = (&self.gl, &self.targets);
        let Some(a) = &t.primary else { return };
        let hits = a.shadow_hit.read_f32(gl);
        let rays = t.shadow.direction.read_f32(gl);
        for ((n, h), d) in self.unblocked.iter_mut().zip(&hits).zip(&rays) {
            *n += (d[3] > 0.0 && h[3] == -1.0) as u32;
        }
    }

    /// One bounce: trace the rays of `cur`, shade, generate the next bounce's rays.
    fn bounce(&mut self, camera: &Camera, bounce: u32) {
        let cur = (bounce % 2) as usize;
        self.count_as(Bank::closest_hit(bounce));
        self.trace(cur, false);
        self.count_as(Bank::Frame);
        self.keep_hits();
        if bounce == 0 {
            self.keep_primary();
        }
        self.shade(cur, 0, 0);
        for light in 0..self.scene.lights.len() {
            self.count_as(Bank::occluded(light));
            self.generate(camera, 1, cur, 2, light);
            self.trace(2, true);
            self.count_as(Bank::Frame);
            if bounce == 0 {
                self.count_unblocked();
            }
            self.shade(cur, 1, light);
        }
        if bounce < self.options.refl_depth {
            self.count_as(Bank::Reflection);
            self.generate(camera, 2, cur, 1 - cur, 0);
            self.count_as(Bank::Frame);
        }
    }

    /// The whole frame: the primary rays, then every bounce.
    fn frame(&mut self, camera: &Camera) {
        let gl = &self.gl;
        self.counters.clear(gl, &mut self.timers);
        self.textures.bind(gl);
        gl.clear_tex_f32(self.targets.color.texture.raw(), [0.0, 0.0, 0.0, 1.0]);
        self.calls = Calls::default();
        self.unblocked.iter_mut().for_each(|n| *n = 0);
        self.count_as(Bank::Primary);
        self.generate(camera, 0, 1, 0, 0);
        for b in 0..=self.options.refl_depth {
            self.bounce(camera, b);
        }
    }

    /// The passes from now on count into `bank` and are timed under its kind of ray
    /// ([`super::ray_kinds`]): the generation and traversal of the primary, shadow and
    /// reflection rays apart.
    fn count_as(&mut self, bank: Bank) {
        self.counters.bind(&self.gl, &mut self.timers, bank);
    }

    /// The counters, timers and facts of the frame.
    fn frame_stats(&mut self) -> FrameStats {
        let banks = self.counters.read(&self.gl);
        let count = |i: usize| banks.iter().map(|b| b[i]).sum::<u64>();
        let gpu_ms = self.timers.resolve(&self.gl);
        let tests = ["closest_tests", "shadow_tests"];
        let kind_ms = self.timers.take_ray_kind_ms();
        let mut stats = FrameStats {
            ray_kinds: ray_kinds::ray_kind_stats(&banks, COUNTERS, &tests, kind_ms),
            gpu_ms,
            truncated_rays: self.calls.unfinished,
            ..Default::default()
        };
        stats.triangle_tests.insert("closest".into(), count(0));
        stats.triangle_tests.insert("shadow".into(), count(1));
        stats.events.insert("voxels_visited".into(), count(2));
        stats.events.insert("cloud_jumps".into(), count(3));
        stats.events.insert("empty_cells_skipped".into(), count(4));
        stats.events.insert("rays".into(), count(5));
        stats.events.insert("kernel_calls".into(), self.calls.total);
        stats
            .events
            .insert("traversals".into(), self.calls.traversals);
        stats
            .events
            .insert("max_calls_per_traversal".into(), self.calls.max);
        let g = &self.grid;
        let [cells, refs, tris] = self.textures.bytes();
        let d = g.bx.dims;
        for (k, v) in [
            ("grid_dims", json!([d.x, d.y, d.z])),
            ("grid_bytes", json!(cells + refs + tris)),
            ("grid_cell_bytes", json!(cells)),
            ("grid_reference_bytes", json!(refs)),
            ("grid_triangle_bytes", json!(tris)),
            ("grid_paper_bytes", json!(g.paper_bytes())),
            ("grid_references", json!(g.refs.len())),
            ("grid_build_ms", json!(self.grid_ms)),
            ("proximity_clouds", json!(self.options.proximity_clouds)),
            ("naive_shadows", json!(self.options.naive_shadows)),
            ("masking", json!(!self.options.no_mask)),
            ("single_sided", json!(self.options.single_sided)),
            ("steps_per_call", json!(self.options.steps_per_call)),
        ] {
            stats.facts.insert(k.into(), v);
        }
        stats
    }

    /// The AOVs of the last frame, row 0 = the top row; the normal from the hit record and
    /// the triangles' normals, as shading.frag interpolates it; the shadow AOV from the
    /// shadow rays' results (`shadow_shares`).
    fn aovs(&self) -> Option<Aovs> {
        let AovTargets { rays, hit, .. } = self.targets.primary.as_ref()?;
        let (w, h) = (self.options.width, self.options.height);
        let gl = &self.gl;
        let hits = flip_rows(&hit.read_f32(gl), w, h);
        let dirs = flip_xyz(&rays.direction.read_f32(gl), w, h);
        let a = self.scene.world_attributes();
        let normal = hits
            .iter()
            .zip(&dirs)
            .map(|(h, d)| surface_normal(&a.normals, h, Vec3::from(*d)))
            .collect();
        Some(Aovs {
            ray_origin: flip_xyz(&rays.origin.read_f32(gl), w, h),
            ray_direction: dirs,
            hit_t: hits
                .iter()
                .map(|h| if h[3] < 0.0 { f32::INFINITY } else { h[2] })
                .collect(),
            triangle_id: hits.iter().map(|h| h[3].max(-1.0) as i32).collect(),
            normal,
            shadow: Some(self.shadow_shares(&hits)),
        })
    }
}

impl StreamRenderer {
    /// The shadow AOV, as the ray tracer's: per pixel the share of the point lights whose
    /// shadow ray from the primary hit is unblocked (a light behind the surface counts as
    /// blocked); 1 where the primary ray missed or the scene has no lights. `hits`: the
    /// primary hit records, image row order.
    fn shadow_shares(&self, hits: &[[f32; 4]]) -> Vec<f32> {
        let (w, h) = (self.options.width, self.options.height);
        let lights = self.scene.lights.len();
        let unblocked = flip_rows(&self.unblocked, w, h);
        let share = |(n, hit): (&u32, &[f32; 4])| match lights == 0 || hit[3] < 0.0 {
            true => 1.0,
            false => *n as f32 / lights as f32,
        };
        unblocked.iter().zip(hits).map(share).collect()
    }
}

/// The interpolated normal at hit record `h` (u, v, t, id), turned towards direction `d`.
fn surface_normal(normals: &[Vec3], h: &[f32; 4], d: Vec3) -> [f32; 3] {
    if h[3] < 0.0 {
        return [0.0; 3];
    }
    let k = 3 * h[3] as usize;
    let w = 1.0 - h[0] - h[1];
    let n = (w * normals[k] + h[0] * normals[k + 1] + h[1] * normals[k + 2]).normalize();
    (if n.dot(d) > 0.0 { -n } else { n }).to_array()
}

impl Renderer for StreamRenderer {
    fn name(&self) -> &'static str {
        "stream"
    }

    fn size(&self) -> (u32, u32) {
        (self.options.width, self.options.height)
    }

    fn draw(&mut self, camera: &Camera) -> Result<FrameStats> {
        let start = Instant::now();
        self.frame(camera);
        let mut stats = self.frame_stats();
        if stats.truncated_rays > 0 {
            bail!(
                "{} rays of the streaming tracer were still walking after {} traverse calls \
                 (--stream-max-calls): the frame would be wrong",
                stats.truncated_rays,
                self.options.max_calls
            );
        }
        super::renderer::end_of_frame(&self.gl, &mut stats, start)?;
        self.last = Some((*camera, stats.clone()));
        Ok(stats)
    }

    fn read_back(&mut self) -> Result<Frame> {
        let (_, stats) = super::renderer::last_drawn(&self.last)?;
        let (w, h) = self.size();
        Ok(Frame {
            width: w,
            height: h,
            color: flip_rows(&self.targets.color.read_f32(&self.gl), w, h),
            aovs: self.aovs(),
            stats,
        })
    }

    fn output_texture(&self) -> glow::Texture {
        self.targets.color.texture.raw()
    }

    fn set_model(&mut self, _object: usize, _model: Mat4) -> Result<()> {
        bail!(
            "the streaming tracer's grid is static (as in its paper: built once on the CPU, \
             static scenes only): objects cannot move"
        )
    }

    fn settings(&self) -> serde_json::Map<String, serde_json::Value> {
        let o = &self.options;
        [
            ("pipeline", json!("stream")),
            ("refl_depth", json!(o.refl_depth)),
            ("proximity_clouds", json!(o.proximity_clouds)),
            ("steps_per_call", json!(o.steps_per_call)),
            ("max_calls", json!(o.max_calls)),
            ("naive_shadows", json!(o.naive_shadows)),
            ("masking", json!(!o.no_mask)),
            ("single_sided", json!(o.single_sided)),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }
}
