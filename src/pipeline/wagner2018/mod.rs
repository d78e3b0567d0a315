//! Wagner 2018 (B.Sc. thesis, "Potenzialanalyse der GPU-Beschleunigung beim Raytracing"): a
//! CUDA ray tracer with a BVH, here as its own pipeline (`--tracer bvh --bvh-variant wagner`):
//!
//! 1. the BVH is **built on the CPU** by Listings 4.3/4.4 with the simplified SAH of eq. 4.1
//!    ([`crate::pipeline::wagner2018::bvh`]) — again whenever an object moved (ch. 3.2: "rebuild
//!    the BVH completely") — and uploaded with the triangles into texture buffers: the three
//!    textures of Fig. 4.3 and three for the triangles' vertices, normals and colours
//!    ([`gpu`]);
//! 2. **one kernel** (`glsl/wagner2018/raytrace.comp`), one invocation per pixel in 16×16 work
//!    groups (ch. 3.3.2), does everything: `createRay` (Listing 4.1), the walk through the BVH
//!    with `intersectAABB` (Listing 4.5) and `intersectTriangle` (Listing 4.2), Lambert shading
//!    with one point light and a hard shadow ray (ch. 5), into an RGBA32F image;
//! 3. that image is the output texture, which `view` shows on a screen-filling quad (ch. 4.3's
//!    textured plane) and `render` reads back.
//!
//! The CPU twin of the kernel is [`crate::reference::wagner2018`].

pub mod bvh;
pub mod gpu;
pub mod uniforms;

use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use glam::{Mat4, Vec3};
use serde_json::json;

use self::gpu::{Images, SceneTextures};
use self::uniforms::{Lighting, Surface, WagnerCamera, EPSILON, LOOP_BUDGET, STACK};
use super::renderer::Renderer;
use crate::frame::{flip_rows, flip_xyz, Aovs, Frame, FrameStats};
use crate::gl::resources::{GpuTimers, Ssbo};
use crate::gl::slots::ssbo;
use crate::gl::{check_error, Defines, Gl, GlInfo, Kernel, PixelGrid, ShaderSource};
use crate::pipeline::wagner2018::bvh::{WagnerBvh, WagnerStats};
use crate::scene::{Camera, Scene};

/// The kernel's work group: 16×16 (ch. 3.3.2).
pub const GROUP: u32 = 16;

/// The 64-bit counters of the kernel (`#define COUNTER_*`): triangle tests of the closest-hit
/// walks and of the shadow rays, nodes visited by both, rays cut short.
pub const COUNTERS: &[&str] = &[
    "primary_tests",
    "shadow_tests",
    "nodes_visited",
    "truncated_rays",
    // the primary rays and the shadow rays traced (ours: rays per second in accel-compare)
    "rays",
];

/// Options of Wagner 2018's renderer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WagnerOptions {
    pub width: u32,
    pub height: u32,
    /// Dispatches cover at most tile×tile pixels (a multiple of 16; 0: one dispatch).
    pub tile: u32,
    /// Keep the rays, normals and shadow flags for the AOVs.
    pub aovs: bool,
}

/// The scene in world space as the kernel sees it, and the model matrices it was built for.
pub struct World {
    pub bvh: WagnerBvh,
    /// per-vertex normals and colours, 3 per triangle
    pub normals: Vec<Vec3>,
    pub colors: Vec<Vec3>,
    built_for: Vec<Mat4>,
}

impl World {
    /// Transform `scene`'s objects by their model matrices and build the BVH (Listing 4.3).
    pub fn build(scene: &Scene) -> Result<World> {
        let a = scene.world_attributes();
        let triangles = a
            .positions
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        Ok(World {
            bvh: WagnerBvh::build(triangles)?,
            normals: a.normals,
            colors: a.colors,
            built_for: scene.objects.iter().map(|o| o.model).collect(),
        })
    }

