//! Phase 2 of Klee 2016's pipeline (Fig. 7, ch. 4.3): `glsl/klee2016/linespace_shadow.comp`
//! gives every pixel of the G-buffer its shadow value by walking the N-tree with its line
//! spaces, and multiplies it into the diffuse texture. Its data: the node pool in a texture
//! buffer of (red, green) texels (Fig. 8–9), the line spaces in a 3D R32UI texture laid out as
//! Listing 3, the triangles and the leaves' triangle lists in SSBOs.

use std::sync::Arc;

use anyhow::{bail, Result};
use glam::Vec3;
use glow::HasContext;

use super::linespace_build::{r32ui_texture_3d, read_texture_3d};
use super::ntree::{NTree, PackedLinespaces};
use super::options::SoftShadowOptions;
use crate::gl::context::LoopLimit;
use crate::gl::resources::{read_tex_image, GpuTimers, Image2d, Owned, Ssbo, TextureBuffer};
use crate::gl::slots::{image, sampler, ssbo};
use crate::gl::{Defines, Gl, GlInfo, Kernel, PixelGrid, ShaderSource};
use crate::scene::shadows::KleeShading;
use crate::scene::{AreaLight, ShadowMode};

/// Counter slots of the shadow kernel, shared with it through `#define COUNTER_*`. After the
/// first five, where the time goes (docs/design/linespace.md): lookups per stack depth, the
/// descents by the near-origin rule and by a set bit, the (ray, leaf) pairs whose triangles are
/// tested, what blocked the rays, the triangles a packet's plane test skipped
/// (`linespace-fast`), and the loop iterations: their sum, and the sum over work groups of the
/// group's largest (a SIMD vector iterates while any lane does: the ratio is the divergence),
/// and the most any invocation ran (a maximum, not a sum: the `gpu` profile's frames on
/// llvmpipe are checked against its loop limit with it).
pub const COUNTERS: [&str; 16] = [
    "triangle_tests",
    "linespace_lookups",
    "nodes_visited",
    "truncated",
    "packet_failures",
    "lookups_depth0",
    "lookups_depth1",
    "descents_near",
    "descents_linespace",
    "leaf_rays",
    "rays_blocked_linespace",
    "rays_blocked_triangle",
    "triangles_culled",
    "loop_iterations",
    "loop_iterations_group_max",
    "loop_iterations_max",
];

/// The counters `render --stats` reports as events (all but the ones reported elsewhere).
pub const EVENTS: std::ops::Range<usize> = 5..16;

/// The shadow kernel for a mode and a number of samples (the defines of Algorithm 1).
pub fn shadow_kernel(
    gl: &Arc<Gl>,
    shaders: &ShaderSource,
    tree: &NTree,
    mode: ShadowMode,
    (su, sv): (u32, u32),
    limit: Option<LoopLimit>,
) -> Result<Kernel> {
    if !(1..=10).contains(&su) || !(1..=10).contains(&sv) {
        bail!("{su}x{sv} light samples: 1x1 to 10x10");
    }
    let mut defines = Defines::new()
        .set("NTREE_N", tree.n)
        .set("NUM_MAX_DEPTH", tree.depth - 1)
        .set("LAST_LS_DEPTH", tree.last_linespace_depth())
        .set("SAMPLES_U", su)
        .set("SAMPLES_V", sv)
        .set("NUM_RAYS", su * sv)
        .set("SHADOW_MODE", mode.kernel_mode())
        .set("NEAR_ORIGIN_RULE", mode.near_origin_rule() as u32)
        .set("BIT_IS_HIT", mode.bit_is_hit() as u32)
        .set("FAST_PATH", mode.fast_path() as u32)
        .set("LOOP_BUDGET", format!("{}u", loop_budget(limit, su * sv)));
    for (i, c) in COUNTERS.iter().enumerate() {
        defines = defines.set(&format!("COUNTER_{}", c.to_uppercase()), i);
    }
    let timer = match mode {
        ShadowMode::Exact => "shadow_exact",
        ShadowMode::Linespace => "shadow_linespace",
        ShadowMode::LinespaceDda => "shadow_linespace_dda",
        ShadowMode::Variant1 => "shadow_variant1",
        ShadowMode::Variant2 => "shadow_variant2",
        ShadowMode::LinespaceFast => "shadow_linespace_fast",
    };
    Kernel::compute(
        gl,
        shaders,
        "klee2016/linespace_shadow.comp",
        &defines,
        timer,
    )
}

