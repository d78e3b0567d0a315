//! `gpgpu-rt view`: the thesis' interactive window (Müller 2015, ch. 3.1.3 and 3.3).
//!
//! Every frame the tracer renders the scene from the current camera into its output texture
//! (the camera change reaches the kernels as uniforms, the thesis' `passCameraUpdates()`), and
//! a screen-filling quad shows the texture in the window. Mouse and keys move the camera and
//! switch tracer, grid variant, grid resolution and reflection depth; the title bar shows
//! frames per second, GPU milliseconds per kernel and triangle tests. With `--glsl-dir` the
//! kernels are live: saving a kernel file rebuilds the tracer from the edited sources, and a
//! compile error is shown with file and line while the last good program keeps running.

pub mod orbit;
pub mod watch;
pub mod window;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};
use clap::ValueEnum;
use glow::HasContext;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::WindowId;

use crate::gl::ShaderSource;
use crate::scene::{Camera, Scene};
use crate::tracer::{
    self, FrameStats, GridVariant, RenderOptions, ShadowFlags, Tracer, TracerKind,
};

use watch::GlslWatcher;
use window::{
    compile_quad_program, fit_viewport, read_back_buffer, save_png, GlWindow, ScreenQuad, Viewport,
};

/// The controls, printed by `H` and listed in the README.
pub const CONTROLS: &str = "\
mouse: left drag orbit | right/middle drag or shift+left drag pan | wheel zoom
keys:  arrows orbit (shift: pan) | + - zoom | C or Home reset camera
       T / shift+T next / previous tracer | V next grid variant
       G / shift+G grid resolution +4 / -4 | A grid resolution auto
       ] / [ reflection depth +1 / -1
       R or F5 reload kernels | P save a screenshot | space pause | H help | Q or Esc quit";

/// How often `--glsl-dir` is polled for changes.
const WATCH_INTERVAL: Duration = Duration::from_millis(200);
/// Largest reflection depth the keys go to.
const MAX_REFL_DEPTH: u32 = 16;
/// Grid resolution step of the G keys.
const GRID_STEP: u32 = 4;

/// Options of `gpgpu-rt view`.
#[derive(clap::Args, Debug, Clone)]
pub struct ViewArgs {
    /// Scene file (TOML), e.g. scenes/teapot1.toml.
    pub scene: PathBuf,
    /// Render width in pixels (default: the scene's render.width); the window opens at this size.
    #[arg(long)]
    pub width: Option<u32>,
    /// Render height in pixels (default: the scene's render.height).
    #[arg(long)]
    pub height: Option<u32>,
    /// The tracer to start with (T switches).
    #[arg(long, value_enum, default_value = "base")]
    pub tracer: TracerKind,
    /// Reflection passes after the primary pass, REFL_DEPTH of Fig. 8 (default: the scene's).
    #[arg(long)]
    pub refl_depth: Option<u32>,
    /// Shadow flags: `rgba` as the thesis (4 lights) or `bits` (128 lights).
    #[arg(long, value_enum, default_value = "bits")]
    pub shadow_flags: ShadowFlags,
    /// Split every dispatch into tiles of at most N×N pixels (multiple of 8; 0: no tiling).
    #[arg(long, default_value_t = 256, value_name = "N")]
    pub tile: u32,
    /// The grid tracer's options, as for `render` (G / shift+G / A change the resolution, V
    /// the variant).
    #[command(flatten)]
    pub grid: tracer::GridArgs,
    /// Load the kernels from this directory and reload them whenever a file in it changes.
    #[arg(long, value_name = "DIR")]
    pub glsl_dir: Option<PathBuf>,
    /// Save the window's last frame (see --frames) to this PNG and exit.
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<PathBuf>,
    /// Render N frames, then exit (after saving --screenshot); default with --screenshot: 1.
    #[arg(long, value_name = "N")]
    pub frames: Option<u64>,
    /// With --glsl-dir: count --frames only from the first successful reload of an edited
    /// kernel (capture the effect of an edit from a script).
    #[arg(long)]
    pub wait_reload: bool,
    /// Print one line per frame (GPU ms per kernel, triangle tests) to stdout.
    #[arg(long)]
    pub log_frames: bool,
}

/// Open the viewer and run it until the window closes (or --frames are done).
pub fn run(args: ViewArgs) -> Result<()> {
    if args.frames == Some(0) {
        bail!("--frames must be at least 1");
    }
    if args.wait_reload && args.glsl_dir.is_none() {
        bail!("--wait-reload needs --glsl-dir (the kernels it watches)");
    }
    if args.wait_reload && args.frames.is_none() && args.screenshot.is_none() {
        bail!("--wait-reload needs --frames or --screenshot (what to do after the reload)");
    }
    if let Some(p) = &args.screenshot {
        let ext = p
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        if ext.as_deref() != Some("png") {
            bail!(
                "--screenshot {}: the file name must end in .png",
                p.display()
            );
        }
    }
    let scene = Scene::load(&args.scene)?;
    let shaders = ShaderSource::from_dir(args.glsl_dir.clone())?;
    let options = RenderOptions {
        width: args.width.unwrap_or(scene.settings.width),
        height: args.height.unwrap_or(scene.settings.height),
        refl_depth: args.refl_depth.unwrap_or(scene.settings.refl_depth),
        tile: args.tile,
        shadow_flags: args.shadow_flags,
        aovs: false,
        grid: args.grid.options(),
    };
    if options.width == 0 || options.height == 0 {
        bail!(
            "the image size {}x{} must not be zero",
            options.width,
            options.height
        );
    }
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!(
            "cannot connect to a window system: {e}\n(`view` needs an X11 display — DISPLAY; on a \
             headless machine run it under `xvfb-run -a`, or render to a file with `gpgpu-rt render`)"
        )
    })?;
    let mut app = App::new(args, scene, shaders, options);
    let run = event_loop.run_app(&mut app);
    // GL objects go while the context still exists
    app.running = None;
    run.map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    app.result
}

