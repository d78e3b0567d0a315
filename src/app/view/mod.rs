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
//! (`SoftShadowRenderer`: G-buffer from the current camera, shadow pass, quad into its output
//! texture, which the same screen-filling quad shows): `--shadows` starts with them, `S`
//! cycles off (the ray tracer) / exact / linespace / linespace-dda, `L` / shift+`L` change the
//! light samples (only the shadow kernel is recompiled; the N-tree is built once).
//!
//! The parts: `renderer` (the only user of the library's tracer API: the renderers shown,
//! their frames' statistics), `design` (what is shown, with which options), `keys` (the
//! key table: dispatch and help), `frames` (what to draw next, `--frames`, FPS), `window`
//! (the GL window and the screen-filling quad), `orbit` (camera moves), `watch` (the
//! `--glsl-dir` watcher).

mod app;
mod design;
mod frames;
mod keys;
pub mod orbit;
mod renderer;
pub mod watch;
pub mod window;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::WindowId;

use gpgpu_rt::gl::ShaderSource;
use gpgpu_rt::output::console::ConsoleError;
use gpgpu_rt::output::{self, Format, Target};
use gpgpu_rt::scene::{Camera, Scene};
use gpgpu_rt::{errln, outln};

pub use app::ViewArgs;
use app::{App, Input, Running};
use design::Design;
use frames::{Clock, FrameCount, Picture};
use renderer::{soft_shadow_support, Renderers, ShadowMode, Show, Stats, TracerArg, TracerOptions};
use watch::GlslWatcher;
use window::{
    compile_quad_program, fit_viewport, plain, read_back_buffer, save_image, GlWindow, ScreenQuad,
    Viewport,
};

/// How often `--glsl-dir` is polled for changes.
const WATCH_INTERVAL: Duration = Duration::from_millis(200);