    /// The triangles' normals and colours for the CPU twin.
    pub fn surface(&self) -> Surface<'_> {
        Surface {
            normals: &self.normals,
            colors: &self.colors,
        }
    }
}

/// The last build: its facts (with the upload), how many so far, whether this frame built.
#[derive(Debug, Clone, Copy, Default)]
struct Builds {
    stats: WagnerStats,
    /// the world transform, the build and the upload, in milliseconds (`bvh_build_ms`, as
    /// the SAH BVH reports it; `stats.build_ms`, Listing 4.3 alone: `bvh_recursive_build_ms`)
    ms: f64,
    count: u64,
    rebuilt: bool,
}

/// Wagner 2018's ray tracer: the BVH and the triangles in textures, one kernel.
pub struct WagnerRenderer {
    gl: Arc<Gl>,
    kernel: Kernel,
    options: WagnerOptions,
    pixels: PixelGrid,
    /// the scene with the current model matrices (no textures)
    scene: Scene,
    world: World,
    textures: SceneTextures,
    images: Images,
    counters: Ssbo,
    timers: GpuTimers,
    lighting: Lighting,
    builds: Builds,
    last: Option<(Camera, FrameStats)>,
}

/// The kernel's `#define`s: the walk's bounds, ε, the shadow offset, the counter slots.
fn kernel_defines(scene: &Scene) -> Defines {
    let mut d = Defines::new()
        .set("WAGNER_STACK", STACK)
        .set("LOOP_BUDGET", LOOP_BUDGET)
        .set("EPSILON", format!("{EPSILON:?}"))
        .set(
            "SHADOW_OFFSET",
            format!("{:?}", scene.settings.shadow_offset),
        );
    for (i, c) in COUNTERS.iter().enumerate() {
        d = d.set(&format!("COUNTER_{}", c.to_uppercase()), i);
    }
    d
}

/// The lighting of the kernel: the scene's first point light (the thesis lights with one; the
/// others are left out with a warning), ambient light, background and shadow offset.
pub fn lighting(scene: &Scene) -> Result<Lighting> {
    let Some(light) = scene.lights.first() else {
        bail!(
            "{}: Wagner 2018's kernel lights with one point light ([[light]]); the scene has none",
            scene.path.display()
        );
    };
    if scene.lights.len() > 1 {
        log::warn!(
            "{}: {} point lights; Wagner 2018's kernel lights with the first only",
            scene.path.display(),
            scene.lights.len()
        );
    }
    Ok(Lighting {
        light_position: light.position,
        light_color: light.color,
        ambient: Vec3::from(scene.settings.ambient),
        background: Vec3::from(scene.settings.background),
        shadow_offset: scene.settings.shadow_offset,
    })
}

/// Refuse what the renderer cannot do, before anything is allocated.
fn check(info: &GlInfo, scene: &Scene, o: &WagnerOptions) -> Result<PixelGrid> {
    if scene.triangle_count() == 0 {
        bail!("{}: the scene has no triangles", scene.path.display());
    }
    let max_tex = info.max_texture_size as u32;
    let (w, h) = (o.width, o.height);
    if w == 0 || h == 0 || w > max_tex || h > max_tex {
        bail!("image size {w}x{h} outside 1..={max_tex} (GL_MAX_TEXTURE_SIZE)");
    }
    if !o.tile.is_multiple_of(GROUP) {
        bail!(
            "--tile {} must be a multiple of {GROUP} (Wagner 2018's 16×16 blocks)",
            o.tile
        );
    }
    PixelGrid::new(w, h, o.tile, info.profile.dispatch_threads)
}

