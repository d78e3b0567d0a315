//! The viewer's state: its command line, what runs while the window is open, the input held
//! between events, and the application the event loop drives (its methods in `view/mod.rs`,
//! its keys in `keys.rs`). Below the parts that read it.

use std::path::PathBuf;

use anyhow::Result;
use glow::HasContext;
use winit::keyboard::ModifiersState;

use super::design::Design;
use super::frames::{Clock, FrameCount, Picture};
use super::renderer::Renderers;
use super::watch::GlslWatcher;
use super::window::{fit_viewport, GlWindow, ScreenQuad, Viewport};
use crate::args::DesignArgs;
use gpgpu_rt::gl::ShaderSource;
use gpgpu_rt::limits;
use gpgpu_rt::scene::{Camera, Scene};

/// Options of `gpgpu-rt view`.
#[derive(clap::Args, Debug, Clone)]
pub struct ViewArgs {
    /// Scene file: TOML (e.g. scenes/teapot1.toml) or glTF 2.0 (.gltf, .glb).
    pub scene: PathBuf,
    /// No progress line while the scene loads and the first tracer is built (one appears on a
    /// terminal when that takes more than 2 s).
    #[arg(long)]
    pub quiet: bool,
    /// Render width in pixels, 1 to 16384 (default: the scene's render.width); the window
    /// opens at this size.
    #[arg(long, value_parser = limits::parser(limits::IMAGE_SIDE))]
    pub width: Option<u32>,
    /// Render height in pixels, 1 to 16384 (default: the scene's render.height).
    #[arg(long, value_parser = limits::parser(limits::IMAGE_SIDE))]
    pub height: Option<u32>,
    /// The design to start with and the options of every design, as for `render` (T switches
    /// the tracer, B the BVH variant; G / shift+G / A change the grid's resolution, V its
    /// variant; S cycles the soft shadows' mode, L / shift+L their samples).
    #[command(flatten)]
    pub design: DesignArgs,
    /// Load the kernels from this directory and reload them whenever a file in it changes.
    #[arg(long, value_name = "DIR")]
    pub glsl_dir: Option<PathBuf>,
    /// Save the window's last frame (see --frames) to this image and exit: PNG, or JPEG for a
    /// name ending in .jpg or .jpeg (as `render -o`).
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<PathBuf>,
    /// Render N frames (1 to 100000), then exit (after saving --screenshot); default with
    /// --screenshot: 1.
    #[arg(long, value_name = "N", value_parser = limits::parser(limits::FRAMES))]
    pub frames: Option<u32>,
    /// With --glsl-dir: count --frames only from the first successful reload of an edited
    /// kernel (capture the effect of an edit from a script).
    #[arg(long)]
    pub wait_reload: bool,
    /// Print one line per frame (GPU ms per kernel, triangle tests) to stdout.
    #[arg(long)]
    pub log_frames: bool,
}

/// What runs while the window is open. Field order is drop order: GL objects before the window.
pub(super) struct Running {
    pub(super) renderers: Renderers,
    pub(super) quad: ScreenQuad,
    pub(super) watcher: Option<GlslWatcher>,
    pub(super) window: GlWindow,
}

impl Running {
    /// Show `texture` (the last frame, if any) in the window, letterboxed to the `image` size:
    /// the viewport it fills.
    pub(super) fn present(&self, texture: Option<glow::Texture>, image: (u32, u32)) -> Viewport {
        let size = self.window.size();
        let viewport = fit_viewport(size, image);
        if let Some(texture) = texture {
            // SAFETY: drawing to the window's default framebuffer.
            unsafe { self.window.gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
            self.quad.draw(texture, size, viewport);
        }
        viewport
    }
}

#[derive(Default)]
pub(super) struct Input {
    pub(super) modifiers: ModifiersState,
    pub(super) cursor: Option<(f64, f64)>,
    pub(super) orbiting: bool,
    pub(super) panning: bool,
}

pub(super) struct App {
    pub(super) args: ViewArgs,
    pub(super) scene: Scene,
    pub(super) shaders: ShaderSource,
    /// The design shown and its options.
    pub(super) design: Design,
    pub(super) camera: Camera,
    pub(super) running: Option<Running>,
    pub(super) result: Result<()>,
    pub(super) input: Input,
    pub(super) picture: Picture,
    pub(super) frames: FrameCount,
    pub(super) clock: Clock,
    /// An error or notice shown in the title until the next success.
    pub(super) notice: Option<String>,
    /// Screenshots saved with P.
    pub(super) screenshots: u32,
}
