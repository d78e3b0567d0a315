//! Phase 3 of Klee 2016's pipeline (Fig. 7): the shaded diffuse texture drawn by a
//! screen-filling quad (`glsl/klee2016/linespace_quad.*`, one triangle that covers the
//! viewport) into the output texture — headless, an FBO read back into the PNG; in the viewer,
//! the texture it shows.

use std::sync::Arc;

use anyhow::{anyhow, bail, Result};
use glow::HasContext;

use super::gbuffer::rgba32f_texture;
use crate::gl::resources::{GpuTimers, Owned};
use crate::gl::slots::sampler;
use crate::gl::{Defines, Gl, Kernel, ShaderSource};

pub struct Present {
    gl: Arc<Gl>,
    quad: Kernel,
    vao: Owned<glow::VertexArray>,
    // before the texture attached to it: it drops first
    fbo: Owned<glow::Framebuffer>,
    output: Owned<glow::Texture>,
    width: u32,
    height: u32,
}

/// The screen-filling quad's program.
pub fn quad_kernel(gl: &Arc<Gl>, shaders: &ShaderSource) -> Result<Kernel> {
    Kernel::program(
        gl,
        shaders,
        &[
            (glow::VERTEX_SHADER, "klee2016/linespace_quad.vert"),
            (glow::FRAGMENT_SHADER, "klee2016/linespace_quad.frag"),
        ],
        &Defines::new(),
        "present",
    )
}

impl Present {
    pub fn new(gl: &Arc<Gl>, shaders: &ShaderSource, w: u32, h: u32) -> Result<Present> {
        let quad = quad_kernel(gl, shaders)?;
        let output = rgba32f_texture(gl, w, h)?;
        // SAFETY: FBO and VAO creation on a current context.
        unsafe {
            let fbo = Owned::new(gl, gl.create_framebuffer().map_err(|e| anyhow!(e))?);
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo.raw()));
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(output.raw()),
                0,
            );
            let complete =
                gl.check_framebuffer_status(glow::FRAMEBUFFER) == glow::FRAMEBUFFER_COMPLETE;
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            if !complete {
                bail!("the output FBO is incomplete");
            }
            let vao = Owned::new(gl, gl.create_vertex_array().map_err(|e| anyhow!(e))?);
            Ok(Present {
                gl: gl.clone(),
                quad,
                vao,
                fbo,
                output,
                width: w,
                height: h,
            })
        }
    }

    /// The output texture.
    pub fn output(&self) -> glow::Texture {
        self.output.raw()
    }

    /// Replace the program (the viewer's live reload).
    pub fn set_kernel(&mut self, quad: Kernel) {
        self.quad = quad;
    }

    /// Draw `color` through the quad into the output texture.
    pub fn draw(&self, timers: &mut GpuTimers, color: glow::Texture) {
        let gl = &self.gl;
        self.quad.use_program();
        // sampling what the shadow pass stored
        crate::gl::sync::before(gl, glow::TEXTURE_FETCH_BARRIER_BIT);
        timers.time(gl, self.quad.timer(), || {
            // SAFETY: drawing the quad with our program into our FBO.
            unsafe {
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo.raw()));
                gl.viewport(0, 0, self.width as i32, self.height as i32);
                gl.active_texture(glow::TEXTURE0 + sampler::QUAD_COLOR);
                gl.bind_texture(glow::TEXTURE_2D, Some(color));
                gl.bind_vertex_array(Some(self.vao.raw()));
                gl.draw_arrays(glow::TRIANGLES, 0, 3);
                gl.bind_vertex_array(None);
                gl.bind_texture(glow::TEXTURE_2D, None);
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            }
        });
        crate::gl::sync::after_pass(gl);
    }
}