/// What runs while the window is open. Field order is drop order: GL objects before the window.
struct Running {
    tracer: Box<dyn Tracer>,
    quad: ScreenQuad,
    watcher: Option<GlslWatcher>,
    window: GlWindow,
}

#[derive(Default)]
struct Input {
    modifiers: ModifiersState,
    cursor: Option<(f64, f64)>,
    orbiting: bool,
    panning: bool,
}

struct App {
    args: ViewArgs,
    scene: Scene,
    shaders: ShaderSource,
    kind: TracerKind,
    options: RenderOptions,
    camera: Camera,
    running: Option<Running>,
    result: Result<()>,
    input: Input,
    /// Render continuously (not paused).
    continuous: bool,
    /// Something changed: render the next frame even when paused.
    dirty: bool,
    /// The last render failed: do not retry until something changes.
    render_failed: bool,
    /// A frame has been rendered into the current tracer's output texture.
    has_frame: bool,
    /// Frames rendered (all) and counted toward --frames.
    frames: u64,
    counted: u64,
    /// --wait-reload: frames count only after a successful reload.
    counting: bool,
    last_stats: Option<FrameStats>,
    /// An error or notice shown in the title until the next success.
    notice: Option<String>,
    fps_frames: u32,
    fps_since: Instant,
    fps: Option<f64>,
    title_at: Instant,
    screenshots: u32,
    /// --frames are done: nothing more is drawn while the event loop winds down.
    finished: bool,
}

fn kind_name(kind: TracerKind) -> String {
    kind.to_possible_value()
        .map(|v| v.get_name().to_string())
        .unwrap_or_else(|| format!("{kind:?}").to_lowercase())
}

fn variant_name(v: GridVariant) -> String {
    v.to_possible_value()
        .map(|v| v.get_name().to_string())
        .unwrap_or_else(|| format!("{v:?}").to_lowercase())
}

/// The first line of an error that names a file and line (the compile log's first error), else
/// its first line: what fits into a title bar.
fn headline(error: &str) -> String {
    let lines: Vec<&str> = error
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    lines
        .iter()
        .find(|l| l.contains("error") && l.contains(':') && !l.starts_with("GLSL "))
        .or(lines.first())
        .map(|l| l.to_string())
        .unwrap_or_default()
}