/// The iterations one invocation of the shadow kernel may run (`LOOP_BUDGET`, the kernel's
/// loopLimit): where the GL implementation ends loops, the limit's share of one SIMD lane less
/// initShaft's loop over the rays, which the kernel does not count; no bound elsewhere.
pub fn loop_budget(limit: Option<LoopLimit>, rays: u32) -> u32 {
    limit.map_or(u32::MAX, |l| l.per_invocation().saturating_sub(rays).max(1))
}

/// The counts of one shadow pass.
pub struct ShadowCounts(pub [u64; COUNTERS.len()]);

impl ShadowCounts {
    pub fn get(&self, name: &str) -> u64 {
        COUNTERS
            .iter()
            .position(|c| *c == name)
            .map_or(0, |i| self.0[i])
    }
}

/// The uniforms of the shadow kernel that stay from frame to frame.
pub struct ShadowUniforms {
    pub light: AreaLight,
    pub ambient: [f32; 3],
    pub shadow_offset: f32,
    pub shading: KleeShading,
}

pub struct ShadowPass {
    gl: Arc<Gl>,
    pub kernel: Kernel,
    /// r: shadow value, g: lit rays (summed over batches); b, a: where a truncated pixel goes
    /// on (its first ray not done, the attempt) — after a frame, a: the attempt that completed
    /// the pixel, where the next frame starts it
    shadow_texture: Image2d,
    /// the attempts of the last frame (the next one runs at least as many); 0: none remembered
    /// (the texture then holds zeros)
    remembered_attempts: u32,
    /// RGBA32UI: bit r set where a batch that completed began at ray r
    batch_texture: Owned<glow::Texture>,
    /// the node pool (Fig. 8–9), RG32UI texels
    node_pool: TextureBuffer,
    linespace_texture: Owned<glow::Texture>,
    /// triVertex, leafTriangles, counters
    buffers: [Ssbo; 3],
    min_bound: Vec3,
    inv_node_size: f32,
    texture_layout: [u32; 3],
}

/// The line spaces as a 3D R32UI texture laid out as Listing 3, uploaded from the CPU build.
pub fn linespace_texture(gl: &Arc<Gl>, packed: &PackedLinespaces) -> Result<Owned<glow::Texture>> {
    let t = r32ui_texture_3d(gl, packed)?;
    let (x, y, z) = (
        packed.tex_x_res as i32,
        packed.tex_y_res as i32,
        packed.tex_z_res as i32,
    );
    crate::gl::sync::before(gl, glow::TEXTURE_UPDATE_BARRIER_BIT);
    // SAFETY: upload into our texture; the slice holds x·y·z texels.
    unsafe {
        gl.bind_texture(glow::TEXTURE_3D, Some(t.raw()));
        gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
        let texels = glow::PixelUnpackData::Slice(Some(bytemuck::cast_slice(&packed.texels)));
        let (red, uint) = (glow::RED_INTEGER, glow::UNSIGNED_INT);
        gl.tex_sub_image_3d(glow::TEXTURE_3D, 0, 0, 0, 0, x, y, z, red, uint, texels);
        gl.bind_texture(glow::TEXTURE_3D, None);
    }
    Ok(t)
}

