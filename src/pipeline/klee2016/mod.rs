//! Soft shadows from a rectangular area light with the Cascaded Line Space — Klee 2016
//! (B.Sc. thesis), ch. 3.3, 4 and 5, after Keul et al. \[KLM\].
//!
//! The pipeline of Fig. 7, as [`SoftShadowRenderer::draw`] runs it:
//! 1. **G-buffer** ([`gbuffer`]): the scene rasterised into an FBO with position, normal and
//!    diffuse textures (`glsl/klee2016/gbuffer.vert`, `gbuffer.frag`);
//! 2. **shadow pass** ([`shadow_pass`]): a compute kernel (`glsl/klee2016/linespace_shadow.comp`)
//!    gives every pixel its shadow value — the fraction of its SAMPLES_U × SAMPLES_V shadow rays
//!    that reach the light — by traversing the N-tree ([`crate::pipeline::klee2016::ntree`]) with its
//!    line spaces, and multiplies it into the diffuse texture;
//! 3. **screen-filling quad** ([`present`], `glsl/klee2016/linespace_quad.*`): the diffuse
//!    texture drawn into the output texture (headless: read back into the PNG).
//!
//! The N-tree and the line spaces are built on the CPU once; the node pool goes into a texture
//! buffer (RG32UI), the line spaces into a 3D R32UI texture laid out as Listing 3.

pub mod gbuffer;
pub mod linespace_build;
pub mod linespace_cpu;
pub mod ntree;
pub mod options;
pub mod present;
pub mod shadow_pass;
pub mod shaft;

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Result};
use glam::{Mat4, Vec3};
use serde_json::json;

use self::gbuffer::GBuffer;
use self::ntree::{NTree, PackedLinespaces};
use self::present::Present;
use self::shadow_pass::{shadow_kernel, ShadowPass, ShadowUniforms};
use super::renderer::Renderer;
use crate::frame::{flip_rows, Aovs, Frame, FrameStats};
use crate::gl::context::LoopLimit;
use crate::gl::resources::{GpuTimers, Owned};
use crate::gl::{Gl, GlInfo, PixelGrid, ShaderSource};
pub use crate::scene::shadows::KleeShading;
use crate::scene::{AreaLight, Camera, Scene, ShadowMode};

pub use self::linespace_build::LinespaceBuild;
pub use self::options::SoftShadowOptions;
pub use crate::scene::shadows::parse_samples;

/// The scene's single area light (the thesis lights with one).
pub fn scene_light(scene: &Scene) -> Result<AreaLight> {
    let light = match scene.area_lights.as_slice() {
        [l] => *l,
        [] => bail!(
            "{}: --shadows needs an [[area_light]] in the scene file",
            scene.path.display()
        ),
        _ => bail!(
            "{}: {} area lights; the soft-shadow pipeline (Klee 2016) lights with exactly one",
            scene.path.display(),
            scene.area_lights.len()
        ),
    };
    if !scene.lights.is_empty() {
        bail!(
            "{}: the soft-shadow pipeline (Klee 2016) lights with the [[area_light]] only; the \
             scene's {} point [[light]](s) would be ignored (remove them, or render with the \
             point-light ray tracer)",
            scene.path.display(),
            scene.lights.len()
        );
    }
    Ok(light)
}

/// The view-projection matrix matching `Camera::rays` (pixel centres, image plane at near).
pub fn view_projection(
    camera: &Camera,
    width: u32,
    height: u32,
    scene_lo: Vec3,
    scene_hi: Vec3,
) -> Mat4 {
    let eye = Vec3::from(camera.position);
    let view = Mat4::look_at_rh(eye, Vec3::from(camera.look_at), Vec3::from(camera.up));
    let far_corner = [scene_lo, scene_hi]
        .iter()
        .flat_map(|a| [scene_lo, scene_hi].map(move |b| (*a, b)))
        .map(|(a, b)| {
            Vec3::new(a.x, b.y, a.z)
                .distance(eye)
                .max(Vec3::new(b.x, a.y, b.z).distance(eye))
        })
        .fold(0.0f32, f32::max);
    let far = (far_corner * 2.0).max(camera.near * 10.0);
    let proj = Mat4::perspective_rh_gl(
        camera.fov_y.to_radians(),
        width as f32 / height as f32,
        camera.near,
        far,
    );
    proj * view
}

