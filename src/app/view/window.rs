//! The viewer's window and the screen-filling quad (Müller 2015, ch. 3.1.3).
//!
//! A winit window with a GL 4.5 core context from glutin (GLX, or EGL where GLX is missing),
//! and the small raster pass that shows a tracer's output texture: a fragment shader samples
//! the texture through a 2D sampler and textures a quad that fills the viewport.

use std::num::NonZeroU32;
use std::sync::Arc;

use anyhow::{anyhow, Result};
use glow::HasContext;
use glutin::config::{ColorBufferType, Config, ConfigTemplateBuilder};
use glutin::context::{
    ContextApi, ContextAttributesBuilder, GlProfile, PossiblyCurrentContext, Version,
};
use glutin::display::GetGlDisplay;
use glutin::prelude::*;
use glutin::surface::{Surface, SurfaceAttributesBuilder, SwapInterval, WindowSurface};
use glutin_winit::{ApiPreference, DisplayBuilder, GlWindow as _};
use raw_window_handle::{HasWindowHandle, RawWindowHandle};
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

use gpgpu_rt::gl::context::{load_gl, query_info};
use gpgpu_rt::gl::resources::Owned;
use gpgpu_rt::gl::{compile_program, Defines, Gl, GlInfo, ShaderSource};
use gpgpu_rt::output;

/// A window with a current GL 4.5 core context. Drop GL objects made on `gl` first.
pub struct GlWindow {
    pub gl: Arc<Gl>,
    pub info: GlInfo,
    // field order is drop order: the surface before the context, both before the window
    surface: Surface<WindowSurface>,
    context: PossiblyCurrentContext,
    pub window: Window,
}

/// Prefer plain 8-bit RGB configs without multisampling (the screenshot reads the window's
/// pixels back and must not see resolved or converted colours).
fn config_rank(c: &Config) -> (u32, u8, bool) {
    let deep = match c.color_buffer_type() {
        Some(ColorBufferType::Rgb {
            r_size,
            g_size,
            b_size,
        }) => [r_size, g_size, b_size]
            .iter()
            .map(|s| s.abs_diff(8) as u32)
            .sum(),
        _ => u32::MAX,
    };
    (deep, c.num_samples(), c.srgb_capable())
}

/// Open a `width`×`height` window with the best GL config for it (see [`config_rank`]).
fn open_window(
    event_loop: &ActiveEventLoop,
    title: &str,
    width: u32,
    height: u32,
) -> Result<(Window, Config)> {
    let attributes = Window::default_attributes()
        .with_title(title)
        .with_inner_size(PhysicalSize::new(width, height))
        .with_resizable(true);
    // EGL first (the same Mesa path as headless rendering, whose GL timer queries time the
    // compute kernels), GLX where EGL is missing
    let (window, config) = DisplayBuilder::new()
        .with_preference(ApiPreference::PreferEgl)
        .with_window_attributes(Some(attributes))
        .build(event_loop, ConfigTemplateBuilder::new(), |configs| {
            configs
                .min_by_key(config_rank)
                .expect("glutin offers at least one config")
        })
        .map_err(|e| anyhow!("cannot open a window with an OpenGL config: {}", plain(&e)))?;
    let window = window.ok_or_else(|| anyhow!("the window system gave no window"))?;
    Ok((window, config))
}

/// The window's GL surface (plain, not sRGB); a window of zero size gets the requested size
/// until the first resize.
fn window_surface(
    window: &Window,
    handle: RawWindowHandle,
    config: &Config,
    (width, height): (u32, u32),
) -> Result<Surface<WindowSurface>> {
    let size = window.inner_size();
    let surface_attributes = window
        .build_surface_attributes(SurfaceAttributesBuilder::new().with_srgb(Some(false)))
        .or_else(|_| {
            Ok::<_, anyhow::Error>(SurfaceAttributesBuilder::<WindowSurface>::new().build(
                handle,
                NonZeroU32::new(size.width.max(width).max(1)).unwrap(),
                NonZeroU32::new(size.height.max(height).max(1)).unwrap(),
            ))
        })?;
    // SAFETY: the attributes name this window; the config is the display's.
    unsafe {
        config
            .display()
            .create_window_surface(config, &surface_attributes)
    }
    .map_err(|e| anyhow!("cannot create a GL surface for the window: {}", plain(&e)))
}

