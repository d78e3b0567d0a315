//! The pipelines — how rays flow through the GPU — behind one [`Renderer`] interface that
//! `render`, `view` and `bench` drive the same way, whatever the design:
//!
//! | pipeline | source | module | kernels | accelerators |
//! |---|---|---|---|---|
//! | four compute kernels (eye rays → intersect1 → intersect2 → shading) | Müller 2015 | [`mueller2015`] | `glsl/mueller2015/` | every one of [`crate::accel::REGISTRY`] |
//! | G-buffer + shadow pass + screen-filling quad | Klee 2016 | [`klee2016`] | `glsl/klee2016/` | its N-tree + Cascaded Line Space |
//! | one kernel per pixel (primary ray, BVH walk, Lambert, hard shadow) | Wagner 2018 | [`wagner2018`] | `glsl/wagner2018/` | its BVH in three textures (`--tracer bvh --bvh-variant wagner`) |
//! | fragment programs over a viewport-sized quad, traversal looped until an occlusion query counts no fragment | seed 004 | [`stream`] | `glsl/stream/` | its static grid in textures, proximity clouds (`--tracer stream`) |

pub mod klee2016;
pub mod mueller2015;
pub mod ray_kinds;
pub mod stream;
pub mod wagner2018;

use std::sync::Arc;

use anyhow::Result;
use glam::Mat4;

use crate::accel::{BvhVariant, GridVariant, TracerKind};
use crate::frame::{Frame, FrameStats};
use crate::gl::{Gl, GlInfo, ShaderSource};
use crate::scene::{Camera, Scene};

/// Counter `slot` of a counter buffer read back as u32 words: the 64-bit count of
/// `glsl/common/counters.glsl`, low word at `2·slot`, high word (its carries) at `2·slot + 1`.
pub fn counter_value(raw: &[u32], slot: usize) -> u64 {
    raw[2 * slot] as u64 | ((raw[2 * slot + 1] as u64) << 32)
}

/// A pipeline with its scene on the GPU, ready to render frames.
pub trait Renderer {
    /// The design's name in the statistics: "base", "grid", "linespace".
    fn name(&self) -> &'static str;
    /// The image size (width, height).
    fn size(&self) -> (u32, u32);
    /// Render one frame seen from `camera` into the output texture. Only the counters and
    /// the timers are read back: the viewer's frame.
    fn draw(&mut self, camera: &Camera) -> Result<FrameStats>;
    /// Read the last drawn frame back: colour, the AOVs the renderer was made to keep, and
    /// the statistics [`Renderer::draw`] returned.
    fn read_back(&mut self) -> Result<Frame>;
    /// The RGBA32F output texture of the last frame (rgb colour, a weight), GL row order, for
    /// showing it through a screen-filling quad (Müller 2015, ch. 3.1.3).
    fn output_texture(&self) -> glow::Texture;
    /// Move object `object` (index in the scene's objects): its model matrix for the next
    /// frames. An error where the design's structure is static (the N-tree of Klee 2016).
    fn set_model(&mut self, object: usize, model: Mat4) -> Result<()>;
    /// The renderer's settings for the statistics document (`render --stats`), beside the
    /// statistics of the frame.
    fn settings(&self) -> serde_json::Map<String, serde_json::Value>;

    /// Draw a frame and read it back.
    fn render(&mut self, camera: &Camera) -> Result<Frame> {
        self.draw(camera)?;
        self.read_back()
    }
}

