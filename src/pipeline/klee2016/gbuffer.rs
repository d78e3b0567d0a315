//! Phase 1 of Klee 2016's pipeline (Fig. 7, ch. 4.1): the scene rasterised into an FBO with
//! position, normal and diffuse RGBA32F textures (`glsl/klee2016/gbuffer.vert`, `.frag`).

use std::sync::Arc;

use anyhow::{anyhow, bail, Result};
use glam::{Mat4, Vec3};
use glow::HasContext;

use crate::gl::resources::{depth_renderbuffer, read_texture_rgba32f, GpuTimers, Image2d, Owned};
use crate::gl::{Defines, Gl, Kernel, ShaderSource};
use crate::scene::Scene;

pub struct GBuffer {
    gl: Arc<Gl>,
    raster: Kernel,
    // the FBO and the VAO before what they hold: they drop first
    fbo: Owned<glow::Framebuffer>,
    vao: Owned<glow::VertexArray>,
    // held for the VAO and the FBO, which use them
    _vbos: Vec<Owned<glow::Buffer>>,
    _depth: Owned<glow::Renderbuffer>,
    /// position (w: 1 = geometry), normal (w: triangle id), diffuse (RGBA32F)
    textures: [Owned<glow::Texture>; 3],
    triangles: i32,
    width: u32,
    height: u32,
}

/// The G-buffer's program.
pub fn raster_kernel(gl: &Arc<Gl>, shaders: &ShaderSource) -> Result<Kernel> {
    Kernel::program(
        gl,
        shaders,
        &[
            (glow::VERTEX_SHADER, "klee2016/gbuffer.vert"),
            (glow::FRAGMENT_SHADER, "klee2016/gbuffer.frag"),
        ],
        &Defines::new(),
        "gbuffer",
    )
}

/// A w×h RGBA32F texture.
pub fn rgba32f_texture(gl: &Arc<Gl>, w: u32, h: u32) -> Result<Owned<glow::Texture>> {
    Ok(Image2d::new(gl, w, h, glow::RGBA32F)?.texture)
}

/// The world-space triangles' positions, normals and colours in three vertex buffers of a VAO
/// (attribute locations 0, 1, 2 of gbuffer.vert).
fn upload_vertices(
    gl: &Arc<Gl>,
    scene: &Scene,
) -> Result<(Owned<glow::VertexArray>, Vec<Owned<glow::Buffer>>)> {
    let attrs = scene.world_attributes();
    // the world positions in triangle-id order, as `Scene::world_triangles`
    let pos: Vec<[f32; 3]> = attrs.positions.iter().map(|v| v.to_array()).collect();
    let nor: Vec<[f32; 3]> = attrs.normals.iter().map(|v| v.to_array()).collect();
    let col: Vec<[f32; 3]> = attrs.colors.iter().map(|v| v.to_array()).collect();
    // SAFETY: GL object creation and uploads on a current context; slices match sizes.
    unsafe {
        let vao = Owned::new(gl, gl.create_vertex_array().map_err(|e| anyhow!(e))?);
        gl.bind_vertex_array(Some(vao.raw()));
        let mut vbos = Vec::new();
        for (loc, data) in [(0u32, &pos), (1, &nor), (2, &col)] {
            let b = Owned::new(gl, gl.create_buffer().map_err(|e| anyhow!(e))?);
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(b.raw()));
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
        Ok((vao, vbos))
    }
}

/// An FBO, its depth renderbuffer and the three textures attached to it.
type Framebuffer = (
    Owned<glow::Framebuffer>,
    Owned<glow::Renderbuffer>,
    [Owned<glow::Texture>; 3],
);

