//! Typed helpers for the GL objects the tracers own: shader storage buffers, RGBA32F images,
//! GPU timers. Each GL object name is held in an [`Owned`], which deletes it when dropped, so
//! the pipelines and accelerators that hold these need no `Drop` of their own.

use std::collections::BTreeMap;
use std::sync::Arc;

use anyhow::{anyhow, bail, Result};
use glow::HasContext;

use super::context::Gl;

/// A kind of GL object name and the call that deletes it.
pub trait GlObject: Copy {
    /// Delete `name` (a name of this kind, created on the context `gl` belongs to).
    ///
    /// # Safety
    /// The context must be current and `name` must not be used afterwards.
    unsafe fn delete(gl: &Gl, name: Self);
}

macro_rules! gl_object {
    ($($ty:ty => $delete:ident),* $(,)?) => {
        $(impl GlObject for $ty {
            unsafe fn delete(gl: &Gl, name: Self) {
                gl.$delete(name)
            }
        })*
    };
}

// glow's native types (what `glow::Buffer` and the others name on a native context): trait
// impls cannot name them through the `HasContext` projections
gl_object! {
    glow::NativeBuffer => delete_buffer,
    glow::NativeTexture => delete_texture,
    glow::NativeFramebuffer => delete_framebuffer,
    glow::NativeRenderbuffer => delete_renderbuffer,
    glow::NativeVertexArray => delete_vertex_array,
    glow::NativeQuery => delete_query,
    glow::NativeProgram => delete_program,
    glow::NativeShader => delete_shader,
    glow::NativeFence => delete_sync,
}

/// A GL object name owned: deleted when this drops. It holds the [`Gl`] it was made with; the
/// context ([`super::GlContext`]) must outlive it, as it outlives the renderers that hold these.
pub struct Owned<T: GlObject> {
    gl: Arc<Gl>,
    name: T,
}

impl<T: GlObject> Owned<T> {
    /// Own `name`, a name just created on `gl`'s context (`gl.create_buffer()`, ...).
    pub fn new(gl: &Arc<Gl>, name: T) -> Owned<T> {
        Owned {
            gl: gl.clone(),
            name,
        }
    }

    /// The GL name, for GL calls (valid while this lives).
    pub fn raw(&self) -> T {
        self.name
    }
}

impl<T: GlObject> Drop for Owned<T> {
    fn drop(&mut self) {
        // SAFETY: the name is ours and dies with us; the context outlives its objects.
        unsafe { T::delete(&self.gl, self.name) };
    }
}

/// A shader storage buffer of fixed size.
pub struct Ssbo {
    pub buffer: Owned<glow::Buffer>,
    pub bytes: usize,
    pub name: &'static str,
}

impl Ssbo {
    /// Allocate `bytes` (at least 16) of immutable storage, optionally filled with `data`,
    /// after checking the size against `GL_MAX_SHADER_STORAGE_BLOCK_SIZE`; a buffer the scene
    /// or the image size decides (see [`Ssbo::sized`]).
    pub fn new(
        gl: &Arc<Gl>,
        name: &'static str,
        bytes: usize,
        data: Option<&[u8]>,
        max_block: i64,
    ) -> Result<Ssbo> {
        Self::sized(
            gl,
            name,
            bytes,
            data,
            max_block,
            "the scene or the image size",
        )
    }