/// The N-tree, its packed line spaces, the world triangles and the light: what the shadow
/// pass and the CPU implementation share.
pub struct ShadowScene {
    pub tree: NTree,
    pub packed: PackedLinespaces,
    pub triangles: Vec<[Vec3; 3]>,
    pub light: AreaLight,
    bounds: (Vec3, Vec3),
    background: [f32; 3],
}

pub struct SoftShadowRenderer {
    gl: Arc<Gl>,
    pub options: SoftShadowOptions,
    pub scene: ShadowScene,
    uniforms: ShadowUniforms,
    gbuffer: GBuffer,
    shadow: ShadowPass,
    present: Present,
    timers: GpuTimers,
    /// The image and the tiles of the shadow pass's dispatches.
    pixels: PixelGrid,
    /// Dispatches the shadow rays of a pixel are split into in the first attempt of a frame
    /// (1: the whole packet at once; more only by `set_ray_batches`); back to 1 when the mode
    /// or the samples change.
    ray_batches: u32,
    /// The batches of the last frame's last attempt (more than `ray_batches` where pixels hit
    /// llvmpipe's loop limit and were computed again).
    last_batches: u32,
    /// The loop limit the profile keeps (the shadow kernel's budget follows from it).
    loop_limit: Option<LoopLimit>,
    /// The implementation's loop limit where the profile does not keep it (the `gpu` profile
    /// on llvmpipe): a frame whose loops may have reached it is refused.
    unkept_limit: Option<LoopLimit>,
    /// The camera and the statistics of the last frame drawn.
    last: Option<(Camera, FrameStats)>,
}

/// Refuse a frame of the `gpu` profile on an implementation with a loop limit (llvmpipe) where
/// an invocation ran more loop iterations than its lane's share of the limit: its SIMD vector
/// may have been cut short silently (a vector that reaches the limit has a lane past its share,
/// so no cut frame passes).
fn refuse_unkept_limit(limit: Option<LoopLimit>, counts: &shadow_pass::ShadowCounts) -> Result<()> {
    let Some(l) = limit else { return Ok(()) };
    let most = counts.get("loop_iterations_max");
    if most > l.per_invocation() as u64 {
        bail!(
            "the gpu profile sets no loop budget for the shadow pass, and an invocation ran {most} \
             loop iterations, past its share ({}) of this GL implementation's limit of {} per \
             SIMD vector of {} lanes: the frame may be cut short; use GPGPU_RT_PROFILE=auto (or \
             llvmpipe), or fewer light samples",
            l.per_invocation(),
            l.iterations,
            l.lanes
        );
    }
    Ok(())
}

/// The tree's line spaces in the 3D texture layout of Listing 3: built on the GPU when the
/// tree comes without them ([`NTree::build_nodes`]), uploaded when the CPU built them (the node
/// pool's texture buffer checks its own limit when it is made).
fn linespaces(
    gl: &Arc<Gl>,
    info: &GlInfo,
    shaders: &ShaderSource,
    tree: &mut NTree,
) -> Result<(Owned<glow::Texture>, PackedLinespaces)> {
    let max_dim = (info.max_3d_texture_size.max(1) as u32).min(2048);
    let (texture, packed) = if tree.linespaces.is_empty() {
        let built = linespace_build::build(gl, info, shaders, tree, max_dim)?;
        tree.linespace_gpu_ms = Some(built.gpu_ms);
        (built.texture, built.packed)
    } else {
        let words = ntree::linespace_words(tree.n);
        let count = tree.linespace_count;
        let packed = ntree::pack_linespaces(&tree.linespaces, words, count, max_dim)?;
        (shadow_pass::linespace_texture(gl, &packed)?, packed)
    };
    log::info!(
        "N-tree N={} depth={}: {} node groups, {} leaves, {} line spaces ({} bytes), built in {:.0} + {:.0} ms",
        tree.n,
        tree.depth,
        tree.nodes.len() / (tree.n as usize).pow(3),
        tree.leaf_count,
        tree.linespace_count,
        packed.bytes(),
        tree.build_ms,
        tree.linespace_build_ms
    );
    Ok((texture, packed))
}

