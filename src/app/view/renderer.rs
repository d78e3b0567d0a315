//! The viewer's renderers: the one place the viewer uses the library's tracer API.
//!
//! [`Renderers`] holds what the window can show — a ray tracer (`--tracer`, `T`) and the soft
//! shadows of Klee 2016 (`S`) — and builds, draws and reloads them; [`Stats`] is what a frame
//! reports, as the title and `--log-frames` show it. The rest of the viewer names the designs
//! and their options through the re-exports below and never calls a tracer itself.

use std::sync::Arc;

use anyhow::{bail, Result};

use crate::args::SoftShadowArgs;
use gpgpu_rt::frame::FrameStats;
use gpgpu_rt::gl::{Gl, GlInfo, ShaderSource};
use gpgpu_rt::pipeline::klee2016::{scene_light, SoftShadowOptions, SoftShadowRenderer};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::{Camera, Scene};

pub use crate::args::{DesignArgs, GridResolution, TracerArg};
pub use gpgpu_rt::accel::{BvhVariant, GridVariant};
use gpgpu_rt::design::{Design, Row};
pub use gpgpu_rt::scene::ShadowMode;

/// The ray tracer's options in the window: the command line's design options, which the keys
/// change, with the image size and the reflection depth (no AOVs: the window shows the output
/// texture).
#[derive(Debug, Clone)]
pub struct TracerOptions {
    pub args: DesignArgs,
    pub width: u32,
    pub height: u32,
    pub refl_depth: u32,
}

impl TracerOptions {
    /// The ray tracer `kind` with these options: its row of the registry.
    pub fn row(&self, kind: TracerArg) -> &'static Row {
        self.with(kind).tracer_row()
    }

    /// The design of the ray tracer `kind` with these options (as `render` parses it).
    pub fn design(&self, kind: TracerArg) -> Design {
        let (w, h) = (self.width, self.height);
        (self.with(kind)).tracer_design(self.row(kind), (w, h), self.refl_depth, false)
    }

    fn with(&self, kind: TracerArg) -> DesignArgs {
        DesignArgs {
            tracer: kind,
            ..self.args.clone()
        }
    }

    /// The grid's resolution N (`None`: auto, or cells per axis for the stream).
    pub fn resolution(&self) -> Option<u32> {
        match self.args.grid.grid {
            GridResolution::N(n) => Some(n),
            _ => None,
        }
    }
}

/// Whether `scene` can have soft shadows (one `[[area_light]]`); the error says why not.
pub fn soft_shadow_support(scene: &Scene) -> Result<()> {
    scene_light(scene).map(|_| ())
}

/// What to show (or reload).
#[derive(Clone, Copy)]
pub enum Show<'a> {
    /// The ray tracer `kind` with `options`.
    Tracer(TracerArg, &'a TracerOptions),
    /// The soft shadows `mode` with U×V light `samples`; the N-tree as the command line
    /// (`args`) says, the image size and the tiles as the ray tracer's `options`.
    Soft {
        mode: ShadowMode,
        samples: (u32, u32),
        args: &'a SoftShadowArgs,
        options: &'a TracerOptions,
    },
}

/// The renderers of the window's context. The ray tracer is `None` until it is first shown,
/// and after a change or a reload while the soft shadows are shown (built again when shown);
/// the soft-shadow renderer is built when first shown and kept while the ray tracer is shown
/// (its N-tree is built once).
pub struct Renderers {
    tracer: Option<Box<dyn Renderer>>,
    soft: Option<SoftShadowRenderer>,
    /// The soft-shadow renderer's kernels are older than the sources (a reload while the ray
    /// tracer was shown): recompiled when it is shown again.
    soft_stale: bool,
    gl: Arc<Gl>,
    info: GlInfo,
}

impl Renderers {
    /// No renderer yet; they will be made on `gl` (the window's context, described by `info`).
    pub fn new(gl: Arc<Gl>, info: GlInfo) -> Renderers {
        Renderers {
            tracer: None,
            soft: None,
            soft_stale: false,
            gl,
            info,
        }
    }

    /// Make `what` ready to draw. The ray tracer is built, unless `rebuild` is false and one is
    /// built already; the soft-shadow renderer is built the first time (the N-tree with it),
    /// later only its shadow kernel is recompiled (all its kernels after a reload). On failure
    /// what is built stays.
    pub fn show(
        &mut self,
        scene: &Scene,
        shaders: &ShaderSource,
        what: Show,
        rebuild: bool,
    ) -> Result<()> {
        match what {
            Show::Tracer(kind, options) => {
                if rebuild || self.tracer.is_none() {
                    self.tracer = Some(self.create_tracer(scene, shaders, kind, options)?);
                }
            }
            Show::Soft {
                mode,
                samples,
                args,
                options,
            } => {
                let options = soft_options(args, mode, options);
                self.show_soft(scene, shaders, mode, samples, options)?;
            }
        }
        Ok(())
    }

    fn create_tracer(
        &self,
        scene: &Scene,
        shaders: &ShaderSource,
        kind: TracerArg,
        options: &TracerOptions,
    ) -> Result<Box<dyn Renderer>> {
        options
            .design(kind)
            .renderer(self.gl.clone(), &self.info, scene, shaders)
    }