    /// [`Ssbo::new`] for a buffer whose size `sized_by` decides (options such as `--grid
    /// with --voxel-array-length`): the refusal names them.
    pub fn sized(
        gl: &Arc<Gl>,
        name: &'static str,
        bytes: usize,
        data: Option<&[u8]>,
        max_block: i64,
        sized_by: &str,
    ) -> Result<Ssbo> {
        let bytes = bytes.max(16);
        if bytes as i64 > max_block {
            bail!(
                "buffer `{name}` needs {bytes} bytes, more than GL_MAX_SHADER_STORAGE_BLOCK_SIZE = {max_block} \
                 of this GL implementation; {sized_by} decides its size"
            );
        }
        if bytes > i32::MAX as usize {
            bail!("buffer `{name}` needs {bytes} bytes, more than a GL size can express");
        }
        // SAFETY: plain buffer creation on a current context; data is bytes long if given.
        unsafe {
            let buffer = Owned::new(gl, gl.create_buffer().map_err(|e| anyhow!(e))?);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(buffer.raw()));
            let padded;
            let data = match data {
                Some(d) if d.len() < bytes => {
                    let mut v = d.to_vec();
                    v.resize(bytes, 0);
                    padded = v;
                    Some(&padded[..])
                }
                d => d,
            };
            gl.buffer_storage(
                glow::SHADER_STORAGE_BUFFER,
                bytes as i32,
                data,
                glow::DYNAMIC_STORAGE_BIT,
            );
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, None);
            let what = format!("the shader storage buffer `{name}` (sized by {sized_by})");
            super::check_alloc(gl, &what, bytes as u64)?;
            Ok(Ssbo {
                buffer,
                bytes,
                name,
            })
        }
    }

    pub fn bind(&self, gl: &Gl, binding: u32) {
        // SAFETY: binding an existing buffer.
        unsafe {
            gl.bind_buffer_base(
                glow::SHADER_STORAGE_BUFFER,
                binding,
                Some(self.buffer.raw()),
            )
        };
    }

    /// A buffer texture of `format` (16-byte texels) over this buffer's storage, no copy, for a
    /// kernel to read it as an image buffer: shader stores through the SSBO show through it
    /// after the barrier between passes (`gl::sync`). Llvmpipe loads an image texel for all
    /// lanes at once, a storage-buffer vector lane by lane (docs/design/frame.md). `None`
    /// where `unit` is beyond `GL_MAX_IMAGE_UNITS` or the texels beyond
    /// `GL_MAX_TEXTURE_BUFFER_SIZE`: the kernel reads the SSBO instead.
    pub fn texel_view(
        &self,
        gl: &Arc<Gl>,
        max_image_units: i32,
        unit: u32,
        format: u32,
    ) -> Result<Option<Owned<glow::Texture>>> {
        buffer_view(
            gl,
            self.buffer.raw(),
            self.bytes / 16,
            max_image_units,
            unit,
            format,
        )
    }

    /// Bind `bytes` bytes from `offset` (a multiple of `GlInfo::ssbo_offset_alignment`).
    pub fn bind_range(&self, gl: &Gl, binding: u32, offset: usize, bytes: usize) {
        debug_assert!(offset + bytes <= self.bytes);
        // SAFETY: binding a range inside an existing buffer.
        unsafe {
            gl.bind_buffer_range(
                glow::SHADER_STORAGE_BUFFER,
                binding,
                Some(self.buffer.raw()),
                offset as i32,
                bytes as i32,
            )
        };
    }

    /// `glClearBufferData` with a 32-bit value.
    pub fn clear_u32(&self, gl: &Gl, value: u32) {
        // SAFETY: binding an existing buffer.
        unsafe { gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.buffer.raw())) };
        gl.clear_buffer_u32(glow::SHADER_STORAGE_BUFFER, value);
        unsafe { gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, None) };
    }

    pub fn read_u32(&self, gl: &Gl) -> Vec<u32> {
        let mut bytes = vec![0u8; self.bytes];
        self.read_bytes(gl, &mut bytes);
        bytemuck::pod_collect_to_vec(&bytes)
    }

    /// The buffer's first `bytes.len()` bytes (at most its size).
    pub fn read_bytes(&self, gl: &Gl, bytes: &mut [u8]) {
        assert!(
            bytes.len() <= self.bytes,
            "{}: read past the end",
            self.name
        );
        read_buffer(gl, self.buffer.raw(), bytes);
    }
}

