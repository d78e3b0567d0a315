//! The measuring loop every configuration-based protocol shares: load the scenes, make the
//! tracer, render warm-up frames (not counted), render one frame per angle of the rotation,
//! and write the per-frame and per-configuration CSVs.

use std::collections::{BTreeSet, HashMap};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use glam::{Mat4, Vec3};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::machine::Machine;
use super::stats::Stats;
use super::{BenchArgs, Rotation, Scale};
use gpgpu_rt::accel::{GridOptions, GridVariant, TracerKind};
use gpgpu_rt::frame::FrameStats;
use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::pipeline::raytrace::{RayTracer, RenderOptions, ShadowFlags};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::Scene;

/// Which tracer a configuration measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TracerSpec {
    /// The base tracer: every ray against every triangle.
    Base,
    /// The uniform-grid tracer with a fixed resolution (N³ voxels).
    Grid {
        variant: GridVariant,
        resolution: u32,
    },
}

impl TracerSpec {
    pub fn name(&self) -> &'static str {
        match self {
            TracerSpec::Base => "base",
            TracerSpec::Grid { .. } => "grid",
        }
    }
    pub fn variant(&self) -> Option<GridVariant> {
        match self {
            TracerSpec::Base => None,
            TracerSpec::Grid { variant, .. } => Some(*variant),
        }
    }
    pub fn resolution(&self) -> Option<u32> {
        match self {
            TracerSpec::Base => None,
            TracerSpec::Grid { resolution, .. } => Some(*resolution),
        }
    }
    /// "base", "grid thesis 24³".
    pub fn label(&self) -> String {
        match self {
            TracerSpec::Base => "base".into(),
            TracerSpec::Grid {
                variant,
                resolution,
            } => format!("grid {} {}³", variant_name(*variant), resolution),
        }
    }
    /// A file-name friendly form: "base", "grid-thesis-24".
    pub fn slug(&self) -> String {
        match self {
            TracerSpec::Base => "base".into(),
            TracerSpec::Grid {
                variant,
                resolution,
            } => format!("grid-{}-{}", variant_name(*variant), resolution),
        }
    }
}

pub fn variant_name(v: GridVariant) -> &'static str {
    match v {
        GridVariant::Thesis => "thesis",
        GridVariant::Exact => "exact",
    }
}

/// The tracer kind and grid options for a spec. The grid tracer is looked up by its `--tracer`
/// name, so this module needs no change when it is added to [`TracerKind`].
fn tracer_kind(spec: TracerSpec) -> Result<(TracerKind, GridOptions)> {
    match spec {
        TracerSpec::Base => Ok((TracerKind::Base, GridOptions::default())),
        TracerSpec::Grid {
            variant,
            resolution,
        } => {
            let kind = <TracerKind as clap::ValueEnum>::from_str("grid", true).map_err(|_| {
                anyhow::anyhow!("this build of gpgpu-rt has no grid tracer (--tracer grid)")
            })?;
            Ok((
                kind,
                GridOptions {
                    variant,
                    resolution: Some(resolution),
                    ..GridOptions::default()
                },
            ))
        }
    }
}

/// One measured configuration: a scene, a tracer, an image size and the angles of the rotation.
#[derive(Debug, Clone)]
pub struct Config {
    /// File name in the scenes folder, e.g. `bunny.toml`.
    pub scene: String,
    pub tracer: TracerSpec,
    /// REFL_DEPTH: reflection passes after the primary pass.
    pub refl_depth: u32,
    pub width: u32,
    pub height: u32,
    /// Rotation angles in degrees, one measured frame each.
    pub angles: Vec<f64>,
    /// Frames rendered first at the first angle and not counted.
    pub warmup: u32,
}

impl Config {
    /// "bunny", the scene file's stem.
    pub fn scene_name(&self) -> &str {
        self.scene.strip_suffix(".toml").unwrap_or(&self.scene)
    }
    /// "bunny, grid exact 24³".
    pub fn label(&self) -> String {
        format!("{}, {}", self.scene_name(), self.tracer.label())
    }
    pub fn frames(&self) -> u64 {
        self.warmup as u64 + self.angles.len() as u64
    }
}

