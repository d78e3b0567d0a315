//! Soft shadows from a rectangular area light with the Cascaded Line Space — Klee 2016
//! (B.Sc. thesis), ch. 3.3, 4 and 5, after Keul et al. \[KLM\].
//!
//! The pipeline of Fig. 7, as [`SoftShadowRenderer::render`] runs it:
//! 1. **G-buffer**: the scene rasterised into an FBO with position, normal and diffuse
//!    textures (`glsl/gbuffer.vert`, `glsl/gbuffer.frag`);
//! 2. **shadow pass**: a compute kernel (`glsl/linespace_shadow.comp`) gives every pixel its
//!    shadow value — the fraction of its SAMPLES_U × SAMPLES_V shadow rays that reach the
//!    light — by traversing the N-tree ([`ntree`]) with its line spaces, and multiplies it
//!    into the diffuse texture;
//! 3. **screen-filling quad** (`glsl/linespace_quad.*`): the diffuse texture drawn into the
//!    output framebuffer (headless: an FBO read back into the PNG).
//!
//! The N-tree and the line spaces are built on the CPU once; the node pool goes into a texture
//! buffer (RG32UI), the line spaces into a 3D R32UI texture laid out as Listing 3.

pub mod ntree;

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use glam::{Mat4, Vec3};
use glow::HasContext;
use serde_json::json;

use crate::gl::resources::{read_texture_rgba32f, GpuTimers, Image2d, Ssbo};
use crate::gl::{compile_program, Defines, Gl, GlInfo, ShaderSource};
use crate::scene::{AreaLight, Camera, Scene};
use crate::tracer::{flip_rows, Aovs, FrameStats};

pub use crate::scene::shadows::{parse_samples, ShadowMode};
pub use ntree::{NTree, PackedLinespaces};

/// Options of the soft-shadow renderer.
#[derive(Debug, Clone)]
pub struct SoftShadowOptions {
    pub mode: ShadowMode,
    pub samples_u: u32,
    pub samples_v: u32,
    /// N: cells per axis of every N-tree node (10 in the thesis).
    pub ntree_n: u32,
    /// Levels of the N-tree including the root (3 in the thesis).
    pub ntree_depth: u32,
    pub width: u32,
    pub height: u32,
    /// Dispatch the shadow pass in tiles of at most tile×tile pixels (0: one dispatch).
    pub tile: u32,
}

/// A frame of the soft-shadow renderer (row 0 = the top image row everywhere).
#[derive(Debug, Clone)]
pub struct SoftShadowFrame {
    pub width: u32,
    pub height: u32,
    pub color: Vec<[f32; 4]>,
    /// Fraction of unblocked shadow rays per pixel (1 where no geometry was hit).
    pub shadow: Vec<f32>,
    /// The G-buffer's position (w: 1 = geometry) and normal (w: triangle id).
    pub gbuffer_position: Vec<[f32; 4]>,
    pub gbuffer_normal: Vec<[f32; 4]>,
    pub aovs: Aovs,
    pub stats: FrameStats,
}

/// Counter slots of the shadow kernel.
const COUNTERS: [&str; 5] = [
    "triangle_tests",
    "linespace_lookups",
    "nodes_visited",
    "truncated",
    "packet_failures",
];

