//! Memory visibility between passes, in one place (`docs/memory_model.md` has the table of
//! every pipeline's passes, what each writes and who reads it next).
//!
//! GL 4.6 §7.12–7.13: what shaders write through image stores, buffer stores and atomics is
//! not ordered with any later or earlier operation by itself. `glMemoryBarrier(bits)` orders
//! it: shader writes issued before the barrier become visible to the kinds of access the bits
//! name that are issued after it, and stores and atomics issued after it wait until every
//! access issued before it has completed (a write after a read, or after a render). Ordinary GL
//! commands — rendering, clears, copies, uploads — are ordered among themselves.
//!
//! The rule this program follows: **each access to memory a shader may have written issues,
//! just before it, the barrier bits of its own kind that no barrier has issued since the last
//! pass that ran shaders** ([`before`]); every pass that runs shaders — a compute dispatch, a
//! draw — marks every bit pending again after it ([`after_pass`]). So a bit is issued once
//! between a pass and the accesses after it, and only the bits those accesses need:
//!
//! | access | its kind | where |
//! |---|---|---|
//! | a compute dispatch (SSBO, image and texture reads and writes) | [`SHADER`]: `SHADER_STORAGE`, `SHADER_IMAGE_ACCESS`, `TEXTURE_FETCH` | `Kernel::dispatch_*`, the BVH refit's passes |
//! | an indirect dispatch's command | `COMMAND` | `Kernel::dispatch_indirect` |
//! | a draw whose shaders store (Müller 2015's transform pass, the streaming tracer's passes) | [`SHADER`] (the streaming tracer's: [`ALL`]) | `GpuScene::transform`, `stream::targets` |
//! | rendering into a texture a shader stored into (Klee 2016's G-buffer) | `FRAMEBUFFER` and [`SHADER`] | `GBuffer::draw` |
//! | sampling what a shader stored (the screen-filling quads) | `TEXTURE_FETCH` | `Present::draw`, the viewer |
//! | `glGetBufferSubData`, `glClearBufferData`, `glBufferSubData` | `BUFFER_UPDATE` | `resources::read_buffer`, `Gl::clear_buffer_u32`, texture-buffer uploads |
//! | `glGetTexImage`, `glClearTexImage`, `glCopyImageSubData`, `glTexSubImage*` | `TEXTURE_UPDATE` | `resources`, `Gl::clear_tex_*` |
//!
//! A pass's own kinds before it also order its stores after the reads of the passes before
//! (GL 4.6 §7.13.2: stores of a kind issued after a barrier with its bit are not visible to
//! accesses issued before it). `GPGPU_RT_BARRIERS=all` issues every pending bit at the first
//! access after a pass instead, whatever its kind: a GPU run compares the two (`scripts/gpu-check.sh`), since no run on llvmpipe or
//! lavapipe — whose barriers finish all work whatever the bits — can show a missing bit.

use std::ffi::c_void;

use glow::HasContext;

use super::context::Gl;

pub use super::barrier_bits::{ALL, SHADER};

/// The environment variable that makes every access issue every bit (`all`).
pub const BARRIERS_ENV: &str = "GPGPU_RT_BARRIERS";

fn every_bit_always() -> bool {
    static ALL_BITS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ALL_BITS.get_or_init(|| std::env::var(BARRIERS_ENV).is_ok_and(|v| v.trim() == "all"))
}

/// Before an access of `kinds` to memory a shader may have written: the bits of `kinds` not
/// issued since the last pass that ran shaders (see the module's rule).
pub fn before(gl: &Gl, kinds: u32) {
    let kinds = if every_bit_always() { ALL } else { kinds };
    let bits = gl.take_pending_barriers(kinds);
    if bits != 0 {
        // SAFETY: glMemoryBarrier on a current context.
        unsafe { gl.memory_barrier(bits) };
    }
}

/// The bits pending on `gl`'s context: shader writes may not yet be visible to those kinds of
/// access (for tests and inspection).
pub fn pending(gl: &Gl) -> u32 {
    gl.peek_pending_barriers()
}

/// After a pass that ran shaders: every bit pending again.
pub fn after_pass(gl: &Gl) {
    gl.set_all_barriers_pending();
}

/// Before a pass whose shaders access every kind (the streaming tracer's fragment passes).
pub fn barrier(gl: &Gl) {
    before(gl, ALL);
}
/// The clears of buffers and textures that shaders may have written: each issues its barrier
/// first (its fields are the context's, the barrier this module's).
impl Gl {
    /// `glClearBufferData(target, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &value)` on the
    /// buffer bound to `target`: every 32-bit word of it becomes `value`.
    pub fn clear_buffer_u32(&self, target: u32, value: u32) {
        before(self, glow::BUFFER_UPDATE_BARRIER_BIT);
        // SAFETY: value outlives the call; the format describes one u32.
        unsafe {
            (self.clear_buffer_data)(
                target,
                glow::R32UI,
                glow::RED_INTEGER,
                glow::UNSIGNED_INT,
                &value as *const u32 as *const c_void,
            )
        }
    }

    /// `glClearTexImage` of level 0 with four floats (RGBA32F textures).
    pub fn clear_tex_f32(&self, texture: glow::Texture, value: [f32; 4]) {
        before(self, glow::TEXTURE_UPDATE_BARRIER_BIT);
        // SAFETY: value outlives the call.
        unsafe {
            (self.clear_tex_image)(
                texture.0.get(),
                0,
                glow::RGBA,
                glow::FLOAT,
                value.as_ptr() as *const c_void,
            )
        }
    }

    /// `glClearTexImage` of level 0 with four unsigned integers (RGBA32UI / R32UI textures).
    pub fn clear_tex_u32(&self, texture: glow::Texture, format: u32, value: [u32; 4]) {
        before(self, glow::TEXTURE_UPDATE_BARRIER_BIT);
        // SAFETY: value outlives the call.
        unsafe {
            (self.clear_tex_image)(
                texture.0.get(),
                0,
                format,
                glow::UNSIGNED_INT,
                value.as_ptr() as *const c_void,
            )
        }
    }
}