impl WagnerRenderer {
    /// Build the BVH of `scene` on the CPU, upload it, compile the kernel.
    pub fn new(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: WagnerOptions,
    ) -> Result<WagnerRenderer> {
        crate::scene::validate::scene(scene)
            .map_err(|m| anyhow!("{}: {m}", scene.path.display()))?;
        let pixels = check(info, scene, &options)?;
        let lighting = lighting(scene)?;
        let kernel = Kernel::compute(
            &gl,
            shaders,
            "wagner2018/raytrace.comp",
            &kernel_defines(scene),
            "raytrace",
        )?;
        let scene = Scene {
            textures: Vec::new(),
            ..scene.clone()
        };
        let start = Instant::now();
        let world = World::build(&scene)?;
        let textures = SceneTextures::upload(&gl, &world.bvh, &world.normals, &world.colors)?;
        let builds = Builds {
            stats: world.bvh.stats,
            ms: start.elapsed().as_secs_f64() * 1e3,
            count: 1,
            rebuilt: true,
        };
        let counters_bytes = 8 * COUNTERS.len();
        let r = WagnerRenderer {
            images: Images::new(&gl, options.width, options.height)?,
            counters: Ssbo::new(&gl, "counters", counters_bytes, None, i64::MAX)?,
            kernel,
            options,
            pixels,
            scene,
            world,
            textures,
            timers: GpuTimers::new(&gl),
            lighting,
            builds,
            last: None,
            gl,
        };
        check_error(&r.gl, "creating Wagner 2018's ray tracer")?;
        Ok(r)
    }

    /// The BVH and the triangles' attributes the kernel has now (for the CPU twin).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The kernel's lighting (for the CPU twin).
    pub fn lighting(&self) -> Lighting {
        self.lighting
    }

    /// Builds so far (the first, and one per frame after an object moved).
    pub fn builds(&self) -> u64 {
        self.builds.count
    }

    /// Build again and upload when a model matrix changed since the last build.
    fn rebuild_if_moved(&mut self) -> Result<()> {
        let models: Vec<Mat4> = self.scene.objects.iter().map(|o| o.model).collect();
        if models == self.world.built_for {
            return Ok(());
        }
        let start = Instant::now();
        let world = World::build(&self.scene)?;
        let textures = SceneTextures::upload(&self.gl, &world.bvh, &world.normals, &world.colors)?;
        // the old textures drop here, after the new ones are made
        self.textures = textures;
        self.world = world;
        self.builds.stats = self.world.bvh.stats;
        self.builds.ms = start.elapsed().as_secs_f64() * 1e3;
        self.builds.count += 1;
        self.builds.rebuilt = true;
        Ok(())
    }

    /// The kernel over the image, in tiles.
    fn dispatch(&mut self, camera: &Camera) {
        let gl = &self.gl;
        let (w, h) = (self.options.width, self.options.height);
        self.counters.bind(gl, ssbo::COUNTERS);
        self.counters.clear_u32(gl, 0);
        self.textures.bind(gl);
        self.images.bind(gl);
        let k = &self.kernel;
        k.use_program();
        let cam = WagnerCamera::new(camera, w, h);
        gpu::set_uniforms(k, &cam, &self.lighting, (w, h), self.options.aovs);
        k.dispatch_pixel_groups(&mut self.timers, self.pixels, GROUP);
    }

    /// The counters, timers and facts of the frame.
    fn frame_stats(&mut self) -> FrameStats {
        let raw = self.counters.read_u32(&self.gl);
        let count = |i: usize| super::renderer::counter_value(&raw, i);
        let mut stats = FrameStats {
            gpu_ms: self.timers.resolve(&self.gl),
            truncated_rays: count(3),
            ..Default::default()
        };
        stats.triangle_tests.insert("primary".into(), count(0));
        stats.triangle_tests.insert("shadow".into(), count(1));
        stats.events.insert("nodes_visited".into(), count(2));
        stats.events.insert("rays".into(), count(4));
        let (s, b) = (&self.builds.stats, &self.builds);
        let (bvh_bytes, triangle_bytes) = self.textures.bytes();
        for (k, v) in [
            ("bvh_variant", json!("wagner")),
            ("bvh_build_ms", json!(b.ms)),
            ("bvh_recursive_build_ms", json!(s.build_ms)),
            ("bvh_rebuilt", json!(b.rebuilt)),
            ("bvh_nodes", json!(s.nodes)),
            ("bvh_leaves", json!(s.leaves)),
            ("bvh_depth", json!(s.depth)),
            ("bvh_max_leaf", json!(s.max_leaf)),
            ("bvh_bytes", json!(bvh_bytes)),
            ("bvh_sah_cost", json!(s.sah_cost)),
            ("triangle_texture_bytes", json!(triangle_bytes)),
        ] {
            stats.facts.insert(k.into(), v);
        }
        stats
    }