/// The first `bytes.len()` bytes of `buffer`, which must hold at least as many (bound to
/// GL_COPY_READ_BUFFER, which no kernel binding uses).
fn read_buffer(gl: &Gl, buffer: glow::Buffer, bytes: &mut [u8]) {
    super::sync::before(gl, glow::BUFFER_UPDATE_BARRIER_BIT);
    // SAFETY: reading an existing buffer of at least bytes.len() bytes; unbound again.
    unsafe {
        gl.bind_buffer(glow::COPY_READ_BUFFER, Some(buffer));
        gl.get_buffer_sub_data(glow::COPY_READ_BUFFER, 0, bytes);
        gl.bind_buffer(glow::COPY_READ_BUFFER, None);
    }
}

/// Bind level 0 of `texture` (all layers) to image unit `unit` with `access` and `format`.
pub fn bind_image_unit(gl: &Gl, unit: u32, texture: glow::Texture, access: u32, format: u32) {
    // SAFETY: binding an existing texture to an image unit.
    unsafe { gl.bind_image_texture(unit, Some(texture), 0, false, 0, access, format) };
}

/// A buffer texture of `format` over `buffer` (`texels` of that format), no copy, for a kernel
/// to read as an image buffer at image unit `unit`; `None` where `unit` is beyond
/// `GL_MAX_IMAGE_UNITS` or the texels beyond `GL_MAX_TEXTURE_BUFFER_SIZE` (the kernel reads the
/// buffer as a storage buffer instead). See [`Ssbo::texel_view`].
pub fn buffer_view(
    gl: &Arc<Gl>,
    buffer: glow::Buffer,
    texels: usize,
    max_image_units: i32,
    unit: u32,
    format: u32,
) -> Result<Option<Owned<glow::Texture>>> {
    // SAFETY: a limit query on a current context.
    let max_texels = unsafe { gl.get_parameter_i32(glow::MAX_TEXTURE_BUFFER_SIZE) } as i64;
    if unit as i64 >= max_image_units as i64 || texels as i64 > max_texels {
        return Ok(None);
    }
    // SAFETY: a texture over our own buffer on a current context.
    unsafe {
        let t = Owned::new(gl, gl.create_texture().map_err(|e| anyhow!(e))?);
        gl.bind_texture(glow::TEXTURE_BUFFER, Some(t.raw()));
        gl.tex_buffer(format, buffer);
        gl.bind_texture(glow::TEXTURE_BUFFER, None);
        Ok(Some(t))
    }
}

/// A 2D texture used as an image (RGBA32F or RGBA32UI).
pub struct Image2d {
    pub texture: Owned<glow::Texture>,
    pub width: u32,
    pub height: u32,
    pub format: u32,
}

impl Image2d {
    pub fn new(gl: &Arc<Gl>, width: u32, height: u32, format: u32) -> Result<Image2d> {
        // SAFETY: texture creation on a current context.
        unsafe {
            let texture = Owned::new(gl, gl.create_texture().map_err(|e| anyhow!(e))?);
            gl.bind_texture(glow::TEXTURE_2D, Some(texture.raw()));
            gl.tex_storage_2d(glow::TEXTURE_2D, 1, format, width as i32, height as i32);
            let texel = match format {
                glow::R32UI | glow::R32F | glow::RGBA8 => 4,
                glow::RG32UI | glow::RG32F => 8,
                _ => 16,
            };
            let what = format!("a {width}x{height} image texture (sized by the image size)");
            super::check_alloc(gl, &what, width as u64 * height as u64 * texel)?;
            gl.tex_parameter_i32(
                glow::TEXTURE_2D,
                glow::TEXTURE_MIN_FILTER,
                glow::NEAREST as i32,
            );
            gl.tex_parameter_i32(
                glow::TEXTURE_2D,
                glow::TEXTURE_MAG_FILTER,
                glow::NEAREST as i32,
            );
            gl.bind_texture(glow::TEXTURE_2D, None);
            Ok(Image2d {
                texture,
                width,
                height,
                format,
            })
        }
    }