impl App {
    fn new(args: ViewArgs, scene: Scene, shaders: ShaderSource, options: RenderOptions) -> App {
        App {
            kind: args.tracer,
            camera: scene.camera,
            counting: !args.wait_reload,
            args,
            scene,
            shaders,
            options,
            running: None,
            result: Ok(()),
            input: Input::default(),
            continuous: true,
            dirty: true,
            render_failed: false,
            has_frame: false,
            frames: 0,
            counted: 0,
            last_stats: None,
            notice: None,
            fps_frames: 0,
            fps_since: Instant::now(),
            fps: None,
            title_at: Instant::now(),
            screenshots: 0,
            finished: false,
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        if self.result.is_ok() {
            self.result = Err(e);
        }
        event_loop.exit();
    }

    fn scene_name(&self) -> String {
        self.scene
            .path
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_else(|| self.scene.path.display().to_string())
    }

    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let title = format!("gpgpu-rt view · {}", self.scene_name());
        let window = GlWindow::new(event_loop, &title, self.options.width, self.options.height)?;
        let gl = window.gl.clone();
        // watch before compiling: an edit made while the first tracer builds is not missed
        let watcher = self
            .shaders
            .dir
            .as_ref()
            .map(|d| GlslWatcher::new(d, WATCH_INTERVAL));
        let quad = ScreenQuad::new(gl.clone(), compile_quad_program(&gl, &self.shaders)?)?;
        let tracer = tracer::create(
            self.kind,
            gl,
            &window.info,
            &self.scene,
            &self.shaders,
            self.options.clone(),
        )?;
        eprintln!(
            "{}: {} triangles, {} lights, {}x{}, {} tracer on {} ({}, {})\n{CONTROLS}",
            self.scene.path.display(),
            self.scene.triangle_count(),
            self.scene.lights.len(),
            self.options.width,
            self.options.height,
            tracer.name(),
            window.info.renderer,
            window.info.version,
            window.info.egl_device_name,
        );
        if let Some(w) = &watcher {
            println!("watching {} for kernel changes", w.dir().display());
        }
        self.running = Some(Running {
            tracer,
            quad,
            watcher,
            window,
        });
        Ok(())
    }

    /// Rebuild the tracer (and with `quad` the screen quad's program) from the current kernel
    /// sources and options. On failure the running ones stay and the error is returned.
    fn rebuild(
        &mut self,
        quad: bool,
        options: RenderOptions,
        kind: TracerKind,
    ) -> Result<Duration> {
        let running = self.running.as_mut().ok_or_else(|| anyhow!("no window"))?;
        let start = Instant::now();
        let gl = running.window.gl.clone();
        let program = if quad {
            Some(compile_quad_program(&gl, &self.shaders)?)
        } else {
            None
        };
        let tracer = tracer::create(
            kind,
            gl.clone(),
            &running.window.info,
            &self.scene,
            &self.shaders,
            options.clone(),
        );
        let tracer = match tracer {
            Ok(t) => t,
            Err(e) => {
                if let Some(p) = program {
                    // SAFETY: deleting the program we just made.
                    unsafe { gl.delete_program(p) };
                }
                return Err(e);
            }
        };
        if let Some(p) = program {
            running.quad.set_program(p);
        }
        running.tracer = tracer;
        self.options = options;
        self.kind = kind;
        self.has_frame = false;
        self.last_stats = None;
        self.render_failed = false;
        self.dirty = true;
        Ok(start.elapsed())
    }