/// One measured frame.
#[derive(Debug, Clone)]
pub struct FrameRecord {
    pub angle: f64,
    pub stats: FrameStats,
}

impl FrameRecord {
    /// Frames per second from the host's wall-clock time of the frame (what a user sees).
    pub fn fps(&self) -> f64 {
        1e3 / self.stats.wall_ms
    }
    pub fn tests(&self) -> u64 {
        self.stats.total_triangle_tests()
    }
    pub fn voxels(&self) -> Option<u64> {
        self.stats.events.get("voxels_visited").copied()
    }
}

/// The result of one configuration: its frames, or why it could not be measured.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub config: Config,
    pub triangles: usize,
    pub lights: usize,
    /// Making the tracer: compiling kernels, uploading the scene (ms).
    pub setup_ms: f64,
    pub frames: Vec<FrameRecord>,
    /// The error that ended the configuration early; frames before it are kept.
    pub error: Option<String>,
    /// The first measured frame as a PNG, relative to the output folder.
    pub image: Option<PathBuf>,
}

impl Outcome {
    pub fn ok(&self) -> bool {
        self.error.is_none() && !self.frames.is_empty()
    }
    fn series(&self, f: impl Fn(&FrameRecord) -> f64) -> Option<Stats> {
        Stats::of(&self.frames.iter().map(f).collect::<Vec<_>>())
    }
    /// Per-frame FPS (wall clock).
    pub fn fps(&self) -> Option<Stats> {
        self.series(|f| f.fps())
    }
    /// FPS over the whole run: frames / total wall time (the thesis' "durchschnittliche FPS").
    pub fn mean_fps(&self) -> Option<f64> {
        let total: f64 = self.frames.iter().map(|f| f.stats.wall_ms).sum();
        (total > 0.0).then(|| self.frames.len() as f64 * 1e3 / total)
    }
    pub fn wall_ms(&self) -> Option<Stats> {
        self.series(|f| f.stats.wall_ms)
    }
    pub fn gpu_ms(&self) -> Option<Stats> {
        self.series(|f| f.stats.total_gpu_ms())
    }
    pub fn tests(&self) -> Option<Stats> {
        self.series(|f| f.tests() as f64)
    }
    pub fn voxels(&self) -> Option<Stats> {
        if self.frames.iter().any(|f| f.voxels().is_none()) {
            return None;
        }
        self.series(|f| f.voxels().unwrap_or(0) as f64)
    }
}

/// Image size, number of angles and warm-up frames of a protocol at one scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sizing {
    pub width: u32,
    pub height: u32,
    pub angles: u32,
    pub warmup: u32,
}

/// A benchmark session: the GL context, the options, the output folder and the scenes.
pub struct Bench {
    pub args: BenchArgs,
    pub ctx: GlContext,
    pub shaders: ShaderSource,
    pub machine: Machine,
    pub scenes_dir: PathBuf,
    pub out: PathBuf,
    scenes: HashMap<String, Scene>,
    progress: bool,
}

impl Bench {
    pub fn new(args: BenchArgs) -> Result<Bench> {
        validate_args(&args)?;
        let scenes_dir = find_scenes_dir(args.scenes.as_deref())?;
        let out = args.out.clone();
        if out.exists() && !out.is_dir() {
            bail!("--out {}: exists and is not a folder", out.display());
        }
        std::fs::create_dir_all(&out)
            .with_context(|| format!("cannot create the output folder {}", out.display()))?;
        let shaders = ShaderSource::from_dir(args.glsl_dir.clone())?;
        let ctx = GlContext::headless(args.device)?;
        let machine = Machine::describe(&ctx.info);
        let progress = !args.quiet && std::io::stderr().is_terminal();
        Ok(Bench {
            args,
            ctx,
            shaders,
            machine,
            scenes_dir,
            out,
            scenes: HashMap::new(),
            progress,
        })
    }

    pub fn scale(&self) -> Scale {
        self.args.scale
    }