    pub fn bind_image(&self, gl: &Gl, unit: u32) {
        bind_image_unit(gl, unit, self.texture.raw(), glow::READ_WRITE, self.format);
    }

    /// Every texel of an RGBA32F image set to `value` (`glClearTexImage`).
    pub fn fill_f32(&self, gl: &Gl, value: [f32; 4]) {
        assert_eq!(self.format, glow::RGBA32F, "fill_f32 of an RGBA32F image");
        gl.clear_tex_f32(self.texture.raw(), value);
    }

    pub fn clear(&self, gl: &Gl) {
        match self.format {
            glow::RGBA32UI => gl.clear_tex_u32(self.texture.raw(), glow::RGBA_INTEGER, [0; 4]),
            _ => gl.clear_tex_f32(self.texture.raw(), [0.0; 4]),
        }
    }

    /// Copy the texels of `src` (same size and format) into this image, on the GPU.
    pub fn copy_from(&self, gl: &Gl, src: &Image2d) {
        super::sync::before(gl, glow::TEXTURE_UPDATE_BARRIER_BIT);
        // SAFETY: glCopyImageSubData between two of our textures of the same size and format.
        unsafe {
            gl.copy_image_sub_data(
                src.texture.raw(),
                glow::TEXTURE_2D,
                0,
                0,
                0,
                0,
                self.texture.raw(),
                glow::TEXTURE_2D,
                0,
                0,
                0,
                0,
                self.width as i32,
                self.height as i32,
                1,
            )
        };
    }

    /// Read back RGBA32F texels, row 0 = the bottom row (GL order).
    pub fn read_f32(&self, gl: &Gl) -> Vec<[f32; 4]> {
        read_texture_rgba32f(gl, self.texture.raw(), self.width, self.height)
    }

    /// Read back RGBA32UI texels, row 0 = the bottom row (GL order).
    pub fn read_u32(&self, gl: &Gl) -> Vec<[u32; 4]> {
        super::sync::before(gl, glow::TEXTURE_UPDATE_BARRIER_BIT);
        let mut data = vec![[0u32; 4]; (self.width * self.height) as usize];
        // SAFETY: the slice holds w·h RGBA uints.
        unsafe {
            gl.bind_texture(glow::TEXTURE_2D, Some(self.texture.raw()));
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            gl.get_tex_image(
                glow::TEXTURE_2D,
                0,
                glow::RGBA_INTEGER,
                glow::UNSIGNED_INT,
                glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut data))),
            );
            gl.bind_texture(glow::TEXTURE_2D, None);
        }
        data
    }
}

/// A buffer texture (`GL_TEXTURE_BUFFER`): texels in a buffer, read by kernels with
/// `texelFetch` through a `samplerBuffer` (Wagner 2018 keeps its BVH in such textures, Fig. 4.3).
/// For data every invocation reads at its own index: llvmpipe fetches texels for its 8 lanes
/// at once, where it loads storage buffers lane by lane.
pub struct TextureBuffer {
    // the texture first: it drops before the buffer it reads
    pub texture: Owned<glow::Texture>,
    pub buffer: Owned<glow::Buffer>,
    /// The texel format (`GL_RGBA32F`, ...).
    pub format: u32,
    /// Texels and bytes of the data.
    pub texels: usize,
    pub bytes: usize,
}