impl GlWindow {
    /// Open a `width`×`height` window (physical pixels) with a GL 4.5 core context current.
    pub fn new(
        event_loop: &ActiveEventLoop,
        title: &str,
        width: u32,
        height: u32,
    ) -> Result<GlWindow> {
        let (window, config) = open_window(event_loop, title, width, height)?;
        let handle = window
            .window_handle()
            .map_err(|e| anyhow!("no native window handle: {}", plain(&e)))?
            .as_raw();
        let display = config.display();
        let attributes = ContextAttributesBuilder::new()
            .with_context_api(ContextApi::OpenGl(Some(Version::new(4, 5))))
            .with_profile(GlProfile::Core)
            .with_debug(gpgpu_rt::gl::context::gl_debug_requested())
            .build(Some(handle));
        // SAFETY: the config belongs to this display; the handle is the window's.
        let context = unsafe { display.create_context(&config, &attributes) }.map_err(|e| {
            anyhow!(
                "cannot create an OpenGL 4.5 core context for the window: {}",
                plain(&e)
            )
        })?;
        let surface = window_surface(&window, handle, &config, (width, height))?;
        let context = context
            .make_current(&surface)
            .map_err(|e| anyhow!("cannot make the window's GL context current: {}", plain(&e)))?;
        // No vsync: the viewer measures frames per second of the tracer, not of the display.
        if let Err(e) = surface.set_swap_interval(&context, SwapInterval::DontWait) {
            log::info!("cannot turn vsync off: {}", plain(&e));
        }
        // SAFETY: the context is current; symbols come from its display.
        let gl = unsafe {
            load_gl(
                |name| display.get_proc_address(name),
                "the window's context",
            )
        }?;
        let choice = gpgpu_rt::gl::ProfileChoice::from_env()?;
        let info = query_info(
            &gl,
            0,
            &format!("window ({})", display.version_string()),
            choice,
        );
        // SAFETY: state changes on the current context: colours reach the window unchanged.
        unsafe {
            gl.disable(glow::FRAMEBUFFER_SRGB);
            gl.disable(glow::DITHER);
            gl.disable(glow::BLEND);
            gl.disable(glow::DEPTH_TEST);
            gl.disable(glow::MULTISAMPLE);
        }
        Ok(GlWindow {
            gl: Arc::new(gl),
            info,
            surface,
            context,
            window,
        })
    }

    /// The drawable size in pixels.
    pub fn size(&self) -> (u32, u32) {
        let s = self.window.inner_size();
        (s.width, s.height)
    }

    /// Follow a window resize.
    pub fn resize(&self) {
        self.window.resize_surface(&self.surface, &self.context);
    }

    /// Before the tracer's kernels: with EGL, make the context current without a surface, as
    /// headless rendering does. With the window's framebuffer bound, Mesa's llvmpipe defers
    /// GL timestamp queries to the next raster flush, so every kernel would measure 0 ms.
    pub fn begin_compute(&self) {
        #[allow(irrefutable_let_patterns)]
        if let PossiblyCurrentContext::Egl(c) = &self.context {
            if let Err(e) = c.make_current_surfaceless() {
                log::info!(
                    "cannot make the context current without a surface: {}",
                    plain(&e)
                );
            }
        }
    }

    /// Before drawing to the window: its surface current again.
    pub fn begin_present(&self) -> Result<()> {
        self.context
            .make_current(&self.surface)
            .map_err(|e| anyhow!("cannot make the window's GL context current: {}", plain(&e)))
    }

    pub fn swap(&self) -> Result<()> {
        self.surface
            .swap_buffers(&self.context)
            .map_err(|e| anyhow!("swapping the window's buffers failed: {}", plain(&e)))
    }
}

/// The screen-filling quad's program (`glsl/common/screen_quad.vert` + `.frag`), from `source` when it
/// has them, else from the copies built into the binary (a `--glsl-dir` made before the viewer
/// existed lacks them).
pub fn compile_quad_program(gl: &Arc<Gl>, source: &ShaderSource) -> Result<Owned<glow::Program>> {
    let has_own = source
        .dir
        .as_ref()
        .map(|d| {
            d.join("common/screen_quad.vert").is_file()
                && d.join("common/screen_quad.frag").is_file()
        })
        .unwrap_or(true);
    let embedded = ShaderSource::default();
    let source = if has_own { source } else { &embedded };
    compile_program(
        gl,
        source,
        &[
            (glow::VERTEX_SHADER, "common/screen_quad.vert"),
            (glow::FRAGMENT_SHADER, "common/screen_quad.frag"),
        ],
        &Defines::new(),
    )
}

/// A viewport rectangle in window pixels, origin bottom left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Viewport {
    pub x: i32,
    pub y: i32,
    pub width: u32,
    pub height: u32,
}