    /// The protocol's sizing at the chosen scale, with the command line's overrides applied.
    pub fn sizing(&self, quick: Sizing, full: Sizing) -> Sizing {
        let s = match self.args.scale {
            Scale::Quick => quick,
            Scale::Full => full,
        };
        Sizing {
            width: self.args.width.unwrap_or(s.width),
            height: self.args.height.unwrap_or(s.height),
            angles: self.args.angles.unwrap_or(s.angles),
            warmup: self.args.warmup.unwrap_or(s.warmup),
        }
    }

    /// The grid resolutions to measure: `--grid-res` or the protocol's list for the scale.
    pub fn grid_resolutions(&self, quick: &[u32], full: &[u32]) -> Vec<u32> {
        match (&self.args.grid_res, self.args.scale) {
            (Some(r), _) => r.clone(),
            (None, Scale::Quick) => quick.to_vec(),
            (None, Scale::Full) => full.to_vec(),
        }
    }

    /// The grid variants to measure: `--variants` or both.
    pub fn variants(&self) -> Vec<GridVariant> {
        self.args
            .variants
            .clone()
            .unwrap_or_else(|| vec![GridVariant::Thesis, GridVariant::Exact])
    }

    /// Load a scene of the scenes folder (once).
    pub fn scene(&mut self, name: &str) -> Result<&Scene> {
        if !self.scenes.contains_key(name) {
            let path = self.scenes_dir.join(name);
            let scene = Scene::load(&path)?;
            self.scenes.insert(name.to_string(), scene);
        }
        Ok(&self.scenes[name])
    }