impl SoftShadowRenderer {
    pub fn new(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: SoftShadowOptions,
    ) -> Result<Self> {
        scene_light(scene)?;
        crate::scene::validate::scene(scene)
            .map_err(|m| anyhow::anyhow!("{}: {m}", scene.path.display()))?;
        let mut tree = NTree::build_nodes(
            &scene.world_triangles(),
            options.ntree_n,
            options.ntree_depth,
        )?;
        if !options.linespace_build.on_gpu(info) {
            tree.build_linespaces_cpu();
        }
        Self::with_tree(gl, info, scene, shaders, options, tree)
    }

    /// Like [`SoftShadowRenderer::new`] with an N-tree built before (over the scene's
    /// world triangles).
    pub fn with_tree(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: SoftShadowOptions,
        mut tree: NTree,
    ) -> Result<Self> {
        let light = scene_light(scene)?;
        if options.width == 0 || options.height == 0 {
            bail!("width and height must be positive");
        }
        // (its G-buffer and shadow values are read back for the AOVs whenever they are asked)
        crate::frame::check_host(options.width, options.height, true)
            .map_err(anyhow::Error::msg)?;
        let pixels = PixelGrid::new(
            options.width,
            options.height,
            options.tile,
            info.profile.dispatch_threads,
        )?;
        let (linespace_texture, packed) = linespaces(&gl, info, shaders, &mut tree)?;
        let samples = (options.samples_u, options.samples_v);
        let limit = info.profile.loop_limit;
        let kernel = shadow_kernel(&gl, shaders, &tree, options.mode, samples, limit)?;
        let (w, h) = (options.width, options.height);
        let triangles = scene.world_triangles();
        let ls = (linespace_texture, &packed);
        let shadow = ShadowPass::new(&gl, info, kernel, &tree, ls, &triangles, &options)?;
        Ok(SoftShadowRenderer {
            gbuffer: GBuffer::new(&gl, shaders, scene, w, h)?,
            present: Present::new(&gl, shaders, w, h)?,
            shadow,
            uniforms: ShadowUniforms {
                light,
                ambient: scene.settings.ambient,
                shadow_offset: scene.settings.shadow_offset,
                shading: options.shading,
            },
            scene: ShadowScene {
                tree,
                packed,
                triangles,
                light,
                bounds: scene.bounds(),
                background: scene.settings.background,
            },
            options,
            timers: GpuTimers::new(&gl),
            pixels,
            ray_batches: 1,
            last_batches: 1,
            loop_limit: limit,
            unkept_limit: info.unkept_loop_limit(),
            last: None,
            gl,
        })
    }

    /// Switch the shadow mode and the light samples (recompiles the shadow kernel only; the
    /// N-tree and the line spaces stay; on failure the old kernel stays).
    pub fn reconfigure(
        &mut self,
        shaders: &ShaderSource,
        mode: ShadowMode,
        su: u32,
        sv: u32,
    ) -> Result<()> {
        let (tree, limit) = (&self.scene.tree, self.loop_limit);
        self.shadow.kernel = shadow_kernel(&self.gl, shaders, tree, mode, (su, sv), limit)?;
        self.options.mode = mode;
        self.options.samples_u = su;
        self.options.samples_v = sv;
        self.ray_batches = 1;
        self.shadow.forget_attempts();
        Ok(())
    }

    /// Recompile every kernel (G-buffer, shadow pass, quad) from `shaders`, with the current
    /// mode and samples: the viewer's live reload. The N-tree and the line spaces stay; on
    /// failure the old programs stay too.
    pub fn recompile(&mut self, shaders: &ShaderSource) -> Result<()> {
        let raster = gbuffer::raster_kernel(&self.gl, shaders)?;
        let quad = present::quad_kernel(&self.gl, shaders)?;
        let o = &self.options;
        self.reconfigure(shaders, o.mode, o.samples_u, o.samples_v)?;
        self.gbuffer.set_kernel(raster);
        self.present.set_kernel(quad);
        Ok(())
    }

    /// Bytes of the node pool (texture buffer) and the leaves' triangle lists.
    pub fn ntree_bytes(&self) -> usize {
        self.scene.tree.node_bytes()
    }

    /// Bytes of the 3D line-space texture.
    pub fn linespace_bytes(&self) -> usize {
        self.scene.packed.bytes()
    }

    /// Read the 3D line-space texture back (the round-trip test).
    pub fn read_linespace_texture(&self) -> Vec<u32> {
        self.shadow
            .read_linespace_texture(self.scene.packed.texels.len())
    }

