//! The one interface every pipeline implements ([`Renderer`]: draw a frame without reading it
//! back, read it back on demand, its output texture, move an object) and what every frame's
//! end shares; below the pipelines, which all implement and call it.

use std::time::Instant;

use anyhow::{anyhow, Result};
use glam::Mat4;

use crate::frame::{Frame, FrameStats};
use crate::gl::{check_error, Gl};
use crate::scene::Camera;

/// The end of every frame's draw: a GL error fails the frame (naming what was rendered), and
/// the wall time since `start` goes into the statistics, taken after `glFinish` — the whole
/// frame, the gaps between its dispatches included, which `gpu_ms` (the sum of the timed
/// dispatches) leaves out.
pub(crate) fn end_of_frame(gl: &Gl, stats: &mut FrameStats, start: Instant) -> Result<()> {
    finish(gl);
    check_error(gl, "rendering a frame").map_err(|e| anyhow!("{e:#}"))?;
    stats.wall_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(())
}

/// `glFinish`: every command issued so far has completed.
pub(crate) fn finish(gl: &Gl) {
    use glow::HasContext;
    // SAFETY: a plain command on the current context.
    unsafe { gl.finish() };
}

/// What [`Renderer::draw`] kept of the last frame, for [`Renderer::read_back`].
pub(crate) fn last_drawn<T: Clone>(last: &Option<T>) -> Result<T> {
    last.clone().ok_or_else(|| anyhow!("no frame drawn yet"))
}

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