    fn show_soft(
        &mut self,
        scene: &Scene,
        shaders: &ShaderSource,
        mode: ShadowMode,
        (su, sv): (u32, u32),
        mut options: SoftShadowOptions,
    ) -> Result<()> {
        (options.samples_u, options.samples_v) = (su, sv);
        match self.soft.as_mut() {
            None => {
                let soft =
                    SoftShadowRenderer::new(self.gl.clone(), &self.info, scene, shaders, options)?;
                self.soft = Some(soft);
            }
            Some(s) => {
                if self.soft_stale {
                    s.recompile(shaders)?;
                }
                let o = &s.options;
                if (o.mode, o.samples_u, o.samples_v) != (mode, su, sv) {
                    s.reconfigure(shaders, mode, su, sv)?;
                }
            }
        }
        self.soft_stale = false;
        Ok(())
    }

    /// Let the ray tracer go (its options changed while the soft shadows are shown); it is
    /// built again when shown.
    pub fn forget_tracer(&mut self) {
        self.tracer = None;
    }

    /// Rebuild the kernels of `what` (what the window shows) from `shaders`; on failure the
    /// running ones stay. The renderer not shown follows when it is shown next.
    pub fn reload(&mut self, scene: &Scene, shaders: &ShaderSource, what: Show) -> Result<()> {
        match (what, self.soft.as_mut()) {
            // the soft shadows shown are the renderer's mode and samples
            (Show::Soft { .. }, Some(soft)) => soft.recompile(shaders)?,
            // the soft shadows are shown only once built
            (Show::Soft { .. }, None) => {}
            (Show::Tracer(kind, options), _) => {
                self.tracer = Some(self.create_tracer(scene, shaders, kind, options)?);
            }
        }
        match what {
            Show::Soft { .. } => self.tracer = None,
            Show::Tracer(..) => self.soft_stale = self.soft.is_some(),
        }
        Ok(())
    }

    /// Draw a frame from `camera` into the output texture: the soft shadows with `soft`, else
    /// the ray tracer.
    pub fn draw(&mut self, soft: bool, camera: &Camera) -> Result<Stats> {
        match self.shown(soft) {
            Some(r) => r.draw(camera).map(Stats),
            None => bail!("no renderer is built"),
        }
    }

    /// The soft shadows with `soft`, else the ray tracer (once built).
    fn shown(&mut self, soft: bool) -> Option<&mut (dyn Renderer + 'static)> {
        if soft {
            self.soft
                .as_mut()
                .map(|s| s as &mut (dyn Renderer + 'static))
        } else {
            self.tracer.as_deref_mut()
        }
    }

    /// The output texture of the soft shadows with `soft`, else of the ray tracer.
    pub fn output_texture(&self, soft: bool) -> Option<glow::Texture> {
        if soft {
            self.soft.as_ref().map(|s| s.output_texture())
        } else {
            self.tracer.as_ref().map(|t| t.output_texture())
        }
    }

    /// The soft shadows' N-tree: cells per axis and levels (once built).
    pub fn ntree(&self) -> Option<(u32, u32)> {
        self.soft
            .as_ref()
            .map(|s| (s.scene.tree.n, s.scene.tree.depth))
    }
}

/// The soft-shadow renderer's options: `mode`, the command line's N-tree, `options`' size and
/// tiles.
fn soft_options(
    args: &SoftShadowArgs,
    mode: ShadowMode,
    options: &TracerOptions,
) -> SoftShadowOptions {
    args.options(mode, options.width, options.height, options.args.tile)
}

/// The statistics of a drawn frame.
pub struct Stats(FrameStats);

impl Stats {
    /// The GPU milliseconds of every kernel as `each` writes them, joined by `sep`.
    fn kernels(&self, each: impl Fn(&str, f64) -> String, sep: &str) -> String {
        let all: Vec<String> = self.0.gpu_ms.iter().map(|(k, ms)| each(k, *ms)).collect();
        all.join(sep)
    }

    /// The soft shadows' line-space lookups.
    fn lookups(&self) -> Option<u64> {
        self.0.events.get("linespace_lookups").copied()
    }

    /// The title's part: " · GPU 1.2 ms (kernel 0.4, …) · 1 234 triangle tests", and the
    /// line-space lookups of the soft shadows.
    pub fn title(&self) -> String {
        let s = &self.0;
        let mut t = format!(
            " · GPU {:.1} ms ({}) · {} triangle tests",
            s.total_gpu_ms(),
            self.kernels(|k, ms| format!("{k} {ms:.1}"), ", "),
            group_digits(s.total_triangle_tests())
        );
        if let Some(n) = self.lookups() {
            t += &format!(" · {} line-space lookups", group_digits(n));
        }
        t
    }

    /// The `--log-frames` line's part: "wall 1.0 ms, gpu 0.400 ms [kernel=0.400 …], triangle
    /// tests 1234", and the line-space lookups of the soft shadows.
    pub fn log(&self) -> String {
        let s = &self.0;
        let lookups = self
            .lookups()
            .map(|n| format!(", line-space lookups {n}"))
            .unwrap_or_default();
        format!(
            "wall {:.1} ms, gpu {:.3} ms [{}], triangle tests {}{lookups}",
            s.wall_ms,
            s.total_gpu_ms(),
            self.kernels(|k, ms| format!("{k}={ms:.3}"), " "),
            s.total_triangle_tests()
        )
    }

    /// The grid resolution the grid tracer used (what `auto` chose).
    pub fn grid_resolution(&self) -> Option<u32> {
        let r = self.0.facts.get("grid_resolution")?.as_u64()?;
        Some(r as u32)
    }
}

/// 1234567 -> "1 234 567".
pub(super) fn group_digits(n: u64) -> String {
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