/// The largest rectangle of the image's aspect ratio centred in the window (letterboxing); at
/// the image's own size, the whole window.
pub fn fit_viewport(window: (u32, u32), image: (u32, u32)) -> Viewport {
    let (ww, wh) = (window.0.max(1) as f64, window.1.max(1) as f64);
    let (iw, ih) = (image.0.max(1) as f64, image.1.max(1) as f64);
    let scale = (ww / iw).min(wh / ih);
    let width = ((iw * scale).round() as u32).clamp(1, window.0.max(1));
    let height = ((ih * scale).round() as u32).clamp(1, window.1.max(1));
    Viewport {
        x: ((window.0.max(1) - width) / 2) as i32,
        y: ((window.1.max(1) - height) / 2) as i32,
        width,
        height,
    }
}

/// The screen-filling quad: its vertex positions in a VBO (the thesis keeps them in the scene
/// object, ch. 3.3) and the program that textures it with the output texture.
pub struct ScreenQuad {
    gl: Arc<Gl>,
    program: Owned<glow::Program>,
    vao: Owned<glow::VertexArray>,
    // held for the VAO, which reads it
    _vbo: Owned<glow::Buffer>,
}

impl ScreenQuad {
    pub fn new(gl: Arc<Gl>, program: Owned<glow::Program>) -> Result<ScreenQuad> {
        // a triangle strip covering clip space
        let positions: [f32; 8] = [-1.0, -1.0, 1.0, -1.0, -1.0, 1.0, 1.0, 1.0];
        // SAFETY: object creation and vertex setup on the current context.
        unsafe {
            let vao = Owned::new(&gl, gl.create_vertex_array().map_err(|e| anyhow!(e))?);
            let vbo = Owned::new(&gl, gl.create_buffer().map_err(|e| anyhow!(e))?);
            gl.bind_vertex_array(Some(vao.raw()));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo.raw()));
            gl.buffer_data_u8_slice(
                glow::ARRAY_BUFFER,
                bytemuck::cast_slice(&positions),
                glow::STATIC_DRAW,
            );
            gl.enable_vertex_attrib_array(0);
            gl.vertex_attrib_pointer_f32(0, 2, glow::FLOAT, false, 8, 0);
            gl.bind_vertex_array(None);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
            Ok(ScreenQuad {
                gl,
                program,
                vao,
                _vbo: vbo,
            })
        }
    }

    /// Replace the program (after a live reload); the old one is deleted.
    pub fn set_program(&mut self, program: Owned<glow::Program>) {
        self.program = program;
    }

    /// Clear the bound draw framebuffer (`size`: its size) to the letterbox colour and draw
    /// `texture` into `viewport`.
    pub fn draw(&self, texture: glow::Texture, size: (u32, u32), viewport: Viewport) {
        let gl = &self.gl;
        // sampling the output texture the kernels stored into (gl::sync)
        gpgpu_rt::gl::sync::before(gl, glow::TEXTURE_FETCH_BARRIER_BIT);
        // SAFETY: drawing with our own objects on the current context.
        unsafe {
            gl.viewport(0, 0, size.0 as i32, size.1 as i32);
            gl.clear_color(0.08, 0.08, 0.08, 1.0);
            gl.clear(glow::COLOR_BUFFER_BIT);
            gl.viewport(
                viewport.x,
                viewport.y,
                viewport.width as i32,
                viewport.height as i32,
            );
            gl.use_program(Some(self.program.raw()));
            gl.active_texture(glow::TEXTURE0);
            gl.bind_texture(glow::TEXTURE_2D, Some(texture));
            gl.bind_vertex_array(Some(self.vao.raw()));
            gl.draw_arrays(glow::TRIANGLE_STRIP, 0, 4);
            gl.bind_vertex_array(None);
            gl.bind_texture(glow::TEXTURE_2D, None);
            gl.use_program(None);
        }
        // its texture fetches: a later kernel's stores into the texture wait for them (gl::sync)
        gpgpu_rt::gl::sync::after_pass(gl);
    }

    /// Draw `texture` at `width`×`height` into an offscreen RGBA8 framebuffer and read it back
    /// (for a screenshot when the window is not the image's size), rows bottom first.
    pub fn draw_offscreen(
        &self,
        texture: glow::Texture,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>> {
        let gl = &self.gl;
        // SAFETY: a framebuffer of our own, deleted as it drops (at the return).
        unsafe {
            let fbo = Owned::new(gl, gl.create_framebuffer().map_err(|e| anyhow!(e))?);
            let rb = Owned::new(gl, gl.create_renderbuffer().map_err(|e| anyhow!(e))?);
            let (fbo, rb) = (fbo.raw(), rb.raw());
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
            gl.renderbuffer_storage(glow::RENDERBUFFER, glow::RGBA8, width as i32, height as i32);
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::RENDERBUFFER,
                Some(rb),
            );
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            let result = if status == glow::FRAMEBUFFER_COMPLETE {
                let full = Viewport {
                    x: 0,
                    y: 0,
                    width,
                    height,
                };
                self.draw(texture, (width, height), full);
                gl.read_buffer(glow::COLOR_ATTACHMENT0);
                Ok(read_pixels(gl, full))
            } else {
                Err(anyhow!("offscreen framebuffer incomplete (0x{status:x})"))
            };
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            result
        }
    }
}