/// The scene's single area light (the thesis lights with one).
pub fn scene_light(scene: &Scene) -> Result<AreaLight> {
    match scene.area_lights.as_slice() {
        [l] => Ok(*l),
        [] => bail!(
            "{}: --shadows needs an [[area_light]] in the scene file",
            scene.path.display()
        ),
        _ => bail!(
            "{}: {} area lights; the soft-shadow pipeline (Klee 2016) lights with exactly one",
            scene.path.display(),
            scene.area_lights.len()
        ),
    }
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

pub struct SoftShadowRenderer {
    gl: Arc<Gl>,
    pub options: SoftShadowOptions,
    pub tree: NTree,
    pub packed: PackedLinespaces,
    pub triangles: Vec<[Vec3; 3]>,
    pub light: AreaLight,
    background: [f32; 3],
    ambient: [f32; 3],
    shadow_offset: f32,
    scene_bounds: (Vec3, Vec3),
    triangle_count: usize,
    // G-buffer
    raster: glow::Program,
    vao: glow::VertexArray,
    vbos: Vec<glow::Buffer>,
    gbuffer_fbo: glow::Framebuffer,
    gbuffer_depth: glow::Renderbuffer,
    /// position, normal, diffuse (RGBA32F)
    gbuffer: [glow::Texture; 3],
    // shadow pass
    shadow_program: glow::Program,
    shadow_texture: glow::Texture,
    node_buffer: glow::Buffer,
    node_texture: glow::Texture,
    linespace_texture: glow::Texture,
    tri_ssbo: Ssbo,
    leaf_ssbo: Ssbo,
    counter_ssbo: Ssbo,
    // present
    quad_program: glow::Program,
    quad_vao: glow::VertexArray,
    output_fbo: glow::Framebuffer,
    output_texture: glow::Texture,
    timers: GpuTimers,
    /// Dispatches the shadow rays of a pixel are split into (1: the whole packet at once).
    /// Doubled when a frame hits llvmpipe's loop limit, kept for the next frames, back to 1
    /// when the mode or the samples change.
    ray_batches: u32,
}

fn rgba32f_texture(gl: &Gl, w: u32, h: u32) -> Result<glow::Texture> {
    Ok(Image2d::new(gl, w, h, glow::RGBA32F)?.texture)
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
        let tree = NTree::build(
            &scene.world_triangles(),
            options.ntree_n,
            options.ntree_depth,
        )?;
        Self::with_tree(gl, info, scene, shaders, options, tree)
    }

    /// The shadow kernel for a mode and a number of samples (the defines of Algorithm 1).
    fn shadow_kernel(
        gl: &Gl,
        shaders: &ShaderSource,
        tree: &NTree,
        mode: ShadowMode,
        su: u32,
        sv: u32,
    ) -> Result<glow::Program> {
        if !(1..=10).contains(&su) || !(1..=10).contains(&sv) {
            bail!("{su}x{sv} light samples: 1x1 to 10x10");
        }
        let defines = Defines::new()
            .set("NTREE_N", tree.n)
            .set("NUM_MAX_DEPTH", tree.depth - 1)
            .set("LAST_LS_DEPTH", tree.last_linespace_depth())
            .set("SAMPLES_U", su)
            .set("SAMPLES_V", sv)
            .set("NUM_RAYS", su * sv)
            .set("SHADOW_MODE", mode.kernel_mode());
        compile_program(
            gl,
            shaders,
            &[(glow::COMPUTE_SHADER, "linespace_shadow.comp")],
            &defines,
        )
    }

    /// Switch the shadow mode and the light samples (recompiles the shadow kernel only; the
    /// N-tree and the line spaces stay).
    pub fn reconfigure(
        &mut self,
        shaders: &ShaderSource,
        mode: ShadowMode,
        su: u32,
        sv: u32,
    ) -> Result<()> {
        let p = Self::shadow_kernel(&self.gl, shaders, &self.tree, mode, su, sv)?;
        // SAFETY: deleting our old program.
        unsafe { self.gl.delete_program(self.shadow_program) };
        self.shadow_program = p;
        self.options.mode = mode;
        self.options.samples_u = su;
        self.options.samples_v = sv;
        self.ray_batches = 1;
        Ok(())
    }

    /// Recompile every kernel (G-buffer, shadow pass, quad) from `shaders` with a mode and a
    /// number of samples: the viewer's live reload. The N-tree and the line spaces stay; on
    /// failure the old programs stay too.
    pub fn recompile(
        &mut self,
        shaders: &ShaderSource,
        mode: ShadowMode,
        su: u32,
        sv: u32,
    ) -> Result<()> {
        let gl = self.gl.clone();
        let (raster, quad) = Self::raster_programs(&gl, shaders)?;
        // the shadow kernel as `reconfigure` makes it (which keeps the old one on failure)
        if let Err(e) = self.reconfigure(shaders, mode, su, sv) {
            // SAFETY: deleting the programs we just made.
            unsafe {
                gl.delete_program(raster);
                gl.delete_program(quad);
            }
            return Err(e);
        }
        // SAFETY: deleting our old programs.
        unsafe {
            gl.delete_program(self.raster);
            gl.delete_program(self.quad_program);
        }
        self.raster = raster;
        self.quad_program = quad;
        Ok(())
    }

    /// The G-buffer's and the screen-filling quad's programs.
    fn raster_programs(gl: &Gl, shaders: &ShaderSource) -> Result<(glow::Program, glow::Program)> {
        let raster = compile_program(
            gl,
            shaders,
            &[
                (glow::VERTEX_SHADER, "gbuffer.vert"),
                (glow::FRAGMENT_SHADER, "gbuffer.frag"),
            ],
            &Defines::new(),
        )?;
        let quad = compile_program(
            gl,
            shaders,
            &[
                (glow::VERTEX_SHADER, "linespace_quad.vert"),
                (glow::FRAGMENT_SHADER, "linespace_quad.frag"),
            ],
            &Defines::new(),
        );
        match quad {
            Ok(q) => Ok((raster, q)),
            Err(e) => {
                // SAFETY: deleting the program we just made.
                unsafe { gl.delete_program(raster) };
                Err(e)
            }
        }
    }

    /// Like [`SoftShadowRenderer::new`] with an N-tree built before (over the scene's
    /// world triangles).
    pub fn with_tree(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: SoftShadowOptions,
        tree: NTree,
    ) -> Result<Self> {
        let light = scene_light(scene)?;
        if options.width == 0 || options.height == 0 {
            bail!("width and height must be positive");
        }
        if options.tile != 0 && !options.tile.is_multiple_of(8) {
            bail!("--tile {} must be a multiple of 8 (or 0)", options.tile);
        }
        let triangles = scene.world_triangles();
        let words = ntree::linespace_words(tree.n);
        let max_dim = (info.max_3d_texture_size.max(1) as u32).min(2048);
        let packed =
            ntree::pack_linespaces(&tree.linespaces, words, tree.linespace_count, max_dim)?;
        let max_tb = unsafe { gl.get_parameter_i32(glow::MAX_TEXTURE_BUFFER_SIZE) } as i64;
        if tree.nodes.len() as i64 > max_tb {
            bail!(
                "the node pool has {} nodes, more than GL_MAX_TEXTURE_BUFFER_SIZE = {max_tb} texels",
                tree.nodes.len()
            );
        }
        let nn = (tree.n as usize).pow(3);
        log::info!(
            "N-tree N={} depth={}: {} node groups, {} leaves, {} line spaces ({} bytes), built in {:.0} + {:.0} ms",
            tree.n,
            tree.depth,
            tree.nodes.len() / nn,
            tree.leaf_count,
            tree.linespace_count,
            packed.bytes(),
            tree.build_ms,
            tree.linespace_build_ms
        );
        let shadow_program = Self::shadow_kernel(
            &gl,
            shaders,
            &tree,
            options.mode,
            options.samples_u,
            options.samples_v,
        )?;
        let (raster, quad_program) = match Self::raster_programs(&gl, shaders) {
            Ok(p) => p,
            Err(e) => {
                // SAFETY: deleting the program we just made.
                unsafe { gl.delete_program(shadow_program) };
                return Err(e);
            }
        };
        let attrs = scene.world_attributes();
        let pos: Vec<[f32; 3]> = triangles.iter().flatten().map(|v| v.to_array()).collect();
        let nor: Vec<[f32; 3]> = attrs.normals.iter().map(|v| v.to_array()).collect();
        let col: Vec<[f32; 3]> = attrs.colors.iter().map(|v| v.to_array()).collect();
        let max = info.max_ssbo_block_size;
        let tri4: Vec<[f32; 4]> = triangles
            .iter()
            .flatten()
            .map(|v| [v.x, v.y, v.z, 1.0])
            .collect();
        let tri_ssbo = Ssbo::new(
            &gl,
            "triVertex",
            16 * tri4.len(),
            Some(bytemuck::cast_slice(&tri4)),
            max,
        )?;
        let leaf_ssbo = Ssbo::new(
            &gl,
            "leafTriangles",
            4 * tree.leaf_triangles.len(),
            Some(bytemuck::cast_slice(&tree.leaf_triangles)),
            max,
        )?;
        let counter_ssbo = Ssbo::new(&gl, "counters", 8 * COUNTERS.len(), None, max)?;
        let (w, h) = (options.width, options.height);
        // SAFETY: GL object creation and uploads on a current context; slices match sizes.
        unsafe {
            let vao = gl.create_vertex_array().map_err(|e| anyhow!(e))?;
            gl.bind_vertex_array(Some(vao));
            let mut vbos = Vec::new();
            for (loc, data) in [(0u32, &pos), (1, &nor), (2, &col)] {
                let b = gl.create_buffer().map_err(|e| anyhow!(e))?;
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(b));
                gl.buffer_data_u8_slice(
                    glow::ARRAY_BUFFER,
                    bytemuck::cast_slice(&data[..]),
                    glow::STATIC_DRAW,
                );
                gl.enable_vertex_attrib_array(loc);
                gl.vertex_attrib_pointer_f32(loc, 3, glow::FLOAT, false, 0, 0);
                vbos.push(b);
            }
            gl.bind_vertex_array(None);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);

            let gbuffer = [
                rgba32f_texture(&gl, w, h)?,
                rgba32f_texture(&gl, w, h)?,
                rgba32f_texture(&gl, w, h)?,
            ];
            let gbuffer_fbo = gl.create_framebuffer().map_err(|e| anyhow!(e))?;
            let gbuffer_depth = gl.create_renderbuffer().map_err(|e| anyhow!(e))?;
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(gbuffer_depth));
            gl.renderbuffer_storage(
                glow::RENDERBUFFER,
                glow::DEPTH_COMPONENT32F,
                w as i32,
                h as i32,
            );
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(gbuffer_fbo));
            for (i, t) in gbuffer.iter().enumerate() {
                gl.framebuffer_texture_2d(
                    glow::FRAMEBUFFER,
                    glow::COLOR_ATTACHMENT0 + i as u32,
                    glow::TEXTURE_2D,
                    Some(*t),
                    0,
                );
            }
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::RENDERBUFFER,
                Some(gbuffer_depth),
            );
            gl.draw_buffers(&[
                glow::COLOR_ATTACHMENT0,
                glow::COLOR_ATTACHMENT1,
                glow::COLOR_ATTACHMENT2,
            ]);
            if gl.check_framebuffer_status(glow::FRAMEBUFFER) != glow::FRAMEBUFFER_COMPLETE {
                bail!("the G-buffer FBO is incomplete");
            }
            let output_texture = rgba32f_texture(&gl, w, h)?;
            let output_fbo = gl.create_framebuffer().map_err(|e| anyhow!(e))?;
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(output_fbo));
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(output_texture),
                0,
            );
            if gl.check_framebuffer_status(glow::FRAMEBUFFER) != glow::FRAMEBUFFER_COMPLETE {
                bail!("the output FBO is incomplete");
            }
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            let quad_vao = gl.create_vertex_array().map_err(|e| anyhow!(e))?;
            let shadow_texture = rgba32f_texture(&gl, w, h)?;

            // the node pool: a texture buffer of (red, green) texels (Fig. 8–9)
            let node_buffer = gl.create_buffer().map_err(|e| anyhow!(e))?;
            gl.bind_buffer(glow::TEXTURE_BUFFER, Some(node_buffer));
            gl.buffer_data_u8_slice(
                glow::TEXTURE_BUFFER,
                bytemuck::cast_slice(&tree.nodes),
                glow::STATIC_DRAW,
            );
            gl.bind_buffer(glow::TEXTURE_BUFFER, None);
            let node_texture = gl.create_texture().map_err(|e| anyhow!(e))?;
            gl.bind_texture(glow::TEXTURE_BUFFER, Some(node_texture));
            gl.tex_buffer(glow::RG32UI, node_buffer);
            gl.bind_texture(glow::TEXTURE_BUFFER, None);

            // the line spaces: a 3D R32UI texture laid out as Listing 3
            let linespace_texture = gl.create_texture().map_err(|e| anyhow!(e))?;
            gl.bind_texture(glow::TEXTURE_3D, Some(linespace_texture));
            gl.tex_storage_3d(
                glow::TEXTURE_3D,
                1,
                glow::R32UI,
                packed.tex_x_res as i32,
                packed.tex_y_res as i32,
                packed.tex_z_res as i32,
            );
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
            gl.tex_sub_image_3d(
                glow::TEXTURE_3D,
                0,
                0,
                0,
                0,
                packed.tex_x_res as i32,
                packed.tex_y_res as i32,
                packed.tex_z_res as i32,
                glow::RED_INTEGER,
                glow::UNSIGNED_INT,
                glow::PixelUnpackData::Slice(Some(bytemuck::cast_slice(&packed.texels))),
            );
            gl.tex_parameter_i32(
                glow::TEXTURE_3D,
                glow::TEXTURE_MIN_FILTER,
                glow::NEAREST as i32,
            );
            gl.tex_parameter_i32(
                glow::TEXTURE_3D,
                glow::TEXTURE_MAG_FILTER,
                glow::NEAREST as i32,
            );
            gl.bind_texture(glow::TEXTURE_3D, None);
            crate::gl::check_error(&gl, "uploading the N-tree and the line spaces")?;

            Ok(SoftShadowRenderer {
                gl: gl.clone(),
                options,
                tree,
                packed,
                triangle_count: triangles.len(),
                triangles,
                light,
                background: scene.settings.background,
                ambient: scene.settings.ambient,
                shadow_offset: scene.settings.shadow_offset,
                scene_bounds: scene.bounds(),
                raster,
                vao,
                vbos,
                gbuffer_fbo,
                gbuffer_depth,
                gbuffer,
                shadow_program,
                shadow_texture,
                node_buffer,
                node_texture,
                linespace_texture,
                tri_ssbo,
                leaf_ssbo,
                counter_ssbo,
                quad_program,
                quad_vao,
                output_fbo,
                output_texture,
                timers: GpuTimers::default(),
                ray_batches: 1,
            })
        }
    }

    /// Bytes of the node pool (texture buffer) and the leaves' triangle lists.
    pub fn ntree_bytes(&self) -> usize {
        self.tree.node_bytes()
    }

    /// Bytes of the 3D line-space texture.
    pub fn linespace_bytes(&self) -> usize {
        self.packed.bytes()
    }

    /// Read the 3D line-space texture back (the round-trip test).
    pub fn read_linespace_texture(&self) -> Vec<u32> {
        let gl = &self.gl;
        let mut data = vec![0u32; self.packed.texels.len()];
        // SAFETY: the slice holds all texels of the texture.
        unsafe {
            gl.bind_texture(glow::TEXTURE_3D, Some(self.linespace_texture));
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            gl.get_tex_image(
                glow::TEXTURE_3D,
                0,
                glow::RED_INTEGER,
                glow::UNSIGNED_INT,
                glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut data))),
            );
            gl.bind_texture(glow::TEXTURE_3D, None);
        }
        data
    }

    /// Dispatch the shadow rays of every pixel in `n` batches from the next frame on (normally
    /// automatic: see [`SoftShadowRenderer::draw`]); clamped to 1..=rays.
    pub fn set_ray_batches(&mut self, n: u32) {
        self.ray_batches = n.clamp(1, self.options.samples_u * self.options.samples_v);
    }

    /// The RGBA32F output texture of the last frame (what the screen-filling quad drew), GL
    /// row order: the viewer shows it through its own screen-filling quad.
    pub fn output_texture(&self) -> glow::Texture {
        self.output_texture
    }

    /// Render one frame: G-buffer, shadow pass, screen-filling quad; read everything back.
    pub fn render(&mut self, camera: &Camera) -> Result<SoftShadowFrame> {
        let t0 = Instant::now();
        let mut stats = self.draw(camera)?;
        let gl = self.gl.clone();
        let (w, h) = (self.options.width, self.options.height);
        let gb = self.gbuffer;
        let color = flip_rows(&read_texture_rgba32f(&gl, self.output_texture, w, h), w, h);
        let shadow: Vec<f32> =
            flip_rows(&read_texture_rgba32f(&gl, self.shadow_texture, w, h), w, h)
                .iter()
                .map(|c| c[0])
                .collect();
        let gbuffer_position = flip_rows(&read_texture_rgba32f(&gl, gb[0], w, h), w, h);
        let gbuffer_normal = flip_rows(&read_texture_rgba32f(&gl, gb[1], w, h), w, h);
        // the AOVs of the base tracer: primary rays from the camera, hits from the G-buffer
        let rays = camera.rays(w, h);
        let mut aovs = Aovs::default();
        for row in 0..h {
            let y = h - 1 - row; // GL row of image row `row`
            for x in 0..w {
                let (o, d) = rays.primary_ray(x, y);
                let i = (row * w + x) as usize;
                let (p, nrm) = (gbuffer_position[i], gbuffer_normal[i]);
                aovs.ray_origin.push(o.to_array());
                aovs.ray_direction.push(d.to_array());
                if p[3] > 0.0 {
                    aovs.hit_t.push((Vec3::new(p[0], p[1], p[2]) - o).dot(d));
                    aovs.triangle_id.push(nrm[3] as i32);
                    aovs.normal.push([nrm[0], nrm[1], nrm[2]]);
                } else {
                    aovs.hit_t.push(f32::INFINITY);
                    aovs.triangle_id.push(-1);
                    aovs.normal.push([0.0; 3]);
                }
            }
        }
        stats.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(SoftShadowFrame {
            width: w,
            height: h,
            color,
            shadow,
            gbuffer_position,
            gbuffer_normal,
            aovs,
            stats,
        })
    }

    /// Render one frame (G-buffer, shadow pass, screen-filling quad into the output texture)
    /// and read back only the counters and the timers: the viewer's frame, which shows
    /// [`SoftShadowRenderer::output_texture`]. A frame that hit llvmpipe's loop limit is
    /// rendered again with each pixel's shadow rays split into twice as many dispatches
    /// (`ray_batches` in the facts), until none does; with one ray per dispatch it is refused.
    pub fn draw(&mut self, camera: &Camera) -> Result<FrameStats> {
        let t0 = Instant::now();
        let rays = self.options.samples_u * self.options.samples_v;
        loop {
            let (mut stats, truncated) = self.draw_once(camera)?;
            if truncated == 0 {
                stats.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
                return Ok(stats);
            }
            if self.ray_batches >= rays {
                bail!(
                    "{truncated} pixels of the shadow pass hit the loop budget even with one shadow ray per \
                     dispatch (llvmpipe ends loops after 65535 iterations); use a coarser N-tree or the \
                     linespace mode"
                );
            }
            // llvmpipe's loop limit: the same frame again with half as many rays per dispatch
            self.ray_batches = (self.ray_batches * 2).min(rays);
            log::info!(
                "{truncated} pixels hit the loop budget: the shadow rays in {} batches per pixel",
                self.ray_batches
            );
        }
    }

    /// One attempt at a frame with `ray_batches` dispatches of the shadow pass per tile: the
    /// statistics and the number of truncated pixels (then the image is incomplete).
    fn draw_once(&mut self, camera: &Camera) -> Result<(FrameStats, u64)> {
        let gl = self.gl.clone();
        let (w, h) = (self.options.width, self.options.height);
        let vp = view_projection(camera, w, h, self.scene_bounds.0, self.scene_bounds.1);
        self.counter_ssbo.clear_u32(&gl, 0);
        // 1. G-buffer
        let (raster, vao, fbo, gb) = (self.raster, self.vao, self.gbuffer_fbo, self.gbuffer);
        let tri_count = self.triangle_count as i32;
        let bg = self.background;
        self.timers.time(&gl, "gbuffer", || {
            // SAFETY: drawing with our program, VAO and FBO.
            unsafe {
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
                gl.viewport(0, 0, w as i32, h as i32);
                gl.enable(glow::DEPTH_TEST);
                gl.depth_func(glow::LESS);
                gl.clear_buffer_f32_slice(glow::COLOR, 0, &[0.0; 4]);
                gl.clear_buffer_f32_slice(glow::COLOR, 1, &[0.0, 0.0, 0.0, -1.0]);
                gl.clear_buffer_f32_slice(glow::COLOR, 2, &[bg[0], bg[1], bg[2], 0.0]);
                gl.clear_buffer_f32_slice(glow::DEPTH, 0, &[1.0]);
                gl.use_program(Some(raster));
                gl.uniform_matrix_4_f32_slice(
                    gl.get_uniform_location(raster, "viewProjection").as_ref(),
                    false,
                    &vp.to_cols_array(),
                );
                gl.uniform_3_f32_slice(
                    gl.get_uniform_location(raster, "cameraPosition").as_ref(),
                    &camera.position,
                );
                gl.bind_vertex_array(Some(vao));
                gl.draw_arrays(glow::TRIANGLES, 0, 3 * tri_count);
                gl.bind_vertex_array(None);
                gl.disable(glow::DEPTH_TEST);
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
                gl.memory_barrier(
                    glow::SHADER_IMAGE_ACCESS_BARRIER_BIT | glow::TEXTURE_FETCH_BARRIER_BIT,
                );
            }
        });
        crate::gl::check_error(&gl, "the G-buffer pass")?;
        // 2. shadow pass
        let p = self.shadow_program;
        // SAFETY: uniforms and bindings of our program and objects.
        unsafe {
            gl.use_program(Some(p));
            let loc = |n: &str| gl.get_uniform_location(p, n);
            gl.uniform_3_f32_slice(loc("minBound").as_ref(), &self.tree.min_bound.to_array());
            gl.uniform_1_f32(loc("invNodeSize").as_ref(), self.tree.inv_node_size());
            gl.uniform_3_f32_slice(loc("lightCorner").as_ref(), &self.light.corner.to_array());
            gl.uniform_3_f32_slice(loc("lightEdgeU").as_ref(), &self.light.edge_u.to_array());
            gl.uniform_3_f32_slice(loc("lightEdgeV").as_ref(), &self.light.edge_v.to_array());
            gl.uniform_3_f32_slice(loc("lightColor").as_ref(), &self.light.color.to_array());
            gl.uniform_3_f32_slice(loc("ambient").as_ref(), &self.ambient);
            gl.uniform_1_f32(loc("shadowOffset").as_ref(), self.shadow_offset);
            gl.uniform_1_i32(loc("tex_x_res").as_ref(), self.packed.tex_x_res as i32);
            gl.uniform_1_i32(loc("tex_y_res").as_ref(), self.packed.tex_y_res as i32);
            gl.uniform_1_i32(loc("ls_y_size").as_ref(), self.packed.ls_y_size as i32);
            gl.uniform_1_i32(loc("nodePool").as_ref(), 1);
            gl.uniform_1_i32(loc("loopSentinel").as_ref(), 2);
            gl.active_texture(glow::TEXTURE1);
            gl.bind_texture(glow::TEXTURE_BUFFER, Some(self.node_texture));
            gl.active_texture(glow::TEXTURE0);
            gl.bind_image_texture(0, Some(gb[0]), 0, false, 0, glow::READ_ONLY, glow::RGBA32F);
            gl.bind_image_texture(1, Some(gb[1]), 0, false, 0, glow::READ_ONLY, glow::RGBA32F);
            gl.bind_image_texture(2, Some(gb[2]), 0, false, 0, glow::READ_WRITE, glow::RGBA32F);
            gl.bind_image_texture(
                3,
                Some(self.shadow_texture),
                0,
                false,
                0,
                glow::READ_WRITE,
                glow::RGBA32F,
            );
            gl.bind_image_texture(
                4,
                Some(self.linespace_texture),
                0,
                true,
                0,
                glow::READ_ONLY,
                glow::R32UI,
            );
        }
        self.tri_ssbo.bind(&gl, 0);
        self.leaf_ssbo.bind(&gl, 1);
        self.counter_ssbo.bind(&gl, 8);
        let tile = if self.options.tile == 0 {
            w.max(h)
        } else {
            self.options.tile
        };
        let kernel: &'static str = match self.options.mode {
            ShadowMode::Exact => "shadow_exact",
            ShadowMode::Linespace => "shadow_linespace",
            ShadowMode::LinespaceDda => "shadow_linespace_dda",
        };
        // the shadow rays of a pixel in `ray_batches` dispatches (see `draw`)
        let rays = self.options.samples_u * self.options.samples_v;
        let batches = self.ray_batches.clamp(1, rays);
        let per_batch = rays.div_ceil(batches);
        // SAFETY: a uniform query of our program.
        let tile_offset = unsafe { gl.get_uniform_location(p, "tileOffset") };
        for begin in (0..rays).step_by(per_batch as usize) {
            let end = (begin + per_batch).min(rays);
            // SAFETY: uniforms of our program.
            unsafe {
                let loc = |n: &str| gl.get_uniform_location(p, n);
                gl.uniform_1_i32(loc("rayBegin").as_ref(), begin as i32);
                gl.uniform_1_i32(loc("rayEnd").as_ref(), end as i32);
                gl.uniform_1_i32(loc("accumulate").as_ref(), (begin > 0) as i32);
                gl.uniform_1_i32(loc("lastBatch").as_ref(), (end == rays) as i32);
            }
            for ty in (0..h).step_by(tile as usize) {
                for tx in (0..w).step_by(tile as usize) {
                    let (tw, th) = (tile.min(w - tx), tile.min(h - ty));
                    self.timers.time(&gl, kernel, || {
                        // SAFETY: dispatch of our program.
                        unsafe {
                            gl.uniform_2_i32(tile_offset.as_ref(), tx as i32, ty as i32);
                            gl.dispatch_compute(tw.div_ceil(8), th.div_ceil(8), 1);
                            gl.memory_barrier(glow::ALL_BARRIER_BITS);
                        }
                    });
                }
            }
        }
        crate::gl::check_error(&gl, "the shadow pass")?;
        // 3. the screen-filling quad
        let (qp, qvao, ofbo) = (self.quad_program, self.quad_vao, self.output_fbo);
        self.timers.time(&gl, "present", || {
            // SAFETY: drawing the quad with our program into our FBO.
            unsafe {
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(ofbo));
                gl.viewport(0, 0, w as i32, h as i32);
                gl.use_program(Some(qp));
                gl.active_texture(glow::TEXTURE0);
                gl.bind_texture(glow::TEXTURE_2D, Some(gb[2]));
                gl.uniform_1_i32(gl.get_uniform_location(qp, "colorTexture").as_ref(), 0);
                gl.bind_vertex_array(Some(qvao));
                gl.draw_arrays(glow::TRIANGLES, 0, 3);
                gl.bind_vertex_array(None);
                gl.bind_texture(glow::TEXTURE_2D, None);
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            }
        });
        crate::gl::check_error(&gl, "the screen-filling quad")?;
        let gpu_ms = self.timers.resolve(&gl);
        let counters = self.counter_ssbo.read_u32(&gl);
        let count = |i: usize| counters[2 * i] as u64 | ((counters[2 * i + 1] as u64) << 32);
        let truncated = count(3);
        let mut stats = FrameStats {
            gpu_ms,
            truncated_rays: truncated,
            ..Default::default()
        };
        stats.triangle_tests.insert(kernel.to_string(), count(0));
        stats.events.insert("linespace_lookups".into(), count(1));
        stats.events.insert("nodes_visited".into(), count(2));
        stats.events.insert("packet_failures".into(), count(4));
        stats.facts = self.facts();
        Ok((stats, truncated))
    }

    /// The renderer's facts in the frame statistics (options, N-tree and line-space sizes,
    /// build times).
    fn facts(&self) -> BTreeMap<String, serde_json::Value> {
        [
            ("shadows", json!(self.options.mode)),
            ("ray_batches", json!(self.ray_batches)),
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
            ("ntree_n", json!(self.tree.n)),
            ("ntree_depth", json!(self.tree.depth)),
            ("ntree_bytes", json!(self.ntree_bytes())),
            ("linespace_bytes", json!(self.linespace_bytes())),
            ("linespaces", json!(self.tree.linespace_count)),
            (
                "ntree_node_groups",
                json!(self.tree.nodes.len() / (self.tree.n as usize).pow(3)),
            ),
            ("ntree_leaves", json!(self.tree.leaf_count)),
            ("ntree_build_ms", json!(self.tree.build_ms)),
            ("linespace_build_ms", json!(self.tree.linespace_build_ms)),
            (
                "linespace_texture",
                json!([
                    self.packed.tex_x_res,
                    self.packed.tex_y_res,
                    self.packed.tex_z_res
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
            tree: &self.tree,
            packed: &self.packed,
            triangles: &self.triangles,
            light: self.light,
            samples_u: self.options.samples_u,
            samples_v: self.options.samples_v,
            offset: self.shadow_offset,
        }
    }
}

impl Drop for SoftShadowRenderer {
    fn drop(&mut self) {
        let gl = &self.gl;
        // SAFETY: deleting our own objects.
        unsafe {
            gl.delete_program(self.raster);
            gl.delete_program(self.shadow_program);
            gl.delete_program(self.quad_program);
            gl.delete_vertex_array(self.vao);
            gl.delete_vertex_array(self.quad_vao);
            for b in &self.vbos {
                gl.delete_buffer(*b);
            }
            gl.delete_framebuffer(self.gbuffer_fbo);
            gl.delete_framebuffer(self.output_fbo);
            gl.delete_renderbuffer(self.gbuffer_depth);
            for t in self.gbuffer {
                gl.delete_texture(t);
            }
            gl.delete_texture(self.shadow_texture);
            gl.delete_texture(self.output_texture);
            gl.delete_texture(self.node_texture);
            gl.delete_texture(self.linespace_texture);
            gl.delete_buffer(self.node_buffer);
        }
        self.tri_ssbo.delete(gl);
        self.leaf_ssbo.delete(gl);
        self.counter_ssbo.delete(gl);
        self.timers.delete(gl);
    }
}
