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
//! The rule this program follows: every pass whose shaders write memory — every compute
//! dispatch, and the draws whose vertex or fragment shaders store or count (Müller 2015's
//! transform pass, seed 004's passes with their counters) — is issued between two calls of
//! [`barrier`], before it and after it; passes whose shaders only read (the G-buffer, the
//! screen-filling quads) need none of their own. [`barrier`] sets the bit of every kind of
//! access this program makes to memory a shader may have written, so no reader needs a
//! barrier of its own and no pass needs to know who reads its output.

use glow::HasContext;

use super::context::Gl;

/// Every kind of later access this program makes to memory that shaders wrote:
///
/// | bit | the later access |
/// |---|---|
/// | `SHADER_STORAGE_BARRIER_BIT` | SSBO loads, stores and atomics of the next kernels |
/// | `SHADER_IMAGE_ACCESS_BARRIER_BIT` | image loads and stores (the ray-state images, the BVH's image buffer) |
/// | `TEXTURE_FETCH_BARRIER_BIT` | sampler and `texelFetch` reads, texture buffers included (the quads, Wagner's and the streaming tracer's textures) |
/// | `BUFFER_UPDATE_BARRIER_BIT` | `glGetBufferSubData` (counters, grid totals), `glClearBufferData` |
/// | `TEXTURE_UPDATE_BARRIER_BIT` | `glGetTexImage` (frames, AOVs), `glClearTexImage` (the ray-state images each frame, the shadow flags each pass), `glCopyImageSubData` (the AOV copies) |
/// | `FRAMEBUFFER_BARRIER_BIT` | rendering or clearing into a texture a shader stored into (Klee 2016's G-buffer diffuse texture, which the shadow pass shades in place) |
/// | `COMMAND_BARRIER_BIT` | indirect dispatch commands (the SAH BVH's fused pass over the block lists its entry pass counts) |
///
/// Not needed: no vertex or index data written by shaders, no atomic counter buffers, pixel
/// buffers, uniform buffers or transform feedback.
pub const SHADER_WRITE_READERS: u32 = glow::SHADER_STORAGE_BARRIER_BIT
    | glow::SHADER_IMAGE_ACCESS_BARRIER_BIT
    | glow::TEXTURE_FETCH_BARRIER_BIT
    | glow::BUFFER_UPDATE_BARRIER_BIT
    | glow::TEXTURE_UPDATE_BARRIER_BIT
    | glow::FRAMEBUFFER_BARRIER_BIT
    | glow::COMMAND_BARRIER_BIT;

/// The barrier between passes (see the module's rule).
pub fn barrier(gl: &Gl) {
    // SAFETY: glMemoryBarrier on a current context.
    unsafe { gl.memory_barrier(SHADER_WRITE_READERS) };
}