    fn progress_bar(&self, len: u64, prefix: &str) -> ProgressBar {
        let target = if self.progress {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let pb = ProgressBar::with_draw_target(Some(len), target);
        pb.set_style(
            ProgressStyle::with_template(
                "{prefix} [{bar:30}] {pos}/{len} frames, {elapsed} (ETA {eta}) {msg}",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        );
        pb.set_prefix(prefix.to_string());
        pb
    }

    /// Measure `configs`: warm-up, one frame per angle, per-frame and summary CSVs written to
    /// `<out>/<protocol>.csv` and `<out>/<protocol>_summary.csv`, the first frame of each
    /// configuration to `<out>/frames/<protocol>/`. A configuration that fails is recorded with
    /// its error and the others go on; a missing scene fails the whole protocol at once.
    pub fn measure(&mut self, protocol: &str, configs: &[Config]) -> Result<Vec<Outcome>> {
        for c in configs {
            self.scene(&c.scene)?;
            if c.angles.is_empty() {
                bail!("{protocol}: configuration {} has no angles", c.label());
            }
        }
        let frames_dir = self.out.join("frames").join(protocol);
        std::fs::create_dir_all(&frames_dir)
            .with_context(|| format!("cannot create {}", frames_dir.display()))?;
        let pb = self.progress_bar(configs.iter().map(Config::frames).sum(), protocol);
        let mut outcomes = Vec::with_capacity(configs.len());
        for c in configs {
            pb.set_message(c.label());
            let before = pb.position();
            let outcome = self.run_config(protocol, c, &pb);
            pb.set_position(before + c.frames());
            let line = summary_line(&outcome);
            pb.suspend(|| eprintln!("{protocol}: {line}"));
            outcomes.push(outcome);
        }
        pb.finish_and_clear();
        write_frames_csv(
            &self.out.join(format!("{protocol}.csv")),
            protocol,
            &outcomes,
            self.args.rotate,
        )?;
        write_summary_csv(
            &self.out.join(format!("{protocol}_summary.csv")),
            protocol,
            &outcomes,
            self.args.rotate,
        )?;
        Ok(outcomes)
    }

    fn run_config(&mut self, protocol: &str, c: &Config, pb: &ProgressBar) -> Outcome {
        let scene = self.scenes[&c.scene].clone();
        let mut outcome = Outcome {
            config: c.clone(),
            triangles: scene.triangle_count(),
            lights: scene.lights.len(),
            setup_ms: 0.0,
            frames: Vec::with_capacity(c.angles.len()),
            error: None,
            image: None,
        };
        if let Err(e) = self.render_config(protocol, c, &scene, pb, &mut outcome) {
            outcome.error = Some(format!("{e:#}"));
        }
        outcome
    }

    fn render_config(
        &self,
        protocol: &str,
        c: &Config,
        scene: &Scene,
        pb: &ProgressBar,
        out: &mut Outcome,
    ) -> Result<()> {
        let (kind, mut grid) = tracer_kind(c.tracer)?;
        if let Some(l) = self.args.voxel_array_length {
            grid.voxel_array_length = l;
        }
        if let Some(r) = self.args.ray_array_length {
            grid.ray_array_length = Some(r);
        }
        let options = RenderOptions {
            tracer: kind,
            width: c.width,
            height: c.height,
            refl_depth: c.refl_depth,
            tile: self.args.tile,
            shadow_flags: ShadowFlags::Rgba,
            aovs: false,
            grid,
        };
        let start = Instant::now();
        let mut tracer = RayTracer::new(
            self.ctx.gl.clone(),
            &self.ctx.info,
            scene,
            &self.shaders,
            options,
        )?;
        out.setup_ms = start.elapsed().as_secs_f64() * 1e3;
        let center = rotation_center(scene);
        let base_models: Vec<Mat4> = scene.objects.iter().map(|o| o.model).collect();
        let rotate = self.args.rotate;
        let place = |tracer: &mut RayTracer, angle: f64| -> Result<gpgpu_rt::scene::Camera> {
            match rotate {
                Rotation::Objects => {
                    let r = Mat4::from_translation(center)
                        * Mat4::from_rotation_y((angle as f32).to_radians())
                        * Mat4::from_translation(-center);
                    for (i, m) in base_models.iter().enumerate() {
                        tracer.set_model(i, r * *m)?;
                    }
                    Ok(scene.camera)
                }
                // orbiting the camera by −θ shows the objects turned by θ; the light stays put
                Rotation::Camera => Ok(scene.camera.orbited(center, -(angle as f32))),
            }
        };
        for _ in 0..c.warmup {
            let cam = place(&mut tracer, c.angles[0])?;
            tracer.render(&cam).context("warm-up frame")?;
            pb.inc(1);
        }
        for (i, &angle) in c.angles.iter().enumerate() {
            let cam = place(&mut tracer, angle)?;
            let frame = tracer
                .render(&cam)
                .with_context(|| format!("frame at {angle}°"))?;
            if i == 0 {
                let rel = PathBuf::from("frames").join(protocol).join(format!(
                    "{}_{}.png",
                    c.scene_name(),
                    c.tracer.slug()
                ));
                gpgpu_rt::output::write_png(&self.out.join(&rel), &frame)?;
                out.image = Some(rel);
            }
            out.frames.push(FrameRecord {
                angle,
                stats: frame.stats,
            });
            pb.inc(1);
        }
        Ok(())
    }
}

fn validate_args(a: &BenchArgs) -> Result<()> {
    for (name, v) in [("--width", a.width), ("--height", a.height)] {
        if v == Some(0) {
            bail!("{name} must be at least 1");
        }
    }
    for (name, v) in [
        ("--voxel-array-length", a.voxel_array_length),
        ("--ray-array-length", a.ray_array_length),
    ] {
        if v == Some(0) {
            bail!("{name} must be at least 1");
        }
    }
    if a.angles == Some(0) {
        bail!("--angles must be at least 1");
    }
    if let Some(r) = &a.grid_res {
        if r.is_empty() || r.contains(&0) {
            bail!("--grid-res needs resolutions of at least 1, e.g. --grid-res 8,16,24");
        }
    }
    if let Some(v) = &a.variants {
        if v.is_empty() {
            bail!("--variants needs at least one of thesis, exact");
        }
    }
    if !a.tile.is_multiple_of(8) {
        bail!(
            "--tile {} must be a multiple of 8 (the kernels' work group size)",
            a.tile
        );
    }
    Ok(())
}

/// `--scenes DIR`, else `./scenes`, else the source tree's `scenes/`.
fn find_scenes_dir(given: Option<&Path>) -> Result<PathBuf> {
    if let Some(d) = given {
        if !d.is_dir() {
            bail!("--scenes {}: not a folder", d.display());
        }
        return Ok(d.to_path_buf());
    }
    let here = PathBuf::from("scenes");
    if here.join("bunny.toml").is_file() {
        return Ok(here);
    }
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    if built.join("bunny.toml").is_file() {
        return Ok(built);
    }
    bail!(
        "cannot find the scenes folder (looked for ./scenes and {}); pass --scenes DIR",
        built.display()
    )
}

/// The angles of a rotation through 360° in `n` equal steps, starting at 0°.
pub fn rotation_angles(n: u32) -> Vec<f64> {
    (0..n).map(|i| 360.0 * i as f64 / n as f64).collect()
}

/// The vertical axis the scene turns about passes through the centre of its bounding box.
fn rotation_center(scene: &Scene) -> Vec3 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in scene.world_triangles() {
        for v in t {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if lo.is_finite() && hi.is_finite() {
        0.5 * (lo + hi)
    } else {
        Vec3::ZERO
    }
}

fn summary_line(o: &Outcome) -> String {
    let c = &o.config;
    match (&o.error, o.fps(), o.tests()) {
        (Some(e), _, _) => format!(
            "{} {}x{}: FAILED after {} frames: {e}",
            c.label(),
            c.width,
            c.height,
            o.frames.len()
        ),
        (None, Some(fps), Some(t)) => format!(
            "{} {}x{}: {} frames, median {:.3} FPS [{:.3}–{:.3}], median {} triangle tests",
            c.label(),
            c.width,
            c.height,
            fps.n,
            fps.median,
            fps.min,
            fps.max,
            super::report::int(t.median)
        ),
        _ => format!("{}: no frames", c.label()),
    }
}

fn fact_string(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

fn common_columns(protocol: &str, o: &Outcome, rotate: Rotation) -> Vec<String> {
    let c = &o.config;
    vec![
        protocol.to_string(),
        c.scene_name().to_string(),
        o.triangles.to_string(),
        o.lights.to_string(),
        c.tracer.name().to_string(),
        c.tracer
            .variant()
            .map(variant_name)
            .unwrap_or("")
            .to_string(),
        c.tracer
            .resolution()
            .map(|r| r.to_string())
            .unwrap_or_default(),
        c.width.to_string(),
        c.height.to_string(),
        c.refl_depth.to_string(),
        match rotate {
            Rotation::Objects => "objects",
            Rotation::Camera => "camera",
        }
        .to_string(),
    ]
}

const COMMON_HEADER: [&str; 11] = [
    "protocol",
    "scene",
    "triangles",
    "lights",
    "tracer",
    "variant",
    "grid_resolution",
    "width",
    "height",
    "refl_depth",
    "rotation",
];

/// One row per measured frame. Kernel columns are the union over the configurations:
/// `tests_<kernel>`, `gpu_ms_<kernel>`, `event_<name>`, `fact_<name>` (empty where a tracer has
/// no such kernel).
pub fn write_frames_csv(
    path: &Path,
    protocol: &str,
    outcomes: &[Outcome],
    rotate: Rotation,
) -> Result<()> {
    let mut tests = BTreeSet::new();
    let mut gpu = BTreeSet::new();
    let mut events = BTreeSet::new();
    let mut facts = BTreeSet::new();
    for f in outcomes.iter().flat_map(|o| &o.frames) {
        tests.extend(f.stats.triangle_tests.keys().cloned());
        gpu.extend(f.stats.gpu_ms.keys().cloned());
        events.extend(
            f.stats
                .events
                .keys()
                .filter(|k| *k != "voxels_visited")
                .cloned(),
        );
        facts.extend(f.stats.facts.keys().cloned());
    }
    let mut w =
        csv::Writer::from_path(path).with_context(|| format!("cannot write {}", path.display()))?;
    let mut header: Vec<String> = COMMON_HEADER.iter().map(|s| s.to_string()).collect();
    header.extend(
        [
            "angle_deg",
            "frame",
            "wall_ms",
            "fps",
            "gpu_ms_total",
            "triangle_tests",
            "voxels_visited",
        ]
        .map(String::from),
    );
    header.extend(tests.iter().map(|k| format!("tests_{k}")));
    header.extend(gpu.iter().map(|k| format!("gpu_ms_{k}")));
    header.extend(events.iter().map(|k| format!("event_{k}")));
    header.extend(facts.iter().map(|k| format!("fact_{k}")));
    w.write_record(&header)?;
    for o in outcomes {
        let common = common_columns(protocol, o, rotate);
        for (i, f) in o.frames.iter().enumerate() {
            let s = &f.stats;
            let mut row = common.clone();
            row.extend([
                format!("{}", f.angle),
                i.to_string(),
                format!("{:.4}", s.wall_ms),
                format!("{:.4}", f.fps()),
                format!("{:.4}", s.total_gpu_ms()),
                f.tests().to_string(),
                f.voxels().map(|v| v.to_string()).unwrap_or_default(),
            ]);
            row.extend(tests.iter().map(|k| {
                s.triangle_tests
                    .get(k)
                    .map(|v| v.to_string())
                    .unwrap_or_default()
            }));
            row.extend(gpu.iter().map(|k| {
                s.gpu_ms
                    .get(k)
                    .map(|v| format!("{v:.4}"))
                    .unwrap_or_default()
            }));
            row.extend(
                events
                    .iter()
                    .map(|k| s.events.get(k).map(|v| v.to_string()).unwrap_or_default()),
            );
            row.extend(
                facts
                    .iter()
                    .map(|k| s.facts.get(k).map(fact_string).unwrap_or_default()),
            );
            w.write_record(&row)?;
        }
    }
    w.flush()
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// One row per configuration: median, min, max (and mean) over its measured frames.
pub fn write_summary_csv(
    path: &Path,
    protocol: &str,
    outcomes: &[Outcome],
    rotate: Rotation,
) -> Result<()> {
    let mut w =
        csv::Writer::from_path(path).with_context(|| format!("cannot write {}", path.display()))?;
    let mut header: Vec<String> = COMMON_HEADER.iter().map(|s| s.to_string()).collect();
    let stat_cols = |name: &str| ["median", "min", "max", "mean"].map(|s| format!("{name}_{s}"));
    header.extend(["frames", "warmup", "setup_ms", "fps_run"].map(String::from));
    for name in [
        "fps",
        "wall_ms",
        "gpu_ms",
        "triangle_tests",
        "voxels_visited",
    ] {
        header.extend(stat_cols(name));
    }
    header.extend(["image", "error"].map(String::from));
    w.write_record(&header)?;
    for o in outcomes {
        let mut row = common_columns(protocol, o, rotate);
        row.extend([
            o.frames.len().to_string(),
            o.config.warmup.to_string(),
            format!("{:.1}", o.setup_ms),
            o.mean_fps().map(|v| format!("{v:.4}")).unwrap_or_default(),
        ]);
        for (s, integer) in [
            (o.fps(), false),
            (o.wall_ms(), false),
            (o.gpu_ms(), false),
            (o.tests(), true),
            (o.voxels(), true),
        ] {
            match s {
                Some(s) => row.extend(
                    [s.median, s.min, s.max, s.mean]
                        .into_iter()
                        .enumerate()
                        .map(|(i, v)| {
                            // medians of an even count and means may be fractional
                            if integer && i != 3 && v.fract() == 0.0 {
                                format!("{v:.0}")
                            } else if integer {
                                format!("{v:.1}")
                            } else {
                                format!("{v:.4}")
                            }
                        }),
                ),
                None => row.extend(std::iter::repeat_n(String::new(), 4)),
            }
        }
        row.push(
            o.image
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_default(),
        );
        row.push(o.error.clone().unwrap_or_default());
        w.write_record(&row)?;
    }
    w.flush()
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_angles_cover_the_circle_once() {
        assert_eq!(rotation_angles(4), vec![0.0, 90.0, 180.0, 270.0]);
        let full = rotation_angles(360);
        assert_eq!(full.len(), 360);
        assert_eq!(full[1], 1.0);
        assert_eq!(full[359], 359.0);
    }
}