/// Open the viewer and run it until the window closes (or --frames are done).
pub fn run(mut args: ViewArgs) -> Result<()> {
    if args.wait_reload && args.glsl_dir.is_none() {
        bail!("--wait-reload needs --glsl-dir (the kernels it watches)");
    }
    if args.wait_reload && args.frames.is_none() && args.screenshot.is_none() {
        bail!("--wait-reload needs --frames or --screenshot (what to do after the reload)");
    }
    // the same image formats as `render -o`, checked before a window is opened
    let targets: Vec<Target> = (args.screenshot.iter())
        .map(|p| Target::file("--screenshot", p, Format::Image))
        .collect();
    output::check(&targets)?;
    let ticker = gpgpu_rt::progress::Ticker::start(args.quiet);
    gpgpu_rt::progress::stage("loading the scene");
    let scene = Scene::load(&args.scene)?;
    drop(ticker);
    output::refuse_inputs(&targets, &output::scene_inputs(&scene))?;
    // as `render`: the scene file's render.shadows and render.light_samples by default
    args.design.soft = (args.design.soft.clone()).with_scene_defaults(&scene.settings);
    if args.design.soft.shadows.is_some() {
        // the same message as `render --shadows`
        soft_shadow_support(&scene)?;
    }
    let shaders = ShaderSource::from_dir(args.glsl_dir.clone())?;
    let options = TracerOptions {
        args: args.design.clone(),
        width: args.width.unwrap_or(scene.settings.width),
        height: args.height.unwrap_or(scene.settings.height),
        refl_depth: (args.design.refl_depth).unwrap_or(scene.settings.refl_depth),
    };
    if options.width == 0 || options.height == 0 {
        bail!(
            "the image size {}x{} must not be zero",
            options.width,
            options.height
        );
    }
    let event_loop = EventLoop::new().map_err(|e| {
        let e = plain(&e);
        anyhow!(
            "cannot connect to a window system: {e}\n(`view` needs an X11 display — DISPLAY; on a \
             headless machine run it under `xvfb-run -a`, or render to a file with `gpgpu-rt render`)"
        )
    })?;
    let mut app = App::new(args, scene, shaders, options);
    let run = event_loop.run_app(&mut app);
    // GL objects go while the context still exists
    app.running = None;
    run.map_err(|e| anyhow!("the window's event loop failed: {}", plain(&e)))?;
    app.result
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
    fn new(args: ViewArgs, scene: Scene, shaders: ShaderSource, options: TracerOptions) -> App {
        App {
            design: Design::new(
                args.design.tracer,
                options,
                args.design.soft.clone(),
                &scene,
            ),
            camera: scene.camera,
            frames: FrameCount::new(
                args.frames.map(u64::from),
                args.screenshot.is_some(),
                args.wait_reload,
            ),
            args,
            scene,
            shaders,
            running: None,
            result: Ok(()),
            input: Input::default(),
            picture: Picture::new(),
            clock: Clock::new(),
            notice: None,
            screenshots: 0,
        }
    }

    /// A line was printed, or not: a terminal that cannot be written any more ends the viewer
    /// with that error at the next frame (`output::console`: quietly on a closed pipe).
    fn say(&mut self, said: Result<(), ConsoleError>) {
        if let Err(e) = said {
            if self.result.is_ok() {
                self.result = Err(e.into());
            }
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
        // the acceleration structure's build and the kernels' compilation (held to the end)
        let _ticker = gpgpu_rt::progress::Ticker::start(self.args.quiet);
        gpgpu_rt::progress::stage(format!("building the {}", self.design.name()));
        let title = format!("gpgpu-rt view · {}", self.scene_name());
        let (width, height) = self.design.size();
        let window = GlWindow::new(event_loop, &title, width, height)?;
        // watch before compiling: an edit made while the first tracer builds is not missed
        let watcher = self
            .shaders
            .dir
            .as_ref()
            .map(|d| GlslWatcher::new(d, WATCH_INTERVAL));
        let quad = ScreenQuad::new(
            window.gl.clone(),
            compile_quad_program(&window.gl, &self.shaders)?,
        )?;
        let info = window.info.clone();
        self.running = Some(Running {
            renderers: Renderers::new(window.gl.clone(), info.clone()),
            quad,
            watcher,
            window,
        });
        match self.design.shadows {
            Some(mode) => self.show_soft(mode, self.design.samples)?,
            None => self.show_tracer(self.design.kind, self.design.options.clone(), false)?,
        }
        let said = errln!(
            "{}: {} triangles, {} lights, {} area lights, {width}x{height}, {} on {} ({}, {})\n{}",
            self.scene.path.display(),
            self.scene.triangle_count(),
            self.scene.lights.len(),
            self.scene.area_lights.len(),
            self.design.name(),
            info.renderer,
            info.version,
            info.egl_device_name,
            keys::controls(),
        );
        self.say(said);
        if let Some(w) = self.running.as_ref().and_then(|r| r.watcher.as_ref()) {
            let said = outln!("watching {} for kernel changes", w.dir().display());
            self.say(said);
        }
        Ok(())
    }

    /// Show the ray tracer `kind` with `options`; it is built unless `rebuild` is false and one
    /// runs already. On failure what runs stays.
    fn show_tracer(
        &mut self,
        kind: TracerArg,
        options: TracerOptions,
        rebuild: bool,
    ) -> Result<()> {
        let running = self.running.as_mut().ok_or_else(|| anyhow!("no window"))?;
        let what = Show::Tracer(kind, &options);
        running
            .renderers
            .show(&self.scene, &self.shaders, what, rebuild)?;
        self.design.kind = kind;
        self.design.options = options;
        self.design.shadows = None;
        self.picture.reset();
        Ok(())
    }

    /// Show the soft shadows `mode` with `samples`: the renderer is built the first time (the
    /// N-tree with it); later only its shadow kernel is recompiled (all its kernels after a
    /// reload). On failure what runs stays.
    fn show_soft(&mut self, mode: ShadowMode, samples: (u32, u32)) -> Result<()> {
        if let Some(why) = &self.design.no_soft {
            bail!("{why}");
        }
        let running = self.running.as_mut().ok_or_else(|| anyhow!("no window"))?;
        let what = self.design.soft_shadows(mode, samples);
        running
            .renderers
            .show(&self.scene, &self.shaders, what, false)?;
        self.design.shadows = Some(mode);
        self.design.samples = samples;
        self.picture.reset();
        Ok(())
    }

    /// Kernel files changed (or R/F5): rebuild what the window shows (and with `quad` the
    /// screen quad's program) from the current sources. On failure the running ones stay and
    /// the error is returned. The renderer not shown follows when it is shown next.
    fn reload_kernels(&mut self, quad: bool) -> Result<Duration> {
        let running = self.running.as_mut().ok_or_else(|| anyhow!("no window"))?;
        let start = Instant::now();
        let gl = running.window.gl.clone();
        // owned: a failed reload below deletes it as it drops
        let program = match quad {
            true => Some(compile_quad_program(&gl, &self.shaders)?),
            false => None,
        };
        let shown = self.design.shown();
        running
            .renderers
            .reload(&self.scene, &self.shaders, shown)?;
        if let Some(p) = program {
            running.quad.set_program(p);
        }
        self.picture.reset();
        Ok(start.elapsed())
    }

    /// Kernel files changed (or R/F5): rebuild what uses them.
    fn reload(&mut self, changed: Option<Vec<PathBuf>>) {
        let (quad, what) = match &changed {
            Some(files) => (
                files
                    .iter()
                    .any(|f| f.to_string_lossy().starts_with("common/screen_quad")),
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
                let said = outln!(
                    "reload ok: {what} ({} rebuilt in {:.0} ms)",
                    self.design.name(),
                    took.as_secs_f64() * 1e3
                );
                self.say(said);
                self.notice = None;
                self.frames.start_counting();
            }
            Err(e) => {
                let msg = format!("{e:#}");
                // one line on stdout (file:line of the first error), the whole log on stderr
                self.say(outln!("reload failed: {what}: {}", headline(&msg)));
                self.say(errln!(
                    "reload failed: {msg}\nthe last good kernels keep running"
                ));
                self.notice = Some(format!("reload failed: {}", headline(&msg)));
                self.picture.dirty = true;
            }
        }
        self.update_title(true);
    }

    /// Print what a key did, or on failure why (also in the title; what runs stays).
    fn report(&mut self, what: String, result: Result<()>) {
        match result {
            Ok(()) => {
                self.say(outln!("{what}"));
                self.notice = None;
            }
            Err(e) => {
                let msg = format!("{e:#}");
                self.say(errln!("{what} failed: {msg}"));
                self.notice = Some(format!("{what} failed: {}", headline(&msg)));
            }
        }
        self.update_title(true);
    }

    /// New options of the ray tracer (keys). While the soft shadows are shown they are kept
    /// for it (it is built with them when S shows it again); else it is rebuilt, and on
    /// failure the running one stays.
    fn change(&mut self, kind: TracerArg, options: TracerOptions, what: String) {
        if self.design.shadows.is_some() {
            self.design.kind = kind;
            self.design.options = options;
            if let Some(r) = self.running.as_mut() {
                r.renderers.forget_tracer();
            }
            self.say(outln!(
                "{what} (for the ray tracer; soft shadows are shown, S switches)"
            ));
            self.update_title(true);
            return;
        }
        let result = self.show_tracer(kind, options, true);
        self.report(what, result);
    }

    /// Grid options only matter to tracers that use them; the base tracer keeps running.
    fn change_grid(&mut self, options: TracerOptions, what: String) {
        self.change_for(TracerArg::Grid, options, what);
    }

    /// Options only `used_by` uses: another tracer keeps running, the options are kept.
    fn change_for(&mut self, used_by: TracerArg, options: TracerOptions, what: String) {
        if self.design.kind != used_by {
            self.design.options = options;
            let name = design::value_name(used_by);
            self.say(outln!(
                "{what} (used by the {name} tracer; this tracer ignores it)"
            ));
            self.update_title(true);
        } else {
            self.change(self.design.kind, options, what);
        }
    }

    /// The camera moved (mouse, keys): render from `camera`.
    fn move_camera(&mut self, camera: Camera) {
        self.camera = camera;
        self.picture.moved();
    }

    fn update_title(&mut self, now: bool) {
        if !self.clock.title_due(now) {
            return;
        }
        let Some(running) = &self.running else { return };
        let mut t = format!(
            "gpgpu-rt · {} · {}",
            self.scene_name(),
            self.design.title(running.renderers.ntree())
        );
        if !self.picture.continuous {
            t += " · paused";
        } else if let Some(fps) = self.clock.fps() {
            t += &format!(" · {fps:.2} FPS");
        }
        if let Some(s) = &self.picture.last_stats {
            t += &s.title();
        }
        if let Some(n) = &self.notice {
            t += &format!(" · ⚠ {n}");
        }
        running.window.window.set_title(&t);
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        if self.result.is_err() {
            return event_loop.exit();
        }
        if self.frames.finished || self.running.is_none() {
            return;
        }
        if self.picture.wanted() {
            if let Err(e) = self.render_frame() {
                return self.fail(event_loop, e);
            }
        }
        let Some(running) = &self.running else { return };
        let viewport = running.present(self.frame_texture(), self.design.size());
        if self.frames.done() {
            self.frames.finished = true;
            if let Some(path) = self.args.screenshot.clone() {
                if let Err(e) = self.save_screenshot(&path, viewport) {
                    return self.fail(event_loop, e);
                }
            }
            event_loop.exit();
        }
        let Some(running) = &self.running else { return };
        if let Err(e) = running.window.swap() {
            return self.fail(event_loop, e);
        }
        self.clock.tick();
        self.update_title(false);
    }

    /// Render a frame into the shown renderer's output texture. A failed frame ends a run that
    /// counts frames (the error is returned); else it is reported, and no frame is rendered
    /// until something changes.
    fn render_frame(&mut self) -> Result<()> {
        let running = self.running.as_mut().ok_or_else(|| anyhow!("no window"))?;
        self.picture.dirty = false;
        running.window.begin_compute();
        let rendered = running
            .renderers
            .draw(self.design.shadows.is_some(), &self.camera);
        running.window.begin_present()?;
        match rendered {
            Ok(stats) => self.rendered(stats),
            Err(e) => {
                let msg = format!("{e:#}");
                if self.frames.has_target() {
                    bail!("rendering a frame failed: {msg}");
                }
                self.say(errln!("rendering a frame failed: {msg}"));
                self.notice = Some(format!("render failed: {}", headline(&msg)));
                self.picture.render_failed = true;
            }
        }
        Ok(())
    }

    /// A frame was rendered: count it, log it (--log-frames), keep its statistics.
    fn rendered(&mut self, stats: Stats) {
        let n = self.frames.add();
        self.clock.frame();
        self.picture.has_frame = true;
        if self.args.log_frames {
            let said = outln!("frame {n}: {}, {}", self.design.name(), stats.log());
            self.say(said);
        }
        self.design.note(&stats);
        self.picture.last_stats = Some(stats);
    }

    /// The output texture of what is shown, once a frame has been rendered into it.
    fn frame_texture(&self) -> Option<glow::Texture> {
        let running = self.running.as_ref()?;
        let soft = self.design.shadows.is_some();
        running
            .renderers
            .output_texture(soft)
            .filter(|_| self.picture.has_frame)
    }

    /// Save the current frame: the window's back buffer when it shows the image at its own
    /// size, else the quad drawn offscreen at the image size.
    fn save_screenshot(&self, path: &Path, viewport: Viewport) -> Result<()> {
        let running = self.running.as_ref().ok_or_else(|| anyhow!("no window"))?;
        let texture = self
            .frame_texture()
            .ok_or_else(|| anyhow!("no frame has been rendered yet"))?;
        let (w, h) = self.design.size();
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
        save_image(path, w, h, &pixels)?;
        outln!(
            "screenshot: {} ({w}x{h}, frame {}, {from})",
            path.display(),
            self.frames.rendered
        )?;
        Ok(())
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
            .map(|r| fit_viewport(r.window.size(), self.design.size()).height)
            .unwrap_or(self.design.options.height)
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
        self.move_camera(cam);
    }
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
                    self.move_camera(orbit::zoom(&self.camera, 0.9f32.powf(steps)));
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
        if self.picture.wanted() {
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
        use super::renderer::group_digits;
        assert_eq!(group_digits(0), "0");
        assert_eq!(group_digits(1234567), "1\u{202f}234\u{202f}567");
    }
}