    /// Dispatch the shadow rays of every pixel in `n` batches in the first attempt of the next
    /// frames (normally 1: only the pixels that hit the loop limit get more, see
    /// `ShadowPass::run`); clamped to 1..=rays.
    pub fn set_ray_batches(&mut self, n: u32) {
        self.ray_batches = n.clamp(1, self.rays());
        self.shadow.forget_attempts();
    }

    fn rays(&self) -> u32 {
        self.options.samples_u * self.options.samples_v
    }

    /// The G-buffer's position (w: 1 = geometry) and normal (w: triangle id) of the last
    /// frame, row 0 = the top image row.
    pub fn read_gbuffer(&self) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
        let (w, h) = self.size();
        (
            flip_rows(&self.gbuffer.read(0), w, h),
            flip_rows(&self.gbuffer.read(1), w, h),
        )
    }

    /// Per pixel of the last frame (row 0 = the top image row) the first rays of the batches
    /// its shadow rays were traced in, a bit per ray (bit r of word r / 32): the split the
    /// CPU twin needs to count as the GPU did (`LinespaceShadows::shadow_in_ranges`).
    pub fn read_batch_starts(&self) -> Vec<[u32; 4]> {
        let (w, h) = self.size();
        flip_rows(&self.shadow.read_batch_starts(w, h), w, h)
    }

    /// A frame: the G-buffer, the shadow pass (`ray_batches` dispatches per tile, more for the
    /// pixels that hit llvmpipe's loop limit: `ShadowPass::run`) and the quad; its statistics.
    fn draw_passes(&mut self, camera: &Camera) -> Result<FrameStats> {
        let (w, h) = self.size();
        let (lo, hi) = self.scene.bounds;
        let vp = view_projection(camera, w, h, lo, hi);
        let eye = Vec3::from(camera.position);
        self.gbuffer
            .draw(&mut self.timers, &vp, eye, self.scene.background);
        crate::gl::check_error(&self.gl, "the G-buffer pass")?;
        let pixels = self.pixels;
        let batches = (self.rays(), self.ray_batches);
        let (counts, last_batches) = self.shadow.run(
            &mut self.timers,
            pixels,
            &self.gbuffer.textures(),
            &self.uniforms,
            batches,
        )?;
        self.last_batches = last_batches;
        crate::gl::check_error(&self.gl, "the shadow pass")?;
        refuse_unkept_limit(self.unkept_limit, &counts)?;
        self.present
            .draw(&mut self.timers, self.gbuffer.textures()[2]);
        crate::gl::check_error(&self.gl, "the screen-filling quad")?;
        // every truncated pixel was computed again in more batches: the frame is complete
        let mut stats = FrameStats {
            gpu_ms: self.timers.resolve(&self.gl),
            ..Default::default()
        };
        let retried = counts.get("truncated");
        stats.events.insert("retried_pixels".into(), retried);
        let kernel = self.shadow.kernel.timer().to_string();
        stats
            .triangle_tests
            .insert(kernel, counts.get("triangle_tests"));
        for e in ["linespace_lookups", "nodes_visited", "packet_failures"] {
            stats.events.insert(e.into(), counts.get(e));
        }
        for e in &shadow_pass::COUNTERS[shadow_pass::EVENTS] {
            stats.events.insert((*e).into(), counts.get(e));
        }
        stats.facts = self.facts();
        Ok(stats)
    }

    /// The AOVs of the base tracer from the G-buffer: primary rays from the camera, hits from
    /// the G-buffer; the shadow values.
    fn aovs(&self, camera: &Camera) -> Aovs {
        let (w, h) = self.size();
        let (position, normal) = self.read_gbuffer();
        let shadow = crate::gl::resources::read_texture_rgba32f(
            &self.gl,
            self.shadow.shadow_texture(),
            w,
            h,
        );
        let rays = camera.rays(w, h);
        let mut aovs = Aovs {
            shadow: Some(flip_rows(&shadow, w, h).iter().map(|c| c[0]).collect()),
            ..Default::default()
        };
        for row in 0..h {
            let y = h - 1 - row; // GL row of image row `row`
            for x in 0..w {
                let (o, d) = rays.primary_ray(x, y);
                let i = (row * w + x) as usize;
                let (p, nrm) = (position[i], normal[i]);
                aovs.ray_origin.push(o.to_array());
                aovs.ray_direction.push(d.to_array());
                let hit = p[3] > 0.0;
                let hit_t = (Vec3::new(p[0], p[1], p[2]) - o).dot(d);
                aovs.hit_t.push(if hit { hit_t } else { f32::INFINITY });
                aovs.triangle_id.push(if hit { nrm[3] as i32 } else { -1 });
                aovs.normal.push(if hit {
                    [nrm[0], nrm[1], nrm[2]]
                } else {
                    [0.0; 3]
                });
            }
        }
        aovs
    }

    /// The renderer's facts in the frame statistics (options, N-tree and line-space sizes,
    /// build times).
    fn facts(&self) -> BTreeMap<String, serde_json::Value> {
        [
            ("shadows", json!(self.options.mode)),
            ("ray_batches", json!(self.last_batches)),
            (
                "light_samples",
                json!(format!(
                    "{}x{}",
                    self.options.samples_u, self.options.samples_v
                )),
            ),
            (
                "num_rays",
                json!(self.options.samples_u * self.options.samples_v),
            ),
            ("ntree_n", json!(self.scene.tree.n)),
            ("ntree_depth", json!(self.scene.tree.depth)),
            ("ntree_bytes", json!(self.ntree_bytes())),
            ("linespace_bytes", json!(self.linespace_bytes())),
            ("linespaces", json!(self.scene.tree.linespace_count)),
            (
                "ntree_node_groups",
                json!(self.scene.tree.nodes.len() / (self.scene.tree.n as usize).pow(3)),
            ),
            ("ntree_leaves", json!(self.scene.tree.leaf_count)),
            ("ntree_build_ms", json!(self.scene.tree.build_ms)),
            (
                "linespace_build_ms",
                json!(self.scene.tree.linespace_build_ms),
            ),
            (
                "linespace_build_gpu_ms",
                json!(self.scene.tree.linespace_gpu_ms),
            ),
            (
                "linespace_texture",
                json!([
                    self.scene.packed.tex_x_res,
                    self.scene.packed.tex_y_res,
                    self.scene.packed.tex_z_res
                ]),
            ),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }

    /// The CPU implementation over the same N-tree and light (src/reference/linespace.rs).
    pub fn cpu(&self) -> crate::reference::linespace::LinespaceShadows<'_> {
        crate::reference::linespace::LinespaceShadows {
            tree: &self.scene.tree,
            packed: &self.scene.packed,
            triangles: &self.scene.triangles,
            light: self.scene.light,
            samples_u: self.options.samples_u,
            samples_v: self.options.samples_v,
            offset: self.uniforms.shadow_offset,
        }
    }
}