impl ShadowPass {
    pub fn new(
        gl: &Arc<Gl>,
        info: &GlInfo,
        kernel: Kernel,
        tree: &NTree,
        (linespaces, packed): (Owned<glow::Texture>, &PackedLinespaces),
        triangles: &[[Vec3; 3]],
        options: &SoftShadowOptions,
    ) -> Result<ShadowPass> {
        let max = info.max_ssbo_block_size;
        let tri4: Vec<[f32; 4]> = triangles
            .iter()
            .flatten()
            .map(|v| [v.x, v.y, v.z, 1.0])
            .collect();
        let buffers = [
            Ssbo::new(
                gl,
                "triVertex",
                16 * tri4.len(),
                Some(bytemuck::cast_slice(&tri4)),
                max,
            )?,
            Ssbo::new(
                gl,
                "leafTriangles",
                4 * tree.leaf_triangles.len(),
                Some(bytemuck::cast_slice(&tree.leaf_triangles)),
                max,
            )?,
            Ssbo::new(gl, "counters", 8 * COUNTERS.len(), None, max)?,
        ];
        let pool = bytemuck::cast_slice(&tree.nodes);
        let node_pool = TextureBuffer::new(gl, "nodePool", glow::RG32UI, 8, pool)?;
        let mut pass = ShadowPass {
            gl: gl.clone(),
            kernel,
            shadow_texture: Image2d::new(gl, options.width, options.height, glow::RGBA32F)?,
            remembered_attempts: 0,
            batch_texture: Image2d::new(gl, options.width, options.height, glow::RGBA32UI)?.texture,
            node_pool,
            linespace_texture: linespaces,
            buffers,
            min_bound: tree.min_bound,
            inv_node_size: tree.inv_node_size(),
            texture_layout: [packed.tex_x_res, packed.tex_y_res, packed.ls_y_size],
        };
        crate::gl::check_error(gl, "uploading the N-tree and the line spaces")?;
        pass.forget_attempts();
        Ok(pass)
    }

    /// Bind the G-buffer, the shadow texture, the line spaces, the node pool and the buffers
    /// to their slots, and set the uniforms that stay for the frame.
    fn bind(&self, gbuffer: &[glow::Texture; 3], u: &ShadowUniforms) {
        let gl = &self.gl;
        let k = &self.kernel;
        k.use_program();
        k.set_vec3("minBound", self.min_bound.to_array());
        k.set_f32("invNodeSize", self.inv_node_size);
        k.set_vec3("lightCorner", u.light.corner.to_array());
        k.set_vec3("lightEdgeU", u.light.edge_u.to_array());
        k.set_vec3("lightEdgeV", u.light.edge_v.to_array());
        k.set_vec3("lightColor", u.light.color.to_array());
        k.set_vec3("ambient", u.ambient);
        k.set_f32("shadowOffset", u.shadow_offset);
        k.set_i32("fig7Shading", (u.shading == KleeShading::Fig7) as i32);
        let [x, y, ls_y] = self.texture_layout;
        k.set_i32("tex_x_res", x as i32);
        k.set_i32("tex_y_res", y as i32);
        k.set_i32("ls_y_size", ls_y as i32);
        let (rw, ro, f) = (glow::READ_WRITE, glow::READ_ONLY, glow::RGBA32F);
        // SAFETY: binding our textures to their units.
        unsafe {
            self.node_pool.bind(gl, sampler::NODE_POOL);
            let img = |unit, t, access, format| {
                gl.bind_image_texture(unit, Some(t), 0, false, 0, access, format)
            };
            img(image::GBUFFER_POSITION, gbuffer[0], ro, f);
            img(image::GBUFFER_NORMAL, gbuffer[1], ro, f);
            img(image::GBUFFER_DIFFUSE, gbuffer[2], rw, f);
            img(
                image::SHADOW_VALUE,
                self.shadow_texture.texture.raw(),
                rw,
                f,
            );
            img(
                image::SHADOW_BATCHES,
                self.batch_texture.raw(),
                rw,
                glow::RGBA32UI,
            );
            let ls = Some(self.linespace_texture.raw());
            gl.bind_image_texture(image::LINESPACE, ls, 0, true, 0, ro, glow::R32UI);
        }
        let [tris, leaves, counters] = &self.buffers;
        tris.bind(gl, ssbo::TRI_VERTEX);
        leaves.bind(gl, ssbo::LEAF_TRIANGLES);
        counters.bind(gl, ssbo::COUNTERS);
    }

