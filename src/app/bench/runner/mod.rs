//! The benchmark session every protocol gets, and the measuring loop every
//! configuration-based protocol shares: load the scenes, make the tracer, render warm-up frames
//! (not counted), render one frame per angle of the rotation, and write the per-frame and
//! per-configuration CSVs.
//!
//! Beside it, what a run needs: the command line ([`args`]), the configurations ([`config`]),
//! the only door to the library's renderers ([`adapter`]), the CPU reference that judges first
//! hits ([`judge`]), a configuration's frames ([`outcome`]), the CSVs of its frames and
//! statistics ([`csv_files`]), the machine it ran on ([`machine`]), and the units of work of
//! `--list`, `--shard` and `bench merge` ([`units`], [`shard`]).

pub mod adapter;
pub mod args;
pub mod config;
pub mod csv_files;
pub mod judge;
pub mod machine;
pub mod outcome;
pub mod shard;
pub mod units;

use std::cell::RefCell;
use std::collections::{BTreeMap, HashMap};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use glam::{Mat4, Vec3};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::bench::common::section::Section;
use adapter::{Frame, FrameStats, Gpu, RayTracer, BVH_VARIANTS};
use args::{BenchArgs, Rotation, Scale};
use config::{BvhVariant, Config, GridVariant, Overrides, Sizing};
use gpgpu_rt::scene::{Camera, Scene};
use judge::Judge;
use machine::Machine;
use outcome::{FrameRecord, Outcome};
use shard::{Measured, Mode};
use units::Shard;

/// A benchmark session: the GPU, the options, the output folder and the scenes; what it does
/// with each unit of work (measure, list, replay: [`Mode`]) and what it measured.
pub struct Bench {
    pub args: BenchArgs,
    /// `None` where nothing is measured (`--list`, `bench merge`).
    gpu: Option<Gpu>,
    pub machine: Machine,
    pub scenes_dir: PathBuf,
    pub out: PathBuf,
    scenes: HashMap<(String, Overrides), Scene>,
    /// The CPU reference's first hits per scene and image size ([`Config::judge`]).
    judges: RefCell<HashMap<JudgeKey, Rc<Judge>>>,
    progress: bool,
    pub mode: Mode,
    /// The units met so far (the next one's index) and the ids given out.
    units: usize,
    ids: HashMap<String, u32>,
    /// What this run measured, for a shard's manifest: configurations and whole protocols.
    pub measured: BTreeMap<String, Measured>,
    pub sections: BTreeMap<String, Section>,
    /// `bench merge`: the command line of the run and the machine of every shard.
    pub command: Option<String>,
    pub contributors: Vec<(Shard, Machine)>,
}

/// The error a protocol's measuring returns where this run measures nothing of it: `--list`
/// (the units were printed) or a shard that took none of them (their rows are in the CSVs).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct NotMeasuredHere(pub &'static str);

impl Bench {
    /// A session that measures (`mode` `Measure`) or lists: the GPU is opened only to measure.
    pub fn new(args: BenchArgs, mode: Mode) -> Result<Bench> {
        args.validate()?;
        let out = args.out.clone();
        let measuring = matches!(mode, Mode::Measure(_));
        if measuring {
            // before the GPU is opened: a folder, or one that can be made, that takes new files
            gpgpu_rt::output::check_folder("--out", &out)?;
            std::fs::create_dir_all(&out)
                .with_context(|| format!("cannot create the output folder {}", out.display()))?;
        }
        let gpu = match measuring {
            true => Some(Gpu::open(args.gpu.device, args.gpu.glsl_dir.clone())?),
            false => None,
        };
        let machine = match &gpu {
            Some(g) => Machine::describe(g.info()),
            None => Machine::host(),
        };
        Bench::with(args, gpu, machine, mode)
    }

    /// `bench merge`: a session that replays `recorded` into `out`, on `machine` (the first
    /// shard's).
    pub fn replay(args: BenchArgs, recorded: shard::Recorded, machine: Machine) -> Result<Bench> {
        args.validate()?;
        gpgpu_rt::output::check_folder("--out", &args.out)?;
        std::fs::create_dir_all(&args.out)
            .with_context(|| format!("cannot create the output folder {}", args.out.display()))?;
        Bench::with(args, None, machine, Mode::Replay(Box::new(recorded)))
    }

