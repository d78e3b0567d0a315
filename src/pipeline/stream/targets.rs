//! The textures the streaming kernels read and render into, the framebuffer objects that bind
//! them as multiple render targets, and the viewport-sized quad every kernel is drawn with
//! (the streaming tracer, ch. 3: "Redirecting the results of a fragment program to framebuffer
//! attachable images is called using multiple render targets").

use std::sync::Arc;

use anyhow::{anyhow, bail, Result};
use glow::HasContext;

use crate::gl::resources::{depth_renderbuffer, GpuTimers, Image2d, Owned};
use crate::gl::slots::sampler;
use crate::gl::{Gl, Kernel};

/// One set of Fig. 2's traversal state: tMax + ray state, cell + triangles processed, hit.
pub struct StateSet {
    pub tmax: Image2d,
    pub cell: Image2d,
    pub hit: Image2d,
}

/// A pair of ray textures (origin, direction) of Fig. 1.
pub struct Rays {
    pub origin: Image2d,
    pub direction: Image2d,
}

pub struct Targets {
    pub width: u32,
    pub height: u32,
    /// eye and reflection rays, ping-ponged between bounces
    pub rays: [Rays; 2],
    pub shadow: Rays,
    /// the two state sets, ping-ponged between traverse calls
    pub state: [StateSet; 2],
    /// the eye or reflection ray's hit record (hit_record.frag)
    pub hit: Image2d,
    /// the colour, accumulated by blending (rgb, 1)
    pub color: Image2d,
    /// for the AOVs (`--aov-dir`, tests)
    pub primary: Option<AovTargets>,
    /// held for the FBOs it is attached to
    _depth: Owned<glow::Renderbuffer>,
    vao: Owned<glow::VertexArray>,
    pub fbo: Framebuffers,
}

/// What the AOVs read: the primary rays and their hit records, kept from the first bounce, and
/// one shadow ray's hit record with the FBO the hit-record kernel copies it into.
pub struct AovTargets {
    pub rays: Rays,
    pub hit: Image2d,
    pub shadow_hit: Image2d,
    pub shadow_fbo: Owned<glow::Framebuffer>,
}

/// The render-target sets.
pub struct Framebuffers {
    pub rays: [Owned<glow::Framebuffer>; 2],
    pub shadow: Owned<glow::Framebuffer>,
    pub state: [Owned<glow::Framebuffer>; 2],
    pub depth_only: Owned<glow::Framebuffer>,
    pub hit: Owned<glow::Framebuffer>,
    pub color: Owned<glow::Framebuffer>,
}

/// An FBO with `colors` as draw buffers 0.. and, if given, the depth renderbuffer.
fn framebuffer(
    gl: &Arc<Gl>,
    colors: &[&Image2d],
    depth: Option<glow::Renderbuffer>,
) -> Result<Owned<glow::Framebuffer>> {
    // SAFETY: FBO set-up with our own textures on a current context.
    unsafe {
        let fbo = Owned::new(gl, gl.create_framebuffer().map_err(|e| anyhow!(e))?);
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo.raw()));
        let mut buffers = Vec::new();
        for (i, t) in colors.iter().enumerate() {
            let attachment = glow::COLOR_ATTACHMENT0 + i as u32;
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                attachment,
                glow::TEXTURE_2D,
                Some(t.texture.raw()),
                0,
            );
            buffers.push(attachment);
        }
        if let Some(d) = depth {
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::RENDERBUFFER,
                Some(d),
            );
        }
        if buffers.is_empty() {
            gl.draw_buffer(glow::NONE);
        } else {
            gl.draw_buffers(&buffers);
        }
        let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        if status != glow::FRAMEBUFFER_COMPLETE {
            bail!("a framebuffer of the streaming tracer is incomplete (status {status:#x})");
        }
        Ok(fbo)
    }
}

fn rgba(gl: &Arc<Gl>, w: u32, h: u32) -> Result<Image2d> {
    Image2d::new(gl, w, h, glow::RGBA32F)
}

fn rays(gl: &Arc<Gl>, w: u32, h: u32) -> Result<Rays> {
    Ok(Rays {
        origin: rgba(gl, w, h)?,
        direction: rgba(gl, w, h)?,
    })
}

fn state_set(gl: &Arc<Gl>, w: u32, h: u32) -> Result<StateSet> {
    Ok(StateSet {
        tmax: rgba(gl, w, h)?,
        cell: rgba(gl, w, h)?,
        hit: rgba(gl, w, h)?,
    })
}