impl TextureBuffer {
    /// Upload `data` as texels of `format` (`texel_bytes` each), after checking the count
    /// against `GL_MAX_TEXTURE_BUFFER_SIZE`; `name` is for the message.
    pub fn new(
        gl: &Arc<Gl>,
        name: &str,
        format: u32,
        texel_bytes: usize,
        data: &[u8],
    ) -> Result<TextureBuffer> {
        // at least one texel: an empty list still makes a valid texture
        let texels = data.len().div_ceil(texel_bytes).max(1);
        // the data itself where it fills whole texels (no copy of a large buffer), else a
        // padded copy
        let padded: std::borrow::Cow<[u8]> = if data.len() == texels * texel_bytes {
            data.into()
        } else {
            let mut v = data.to_vec();
            v.resize(texels * texel_bytes, 0);
            v.into()
        };
        // SAFETY: a limit query on a current context.
        let max = unsafe { gl.get_parameter_i32(glow::MAX_TEXTURE_BUFFER_SIZE) } as i64;
        if texels as i64 > max || padded.len() > i32::MAX as usize {
            bail!(
                "texture `{name}` needs {texels} texels, more than GL_MAX_TEXTURE_BUFFER_SIZE = {max} \
                 of this GL implementation; the scene decides its size"
            );
        }
        // SAFETY: buffer and texture creation on a current context.
        unsafe {
            let buffer = Owned::new(gl, gl.create_buffer().map_err(|e| anyhow!(e))?);
            gl.bind_buffer(glow::TEXTURE_BUFFER, Some(buffer.raw()));
            gl.buffer_data_u8_slice(glow::TEXTURE_BUFFER, &padded, glow::STATIC_DRAW);
            gl.bind_buffer(glow::TEXTURE_BUFFER, None);
            let what = format!("the texture buffer `{name}` (sized by the scene)");
            super::check_alloc(gl, &what, padded.len() as u64)?;
            let texture = Owned::new(gl, gl.create_texture().map_err(|e| anyhow!(e))?);
            gl.bind_texture(glow::TEXTURE_BUFFER, Some(texture.raw()));
            gl.tex_buffer(format, buffer.raw());
            gl.bind_texture(glow::TEXTURE_BUFFER, None);
            Ok(TextureBuffer {
                texture,
                buffer,
                format,
                texels,
                bytes: data.len(),
            })
        }
    }

    /// Bind to texture unit `unit` (a `samplerBuffer` with `layout(binding = unit)`).
    pub fn bind(&self, gl: &Gl, unit: u32) {
        // SAFETY: binding our own texture to a texture unit.
        unsafe {
            gl.active_texture(glow::TEXTURE0 + unit);
            gl.bind_texture(glow::TEXTURE_BUFFER, Some(self.texture.raw()));
            gl.active_texture(glow::TEXTURE0);
        }
    }

    /// Bind to image unit `unit` with `access` (`glow::READ_ONLY`: an `imageBuffer` with
    /// `layout(format, binding = unit) readonly`). llvmpipe generates image loads inline, where
    /// it calls a function for every `texelFetch` of a format other than 8-bit RGBA
    /// (docs/design/bvh.md, step 2).
    pub fn bind_image(&self, gl: &Gl, unit: u32, access: u32) {
        bind_image_unit(gl, unit, self.texture.raw(), access, self.format);
    }
}

/// One texture buffer's data: its name (for messages), texel format and size, bytes, and the
/// sampler slot it binds to.
pub struct TexelData<'a> {
    pub name: &'static str,
    pub format: u32,
    pub texel_bytes: usize,
    pub bytes: std::borrow::Cow<'a, [u8]>,
    pub unit: u32,
}

impl<'a> TexelData<'a> {
    /// `bytes` (borrowed) as texels of `format` (`texel_bytes` each), for sampler slot `unit`.
    pub fn new(
        name: &'static str,
        format: u32,
        texel_bytes: usize,
        bytes: &'a [u8],
        unit: u32,
    ) -> Self {
        TexelData {
            name,
            format,
            texel_bytes,
            bytes: bytes.into(),
            unit,
        }
    }

    /// The same data, owning its bytes (to outlive the buffer it was made from).
    pub fn into_owned(self) -> TexelData<'static> {
        TexelData {
            bytes: self.bytes.into_owned().into(),
            ..self
        }
    }
}

/// Texture buffers uploaded and bound together (a design's data structure).
pub struct TextureBuffers(Vec<(TextureBuffer, u32)>);