    fn with(args: BenchArgs, gpu: Option<Gpu>, machine: Machine, mode: Mode) -> Result<Bench> {
        let scenes_dir = find_scenes_dir(args.scenes.as_deref())?;
        let progress = !args.quiet && std::io::stderr().is_terminal();
        Ok(Bench {
            out: args.out.clone(),
            args,
            gpu,
            machine,
            scenes_dir,
            scenes: HashMap::new(),
            judges: RefCell::default(),
            progress,
            mode,
            units: 0,
            ids: HashMap::new(),
            measured: BTreeMap::new(),
            sections: BTreeMap::new(),
            command: None,
            contributors: Vec::new(),
        })
    }

    /// The GPU; an error where this session measures nothing.
    pub fn gpu(&self) -> Result<&Gpu> {
        self.gpu
            .as_ref()
            .context("this bench session measures nothing (--list, bench merge): no GPU")
    }

    /// The next unit of work: its index and its id, `base` made unique within the run.
    pub fn next_unit(&mut self, base: String) -> (usize, String) {
        let seen = self.ids.entry(base.clone()).or_insert(0);
        *seen += 1;
        let id = match *seen {
            1 => base,
            k => format!("{base}#{k}"),
        };
        self.units += 1;
        (self.units - 1, id)
    }

    /// The units met so far.
    pub fn units(&self) -> usize {
        self.units
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
        match (&self.args.grid.grid_res, self.args.scale) {
            (Some(r), _) => r.clone(),
            (None, Scale::Quick) => quick.to_vec(),
            (None, Scale::Full) => full.to_vec(),
        }
    }

    /// The grid variants to measure: `--variants` or both.
    pub fn variants(&self) -> Vec<GridVariant> {
        self.args
            .grid
            .variants
            .clone()
            .unwrap_or_else(|| vec![GridVariant::Thesis, GridVariant::Exact])
    }

    /// The image sizes to measure: `--sizes`, else `--width`×`--height` (each defaulting to
    /// the first size of the list), else the protocol's list for the scale.
    pub fn sizes(&self, quick: &[(u32, u32)], full: &[(u32, u32)]) -> Vec<(u32, u32)> {
        let list = match self.args.scale {
            Scale::Quick => quick,
            Scale::Full => full,
        };
        match (&self.args.wagner.sizes, self.args.width, self.args.height) {
            (Some(s), _, _) => s.clone(),
            (None, None, None) => list.to_vec(),
            (None, w, h) => vec![(w.unwrap_or(list[0].0), h.unwrap_or(list[0].1))],
        }
    }

    /// Whether the command line chose the image sizes (`--sizes`, `--width`, `--height`).
    pub fn sizes_given(&self) -> bool {
        let a = &self.args;
        a.wagner.sizes.is_some() || a.width.is_some() || a.height.is_some()
    }

    /// The square's subdivision levels to measure: `--levels` or the protocol's for the scale.
    pub fn levels(&self, quick: &[u32], full: &[u32]) -> Vec<u32> {
        match (&self.args.wagner.levels, self.args.scale) {
            (Some(l), _) => l.clone(),
            (None, Scale::Quick) => quick.to_vec(),
            (None, Scale::Full) => full.to_vec(),
        }
    }

    /// The BVH variants to measure: `--bvh-variants` or those this build has.
    pub fn bvh_variants(&self) -> Vec<BvhVariant> {
        let given = self.args.wagner.bvh_variants.clone();
        given.unwrap_or_else(|| BVH_VARIANTS.to_vec())
    }

    /// Load a scene of the scenes folder (once).
    pub fn scene(&mut self, name: &str) -> Result<&Scene> {
        self.scene_with(name, Overrides::default())
    }