/// An FBO with the three G-buffer textures and a depth renderbuffer.
fn framebuffer(gl: &Arc<Gl>, w: u32, h: u32) -> Result<Framebuffer> {
    let textures = [
        rgba32f_texture(gl, w, h)?,
        rgba32f_texture(gl, w, h)?,
        rgba32f_texture(gl, w, h)?,
    ];
    // SAFETY: FBO set-up with our textures on a current context.
    unsafe {
        let fbo = Owned::new(gl, gl.create_framebuffer().map_err(|e| anyhow!(e))?);
        let depth = depth_renderbuffer(gl, w, h)?;
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo.raw()));
        for (i, t) in textures.iter().enumerate() {
            let attachment = glow::COLOR_ATTACHMENT0 + i as u32;
            let t = Some(t.raw());
            gl.framebuffer_texture_2d(glow::FRAMEBUFFER, attachment, glow::TEXTURE_2D, t, 0);
        }
        gl.framebuffer_renderbuffer(
            glow::FRAMEBUFFER,
            glow::DEPTH_ATTACHMENT,
            glow::RENDERBUFFER,
            Some(depth.raw()),
        );
        gl.draw_buffers(&[
            glow::COLOR_ATTACHMENT0,
            glow::COLOR_ATTACHMENT1,
            glow::COLOR_ATTACHMENT2,
        ]);
        let complete = gl.check_framebuffer_status(glow::FRAMEBUFFER) == glow::FRAMEBUFFER_COMPLETE;
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        if !complete {
            bail!("the G-buffer FBO is incomplete");
        }
        Ok((fbo, depth, textures))
    }
}

impl GBuffer {
    pub fn new(
        gl: &Arc<Gl>,
        shaders: &ShaderSource,
        scene: &Scene,
        w: u32,
        h: u32,
    ) -> Result<GBuffer> {
        let raster = raster_kernel(gl, shaders)?;
        let (vao, vbos) = upload_vertices(gl, scene)?;
        let (fbo, depth, textures) = framebuffer(gl, w, h)?;
        Ok(GBuffer {
            gl: gl.clone(),
            raster,
            fbo,
            vao,
            _vbos: vbos,
            _depth: depth,
            textures,
            triangles: scene.triangle_count() as i32,
            width: w,
            height: h,
        })
    }

    /// Replace the program (the viewer's live reload).
    pub fn set_kernel(&mut self, raster: Kernel) {
        self.raster = raster;
    }

    /// Rasterise the scene with `view_projection` seen from `eye`.
    pub fn draw(
        &self,
        timers: &mut GpuTimers,
        view_projection: &Mat4,
        eye: Vec3,
        background: [f32; 3],
    ) {
        let gl = &self.gl;
        let (w, h) = (self.width as i32, self.height as i32);
        let bg = background;
        self.raster.use_program();
        self.raster
            .set_mat4("viewProjection", &view_projection.to_cols_array());
        self.raster.set_vec3("cameraPosition", eye.to_array());
        // clearing and rendering into the diffuse texture the last shadow pass stored into
        crate::gl::sync::before(gl, glow::FRAMEBUFFER_BARRIER_BIT | crate::gl::sync::SHADER);
        timers.time(gl, "gbuffer", || {
            // SAFETY: drawing with our program, VAO and FBO.
            unsafe {
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo.raw()));
                gl.viewport(0, 0, w, h);
                gl.enable(glow::DEPTH_TEST);
                gl.depth_func(glow::LESS);
                gl.clear_buffer_f32_slice(glow::COLOR, 0, &[0.0; 4]);
                gl.clear_buffer_f32_slice(glow::COLOR, 1, &[0.0, 0.0, 0.0, -1.0]);
                gl.clear_buffer_f32_slice(glow::COLOR, 2, &[bg[0], bg[1], bg[2], 0.0]);
                gl.clear_buffer_f32_slice(glow::DEPTH, 0, &[1.0]);
                gl.bind_vertex_array(Some(self.vao.raw()));
                gl.draw_arrays(glow::TRIANGLES, 0, 3 * self.triangles);
                gl.bind_vertex_array(None);
                gl.disable(glow::DEPTH_TEST);
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            }
        });
        crate::gl::sync::after_pass(gl);
    }

    /// The position (w: 1 = geometry), normal (w: triangle id) and diffuse (RGBA32F)
    /// textures.
    pub fn textures(&self) -> [glow::Texture; 3] {
        self.textures.each_ref().map(Owned::raw)
    }

    /// Texture `i` (0 position, 1 normal, 2 diffuse) read back, GL row order.
    pub fn read(&self, i: usize) -> Vec<[f32; 4]> {
        read_texture_rgba32f(&self.gl, self.textures[i].raw(), self.width, self.height)
    }
}