impl TextureBuffers {
    /// Upload every one; on an error the ones made so far are deleted (as they drop).
    pub fn upload<'a>(
        gl: &Arc<Gl>,
        data: impl IntoIterator<Item = TexelData<'a>>,
    ) -> Result<TextureBuffers> {
        let mut made = TextureBuffers(Vec::new());
        for d in data {
            let t = TextureBuffer::new(gl, d.name, d.format, d.texel_bytes, &d.bytes)?;
            made.0.push((t, d.unit));
        }
        Ok(made)
    }

    /// Bytes of the buffers in `range` (in upload order).
    pub fn bytes(&self, range: std::ops::Range<usize>) -> usize {
        self.0[range].iter().map(|(t, _)| t.bytes).sum()
    }

    pub fn bind(&self, gl: &Gl) {
        for (t, unit) in &self.0 {
            t.bind(gl, *unit);
        }
    }

    /// Bind every one to its unit as an image with `access` (the units are image units).
    pub fn bind_images(&self, gl: &Gl, access: u32) {
        for (t, unit) in &self.0 {
            t.bind_image(gl, *unit, access);
        }
    }

    /// Bind buffer `index` (in upload order) also as the storage buffer `binding`, where it
    /// fits `max_block` (`GL_MAX_SHADER_STORAGE_BLOCK_SIZE`): whether it was bound.
    pub fn bind_storage(&self, gl: &Gl, index: usize, binding: u32, max_block: i64) -> bool {
        let t = &self.0[index].0;
        let bytes = t.texels * 16;
        if bytes as i64 > max_block {
            return false;
        }
        // SAFETY: binding our own buffer to a storage-buffer binding point.
        unsafe {
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, binding, Some(t.buffer.raw()));
        }
        true
    }

    /// Overwrite the first words of buffer `index` (in upload order) with `words`, which must
    /// fit in it. Dispatches issued later read them (GL orders a buffer update before the
    /// commands after it).
    pub fn write_u32(&self, gl: &Gl, index: usize, words: &[u32]) {
        // after kernels that stored into the buffer (gl::sync)
        super::sync::before(gl, glow::BUFFER_UPDATE_BARRIER_BIT);
        let t = &self.0[index].0;
        assert!(4 * words.len() <= t.bytes, "a write within the buffer");
        // SAFETY: an update of our own buffer within its size.
        unsafe {
            gl.bind_buffer(glow::TEXTURE_BUFFER, Some(t.buffer.raw()));
            gl.buffer_sub_data_u8_slice(glow::TEXTURE_BUFFER, 0, bytemuck::cast_slice(words));
            gl.bind_buffer(glow::TEXTURE_BUFFER, None);
        }
    }

    /// For tests: the 32-bit words of buffer `index` (in upload order), as kernels left them.
    pub fn read_u32(&self, gl: &Gl, index: usize) -> Vec<u32> {
        let t = &self.0[index].0;
        let mut bytes = vec![0u8; t.bytes];
        read_buffer(gl, t.buffer.raw(), &mut bytes);
        bytemuck::pod_collect_to_vec(&bytes)
    }
}

/// A 32-bit float depth renderbuffer of `w`×`h` (the depth test of a pass that rasterises the
/// scene), unbound again.
pub fn depth_renderbuffer(gl: &Arc<Gl>, w: u32, h: u32) -> Result<Owned<glow::Renderbuffer>> {
    // SAFETY: renderbuffer creation and storage on a current context.
    unsafe {
        let depth = Owned::new(gl, gl.create_renderbuffer().map_err(|e| anyhow!(e))?);
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth.raw()));
        gl.renderbuffer_storage(
            glow::RENDERBUFFER,
            glow::DEPTH_COMPONENT32F,
            w as i32,
            h as i32,
        );
        gl.bind_renderbuffer(glow::RENDERBUFFER, None);
        Ok(depth)
    }
}

/// Read back a w×h RGBA32F 2D texture (written by image stores or by rendering into it),
/// row 0 = the bottom row (GL order).
pub fn read_texture_rgba32f(gl: &Gl, texture: glow::Texture, w: u32, h: u32) -> Vec<[f32; 4]> {
    let mut data = vec![[0f32; 4]; (w * h) as usize];
    read_tex_image(
        gl,
        texture,
        (glow::TEXTURE_2D, glow::RGBA, glow::FLOAT),
        &mut data,
    );
    data
}