    /// Load a scene of the scenes folder with some procedural sizes replaced (once).
    pub fn scene_with(&mut self, name: &str, overrides: Overrides) -> Result<&Scene> {
        let key = (name.to_string(), overrides);
        if !self.scenes.contains_key(&key) {
            let path = self.scenes_dir.join(name);
            let scene = Scene::load_with(&path, &overrides)?;
            self.scenes.insert(key.clone(), scene);
        }
        Ok(&self.scenes[&key])
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
    ///
    /// Each configuration is a unit of work ([`shard`]): `--list` prints them and a shard
    /// measures those it takes — both then end the protocol with [`NotMeasuredHere`], as a
    /// report of part of the configurations would mislead — and `bench merge` replays them.
    pub fn measure(&mut self, protocol: &str, configs: &[Config]) -> Result<Vec<Outcome>> {
        for c in configs {
            self.scene_with(&c.scene, c.overrides)?;
            if c.angles.is_empty() {
                bail!("{protocol}: configuration {} has no angles", c.label());
            }
        }
        let units: Vec<(usize, String)> = (configs.iter())
            .map(|c| self.next_unit(config_id(protocol, c)))
            .collect();
        if let Mode::List = self.mode {
            for ((i, id), c) in units.iter().zip(configs) {
                shard::print_list_line(*i, id, &c.label())?;
            }
            return Err(NotMeasuredHere("listed").into());
        }
        let outcomes = match &self.mode {
            Mode::Replay(r) => replayed(r, protocol, configs, &units, &self.out)?,
            Mode::Measure(shard) => {
                let shard = *shard;
                let taken = |i: usize| shard.is_none_or(|s| s.takes(i));
                let mine: Vec<bool> = units.iter().map(|(i, _)| taken(*i)).collect();
                self.measure_configs(protocol, configs, &mine, &units)?
            }
            Mode::List => unreachable!("returned above"),
        };
        csv_files::write(&self.out, protocol, &outcomes, self.args.rotate)?;
        if let Mode::Measure(Some(_)) = self.mode {
            return Err(NotMeasuredHere("a shard reports nothing: bench merge does").into());
        }
        Ok(outcomes)
    }

    /// Measure the configurations marked in `mine`; a shard records each in [`Bench::measured`].
    fn measure_configs(
        &mut self,
        protocol: &str,
        configs: &[Config],
        mine: &[bool],
        units: &[(usize, String)],
    ) -> Result<Vec<Outcome>> {
        let frames_dir = self.out.join("frames").join(protocol);
        std::fs::create_dir_all(&frames_dir)
            .with_context(|| format!("cannot create {}", frames_dir.display()))?;
        let todo = configs.iter().zip(mine).filter(|(_, &m)| m);
        let pb = self.progress_bar(todo.map(|(c, _)| c.frames()).sum(), protocol);
        let mut outcomes = Vec::new();
        let pngs = first_frame_pngs(protocol, configs);
        for (((c, png), &m), (_, id)) in configs.iter().zip(pngs).zip(mine).zip(units) {
            if !m {
                continue;
            }
            pb.set_message(c.label());
            let before = pb.position();
            let outcome = self.run_config(c, png, &pb);
            pb.set_position(before + c.frames());
            let line = outcome.summary_line();
            pb.suspend(|| gpgpu_rt::errln!("{protocol}: {line}"))?;
            if let Mode::Measure(Some(_)) = self.mode {
                self.measured.insert(id.clone(), Measured::of(&outcome));
            }
            outcomes.push(outcome);
        }
        pb.finish_and_clear();
        Ok(outcomes)
    }

    /// Measure `c`, its first frame written to `png` (relative to the output folder).
    fn run_config(&self, c: &Config, png: PathBuf, pb: &ProgressBar) -> Outcome {
        let loaded = &self.scenes[&(c.scene.clone(), c.overrides)];
        let relit;
        let scene = if !c.shadows {
            relit = without_lights(loaded);
            &relit
        } else if loaded.lights.is_empty() && !loaded.area_lights.is_empty() {
            relit = area_centres_lit(loaded);
            &relit
        } else {
            loaded
        };
        let mut outcome = Outcome {
            config: c.clone(),
            triangles: scene.triangle_count(),
            lights: scene.lights.len(),
            setup_ms: 0.0,
            frames: Vec::with_capacity(c.angles.len()),
            error: None,
            image: None,
        };
        if let Err(e) = self.render_config(c, scene, png, pb, &mut outcome) {
            outcome.error = Some(format!("{e:#}"));
        }
        outcome
    }

    fn render_config(
        &self,
        c: &Config,
        scene: &Scene,
        first_png: PathBuf,
        pb: &ProgressBar,
        out: &mut Outcome,
    ) -> Result<()> {
        let start = Instant::now();
        let mut tracer = RayTracer::new(self.gpu()?, scene, c, &self.args)?;
        out.setup_ms = start.elapsed().as_secs_f64() * 1e3;
        let turntable = Turntable::new(scene, self.args.rotate);
        for _ in 0..c.warmup {
            let camera = turntable.turn(&mut |k, m| tracer.set_model(k, m), c.angles[0])?;
            tracer.render(&camera, None).context("warm-up frame")?;
            pb.inc(1);
        }
        for (i, &angle) in c.angles.iter().enumerate() {
            let camera = turntable.turn(&mut |k, m| tracer.set_model(k, m), angle)?;
            let image = (i == 0).then(|| first_png.clone());
            let png = image.as_ref().map(|rel| self.out.join(rel));
            let at = || format!("frame at {angle}°");
            let stats = match (&png, c.judge) {
                (Some(png), true) => {
                    let frame = tracer.render_frame(&camera, png).with_context(at)?;
                    self.judged(c, scene, frame, angle)?
                }
                _ => tracer.render(&camera, png.as_deref()).with_context(at)?,
            };
            if image.is_some() {
                out.image = image;
            }
            out.frames.push(FrameRecord { angle, stats });
            pb.inc(1);
        }
        Ok(())
    }

    /// `frame`'s statistics with its first hits judged against the CPU reference's
    /// (computed once per scene and size): the facts `first_hit_agreement` (a share) and
    /// `first_hit_judge`.
    fn judged(&self, c: &Config, scene: &Scene, frame: Frame, angle: f64) -> Result<FrameStats> {
        if angle != 0.0 {
            // the judge sees the scene as loaded
            bail!(
                "{}: first hits are judged at 0° only, not {angle}°",
                c.label()
            );
        }
        let key = (c.scene.clone(), c.overrides, c.width, c.height);
        let known = self.judges.borrow().get(&key).cloned();
        let judge = match known {
            Some(j) => j,
            None => {
                let j = Rc::new(Judge::of(scene, c.width, c.height)?);
                self.judges.borrow_mut().insert(key, j.clone());
                j
            }
        };
        let mut stats = frame.stats.clone();
        if let Some(a) = judge.agreement(&frame) {
            stats.facts.insert("first_hit_agreement".into(), a.into());
            stats
                .facts
                .insert("first_hit_judge".into(), judge.name.into());
        }
        Ok(stats)
    }
}

/// A scene (with its overrides) at an image size.
type JudgeKey = (String, Overrides, u32, u32);

/// A configuration's unit id: `<protocol>/<scene>_<tracer>_<W>x<H>_refl<D>`, e.g.
/// `thesis-5.3/bunny_grid-exact-24_64x64_refl0` (made unique by [`Bench::next_unit`]).
pub fn config_id(protocol: &str, c: &Config) -> String {
    let angles = c.angles.len();
    let lights = if c.shadows { "" } else { "_nolights" };
    format!(
        "{protocol}/{}_{}x{}_refl{}{lights}_{angles}f",
        c.slug(),
        c.width,
        c.height,
        c.refl_depth
    )
}

/// The outcomes of `configs` as the shards recorded them, their first frames copied into
/// `out`; an error names a configuration no shard measured.
fn replayed(
    r: &shard::Recorded,
    protocol: &str,
    configs: &[Config],
    units: &[(usize, String)],
    out: &Path,
) -> Result<Vec<Outcome>> {
    let mut outcomes = Vec::with_capacity(configs.len());
    for (c, (_, id)) in configs.iter().zip(units) {
        let Some((m, dir)) = r.configs.get(id) else {
            bail!("{protocol}: configuration {id} was measured by none of the shards");
        };
        if let Some(png) = &m.image {
            shard::copy_file(dir, png, out)?;
        }
        outcomes.push(m.outcome(c));
    }
    Ok(outcomes)
}

/// `scene` (whose only lights are area lights, for Klee 2016's pipeline) lit by a point light at
/// the centre of each area light: the area scenes' geometry in the point-light ray tracer.
fn area_centres_lit(scene: &Scene) -> Scene {
    let lights = scene.area_lights.iter().map(|a| gpgpu_rt::scene::Light {
        position: a.center(),
        color: a.color,
    });
    Scene {
        lights: lights.collect(),
        area_lights: Vec::new(), // now point lights: none is ignored
        ..scene.clone()
    }
}

/// `scene` with its lights removed: eye (and reflection) rays only, no shadow rays (the streaming
/// tracer's Table 1, "ray casting (eye rays only)").
fn without_lights(scene: &Scene) -> Scene {
    Scene {
        lights: Vec::new(),
        area_lights: Vec::new(),
        ..scene.clone()
    }
}

/// Where the first measured frame of each configuration goes, relative to the output folder:
/// `frames/<protocol>/<scene>_<tracer>.png`, with `_<W>x<H>` where configurations differ only
/// in their image size.
fn first_frame_pngs(protocol: &str, configs: &[Config]) -> Vec<PathBuf> {
    let slugs: Vec<String> = configs.iter().map(Config::slug).collect();
    let shared = |s: &String| slugs.iter().filter(|t| *t == s).count() > 1;
    let names = configs.iter().zip(&slugs).map(|(c, s)| match shared(s) {
        true => format!("{s}_{}x{}.png", c.width, c.height),
        false => format!("{s}.png"),
    });
    let dir = PathBuf::from("frames").join(protocol);
    names.map(|n| dir.join(n)).collect()
}

/// "The scene rotated through 360°": its objects turned about the vertical axis through the
/// centre of its bounding box, or the camera orbiting that axis (`--rotate`).
pub(crate) struct Turntable<'a> {
    scene: &'a Scene,
    center: Vec3,
    models: Vec<Mat4>,
    rotate: Rotation,
    /// Whether the objects were moved from where the scene put them.
    turned: std::cell::Cell<bool>,
}

