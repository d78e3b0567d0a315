//! `gpgpu-rt view`: the thesis' interactive window (Müller 2015, ch. 3.1.3 and 3.3).
//!
//! Every frame the tracer renders the scene from the current camera into its output texture
//! (the camera change reaches the kernels as uniforms, the thesis' `passCameraUpdates()`), and
//! a screen-filling quad shows the texture in the window. Mouse and keys move the camera and
//! switch tracer, grid variant, grid resolution and reflection depth; the title bar shows
//! frames per second, GPU milliseconds per kernel and triangle tests. With `--glsl-dir` the
//! kernels are live: saving a kernel file rebuilds the tracer from the edited sources, and a
//! compile error is shown with file and line while the last good program keeps running.
//!
//! In a scene with an `[[area_light]]` the viewer also shows the soft shadows of Klee 2016
//! ([`SoftShadowRenderer`]: G-buffer from the current camera, shadow pass, quad into its output
//! texture, which the same screen-filling quad shows): `--shadows` starts with them, `S`
//! cycles off (the ray tracer) / exact / linespace / linespace-dda, `L` / shift+`L` change the
//! light samples (only the shadow kernel is recompiled; the N-tree is built once).

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

use crate::args::SoftShadowArgs;
use gpgpu_rt::accel::{GridVariant, TracerKind};
use gpgpu_rt::frame::FrameStats;
use gpgpu_rt::gl::ShaderSource;
use gpgpu_rt::gl::{Gl, GlInfo};
use gpgpu_rt::pipeline::raytrace::{RayTracer, RenderOptions, ShadowFlags};
use gpgpu_rt::pipeline::softshadow::{scene_light, SoftShadowRenderer};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::ShadowMode;
use gpgpu_rt::scene::{Camera, Scene};

/// The ray tracer with the accelerator `kind`.
fn create_tracer(
    kind: TracerKind,
    gl: std::sync::Arc<Gl>,
    info: &GlInfo,
    scene: &Scene,
    shaders: &ShaderSource,
    options: RenderOptions,
) -> Result<Box<dyn Renderer>> {
    let options = RenderOptions {
        tracer: kind,
        ..options
    };
    Ok(Box::new(RayTracer::new(gl, info, scene, shaders, options)?))
}

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
       S / shift+S soft shadows next / previous (off, exact, linespace, linespace-dda)
       L / shift+L light samples +1 / -1 per axis (2x2 ... 10x10; S and L: [[area_light]] scenes)
       R or F5 reload kernels | P save a screenshot | space pause | H help | Q or Esc quit";