/// Read RGBA8 pixels of `rect` from the bound read framebuffer, rows bottom first.
pub fn read_pixels(gl: &Gl, rect: Viewport) -> Vec<u8> {
    let mut pixels = vec![0u8; rect.width as usize * rect.height as usize * 4];
    // SAFETY: the slice holds width·height RGBA8 pixels with pack alignment 1.
    unsafe {
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
        gl.read_pixels(
            rect.x,
            rect.y,
            rect.width as i32,
            rect.height as i32,
            glow::RGBA,
            glow::UNSIGNED_BYTE,
            glow::PixelPackData::Slice(Some(&mut pixels)),
        );
    }
    pixels
}

/// Read the window's back buffer (what the next swap shows) in `rect`, rows bottom first.
pub fn read_back_buffer(gl: &Gl, rect: Viewport) -> Vec<u8> {
    // SAFETY: selecting the default framebuffer's back buffer for reading.
    unsafe {
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
        gl.read_buffer(glow::BACK);
    }
    read_pixels(gl, rect)
}

/// Save RGBA8 pixels (rows bottom first, as GL reads them) as an RGB image (PNG, or JPEG by the
/// extension), top row first, replacing `path` only when complete.
pub fn save_image(path: &std::path::Path, width: u32, height: u32, pixels: &[u8]) -> Result<()> {
    let img = image::RgbImage::from_fn(width, height, |x, y| {
        let i = (((height - 1 - y) * width + x) * 4) as usize;
        image::Rgb([pixels[i], pixels[i + 1], pixels[i + 2]])
    });
    output::write_file(path, |w| output::encode_image(&img, path, w))
}

/// A window-system library's error without the source location it may carry (winit's
/// `OsError` prints `os error at /…/winit-0.30.13/src/platform_impl/linux/mod.rs:765: …`): a
/// user's message names what failed, not a dependency's source file.
pub fn plain(e: &dyn std::fmt::Display) -> String {
    let msg = e.to_string();
    let mut out = String::new();
    let mut rest = msg.as_str();
    while let Some(i) = rest.find(".rs:") {
        let digits = rest[i + 4..].bytes().take_while(u8::is_ascii_digit).count();
        if digits == 0 {
            out.push_str(&rest[..i + 4]);
            rest = &rest[i + 4..];
            continue;
        }
        let start = rest[..i].rfind(char::is_whitespace).map_or(0, |k| k + 1);
        let before = rest[..start].trim_end();
        out.push_str(before.strip_suffix(" at").unwrap_or(before));
        rest = &rest[i + 4 + digits..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn source_locations_are_dropped() {
        let m = "os error at /root/.cargo/registry/src/x/winit-0.30.13/src/platform_impl/linux/mod.rs:765: no DISPLAY";
        assert_eq!(plain(&m), "os error: no DISPLAY");
        assert_eq!(plain(&"a file.rs: fine"), "a file.rs: fine");
    }

    #[test]
    fn viewport_fills_a_window_of_the_image_size_and_letterboxes_otherwise() {
        let full = fit_viewport((96, 96), (96, 96));
        assert_eq!(
            full,
            Viewport {
                x: 0,
                y: 0,
                width: 96,
                height: 96
            }
        );
        let wide = fit_viewport((300, 100), (100, 100));
        assert_eq!(
            wide,
            Viewport {
                x: 100,
                y: 0,
                width: 100,
                height: 100
            }
        );
        let tall = fit_viewport((200, 500), (400, 200));
        assert_eq!(
            tall,
            Viewport {
                x: 0,
                y: 200,
                width: 200,
                height: 100
            }
        );
        // a minimized window: still a valid (1-pixel) viewport
        let tiny = fit_viewport((0, 0), (64, 64));
        assert_eq!((tiny.width, tiny.height), (1, 1));
    }
}