impl<'a> Turntable<'a> {
    pub(crate) fn new(scene: &'a Scene, rotate: Rotation) -> Turntable<'a> {
        Turntable {
            scene,
            center: rotation_center(scene),
            models: scene.objects.iter().map(|o| o.model).collect(),
            rotate,
            turned: false.into(),
        }
    }

    /// Turn the scene to `angle` degrees: the objects' models through `set_model` (a tracer's
    /// or a renderer's), or the camera. The camera to render with.
    pub(crate) fn turn(
        &self,
        set_model: &mut dyn FnMut(usize, Mat4) -> Result<()>,
        angle: f64,
    ) -> Result<Camera> {
        // a whole number of turns changes nothing: the pose stays finite and exact for any
        // count of frames (a frame count times the step may pass what an f32 holds)
        let angle = angle.rem_euclid(360.0);
        Ok(match self.rotate {
            // at 0° before any turn the objects stay where they are: a static tracer (seed
            // 004's stream, which refuses moving objects) renders fixed configurations
            Rotation::Objects if angle == 0.0 && !self.turned.get() => self.scene.camera,
            Rotation::Objects => {
                self.turned.set(true);
                let r = turn_about(self.center, angle as f32);
                for (i, m) in self.models.iter().enumerate() {
                    set_model(i, r * *m)?;
                }
                self.scene.camera
            }
            // orbiting the camera by −θ shows the objects turned by θ; the light stays put
            Rotation::Camera => self.scene.camera.orbited(self.center, -(angle as f32)),
        })
    }
}

/// The turn by `degrees` about the vertical axis through `center`.
fn turn_about(center: Vec3, degrees: f32) -> Mat4 {
    Mat4::from_translation(center)
        * Mat4::from_rotation_y(degrees.to_radians())
        * Mat4::from_translation(-center)
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

/// `--scenes DIR`, else `./scenes`, else the source tree's `scenes/`.
pub(crate) fn find_scenes_dir(given: Option<&Path>) -> Result<PathBuf> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The turntable the bench protocols and `render --rotate` share, against the turn written
    /// out independently: a world point p of an object lands at R(θ)·(p − c) + c (c the centre
    /// of the scene's box, R about +y), and the orbiting camera's eye at R(−θ)·(e − c) + c.
    /// `tests/turning_pose.rs` checks the rendered frames the same way.
    #[test]
    fn the_turntable_turns_about_the_scene_centre() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let scene = Scene::load(&root.join("scenes/teapot3.toml")).unwrap();
        let world = scene.world_triangles();
        let (lo, hi) = world.iter().flatten().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let c = (0.5 * (lo + hi)).as_dvec3();
        let turned = |p: glam::DVec3, degrees: f64| {
            let (s, k) = degrees.to_radians().sin_cos();
            let (x, z) = (p.x - c.x, p.z - c.z);
            glam::DVec3::new(c.x + k * x + s * z, p.y, c.z - s * x + k * z)
        };
        for degrees in [0.0, 45.0, 200.0, 720.0 + 10.0] {
            let table = Turntable::new(&scene, Rotation::Objects);
            let mut models = vec![Mat4::IDENTITY; scene.objects.len()];
            let mut keep = |k: usize, m: Mat4| {
                models[k] = m;
                Ok(())
            };
            let camera = table.turn(&mut keep, degrees).unwrap();
            assert_eq!(camera.position, scene.camera.position);
            let mut first = 0;
            for (o, m) in scene.objects.iter().zip(&models) {
                let m = if degrees == 0.0 { o.model } else { *m };
                for (k, t) in o.mesh.positions.chunks(3).enumerate() {
                    for (v, p) in t.iter().enumerate() {
                        let got = m.transform_point3(*p).as_dvec3();
                        let want = turned(world[first + k][v].as_dvec3(), degrees);
                        assert!((got - want).length() < 1e-4, "{degrees}°: {got} vs {want}");
                    }
                }
                first += o.mesh.positions.len() / 3;
            }
            let table = Turntable::new(&scene, Rotation::Camera);
            let camera = table.turn(&mut |_, _| unreachable!(), degrees).unwrap();
            let eye = Vec3::from(camera.position).as_dvec3();
            let want = turned(Vec3::from(scene.camera.position).as_dvec3(), -degrees);
            assert!(
                (eye - want).length() < 1e-4,
                "{degrees}°: eye {eye} vs {want}"
            );
        }
    }
}