/// How often `--glsl-dir` is polled for changes.
const WATCH_INTERVAL: Duration = Duration::from_millis(200);
/// Largest reflection depth the keys go to.
const MAX_REFL_DEPTH: u32 = 16;
/// Grid resolution step of the G keys.
const GRID_STEP: u32 = 4;
/// Light samples per axis the L keys go between (Klee 2016: 2×2 … 10×10).
const MIN_LIGHT_SAMPLES: u32 = 2;
const MAX_LIGHT_SAMPLES: u32 = 10;

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
    pub grid: crate::args::GridArgs,
    /// The soft-shadow options, as for `render` (scenes with an `[[area_light]]`; S cycles the
    /// mode, L / shift+L the samples).
    #[command(flatten)]
    pub soft: SoftShadowArgs,
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
pub fn run(mut args: ViewArgs) -> Result<()> {
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
    // as `render`: the scene file's render.shadows and render.light_samples by default
    args.soft = args.soft.clone().with_scene_defaults(&scene.settings);
    if args.soft.shadows.is_some() {
        // the same message as `render --shadows`
        scene_light(&scene)?;
    }
    let shaders = ShaderSource::from_dir(args.glsl_dir.clone())?;
    let options = RenderOptions {
        tracer: args.tracer,
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
    /// The ray tracer (`App::kind`, `App::options`); `None` until it is first shown, and after
    /// a change or a reload while the soft shadows are shown (built again when shown).
    tracer: Option<Box<dyn Renderer>>,
    /// The soft-shadow renderer, built when first shown and kept while the ray tracer is shown
    /// (its N-tree is built once).
    soft: Option<SoftShadowRenderer>,
    quad: ScreenQuad,
    watcher: Option<GlslWatcher>,
    window: GlWindow,
}

impl Running {
    /// Render a frame from `camera` with the soft shadows `shadows`, else the ray tracer.
    fn render(&mut self, shadows: Option<ShadowMode>, camera: &Camera) -> Result<FrameStats> {
        match (shadows, self.soft.as_mut(), self.tracer.as_mut()) {
            (Some(_), Some(soft), _) => soft.draw(camera),
            (None, _, Some(tracer)) => tracer.draw(camera),
            _ => bail!("no renderer is built"),
        }
    }

    /// The output texture of what is shown (the soft shadows or the ray tracer).
    fn output_texture(&self, shadows: Option<ShadowMode>) -> Option<glow::Texture> {
        match shadows {
            Some(_) => self.soft.as_ref().map(|s| s.output_texture()),
            None => self.tracer.as_ref().map(|t| t.output_texture()),
        }
    }
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
    /// Soft shadows shown (`None`: the ray tracer `kind`).
    shadows: Option<ShadowMode>,
    /// Light samples U×V of the soft shadows.
    samples: (u32, u32),
    /// Why the scene cannot have soft shadows (no or several area lights); `None`: it can.
    no_soft: Option<String>,
    /// The soft-shadow renderer's kernels are older than the sources (a reload while the ray
    /// tracer was shown): recompiled when it is shown again.
    soft_stale: bool,
    /// The grid resolution the grid tracer last reported (for `auto`).
    grid_in_use: Option<u32>,
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
            shadows: args.soft.shadows,
            samples: args.soft.samples(),
            no_soft: scene_light(&scene).err().map(|e| format!("{e:#}")),
            soft_stale: false,
            grid_in_use: None,
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
        let quad = ScreenQuad::new(gl, compile_quad_program(&window.gl, &self.shaders)?)?;
        let info = window.info.clone();
        self.running = Some(Running {
            tracer: None,
            soft: None,
            quad,
            watcher,
            window,
        });
        match self.shadows {
            Some(mode) => self.show_soft(mode, self.samples)?,
            None => self.show_tracer(self.kind, self.options.clone(), false)?,
        }
        eprintln!(
            "{}: {} triangles, {} lights, {} area lights, {}x{}, {} on {} ({}, {})\n{CONTROLS}",
            self.scene.path.display(),
            self.scene.triangle_count(),
            self.scene.lights.len(),
            self.scene.area_lights.len(),
            self.options.width,
            self.options.height,
            self.shown_name(),
            info.renderer,
            info.version,
            info.egl_device_name,
        );
        if let Some(w) = self.running.as_ref().and_then(|r| r.watcher.as_ref()) {
            println!("watching {} for kernel changes", w.dir().display());
        }
        Ok(())
    }

    /// What the window shows: "base tracer", "soft shadows linespace 3x3".
    fn shown_name(&self) -> String {
        match self.shadows {
            Some(mode) => format!(
                "soft shadows {} {}x{}",
                mode.name(),
                self.samples.0,
                self.samples.1
            ),
            None => format!("{} tracer", kind_name(self.kind)),
        }
    }

    /// A new renderer or new options: the next frame is rendered, the old statistics go.
    fn new_picture(&mut self) {
        self.has_frame = false;
        self.last_stats = None;
        self.render_failed = false;
        self.dirty = true;
    }

    /// Show the ray tracer `kind` with `options`; it is built unless `rebuild` is false and one
    /// runs already. On failure what runs stays.
    fn show_tracer(
        &mut self,
        kind: TracerKind,
        options: RenderOptions,
        rebuild: bool,
    ) -> Result<()> {
        let running = self.running.as_mut().ok_or_else(|| anyhow!("no window"))?;
        if rebuild || running.tracer.is_none() {
            let tracer = create_tracer(
                kind,
                running.window.gl.clone(),
                &running.window.info,
                &self.scene,
                &self.shaders,
                options.clone(),
            )?;
            running.tracer = Some(tracer);
        }
        self.kind = kind;
        self.options = options;
        self.shadows = None;
        self.new_picture();
        Ok(())
    }

    /// Show the soft shadows `mode` with `samples`: the renderer is built the first time (the
    /// N-tree with it); later only its shadow kernel is recompiled (all its kernels after a
    /// reload). On failure what runs stays.
    fn show_soft(&mut self, mode: ShadowMode, samples: (u32, u32)) -> Result<()> {
        if let Some(why) = &self.no_soft {
            bail!("{why}");
        }
        let mut options = self.args.soft.options(
            mode,
            self.options.width,
            self.options.height,
            self.options.tile,
        );
        (options.samples_u, options.samples_v) = samples;
        let running = self.running.as_mut().ok_or_else(|| anyhow!("no window"))?;
        match running.soft.as_mut() {
            None => {
                let soft = SoftShadowRenderer::new(
                    running.window.gl.clone(),
                    &running.window.info,
                    &self.scene,
                    &self.shaders,
                    options,
                )?;
                running.soft = Some(soft);
            }
            Some(s) if self.soft_stale => s.recompile(&self.shaders, mode, samples.0, samples.1)?,
            Some(s) => {
                let o = &s.options;
                if (o.mode, o.samples_u, o.samples_v) != (mode, samples.0, samples.1) {
                    s.reconfigure(&self.shaders, mode, samples.0, samples.1)?;
                }
            }
        }
        self.soft_stale = false;
        self.shadows = Some(mode);
        self.samples = samples;
        self.new_picture();
        Ok(())
    }

    /// Kernel files changed (or R/F5): rebuild what the window shows (and with `quad` the
    /// screen quad's program) from the current sources. On failure the running ones stay and
    /// the error is returned. The renderer not shown follows when it is shown next.
    fn reload_kernels(&mut self, quad: bool) -> Result<Duration> {
        let running = self.running.as_mut().ok_or_else(|| anyhow!("no window"))?;
        let start = Instant::now();
        let gl = running.window.gl.clone();
        let program = if quad {
            Some(compile_quad_program(&gl, &self.shaders)?)
        } else {
            None
        };
        let rebuilt = match (self.shadows, running.soft.as_mut()) {
            (Some(mode), Some(soft)) => {
                soft.recompile(&self.shaders, mode, self.samples.0, self.samples.1)
            }
            _ => create_tracer(
                self.kind,
                gl.clone(),
                &running.window.info,
                &self.scene,
                &self.shaders,
                self.options.clone(),
            )
            .map(|t| running.tracer = Some(t)),
        };
        if let Err(e) = rebuilt {
            if let Some(p) = program {
                // SAFETY: deleting the program we just made.
                unsafe { gl.delete_program(p) };
            }
            return Err(e);
        }
        if let Some(p) = program {
            running.quad.set_program(p);
        }
        if self.shadows.is_some() {
            running.tracer = None;
        } else {
            self.soft_stale = running.soft.is_some();
        }
        self.new_picture();
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
        match self.reload_kernels(quad) {
            Ok(took) => {
                println!(
                    "reload ok: {what} ({} rebuilt in {:.0} ms)",
                    self.shown_name(),
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

    /// Print what a key did, or on failure why (also in the title; what runs stays).
    fn report(&mut self, what: String, result: Result<()>) {
        match result {
            Ok(()) => {
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

    /// New options of the ray tracer (keys). While the soft shadows are shown they are kept
    /// for it (it is built with them when S shows it again); else it is rebuilt, and on
    /// failure the running one stays.
    fn change(&mut self, kind: TracerKind, options: RenderOptions, what: String) {
        if self.shadows.is_some() {
            self.kind = kind;
            self.options = options;
            if let Some(r) = self.running.as_mut() {
                r.tracer = None;
            }
            println!("{what} (for the ray tracer; soft shadows are shown, S switches)");
            self.update_title(true);
            return;
        }
        let result = self.show_tracer(kind, options, true);
        self.report(what, result);
    }

    fn update_title(&mut self, now: bool) {
        if !now && self.title_at.elapsed() < Duration::from_millis(250) {
            return;
        }
        self.title_at = Instant::now();
        let Some(running) = &self.running else { return };
        let mut t = format!("gpgpu-rt · {} · ", self.scene_name());
        match (self.shadows, running.soft.as_ref()) {
            (Some(mode), Some(soft)) => {
                t += &format!(
                    "soft shadows {} {}×{} · N-tree {}/{}",
                    mode.name(),
                    self.samples.0,
                    self.samples.1,
                    soft.scene.tree.n,
                    soft.scene.tree.depth
                );
            }
            _ => {
                t += &kind_name(self.kind);
                if self.kind != TracerKind::Base {
                    let g = &self.options.grid;
                    let res = g
                        .resolution
                        .map(|r| r.to_string())
                        .or_else(|| self.grid_in_use.map(|r| format!("auto={r}")))
                        .unwrap_or_else(|| "auto".into());
                    t += &format!(" {} {res}³", variant_name(g.variant));
                }
            }
        }
        t += &format!(" · {}×{}", self.options.width, self.options.height);
        if self.shadows.is_none() {
            t += &format!(" · refl {}", self.options.refl_depth);
        }
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
            if let Some(n) = s.events.get("linespace_lookups") {
                t += &format!(" · {} line-space lookups", group_digits(*n));
            }
        }
        if let Some(n) = &self.notice {
            t += &format!(" · ⚠ {n}");
        }
        running.window.window.set_title(&t);
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        if self.finished {
            return;
        }
        let want = (self.continuous || self.dirty) && !self.render_failed;
        let name = self.shown_name();
        let Some(running) = self.running.as_mut() else {
            return;
        };
        if want {
            self.dirty = false;
            running.window.begin_compute();
            let rendered = running.render(self.shadows, &self.camera);
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
                    let s = frame;
                    if self.args.log_frames {
                        let kernels: Vec<String> = s
                            .gpu_ms
                            .iter()
                            .map(|(k, v)| format!("{k}={v:.3}"))
                            .collect();
                        let lookups = s
                            .events
                            .get("linespace_lookups")
                            .map(|n| format!(", line-space lookups {n}"))
                            .unwrap_or_default();
                        println!(
                            "frame {}: {}, wall {:.1} ms, gpu {:.3} ms [{}], triangle tests {}{lookups}",
                            self.frames,
                            name,
                            s.wall_ms,
                            s.total_gpu_ms(),
                            kernels.join(" "),
                            s.total_triangle_tests()
                        );
                    }
                    if self.shadows.is_none() {
                        if let Some(r) = s.facts.get("grid_resolution").and_then(|r| r.as_u64()) {
                            self.grid_in_use = Some(r as u32);
                        }
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
        if let Some(texture) = running
            .output_texture(self.shadows)
            .filter(|_| self.has_frame)
        {
            // SAFETY: drawing to the window's default framebuffer.
            unsafe { running.window.gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
            running.quad.draw(texture, size, viewport);
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
        let texture = running
            .output_texture(self.shadows)
            .filter(|_| self.has_frame)
            .ok_or_else(|| anyhow!("no frame has been rendered yet"))?;
        let (w, h) = (self.options.width, self.options.height);
        let (pixels, from) = if (viewport.width, viewport.height) == (w, h) {
            (
                read_back_buffer(&running.window.gl, viewport),
                "window framebuffer",
            )
        } else {
            let p = running.quad.draw_offscreen(texture, w, h)?;
            // the window's framebuffer again for the next draw
            (
                p,
                "offscreen framebuffer (the window is not the image's size)",
            )
        };
        gpgpu_rt::gl::check_error(&running.window.gl, "reading the frame back")?;
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
                if self.shadows.is_some() {
                    // from the soft shadows to the next ray tracer
                    let rebuild = next != self.kind;
                    let result = self.show_tracer(next, self.options.clone(), rebuild);
                    self.report(
                        format!("tracer {} (soft shadows off)", kind_name(next)),
                        result,
                    );
                } else if n == 1 {
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
                    .or(self.grid_in_use)
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
            Key::Character("s") | Key::Character("S") => {
                // off (the ray tracer), exact, linespace, linespace-dda
                let mut cycle = vec![None];
                cycle.extend(ShadowMode::value_variants().iter().copied().map(Some));
                let i = cycle.iter().position(|m| *m == self.shadows).unwrap_or(0);
                let n = cycle.len();
                let next = cycle[if shift { (i + n - 1) % n } else { (i + 1) % n }];
                let (what, result) = match next {
                    _ if self.no_soft.is_some() => {
                        ("soft shadows".to_string(), Err(self.no_soft_error()))
                    }
                    None => (
                        format!("soft shadows off: {} tracer", kind_name(self.kind)),
                        self.show_tracer(self.kind, self.options.clone(), false),
                    ),
                    Some(mode) => (
                        format!(
                            "soft shadows {} {}x{}",
                            mode.name(),
                            self.samples.0,
                            self.samples.1
                        ),
                        self.show_soft(mode, self.samples),
                    ),
                };
                self.report(what, result);
            }
            Key::Character("l") | Key::Character("L") => {
                let step = |n: u32| {
                    if shift {
                        if n > MIN_LIGHT_SAMPLES {
                            n - 1
                        } else {
                            n
                        }
                    } else {
                        (n + 1).clamp(MIN_LIGHT_SAMPLES, MAX_LIGHT_SAMPLES)
                    }
                };
                let next = (step(self.samples.0), step(self.samples.1));
                let what = format!("light samples {}x{}", next.0, next.1);
                if self.no_soft.is_some() {
                    let e = self.no_soft_error();
                    self.report("light samples".into(), Err(e));
                } else if next == self.samples {
                    self.notice = Some(format!(
                        "light samples {}x{}: the keys go from {MIN_LIGHT_SAMPLES}x{MIN_LIGHT_SAMPLES} to \
                         {MAX_LIGHT_SAMPLES}x{MAX_LIGHT_SAMPLES}",
                        next.0, next.1
                    ));
                    self.update_title(true);
                } else if let Some(mode) = self.shadows {
                    let result = self.show_soft(mode, next);
                    self.report(what, result);
                } else {
                    self.samples = next;
                    println!("{what} (for the soft shadows; S shows them)");
                    self.notice = None;
                    self.update_title(true);
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

    /// Why S and L do nothing in this scene.
    fn no_soft_error(&self) -> anyhow::Error {
        anyhow!(
            "{} (S and L need a scene with one [[area_light]])",
            self.no_soft.as_deref().unwrap_or("no area light")
        )
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