impl Renderer for SoftShadowRenderer {
    fn name(&self) -> &'static str {
        "linespace"
    }

    fn size(&self) -> (u32, u32) {
        (self.options.width, self.options.height)
    }

    /// Render one frame (G-buffer, shadow pass, screen-filling quad into the output texture)
    /// and read back only the counters and the timers.
    fn draw(&mut self, camera: &Camera) -> Result<FrameStats> {
        let t0 = Instant::now();
        let mut stats = self.draw_passes(camera)?;
        super::renderer::finish(&self.gl);
        stats.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        self.last = Some((*camera, stats.clone()));
        Ok(stats)
    }

    fn read_back(&mut self) -> Result<Frame> {
        let t0 = Instant::now();
        let (camera, mut stats) = super::renderer::last_drawn(&self.last)?;
        let (w, h) = self.size();
        let color =
            crate::gl::resources::read_texture_rgba32f(&self.gl, self.present.output(), w, h);
        let aovs = self.aovs(&camera);
        stats.wall_ms += t0.elapsed().as_secs_f64() * 1e3;
        Ok(Frame {
            width: w,
            height: h,
            color: flip_rows(&color, w, h),
            aovs: Some(aovs),
            stats,
        })
    }

    /// The RGBA32F output texture of the last frame (what the screen-filling quad drew), GL
    /// row order.
    fn output_texture(&self) -> glow::Texture {
        self.present.output()
    }

    fn set_model(&mut self, _object: usize, _model: Mat4) -> Result<()> {
        bail!("the soft-shadow pipeline's N-tree is built once: its objects cannot move")
    }

    fn settings(&self) -> serde_json::Map<String, serde_json::Value> {
        // the scene has exactly one area light (`scene_light`)
        [
            ("area_lights", json!(1)),
            ("tile", json!(self.options.tile)),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }
}
