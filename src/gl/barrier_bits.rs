//! The barrier bits this program issues (`glMemoryBarrier`), below the context, which starts
//! with every bit pending, and `sync`, which issues them.

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
pub const ALL: u32 = glow::SHADER_STORAGE_BARRIER_BIT
    | glow::SHADER_IMAGE_ACCESS_BARRIER_BIT
    | glow::TEXTURE_FETCH_BARRIER_BIT
    | glow::BUFFER_UPDATE_BARRIER_BIT
    | glow::TEXTURE_UPDATE_BARRIER_BIT
    | glow::FRAMEBUFFER_BARRIER_BIT
    | glow::COMMAND_BARRIER_BIT;

/// What a compute kernel may access: storage buffers, images, textures (and texture buffers).
pub const SHADER: u32 = glow::SHADER_STORAGE_BARRIER_BIT
    | glow::SHADER_IMAGE_ACCESS_BARRIER_BIT
    | glow::TEXTURE_FETCH_BARRIER_BIT;