    /// Kernel files changed (or R/F5): rebuild what uses them.
    fn reload(&mut self, changed: Option<Vec<PathBuf>>) {
        let (quad, what) = match &changed {
            Some(files) => (
                files
                    .iter()
                    .any(|f| f.to_string_lossy().starts_with("screen_quad")),
                files
                    .iter()
                    .map(|f| f.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
            None => (true, "all kernels".to_string()),
        };
        match self.rebuild(quad, self.options.clone(), self.kind) {
            Ok(took) => {
                println!(
                    "reload ok: {what} ({} tracer rebuilt in {:.0} ms)",
                    kind_name(self.kind),
                    took.as_secs_f64() * 1e3
                );
                self.notice = None;
                if self.args.wait_reload && !self.counting {
                    self.counting = true;
                }
            }
            Err(e) => {
                let msg = format!("{e:#}");
                // one line on stdout (file:line of the first error), the whole log on stderr
                println!("reload failed: {what}: {}", headline(&msg));
                eprintln!("reload failed: {msg}\nthe last good kernels keep running");
                self.notice = Some(format!("reload failed: {}", headline(&msg)));
                self.dirty = true;
            }
        }
        self.update_title(true);
    }

    /// Switch tracer kind or options (keys); on failure keep the running ones.
    fn change(&mut self, kind: TracerKind, options: RenderOptions, what: String) {
        match self.rebuild(false, options, kind) {
            Ok(_) => {
                println!("{what}");
                self.notice = None;
            }
            Err(e) => {
                let msg = format!("{e:#}");
                eprintln!("{what} failed: {msg}");
                self.notice = Some(format!("{what} failed: {}", headline(&msg)));
            }
        }
        self.update_title(true);
    }

    fn update_title(&mut self, now: bool) {
        if !now && self.title_at.elapsed() < Duration::from_millis(250) {
            return;
        }
        self.title_at = Instant::now();
        let Some(running) = &self.running else { return };
        let mut t = format!(
            "gpgpu-rt · {} · {}",
            self.scene_name(),
            running.tracer.name()
        );
        if self.kind != TracerKind::Base {
            let g = &self.options.grid;
            let res = g
                .resolution
                .map(|r| r.to_string())
                .or_else(|| self.grid_resolution_in_use().map(|r| format!("auto={r}")))
                .unwrap_or_else(|| "auto".into());
            t += &format!(" {} {res}³", variant_name(g.variant));
        }
        t += &format!(
            " · {}×{} · refl {}",
            self.options.width, self.options.height, self.options.refl_depth
        );
        if !self.continuous {
            t += " · paused";
        } else if let Some(fps) = self.fps {
            t += &format!(" · {fps:.2} FPS");
        }
        if let Some(s) = &self.last_stats {
            let kernels: Vec<String> = s
                .gpu_ms
                .iter()
                .map(|(k, v)| format!("{k} {v:.1}"))
                .collect();
            t += &format!(
                " · GPU {:.1} ms ({}) · {} triangle tests",
                s.total_gpu_ms(),
                kernels.join(", "),
                group_digits(s.total_triangle_tests())
            );
        }
        if let Some(n) = &self.notice {
            t += &format!(" · ⚠ {n}");
        }
        running.window.window.set_title(&t);
    }

    /// The grid resolution the running tracer reports using (for `auto`).
    fn grid_resolution_in_use(&self) -> Option<u32> {
        self.last_stats
            .as_ref()?
            .facts
            .get("grid_resolution")?
            .as_u64()
            .map(|r| r as u32)
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        if self.finished {
            return;
        }
        let want = (self.continuous || self.dirty) && !self.render_failed;
        let Some(running) = self.running.as_mut() else {
            return;
        };
        if want {
            self.dirty = false;
            running.window.begin_compute();
            let rendered = running.tracer.render(&self.camera);
            if let Err(e) = running.window.begin_present() {
                return self.fail(event_loop, e);
            }
            match rendered {
                Ok(frame) => {
                    self.frames += 1;
                    self.fps_frames += 1;
                    self.has_frame = true;
                    if self.counting {
                        self.counted += 1;
                    }
                    let s = frame.stats;
                    if self.args.log_frames {
                        let kernels: Vec<String> = s
                            .gpu_ms
                            .iter()
                            .map(|(k, v)| format!("{k}={v:.3}"))
                            .collect();
                        println!(
                            "frame {}: {} tracer, wall {:.1} ms, gpu {:.3} ms [{}], triangle tests {}",
                            self.frames,
                            running.tracer.name(),
                            s.wall_ms,
                            s.total_gpu_ms(),
                            kernels.join(" "),
                            s.total_triangle_tests()
                        );
                    }
                    self.last_stats = Some(s);
                }
                Err(e) => {
                    let msg = format!("{e:#}");
                    if self.args.frames.is_some() || self.args.screenshot.is_some() {
                        return self.fail(event_loop, anyhow!("rendering a frame failed: {msg}"));
                    }
                    eprintln!("rendering a frame failed: {msg}");
                    self.notice = Some(format!("render failed: {}", headline(&msg)));
                    self.render_failed = true;
                }
            }
        }
        let size = running.window.size();
        let viewport = fit_viewport(size, (self.options.width, self.options.height));
        if self.has_frame {
            // SAFETY: drawing to the window's default framebuffer.
            unsafe { running.window.gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
            running
                .quad
                .draw(running.tracer.output_texture(), size, viewport);
        }
        let target = self.args.frames.unwrap_or(1);
        let done = (self.args.frames.is_some() || self.args.screenshot.is_some())
            && self.counted >= target;
        if done {
            self.finished = true;
            if let Some(path) = self.args.screenshot.clone() {
                if let Err(e) = self.save_screenshot(&path, viewport) {
                    return self.fail(event_loop, e);
                }
            }
            event_loop.exit();
        }
        let Some(running) = self.running.as_mut() else {
            return;
        };
        if let Err(e) = running.window.swap() {
            return self.fail(event_loop, e);
        }
        let elapsed = self.fps_since.elapsed();
        if elapsed >= Duration::from_millis(500) {
            self.fps = Some(self.fps_frames as f64 / elapsed.as_secs_f64());
            self.fps_frames = 0;
            self.fps_since = Instant::now();
        }
        self.update_title(false);
    }

    /// Save the current frame: the window's back buffer when it shows the image at its own
    /// size, else the quad drawn offscreen at the image size.
    fn save_screenshot(&mut self, path: &Path, viewport: Viewport) -> Result<()> {
        let running = self.running.as_ref().ok_or_else(|| anyhow!("no window"))?;
        if !self.has_frame {
            bail!("no frame has been rendered yet");
        }
        let (w, h) = (self.options.width, self.options.height);
        let (pixels, from) = if (viewport.width, viewport.height) == (w, h) {
            (
                read_back_buffer(&running.window.gl, viewport),
                "window framebuffer",
            )
        } else {
            let p = running
                .quad
                .draw_offscreen(running.tracer.output_texture(), w, h)?;
            // the window's framebuffer again for the next draw
            (
                p,
                "offscreen framebuffer (the window is not the image's size)",
            )
        };
        crate::gl::check_error(&running.window.gl, "reading the frame back")?;
        save_png(path, w, h, &pixels)?;
        println!(
            "screenshot: {} ({w}x{h}, frame {}, {from})",
            path.display(),
            self.frames
        );
        Ok(())
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, event: KeyEvent) {
        if event.state != ElementState::Pressed {
            return;
        }
        let shift = self.input.modifiers.shift_key();
        let cam = self.camera;
        let moved = |app: &mut App, c: Camera| {
            app.camera = c;
            app.dirty = true;
            app.render_failed = false;
        };
        match event.logical_key.as_ref() {
            Key::Named(NamedKey::Escape) | Key::Character("q") | Key::Character("Q") => {
                event_loop.exit()
            }
            Key::Named(NamedKey::ArrowLeft) if shift => moved(self, orbit::pan(&cam, -0.05, 0.0)),
            Key::Named(NamedKey::ArrowRight) if shift => moved(self, orbit::pan(&cam, 0.05, 0.0)),
            Key::Named(NamedKey::ArrowUp) if shift => moved(self, orbit::pan(&cam, 0.0, -0.05)),
            Key::Named(NamedKey::ArrowDown) if shift => moved(self, orbit::pan(&cam, 0.0, 0.05)),
            Key::Named(NamedKey::ArrowLeft) => moved(self, orbit::orbit(&cam, -5.0, 0.0)),
            Key::Named(NamedKey::ArrowRight) => moved(self, orbit::orbit(&cam, 5.0, 0.0)),
            Key::Named(NamedKey::ArrowUp) => moved(self, orbit::orbit(&cam, 0.0, 5.0)),
            Key::Named(NamedKey::ArrowDown) => moved(self, orbit::orbit(&cam, 0.0, -5.0)),
            Key::Character("+") | Key::Character("=") => moved(self, orbit::zoom(&cam, 0.9)),
            Key::Character("-") | Key::Character("_") => moved(self, orbit::zoom(&cam, 1.0 / 0.9)),
            Key::Named(NamedKey::Home) | Key::Character("c") | Key::Character("C") => {
                let c = self.scene.camera;
                moved(self, c)
            }
            Key::Character("t") | Key::Character("T") => {
                let kinds = TracerKind::value_variants();
                let i = kinds.iter().position(|k| *k == self.kind).unwrap_or(0);
                let n = kinds.len();
                let next = kinds[if shift { (i + n - 1) % n } else { (i + 1) % n }];
                if n == 1 {
                    self.notice = Some(format!("{} is the only tracer", kind_name(next)));
                    self.update_title(true);
                } else {
                    self.change(
                        next,
                        self.options.clone(),
                        format!("tracer {}", kind_name(next)),
                    );
                }
            }
            Key::Character("v") | Key::Character("V") => {
                let variants = GridVariant::value_variants();
                let i = variants
                    .iter()
                    .position(|v| *v == self.options.grid.variant)
                    .unwrap_or(0);
                let mut o = self.options.clone();
                o.grid.variant = variants[(i + 1) % variants.len()];
                let what = format!("grid variant {}", variant_name(o.grid.variant));
                self.change_grid(o, what);
            }
            Key::Character("g") | Key::Character("G") => {
                let current = self
                    .options
                    .grid
                    .resolution
                    .or_else(|| self.grid_resolution_in_use())
                    .unwrap_or(16);
                let next = if shift {
                    current.saturating_sub(GRID_STEP).max(1)
                } else {
                    current.saturating_add(GRID_STEP)
                };
                let mut o = self.options.clone();
                o.grid.resolution = Some(next);
                self.change_grid(o, format!("grid resolution {next}³"));
            }
            Key::Character("a") | Key::Character("A") => {
                let mut o = self.options.clone();
                o.grid.resolution = None;
                self.change_grid(o, "grid resolution auto".into());
            }
            Key::Character("]")
            | Key::Character("}")
            | Key::Character("[")
            | Key::Character("{") => {
                let up = matches!(
                    event.logical_key.as_ref(),
                    Key::Character("]") | Key::Character("}")
                );
                let depth = self.options.refl_depth;
                let next = if up {
                    (depth + 1).min(MAX_REFL_DEPTH)
                } else {
                    depth.saturating_sub(1)
                };
                if next != depth {
                    let mut o = self.options.clone();
                    o.refl_depth = next;
                    self.change(self.kind, o, format!("reflection depth {next}"));
                }
            }
            Key::Named(NamedKey::F5) | Key::Character("r") | Key::Character("R") => {
                self.reload(None)
            }
            Key::Character("p") | Key::Character("P") => {
                self.screenshots += 1;
                let stem = self
                    .scene
                    .path
                    .file_stem()
                    .map(|s| s.to_string_lossy().to_string())
                    .unwrap_or_default();
                let path = PathBuf::from(format!("gpgpu-rt-{stem}-{:03}.png", self.screenshots));
                let full = Viewport {
                    x: 0,
                    y: 0,
                    width: 0,
                    height: 0,
                };
                if let Err(e) = self.save_screenshot(&path, full) {
                    eprintln!("screenshot failed: {e:#}");
                }
                self.dirty = true;
            }
            Key::Named(NamedKey::Space) => {
                self.continuous = !self.continuous;
                self.dirty = true;
                self.update_title(true);
            }
            Key::Named(NamedKey::F1) | Key::Character("h") | Key::Character("H") => {
                println!("{CONTROLS}")
            }
            _ => {}
        }
    }

    /// Grid options only matter to tracers that use them; the base tracer keeps running.
    fn change_grid(&mut self, options: RenderOptions, what: String) {
        if self.kind == TracerKind::Base {
            self.options = options;
            println!("{what} (used by the grid tracer; the base tracer ignores it)");
            self.update_title(true);
        } else {
            self.change(self.kind, options, what);
        }
    }

    fn mouse_move(&mut self, x: f64, y: f64) {
        let Some((px, py)) = self.input.cursor.replace((x, y)) else {
            return;
        };
        let (dx, dy) = ((x - px) as f32, (y - py) as f32);
        if dx == 0.0 && dy == 0.0 {
            return;
        }
        let h = self
            .running
            .as_ref()
            .map(|r| {
                fit_viewport(r.window.size(), (self.options.width, self.options.height)).height
            })
            .unwrap_or(self.options.height)
            .max(1) as f32;
        let pan = self.input.panning || (self.input.orbiting && self.input.modifiers.shift_key());
        let cam = if pan {
            orbit::pan(&self.camera, dx / h, dy / h)
        } else if self.input.orbiting {
            // half a turn per image height
            orbit::orbit(&self.camera, -dx / h * 180.0, dy / h * 180.0)
        } else {
            return;
        };
        self.camera = cam;
        self.dirty = true;
        self.render_failed = false;
    }
}

/// 1234567 -> "1 234 567".
fn group_digits(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push('\u{202f}');
        }
        out.push(c);
    }
    out
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        if let Err(e) = self.start(event_loop) {
            self.fail(event_loop, e);
            return;
        }
        if let Some(r) = &self.running {
            r.window.window.request_redraw();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => {
                if self.args.screenshot.is_some() && self.result.is_ok() {
                    self.result = Err(anyhow!(
                        "the window was closed before the screenshot was taken"
                    ));
                }
                event_loop.exit();
            }
            WindowEvent::Resized(_) => {
                if let Some(r) = &self.running {
                    r.window.resize();
                    r.window.window.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            WindowEvent::ModifiersChanged(m) => self.input.modifiers = m.state(),
            WindowEvent::KeyboardInput { event, .. } => self.key(event_loop, event),
            WindowEvent::CursorMoved { position, .. } => self.mouse_move(position.x, position.y),
            WindowEvent::CursorLeft { .. } => self.input.cursor = None,
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed;
                match button {
                    MouseButton::Left => self.input.orbiting = down,
                    MouseButton::Right | MouseButton::Middle => self.input.panning = down,
                    _ => {}
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                if steps != 0.0 {
                    self.camera = orbit::zoom(&self.camera, 0.9f32.powf(steps));
                    self.dirty = true;
                    self.render_failed = false;
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let changed = self
            .running
            .as_mut()
            .and_then(|r| r.watcher.as_mut())
            .and_then(|w| w.poll());
        if let Some(files) = changed {
            self.reload(Some(files));
        }
        let Some(running) = &self.running else { return };
        if (self.continuous || self.dirty) && !self.render_failed {
            running.window.window.request_redraw();
            event_loop.set_control_flow(ControlFlow::Poll);
        } else if let Some(w) = &running.watcher {
            event_loop.set_control_flow(ControlFlow::WaitUntil(w.next_poll()));
        } else {
            event_loop.set_control_flow(ControlFlow::Wait);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headline_picks_the_first_located_error() {
        let e = "GLSL compile error in /tmp/g/shading.comp:\n/tmp/g/shading.comp:12(5): error: syntax error\n";
        assert_eq!(
            headline(e),
            "/tmp/g/shading.comp:12(5): error: syntax error"
        );
        assert_eq!(
            headline("cannot read GLSL file x\n"),
            "cannot read GLSL file x"
        );
    }

    #[test]
    fn digits_are_grouped() {
        assert_eq!(group_digits(0), "0");
        assert_eq!(group_digits(1234567), "1\u{202f}234\u{202f}567");
    }
}