    /// The shadow pass over the image, each pixel's `rays` shadow rays in `batches`
    /// dispatches per tile; then, while a batch was truncated (llvmpipe's loop limit: the
    /// kernel's header), the pixels it left alone again, each from that batch's first ray on,
    /// in batches of half as many rays — an attempt each, the other pixels untouched. The
    /// counts (`truncated`: the batches truncated) and the batches of the last attempt; an
    /// error where a batch of one ray is truncated.
    pub fn run(
        &mut self,
        timers: &mut GpuTimers,
        pixels: PixelGrid,
        gbuffer: &[glow::Texture; 3],
        uniforms: &ShadowUniforms,
        (rays, batches): (u32, u32),
    ) -> Result<(ShadowCounts, u32)> {
        self.buffers[2].clear_u32(&self.gl, 0);
        self.bind(gbuffer, uniforms);
        let mut batch_rays = rays.div_ceil(batches.clamp(1, rays));
        let mut retried = 0;
        for attempt in 0.. {
            self.dispatch_batches(timers, pixels, rays, batch_rays, attempt);
            let counts = self.counts();
            let truncated = counts.get("truncated") - retried;
            // the pixels the last frame completed in a later attempt start there
            let remembered = attempt + 1 < self.remembered_attempts;
            if truncated == 0 && (!remembered || batch_rays == 1) {
                self.remembered_attempts = attempt + 1;
                return Ok((counts, rays.div_ceil(batch_rays)));
            }
            if truncated > 0 && batch_rays == 1 {
                bail!(
                    "{truncated} pixels of the shadow pass hit the loop budget even with one shadow \
                     ray per dispatch (llvmpipe ends loops after 65535 iterations); use a coarser \
                     N-tree or the linespace mode"
                );
            }
            batch_rays = batch_rays.div_ceil(2);
            if truncated > 0 {
                log::info!(
                    "{truncated} pixels hit the loop budget: their shadow rays go on in batches of {batch_rays}"
                );
            }
            retried += truncated;
        }
        unreachable!("the attempts end by returning")
    }

    /// One attempt of the shadow pass: batches of `batch_rays` rays per pixel, one dispatch per
    /// tile each, for every pixel (attempt 0) or those the attempt before left truncated (from
    /// their first ray not done: at most `rays` of them).
    fn dispatch_batches(
        &self,
        timers: &mut GpuTimers,
        pixels: PixelGrid,
        rays: u32,
        batch_rays: u32,
        attempt: u32,
    ) {
        let k = &self.kernel;
        k.set_i32("attempt", attempt as i32);
        k.set_i32("batchRays", batch_rays as i32);
        for batch in 0..rays.div_ceil(batch_rays) {
            k.set_i32("batchIndex", batch as i32);
            k.dispatch_pixels(timers, pixels);
        }
    }

    /// The counters read back (the GPU waits for the pass).
    fn counts(&self) -> ShadowCounts {
        let raw = self.buffers[2].read_u32(&self.gl);
        ShadowCounts(std::array::from_fn(|i| {
            crate::pipeline::renderer::counter_value(&raw, i)
        }))
    }

    /// The shadow texture (r: shadow value, g: lit rays).
    pub fn shadow_texture(&self) -> glow::Texture {
        self.shadow_texture.texture.raw()
    }

    /// Forget the attempts that completed each pixel (a new mode, new samples, new batches:
    /// the last frame's split says nothing about the next): every pixel starts in attempt 0.
    pub fn forget_attempts(&mut self) {
        self.shadow_texture.clear(&self.gl);
        self.remembered_attempts = 0;
    }

    /// Per pixel (GL rows, bottom first) the first rays of the batches its shadow rays were
    /// traced in: bit r of the 128 set where one began at ray r.
    pub fn read_batch_starts(&self, w: u32, h: u32) -> Vec<[u32; 4]> {
        let mut data = vec![[0u32; 4]; (w * h) as usize];
        let layout = (glow::TEXTURE_2D, glow::RGBA_INTEGER, glow::UNSIGNED_INT);
        read_tex_image(&self.gl, self.batch_texture.raw(), layout, &mut data);
        data
    }

    /// Read the 3D line-space texture back (`texels` of them; the round-trip test).
    pub fn read_linespace_texture(&self, texels: usize) -> Vec<u32> {
        read_texture_3d(&self.gl, self.linespace_texture.raw(), texels)
    }
}