/// `glGetTexImage` of level 0 of `texture` into `data`, which must hold every texel of it:
/// `(target, format, type)` as GL names them, rows packed without padding.
pub fn read_tex_image<T: bytemuck::Pod>(
    gl: &Gl,
    texture: glow::Texture,
    (target, format, ty): (u32, u32, u32),
    data: &mut [T],
) {
    super::sync::before(gl, glow::TEXTURE_UPDATE_BARRIER_BIT);
    // SAFETY: the caller's slice holds the whole level; the texture is unbound again.
    unsafe {
        gl.bind_texture(target, Some(texture));
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
        gl.get_tex_image(
            target,
            0,
            format,
            ty,
            glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(data))),
        );
        gl.bind_texture(target, None);
    }
}

/// GPU time per kernel from GL timer queries: a `GL_TIMESTAMP` query (`glQueryCounter`)
/// before and after every dispatch, differences summed per kernel name when the frame is
/// resolved. (Timestamps rather than `GL_TIME_ELAPSED`, whose compute-dispatch results Mesa's
/// llvmpipe does not fill in; both are GL timer queries.) Dispatches timed while a ray kind is
/// set ([`GpuTimers::set_ray_kind`]) are also summed per ray kind. The queries are deleted as
/// the timers drop.
pub struct GpuTimers {
    gl: Arc<Gl>,
    free: Vec<glow::Query>,
    pending: Vec<Pending>,
    ray_kind: Option<&'static str>,
    ray_kind_ms: BTreeMap<String, f64>,
}

/// A timed dispatch: kernel name, ray kind, the queries before and after.
type Pending = (&'static str, Option<&'static str>, glow::Query, glow::Query);

impl GpuTimers {
    /// Timers with no query yet (made as dispatches are timed, reused frame after frame).
    pub fn new(gl: &Arc<Gl>) -> GpuTimers {
        GpuTimers {
            gl: gl.clone(),
            free: Vec::new(),
            pending: Vec::new(),
            ray_kind: None,
            ray_kind_ms: BTreeMap::new(),
        }
    }

    fn query(&mut self, gl: &Gl) -> glow::Query {
        match self.free.pop() {
            Some(q) => q,
            // SAFETY: query creation on a current context.
            None => unsafe { gl.create_query().expect("glGenQueries failed") },
        }
    }

    /// The kind of rays the dispatches timed from now on trace ("primary", "shadow", ...), or
    /// `None`: work that is not one kind's (builds, eye-ray generation, shading).
    pub fn set_ray_kind(&mut self, kind: Option<&'static str>) {
        self.ray_kind = kind;
    }

    /// Time the GL commands `f` issues under `name`.
    pub fn time<R>(&mut self, gl: &Gl, name: &'static str, f: impl FnOnce() -> R) -> R {
        let (a, b) = (self.query(gl), self.query(gl));
        // SAFETY: timestamp queries on a current context.
        unsafe { gl.query_counter(a, glow::TIMESTAMP) };
        let r = f();
        unsafe { gl.query_counter(b, glow::TIMESTAMP) };
        self.pending.push((name, self.ray_kind, a, b));
        r
    }

    /// Wait for all queries and return milliseconds per kernel name; the milliseconds per ray
    /// kind wait in [`GpuTimers::take_ray_kind_ms`].
    pub fn resolve(&mut self, gl: &Gl) -> BTreeMap<String, f64> {
        let mut out = BTreeMap::new();
        self.ray_kind_ms.clear();
        for (name, kind, a, b) in std::mem::take(&mut self.pending) {
            let ns = gl
                .query_result_u64(b)
                .saturating_sub(gl.query_result_u64(a));
            let ms = ns as f64 / 1e6;
            *out.entry(name.to_string()).or_insert(0.0) += ms;
            if let Some(k) = kind {
                *self.ray_kind_ms.entry(k.to_string()).or_insert(0.0) += ms;
            }
            self.free.push(a);
            self.free.push(b);
        }
        out
    }