impl Targets {
    pub fn new(gl: &Arc<Gl>, w: u32, h: u32, aovs: bool) -> Result<Targets> {
        let ray_pair = [rays(gl, w, h)?, rays(gl, w, h)?];
        let shadow = rays(gl, w, h)?;
        let state = [state_set(gl, w, h)?, state_set(gl, w, h)?];
        let (hit, color) = (rgba(gl, w, h)?, rgba(gl, w, h)?);
        let depth = depth_renderbuffer(gl, w, h)?;
        // SAFETY: VAO creation on a current context.
        let vao = unsafe {
            let vao = gl.create_vertex_array().map_err(|e| anyhow!(e))?;
            Owned::new(gl, vao)
        };
        let set = |s: &StateSet| framebuffer(gl, &[&s.tmax, &s.cell, &s.hit], Some(depth.raw()));
        let pair = |r: &Rays| framebuffer(gl, &[&r.origin, &r.direction], None);
        let fbo = Framebuffers {
            rays: [pair(&ray_pair[0])?, pair(&ray_pair[1])?],
            shadow: pair(&shadow)?,
            state: [set(&state[0])?, set(&state[1])?],
            depth_only: framebuffer(gl, &[], Some(depth.raw()))?,
            hit: framebuffer(gl, &[&hit], None)?,
            color: framebuffer(gl, &[&color], None)?,
        };
        let primary = if aovs {
            let shadow_hit = rgba(gl, w, h)?;
            Some(AovTargets {
                rays: rays(gl, w, h)?,
                hit: rgba(gl, w, h)?,
                shadow_fbo: framebuffer(gl, &[&shadow_hit], None)?,
                shadow_hit,
            })
        } else {
            None
        };
        Ok(Targets {
            width: w,
            height: h,
            rays: ray_pair,
            shadow,
            state,
            hit,
            color,
            primary,
            _depth: depth,
            vao,
            fbo,
        })
    }

    /// Draw the viewport-sized quad with `kernel` (in use, its textures bound) into `fbo`,
    /// timed under the kernel's name.
    /// Its fragment shaders read textures and images and add to the counters (atomics): every
    /// bit before it (gl::sync).
    pub fn draw(&self, gl: &Gl, timers: &mut GpuTimers, kernel: &Kernel, fbo: glow::Framebuffer) {
        crate::gl::sync::barrier(gl);
        timers.time(gl, kernel.timer(), || {
            // SAFETY: drawing four vertices with our program, VAO and FBO.
            unsafe {
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
                gl.viewport(0, 0, self.width as i32, self.height as i32);
                gl.bind_vertex_array(Some(self.vao.raw()));
                gl.draw_arrays(glow::TRIANGLE_STRIP, 0, 4);
                gl.bind_vertex_array(None);
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            }
        });
        crate::gl::sync::after_pass(gl);
    }

    /// Ray textures by number: 0 and 1 the eye or reflection rays, 2 the shadow rays.
    pub fn ray_set(&self, i: usize) -> &Rays {
        if i == 2 {
            &self.shadow
        } else {
            &self.rays[i]
        }
    }

    /// Bind `rays` as the ray textures the next kernel reads.
    pub fn bind_rays(&self, gl: &Gl, rays: &Rays) {
        bind_2d(gl, sampler::STREAM_RAY_ORIGIN, &rays.origin);
        bind_2d(gl, sampler::STREAM_RAY_DIR, &rays.direction);
        bind_2d(gl, sampler::STREAM_HIT, &self.hit);
    }

    /// Bind state set `read` as the one a traverse call reads, and both sets' ray states and
    /// hit records.
    pub fn bind_state(&self, gl: &Gl, read: usize) {
        let s = &self.state[read];
        bind_2d(gl, sampler::STREAM_READ_TMAX, &s.tmax);
        bind_2d(gl, sampler::STREAM_READ_CELL, &s.cell);
        bind_2d(gl, sampler::STREAM_READ_HIT, &s.hit);
        bind_2d(gl, sampler::STREAM_STATE_A, &self.state[0].tmax);
        bind_2d(gl, sampler::STREAM_STATE_B, &self.state[1].tmax);
        bind_2d(gl, sampler::STREAM_HIT_A, &self.state[0].hit);
        bind_2d(gl, sampler::STREAM_HIT_B, &self.state[1].hit);
    }

    /// Unbind every texture unit of the streaming kernels (a texture bound for reading while
    /// it is a render target would be a feedback loop).
    pub fn unbind(&self, gl: &Gl) {
        for unit in sampler::STREAM_RAY_ORIGIN..=sampler::STREAM_HIT_B {
            if unit == sampler::STREAM_REFS || unit == sampler::STREAM_CELLS {
                continue;
            }
            // SAFETY: unbinding texture units.
            unsafe {
                gl.active_texture(glow::TEXTURE0 + unit);
                gl.bind_texture(glow::TEXTURE_2D, None);
            }
        }
        // SAFETY: restoring the default unit.
        unsafe { gl.active_texture(glow::TEXTURE0) };
    }
}

/// Bind a 2D texture to texture unit `unit`.
fn bind_2d(gl: &Gl, unit: u32, image: &Image2d) {
    // SAFETY: binding our own texture to a texture unit.
    unsafe {
        gl.active_texture(glow::TEXTURE0 + unit);
        gl.bind_texture(glow::TEXTURE_2D, Some(image.texture.raw()));
        gl.active_texture(glow::TEXTURE0);
    }
}