/// The point-light ray tracer `options` choose: Müller 2015's four-kernel pipeline with the
/// `--tracer` accelerator, or, for `--tracer bvh --bvh-variant wagner`, Wagner 2018's
/// one-kernel pipeline (which takes only the size, the tiles and the AOVs of `options`).
pub fn ray_tracer(
    gl: Arc<Gl>,
    info: &GlInfo,
    scene: &Scene,
    shaders: &ShaderSource,
    options: mueller2015::RenderOptions,
) -> Result<Box<dyn Renderer>> {
    use crate::limits::{check, IMAGE_SIDE, REFL_DEPTH};
    check("the image width", options.width, &IMAGE_SIDE).map_err(anyhow::Error::msg)?;
    check("the image height", options.height, &IMAGE_SIDE).map_err(anyhow::Error::msg)?;
    check("the reflection depth", options.refl_depth, &REFL_DEPTH).map_err(anyhow::Error::msg)?;
    if let Some(n) = options.grid.resolution {
        check("the grid resolution", n, &crate::limits::GRID_RES).map_err(anyhow::Error::msg)?;
    }
    check_grid_options(&options)?;
    crate::frame::check_host(options.width, options.height, options.aovs)
        .map_err(anyhow::Error::msg)?;
    if !scene.area_lights.is_empty() {
        anyhow::bail!(
            "{}: the point-light ray tracers light with [[light]]s only; the scene's {} \
             [[area_light]](s) would be ignored (render it with --shadows)",
            scene.path.display(),
            scene.area_lights.len()
        );
    }
    let per_triangle = host_bytes_per_triangle(&options);
    let triangles = scene.triangle_count() as u64;
    crate::scene::budget::reserve(
        &format!("building and uploading the scene's {triangles} triangles"),
        "the scene with --tracer",
        triangles.saturating_mul(per_triangle),
    )
    .map_err(|e| anyhow::anyhow!("{}: {e}", scene.path.display()))?;
    if is_wagner(&options) {
        let o = wagner2018::WagnerOptions::of(&options);
        let r = wagner2018::WagnerRenderer::new(gl, info, scene, shaders, o)?;
        return Ok(Box::new(r));
    }
    if options.tracer == TracerKind::Stream {
        let o = stream::StreamOptions::of(&options);
        return Ok(Box::new(stream::StreamRenderer::new(
            gl, info, scene, shaders, o,
        )?));
    }
    let r = mueller2015::RayTracer::new(gl, info, scene, shaders, options)?;
    Ok(Box::new(r))
}

fn is_wagner(options: &mueller2015::RenderOptions) -> bool {
    options.tracer == TracerKind::Bvh && options.bvh_variant == BvhVariant::Wagner
}

/// The grid options that only some designs take, refused for the others (before any design
/// is built, so that none of them ignores one).
fn check_grid_options(options: &mueller2015::RenderOptions) -> Result<()> {
    let stream = options.tracer == TracerKind::Stream;
    if options.grid.stream_naive_shadows && !stream {
        anyhow::bail!("--stream-naive-shadows applies to --tracer stream only");
    }
    if options.grid.stream_no_mask && !stream {
        anyhow::bail!("--stream-no-mask applies to --tracer stream only");
    }
    if options.grid.stream_single_sided && !stream {
        anyhow::bail!("--stream-single-sided applies to --tracer stream only");
    }
    if options.grid.axes.is_some() && !stream {
        anyhow::bail!(
            "--grid GXxGYxGZ applies to --tracer stream only (the compute grids are cubic)"
        );
    }
    let exact = options.tracer == TracerKind::Grid && options.grid.variant == GridVariant::Exact;
    if options.grid.proximity_clouds && !(exact || stream) {
        anyhow::bail!(
            "--proximity-clouds applies to --tracer stream and to --tracer grid with \
             --grid-variant exact only (the thesis grid's per-ray voxel lists cannot skip cells; \
             the BVHs have no cells)"
        );
    }
    Ok(())
}

/// Host bytes per triangle a point-light design takes while it is built and uploaded, beyond
/// the loaded mesh (checked before it is built; `tests/memory_estimates.rs` holds each against
/// the peak of the allocations). Every design makes the world-space triangles (36) and
/// attributes (136), and the driver keeps a copy of what is uploaded (a software driver's GPU
/// memory is the host's).
pub fn host_bytes_per_triangle(options: &mueller2015::RenderOptions) -> u64 {
    const WORLD: u64 = 36 + 136;
    // vertex arrays on the GPU: positions, normals, colours, texture coordinates, material
    const UPLOAD: u64 = 136;
    // the SAH BVH: builder boxes, centres and ids (24 + 12 + 4), at most 2n nodes of 32 bytes
    // and their GPU copy, the wide layout built from them
    const SAH_BVH: u64 = 40 + 2 * 32 * 2 + 2 * 64;
    // Wagner's BVH: builder (24 + 12 + 4 + 4), 2n nodes of 48; its six textures (node bounds
    // and integers 2·48, ids 4, vertices, normals, colours 3·48) staged, owned and copied by
    // the driver
    const WAGNER: u64 = 44 + 2 * 48 + 3 * (2 * 48 + 4 + 3 * 48);
    // seed 004's textures: two of four RGB32F slices per triangle, staged and in the driver
    // (padded to four channels), and the copy of the scene the renderer keeps
    const STREAM: u64 = 2 * 4 * (12 + 16) + 136;
    if is_wagner(options) {
        return WORLD + WAGNER;
    }
    match options.tracer {
        TracerKind::Stream => WORLD + STREAM,
        TracerKind::Bvh => WORLD + UPLOAD + SAH_BVH,
        _ => WORLD + UPLOAD,
    }
}