    /// Milliseconds per ray kind of the frame [`GpuTimers::resolve`] resolved last.
    pub fn take_ray_kind_ms(&mut self) -> BTreeMap<String, f64> {
        std::mem::take(&mut self.ray_kind_ms)
    }
}

impl Drop for GpuTimers {
    fn drop(&mut self) {
        let pending = std::mem::take(&mut self.pending);
        for q in self
            .free
            .drain(..)
            .chain(pending.into_iter().flat_map(|p| [p.2, p.3]))
        {
            // SAFETY: deleting our own queries.
            unsafe { self.gl.delete_query(q) };
        }
    }
}

/// A 3D texture of RGB32F texels read with `texelFetch` through a `sampler3D` (nearest
/// filtering, one level): the cells and the triangle data of the streaming tracer's grid (Fig. 3).
pub struct Texture3d {
    pub texture: Owned<glow::Texture>,
    pub size: [u32; 3],
    pub bytes: usize,
}

impl Texture3d {
    /// Upload `texels` (x fastest, then y, then z; `size` = texels per axis) after checking
    /// every side against `GL_MAX_3D_TEXTURE_SIZE`; `name` is for the message.
    pub fn rgb32f(
        gl: &Arc<Gl>,
        name: &str,
        size: [u32; 3],
        texels: &[[f32; 3]],
    ) -> Result<Texture3d> {
        // SAFETY: a limit query on a current context.
        let max = unsafe { gl.get_parameter_i32(glow::MAX_3D_TEXTURE_SIZE) } as u32;
        if size.iter().any(|&s| s == 0 || s > max) {
            bail!(
                "3D texture `{name}` of {}x{}x{} texels: every side must lie in 1..={max} \
                 (GL_MAX_3D_TEXTURE_SIZE of this GL implementation)",
                size[0],
                size[1],
                size[2]
            );
        }
        let n = (size[0] * size[1] * size[2]) as usize;
        if texels.len() != n {
            bail!(
                "3D texture `{name}`: {} texels for {n} places",
                texels.len()
            );
        }
        // SAFETY: texture creation and upload on a current context; the slice holds n texels.
        unsafe {
            let texture = Owned::new(gl, gl.create_texture().map_err(|e| anyhow!(e))?);
            gl.bind_texture(glow::TEXTURE_3D, Some(texture.raw()));
            gl.tex_storage_3d(
                glow::TEXTURE_3D,
                1,
                glow::RGB32F,
                size[0] as i32,
                size[1] as i32,
                size[2] as i32,
            );
            for p in [glow::TEXTURE_MIN_FILTER, glow::TEXTURE_MAG_FILTER] {
                gl.tex_parameter_i32(glow::TEXTURE_3D, p, glow::NEAREST as i32);
            }
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
            gl.tex_sub_image_3d(
                glow::TEXTURE_3D,
                0,
                0,
                0,
                0,
                size[0] as i32,
                size[1] as i32,
                size[2] as i32,
                glow::RGB,
                glow::FLOAT,
                glow::PixelUnpackData::Slice(Some(bytemuck::cast_slice(texels))),
            );
            gl.bind_texture(glow::TEXTURE_3D, None);
            Ok(Texture3d {
                texture,
                size,
                bytes: 12 * n,
            })
        }
    }

    /// Bind to texture unit `unit` (a `sampler3D` with `layout(binding = unit)`).
    pub fn bind(&self, gl: &Gl, unit: u32) {
        // SAFETY: binding our own texture to a texture unit.
        unsafe {
            gl.active_texture(glow::TEXTURE0 + unit);
            gl.bind_texture(glow::TEXTURE_3D, Some(self.texture.raw()));
            gl.active_texture(glow::TEXTURE0);
        }
    }
}