    /// The AOVs of the last frame, row 0 = the top row: rays from the camera position,
    /// first hits, normals; `shadow`: 1 lit (or no geometry), 0 in shadow.
    fn aovs(&self, camera: &Camera) -> Aovs {
        let (w, h) = (self.options.width, self.options.height);
        let hit = flip_rows(&self.images.hit.read_f32(&self.gl), w, h);
        let normal = flip_rows(&self.images.normal.read_f32(&self.gl), w, h);
        let origin = WagnerCamera::new(camera, w, h).position.to_array();
        Aovs {
            ray_origin: vec![origin; hit.len()],
            ray_direction: flip_xyz(&self.images.ray.read_f32(&self.gl), w, h),
            hit_t: hit.iter().map(|v| v[0]).collect(),
            triangle_id: hit.iter().map(|v| v[1].to_bits() as i32).collect(),
            normal: normal.iter().map(|n| [n[0], n[1], n[2]]).collect(),
            shadow: Some(normal.iter().map(|n| n[3]).collect()),
        }
    }
}

impl Renderer for WagnerRenderer {
    fn name(&self) -> &'static str {
        "bvh"
    }

    fn size(&self) -> (u32, u32) {
        (self.options.width, self.options.height)
    }

    fn draw(&mut self, camera: &Camera) -> Result<FrameStats> {
        let start = Instant::now();
        self.rebuild_if_moved()?;
        self.dispatch(camera);
        let mut stats = self.frame_stats();
        // `bvh_rebuilt` says whether this frame built (the first frame: the build of `new`)
        self.builds.rebuilt = false;
        if stats.truncated_rays > 0 {
            bail!(
                "{} rays of Wagner 2018's kernel stopped early (a walk longer than {LOOP_BUDGET} \
                 steps, or a full stack of {STACK}): the frame would be wrong",
                stats.truncated_rays
            );
        }
        super::renderer::end_of_frame(&self.gl, &mut stats, start)?;
        self.last = Some((*camera, stats.clone()));
        Ok(stats)
    }

    fn read_back(&mut self) -> Result<Frame> {
        let (camera, stats) = super::renderer::last_drawn(&self.last)?;
        let (w, h) = self.size();
        Ok(Frame {
            width: w,
            height: h,
            color: flip_rows(&self.images.output.read_f32(&self.gl), w, h),
            aovs: self.options.aovs.then(|| self.aovs(&camera)),
            stats,
        })
    }

    fn output_texture(&self) -> glow::Texture {
        self.images.output.texture.raw()
    }

    fn set_model(&mut self, object: usize, model: Mat4) -> Result<()> {
        let n = self.scene.objects.len();
        let o = self.scene.objects.get_mut(object);
        o.ok_or_else(|| anyhow!("no object {object}: the scene has {n} objects"))?
            .model = model;
        Ok(())
    }

    fn settings(&self) -> serde_json::Map<String, serde_json::Value> {
        [
            ("pipeline", json!("wagner2018")),
            ("bvh_variant", json!("wagner")),
            ("lights", json!(1)),
            ("lights_ignored", json!(self.scene.lights.len() - 1)),
            ("refl_depth", json!(0)),
            ("tile", json!(self.options.tile)),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }
}
