//! `gpgpu-rt parity`: every design and accelerator on a few scenes, on the current driver; the
//! first hits, the shadows and the exact counts written to a folder (`--out`) and compared with
//! another driver's folder (`--against`). Two conformant drivers must agree: the same first
//! hit on every pixel (a tie on an edge two triangles share — the same distance, the other
//! triangle — aside), the same shadows, equal counts wherever the counts do not depend on the
//! order in which invocations run (`docs/drivers.md`, "Parity").

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

use gpgpu_rt::design::{self, Pipeline, Row};
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::output::write_npy;
use gpgpu_rt::pipeline::klee2016::{SoftShadowOptions, SoftShadowRenderer};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::{Scene, ShadowMode};
use gpgpu_rt::{errln, outln};

use crate::args::{DesignArgs, GpuArgs};

#[derive(clap::Args, Debug)]
pub struct ParityArgs {
    /// Folder for this driver's results (one folder per case: triangle_id.npy, hit_t.npy,
    /// shadow.npy, stats.json; made if missing).
    #[arg(long, value_name = "DIR", required_unless_present = "list")]
    pub out: Option<PathBuf>,
    /// Another driver's `--out` folder to compare with; the exit status is 1 where they differ.
    #[arg(long, value_name = "DIR")]
    pub against: Option<PathBuf>,
    /// Image side in pixels.
    #[arg(long, default_value_t = 48, value_parser = clap::value_parser!(u32).range(8..=512))]
    pub size: u32,
    /// Only the cases whose name contains this text.
    #[arg(long, value_name = "TEXT")]
    pub only: Option<String>,
    /// Print the cases, one a line with the options they are rendered with, and exit.
    #[arg(long)]
    pub list: bool,
    /// Compare with a record of another version or commit of gpgpu-rt (refused otherwise: a
    /// difference could be the code's, not the driver's).
    #[arg(long)]
    pub any_commit: bool,
    /// Share of a case's pixels whose first hit may differ (0: none may). Drivers that contract
    /// a·b + c into one rounding (fma, which GLSL allows) can disagree on rays that graze an
    /// edge; CI's llvmpipe/zink comparison allows none.
    #[arg(long, default_value_t = 0.0, value_parser = crate::args::share_f64)]
    pub tolerance: f64,
    /// Relative difference two drivers' counts may have. The counts of traversals that step by
    /// float comparisons (ray–box slabs, cell boundaries) follow the rounding, and GLSL lets a
    /// compiler contract a·b + c into one fma: on llvmpipe and zink Wagner's node visits differ
    /// by up to 0.3 % and its shadow tests by up to 1.3 % (the turning teapots at 48²), the
    /// stream's cells by one in 92,000, the proximity clouds' jumps by one.
    #[arg(long, default_value_t = 0.02, value_parser = crate::args::share_f64)]
    pub count_tolerance: f64,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// One case's design: a row of the registry, with proximity clouds where the row takes them,
/// or Klee 2016's soft shadows in one mode.
#[derive(Clone, Copy)]
struct Case {
    row: &'static Row,
    clouds: bool,
    mode: Option<ShadowMode>,
}

impl Case {
    /// "grid-exact", "grid-exact-pc", "soft-linespace".
    fn name(&self) -> String {
        match self.mode {
            Some(mode) => format!("soft-{}", mode.name()),
            None if self.clouds => format!("{}-pc", self.row.name),
            None => self.row.name.to_string(),
        }
    }
}

/// The soft-shadow modes of the parity set (the thesis' two variants are `exact` and
/// `linespace` under other names).
const SOFT_MODES: [ShadowMode; 3] = [
    ShadowMode::Exact,
    ShadowMode::Linespace,
    ShadowMode::LinespaceDda,
];

/// Every design of the registry: each point-light row, with and without proximity clouds
/// where it takes them, and the soft shadows in each of [`SOFT_MODES`].
fn designs() -> Vec<Case> {
    let mut v = Vec::new();
    for row in design::REGISTRY {
        if row.pipeline == Pipeline::Klee2016 {
            v.extend(SOFT_MODES.map(|m| Case {
                row,
                clouds: false,
                mode: Some(m),
            }));
            continue;
        }
        for clouds in [false, true] {
            if !clouds || row.takes("proximity-clouds") {
                v.push(Case {
                    row,
                    clouds,
                    mode: None,
                });
            }
        }
    }
    v
}

/// A scene of the parity set: its file below `scenes/`, and the object that turns about the
/// vertical axis by 15° a frame over three frames (the grids rebuild, the BVH refits).
struct SceneCase {
    name: &'static str,
    file: &'static str,
    turning: Option<usize>,
}

/// The point-light scenes: reflections (teapot1), a dense mesh (bunny), the stadium (a scene
/// the grids handle badly) and three teapots of which one turns; the soft shadows take the
/// area-lit bunny.
const RAY_SCENES: [SceneCase; 4] = [
    SceneCase {
        name: "teapot1",
        file: "teapot1.toml",
        turning: None,
    },
    SceneCase {
        name: "bunny",
        file: "bunny.toml",
        turning: None,
    },
    SceneCase {
        name: "stadium",
        file: "stadium.toml",
        turning: None,
    },
    SceneCase {
        name: "teapot3-turning",
        file: "teapot3.toml",
        turning: Some(1),
    },
];
const SOFT_SCENES: [SceneCase; 1] = [SceneCase {
    name: "bunny-area",
    file: "bunny_area.toml",
    turning: None,
}];

/// What a case leaves in its folder beside the arrays.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct CaseRecord {
    renderer: String,
    width: u32,
    height: u32,
    /// The exact counts (`FrameStats::triangle_tests` and `events`, and the grids' references).
    counts: BTreeMap<String, u64>,
    /// Why the counts are not compared ("" where they are).
    counts_depend_on_order: String,
    /// Why the case did not run on this driver ("" where it did).
    skipped: String,
    /// The version and commit of the binary that recorded it (`gpgpu_rt::VERSION`): two
    /// records are compared only where they agree, unless `--any-commit`.
    #[serde(default)]
    version: String,
    /// The implementation profile it ran under (`gl::profile`).
    #[serde(default)]
    profile: String,
}

/// How a case is rendered beyond its design and scene.
#[derive(Clone, Copy)]
struct Render {
    width: u32,
    height: u32,
    /// `--tile` (0: the whole image in one dispatch)
    tile: u32,
    /// options beyond the row's (`--four-kernels`, `--bvh-instances`)
    options: &'static [&'static str],
    /// the soft shadows' light samples, n×n
    samples: u32,
    /// a turning scene's frames drawn one after another, the image read back after the last
    /// only (the bench's and the viewer's path: frames in flight)
    in_flight: bool,
    /// the colour image compared too, not only first hits and shadows
    colour: bool,
}

impl Render {
    fn square(size: u32) -> Render {
        Render {
            width: size,
            height: size,
            tile: 0,
            options: &[],
            samples: 3,
            in_flight: false,
            colour: false,
        }
    }

    /// The options as `--list` prints them.
    fn describe(&self, case: &Case) -> String {
        let mut words = vec![format!("{}x{}", self.width, self.height)];
        words.extend(case.row.select.iter().map(|(o, v)| format!("--{o} {v}")));
        if case.clouds {
            words.push("--proximity-clouds".into());
        }
        if let Some(mode) = case.mode {
            words.push(format!("--shadows {}", mode.name()));
            words.push(format!("--light-samples {0}x{0}", self.samples));
        }
        words.push(format!("--tile {}", self.tile));
        words.extend(self.options.iter().map(|o| o.to_string()));
        if self.in_flight {
            words.push("(frames in flight)".into());
        }
        if self.colour {
            words.push("(colour compared)".into());
        }
        words.join(" ")
    }
}

/// The point-light ray tracer of `case`, the first hits kept.
fn ray_tracer(
    ctx: &GlContext,
    scene: &Scene,
    shaders: &ShaderSource,
    case: Case,
    how: &Render,
) -> Result<Box<dyn Renderer>> {
    let clouds: &[&str] = if case.clouds {
        &["--proximity-clouds"]
    } else {
        &[]
    };
    let tile = how.tile.to_string();
    let args = DesignArgs::of_row(
        case.row,
        &[&["--tile", &tile], clouds, how.options].concat(),
    )?;
    let size = (how.width, how.height);
    let design = args.tracer_design(case.row, size, scene.settings.refl_depth, true);
    design.renderer(ctx.gl.clone(), &ctx.info, scene, shaders)
}

/// The soft-shadow renderer in `mode`: the one of the case before, switched to the mode and the
/// samples, where it has the scene and the size — its N-tree and line spaces are built once for
/// the modes.
fn soft_renderer<'a>(
    kept: &'a mut Option<(&'static str, SoftShadowRenderer)>,
    ctx: &GlContext,
    (file, scene): (&'static str, &Scene),
    shaders: &ShaderSource,
    mode: ShadowMode,
    how: &Render,
) -> Result<&'a mut SoftShadowRenderer> {
    let n = how.samples;
    match kept {
        Some((f, r)) if *f == file && r.size() == (how.width, how.height) => {
            r.reconfigure(shaders, mode, n, n)?
        }
        _ => {
            let options = SoftShadowOptions {
                mode,
                samples_u: n,
                samples_v: n,
                ntree_n: 10,
                ntree_depth: 3,
                shading: Default::default(),
                linespace_build: Default::default(),
                width: how.width,
                height: how.height,
                tile: how.tile,
            };
            let r = SoftShadowRenderer::new(ctx.gl.clone(), &ctx.info, scene, shaders, options)?;
            *kept = Some((file, r));
        }
    }
    Ok(&mut kept.as_mut().expect("made above").1)
}

/// Render the case's frames (three where an object turns; in flight, only the last read back)
/// and return the last.
fn render_case(
    r: &mut dyn Renderer,
    scene: &Scene,
    turning: Option<usize>,
    in_flight: bool,
) -> Result<Frame> {
    let Some(object) = turning else {
        return r.render(&scene.camera);
    };
    let model = scene.objects[object].model;
    for k in 1..=3 {
        let turn = Mat4::from_axis_angle(Vec3::Y, (15.0 * k as f32).to_radians());
        r.set_model(object, model * turn)?;
        if k == 3 {
            break;
        }
        if in_flight {
            r.draw(&scene.camera)?;
        } else {
            r.render(&scene.camera)?;
        }
    }
    r.render(&scene.camera)
}

/// The counts of a frame that a second driver must reproduce, and why none are where they
/// depend on the order of execution.
fn counts_of(case: Case, frame: &Frame) -> (BTreeMap<String, u64>, String) {
    let s = &frame.stats;
    let mut counts: BTreeMap<String, u64> = s
        .triangle_tests
        .iter()
        .map(|(k, v)| (format!("triangle_tests.{k}"), *v))
        .chain(s.events.iter().map(|(k, v)| (format!("events.{k}"), *v)))
        .collect();
    for key in ["grid_triangle_refs", "ray_batches"] {
        if let Some(v) = s.facts.get(key).and_then(|v| v.as_u64()) {
            counts.insert(key.to_string(), v);
        }
    }
    // the fixed-size lists keep whichever references their atomics placed first
    let dropped = s.events.get("dropped_triangle_refs").copied().unwrap_or(0) > 0;
    let why = match case.row.name {
        "grid-thesis" if dropped => {
            "the thesis grid dropped references: which ones depends on the order of its atomics"
        }
        _ => "",
    };
    (counts, why.to_string())
}

/// A case's folder: its record and, where it ran, the frame's first hits and shadows.
fn write_case(dir: &Path, frame: Option<&Frame>, record: &CaseRecord, colour: bool) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot make {}", dir.display()))?;
    if let Some((frame, a)) = frame.and_then(|f| f.aovs.as_ref().map(|a| (f, a))) {
        let shape = [frame.height as u64, frame.width as u64];
        write_npy(
            &dir.join("triangle_id.npy"),
            &shape,
            a.triangle_id.iter().copied(),
        )?;
        write_npy(&dir.join("hit_t.npy"), &shape, a.hit_t.iter().copied())?;
        if let Some(s) = &a.shadow {
            write_npy(&dir.join("shadow.npy"), &shape, s.iter().copied())?;
        }
        if colour {
            let rgb = [shape[0], shape[1], 3];
            let values = frame.color.iter().flat_map(|c| [c[0], c[1], c[2]]);
            write_npy(&dir.join("color.npy"), &rgb, values)?;
        }
    }
    let json = serde_json::to_string_pretty(record)?;
    std::fs::write(dir.join("stats.json"), json)
        .with_context(|| format!("cannot write {}", dir.join("stats.json").display()))
}

/// One case: its folder name, design, scene and how it is rendered.
struct Spec {
    name: String,
    design: Case,
    scene: &'static SceneCase,
    how: Render,
}

/// The row of the registry named `name`.
fn row(name: &str) -> &'static Row {
    design::REGISTRY
        .iter()
        .find(|r| r.name == name)
        .expect("a row of the registry")
}

/// The ray-tracing scene named `name` of [`RAY_SCENES`].
fn ray_scene(name: &str) -> &'static SceneCase {
    RAY_SCENES
        .iter()
        .find(|s| s.name == name)
        .expect("a parity scene")
}

/// How often the race case is repeated: races show as runs that differ.
const REPEATS: u32 = 5;

/// The point-light case `name` of row `row_name` on `scene`.
fn point_case(name: String, row_name: &str, scene: &str, how: Render) -> Spec {
    Spec {
        name,
        design: Case {
            row: row(row_name),
            clouds: false,
            mode: None,
        },
        scene: ray_scene(scene),
        how,
    }
}

/// The cases that look where a GPU could go wrong and the plain matrix does not: the SAH BVH's
/// four kernels beside its default fused pass (the matrix's `bvh` cases, whose block lists and
/// dispatches the GPU writes) with their hit list, the instances' two levels, tiles, an odd size
/// (partial work groups, reads past the image's edge), 5×5 soft shadows, a turning scene's
/// frames in flight, the colour image after reflections, and one 512² case run
/// [`REPEATS`] times.
fn gpu_cases(size: u32) -> Vec<Spec> {
    let square = Render::square(size);
    let mut v = Vec::new();
    let four = Render {
        options: &["--four-kernels"],
        colour: true,
        ..square
    };
    for scene in ["teapot1", "bunny"] {
        v.push(point_case(
            format!("bvh-four-kernels.{scene}"),
            "bvh",
            scene,
            four,
        ));
    }
    let in_flight = Render {
        in_flight: true,
        ..square
    };
    let turning = "teapot3-turning";
    let instances = Render {
        options: &["--bvh-instances"],
        ..in_flight
    };
    let name = format!("bvh-instances.{turning}-in-flight");
    v.push(point_case(name, "bvh", turning, instances));
    for name in ["bvh", "grid-exact", "bvh-wagner"] {
        let case = format!("{name}.{turning}-in-flight");
        v.push(point_case(case, name, turning, in_flight));
    }
    v.extend(edge_cases(square));
    v.extend(soft_cases(square));
    for k in 1..=REPEATS {
        let case = format!("bvh.teapot1-512-run{k}");
        v.push(point_case(case, "bvh", "teapot1", Render::square(512)));
    }
    v
}

/// Tiles of 64² over 136×100, an image of 61×47 and the colour image, on the teapot with its
/// reflection.
fn edge_cases(square: Render) -> Vec<Spec> {
    let tiles = Render {
        width: 136,
        height: 100,
        tile: 64,
        ..square
    };
    let odd = Render {
        width: 61,
        height: 47,
        ..square
    };
    let colour = Render {
        colour: true,
        ..square
    };
    let mut v = Vec::new();
    for name in ["base", "grid-exact", "bvh", "bvh-wagner"] {
        for (suffix, how) in [("tile64", tiles), ("61x47", odd), ("colour", colour)] {
            v.push(point_case(
                format!("{name}.teapot1-{suffix}"),
                name,
                "teapot1",
                how,
            ));
        }
    }
    for name in ["grid-thesis", "stream"] {
        v.push(point_case(
            format!("{name}.teapot1-61x47"),
            name,
            "teapot1",
            odd,
        ));
    }
    v
}

/// Soft shadows at 5×5 rays (the matrix takes 3×3), exact and by the line spaces.
fn soft_cases(square: Render) -> Vec<Spec> {
    let soft = Render {
        samples: 5,
        ..square
    };
    [ShadowMode::Exact, ShadowMode::Linespace]
        .map(|mode| {
            let design = Case {
                row: row("linespace"),
                clouds: false,
                mode: Some(mode),
            };
            Spec {
                name: format!("{}.bunny-area-5x5", design.name()),
                design,
                scene: &SOFT_SCENES[0],
                how: soft,
            }
        })
        .into()
}

/// Every case: the matrix of designs × scenes at `size`², then [`gpu_cases`]; those whose name
/// contains `only`, where given.
fn cases(only: Option<&str>, size: u32) -> Vec<Spec> {
    let mut out = Vec::new();
    for design in designs() {
        let scenes: &'static [SceneCase] = match design.mode {
            Some(_) => &SOFT_SCENES,
            None => &RAY_SCENES,
        };
        for s in scenes {
            out.push(Spec {
                name: format!("{}.{}", design.name(), s.name),
                design,
                scene: s,
                how: Render::square(size),
            });
        }
    }
    out.extend(gpu_cases(size));
    out.retain(|c| only.is_none_or(|o| c.name.contains(o)));
    out
}

/// Render every case on this driver into `out`.
fn record(ctx: &GlContext, args: &ParityArgs, out: &Path) -> Result<()> {
    let shaders = ShaderSource::from_dir(args.gpu.glsl_dir.clone())?;
    let dir = crate::bench::runner::find_scenes_dir(None)?;
    let mut scenes: BTreeMap<&str, Scene> = BTreeMap::new();
    let mut soft = None;
    for spec in cases(args.only.as_deref(), args.size) {
        let (case, design, s, how) = (&spec.name, spec.design, spec.scene, &spec.how);
        if !scenes.contains_key(s.file) {
            scenes.insert(s.file, Scene::load(&dir.join(s.file))?);
        }
        let scene = &scenes[s.file];
        let t0 = std::time::Instant::now();
        let mut ray;
        let r: &mut dyn Renderer = match design.mode {
            Some(mode) => soft_renderer(&mut soft, ctx, (s.file, scene), &shaders, mode, how)
                .with_context(|| format!("parity case {case}"))?,
            None => {
                ray = ray_tracer(ctx, scene, &shaders, design, how)
                    .with_context(|| format!("parity case {case}"))?;
                ray.as_mut()
            }
        };
        let frame = match render_case(r, scene, s.turning, how.in_flight) {
            Ok(f) => f,
            // a static design (the streaming tracer's grid, Klee's N-tree) cannot move: skipped
            Err(e) if s.turning.is_some() => {
                let record = CaseRecord {
                    renderer: ctx.info.renderer.clone(),
                    width: how.width,
                    height: how.height,
                    counts: BTreeMap::new(),
                    counts_depend_on_order: String::new(),
                    skipped: format!("{e:#}"),
                    version: gpgpu_rt::VERSION.into(),
                    profile: ctx.info.profile.name.as_str().into(),
                };
                write_case(&out.join(case), None, &record, how.colour)?;
                errln!("{case}: skipped ({e:#})")?;
                continue;
            }
            Err(e) => return Err(e.context(format!("parity case {case}"))),
        };
        let (counts, why) = counts_of(design, &frame);
        let record = CaseRecord {
            renderer: ctx.info.renderer.clone(),
            width: frame.width,
            height: frame.height,
            counts,
            counts_depend_on_order: why,
            skipped: String::new(),
            version: gpgpu_rt::VERSION.into(),
            profile: ctx.info.profile.name.as_str().into(),
        };
        write_case(&out.join(case), Some(&frame), &record, how.colour)?;
        errln!("{case}: rendered ({:.1} s)", t0.elapsed().as_secs_f64())?;
    }
    Ok(())
}

/// One case's folder read back.
struct Recorded {
    record: CaseRecord,
    triangle_id: Vec<i32>,
    hit_t: Vec<f32>,
    shadow: Option<Vec<f32>>,
    /// rgb per pixel, where the case compares the colour image
    color: Option<Vec<f32>>,
}

fn read_npy<T: npyz::Deserialize>(path: &Path) -> Result<Vec<T>> {
    let bytes = gpgpu_rt::scene::file::read(path)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    let npy = npyz::NpyFile::new(&bytes[..]).with_context(|| format!("{}", path.display()))?;
    let promised: u64 = npy.shape().iter().product();
    npy.into_vec::<T>().map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => anyhow::anyhow!(
            "{}: truncated ({} bytes, its header promises {promised} values)",
            path.display(),
            bytes.len()
        ),
        _ => anyhow::anyhow!("{}: {e}", path.display()),
    })
}

fn load(dir: &Path) -> Result<Recorded> {
    let json = gpgpu_rt::scene::file::read_text(&dir.join("stats.json"))
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", dir.join("stats.json").display()))?;
    let record: CaseRecord = serde_json::from_str(&json)
        .with_context(|| format!("{}: not a parity record", dir.display()))?;
    if !record.skipped.is_empty() {
        return Ok(Recorded {
            record,
            triangle_id: Vec::new(),
            hit_t: Vec::new(),
            shadow: None,
            color: None,
        });
    }
    // every array of the case holds `per_pixel` values per pixel of its record's size
    let pixels = record.width as usize * record.height as usize;
    let sized = |path: PathBuf, len: usize, per_pixel: usize| -> Result<()> {
        if len != per_pixel * pixels {
            bail!(
                "{}: {len} values, but the case is {}x{} pixels of {per_pixel}",
                path.display(),
                record.width,
                record.height
            );
        }
        Ok(())
    };
    let (ids, t, shadow) = (
        dir.join("triangle_id.npy"),
        dir.join("hit_t.npy"),
        dir.join("shadow.npy"),
    );
    let triangle_id: Vec<i32> = read_npy(&ids)?;
    sized(ids, triangle_id.len(), 1)?;
    let hit_t: Vec<f32> = read_npy(&t)?;
    sized(t, hit_t.len(), 1)?;
    let shadow = if shadow.exists() {
        let v: Vec<f32> = read_npy(&shadow)?;
        sized(shadow, v.len(), 1)?;
        Some(v)
    } else {
        None
    };
    let color = dir.join("color.npy");
    let color = if color.exists() {
        let v: Vec<f32> = read_npy(&color)?;
        sized(color, v.len(), 3)?;
        Some(v)
    } else {
        None
    };
    Ok(Recorded {
        triangle_id,
        hit_t,
        shadow,
        color,
        record,
    })
}

/// How two drivers' renderings of one case differ.
#[derive(Debug, Default)]
struct Difference {
    pixels: usize,
    /// Pixels with another first hit (not a tie).
    hits: usize,
    /// Pixels where the two hit other triangles at the same distance (an edge they share).
    ties: usize,
    /// Pixels with the same first hit but another shadow value.
    shadows: usize,
    /// Pixels with the same first hit but another colour (a channel off by more than
    /// [`COLOUR_TOLERANCE`]), where the case compares colours.
    colours: Option<usize>,
    /// Counts that differ, as `name a → b`.
    counts: Vec<String>,
    /// The largest relative difference of a count.
    worst: f64,
    note: String,
    /// The image itself depends on the order of execution (the thesis grid's dropped
    /// references): differences are reported, not failed.
    order_dependent: bool,
}

/// How far one channel of two drivers' colours may differ. Both compute the shading of
/// Listing 16 in f32 from the same first hit; GLSL lets a compiler contract a·b + c into one
/// rounding, which moves a colour by about 1e-6 a step, 1e-5 over a reflection's shading. A
/// quarter of an 8-bit step (1/1020) is a hundred times that, and invisible in a PNG; a lost
/// shadow, a wrong reflection or an unwritten pixel moves a channel by 0.05 or more.
const COLOUR_TOLERANCE: f32 = 1.0 / 1020.0;

/// The same distance along the ray, to the rounding of either driver.
fn same_distance(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-5 * a.abs().max(b.abs()).max(1.0)
}

fn compare(a: &Recorded, b: &Recorded) -> Result<Difference> {
    let mut d = Difference {
        pixels: a.triangle_id.len(),
        ..Default::default()
    };
    let skipped = [&a.record.skipped, &b.record.skipped];
    if let Some(why) = skipped.iter().find(|s| !s.is_empty()) {
        d.note = format!("skipped: {why}");
        return Ok(d);
    }
    if (a.record.width, a.record.height) != (b.record.width, b.record.height) {
        bail!(
            "the two folders were rendered at other sizes ({}x{} and {}x{}): run both with the same --size",
            a.record.width, a.record.height, b.record.width, b.record.height
        );
    }
    let colours = a.color.as_ref().zip(b.color.as_ref());
    if colours.is_some() {
        d.colours = Some(0);
    }
    for i in 0..d.pixels {
        let (ia, ib) = (a.triangle_id[i], b.triangle_id[i]);
        if ia == ib {
            let (sa, sb) = (a.shadow.as_ref(), b.shadow.as_ref());
            if let (Some(sa), Some(sb)) = (sa, sb) {
                if (sa[i] - sb[i]).abs() > 1e-6 {
                    d.shadows += 1;
                }
            }
            if let (Some((ca, cb)), Some(n)) = (colours, d.colours.as_mut()) {
                let off = (0..3).any(|c| (ca[3 * i + c] - cb[3 * i + c]).abs() > COLOUR_TOLERANCE);
                *n += off as usize;
            }
        } else if ia >= 0 && ib >= 0 && same_distance(a.hit_t[i], b.hit_t[i]) {
            d.ties += 1;
        } else {
            d.hits += 1;
        }
    }
    let order = [&a.record, &b.record]
        .iter()
        .map(|r| r.counts_depend_on_order.as_str())
        .find(|w| !w.is_empty());
    let batches = |r: &CaseRecord| r.counts.get("ray_batches").copied();
    if let Some(why) = order {
        d.note = format!("not compared: {why}");
        d.order_dependent = true;
    } else if batches(&a.record) != batches(&b.record) {
        // the soft shadows' packets are split where a driver limits loops: their traversal
        // counts follow the split
        d.note = "counts not compared: the drivers split the shadow rays into other batches".into();
    } else {
        let keys: std::collections::BTreeSet<&String> = a
            .record
            .counts
            .keys()
            .chain(b.record.counts.keys())
            .collect();
        for k in keys {
            let (x, y) = (a.record.counts.get(k), b.record.counts.get(k));
            if x != y {
                let (x0, y0) = (
                    x.copied().unwrap_or(0) as f64,
                    y.copied().unwrap_or(0) as f64,
                );
                d.worst = d.worst.max((x0 - y0).abs() / x0.max(y0).max(1.0));
                d.counts.push(format!(
                    "{k} {} → {}",
                    x.map_or("-".into(), |v| v.to_string()),
                    y.map_or("-".into(), |v| v.to_string())
                ));
            }
        }
    }
    Ok(d)
}

/// A recorded version, or what an older record without one is.
fn or_unknown(version: &str) -> &str {
    if version.is_empty() {
        "(a version that did not record itself)"
    } else {
        version
    }
}

/// Compare every case of `out` with `against`; print a table, write `report.md` into `out`,
/// and fail where the drivers disagree.
fn compare_all(
    args: &ParityArgs,
    out: &Path,
    against: &Path,
    mut theirs: BTreeMap<String, Recorded>,
) -> Result<()> {
    let mut lines = vec![
        "| case | pixels | allowed | other first hit | edge ties | other shadow | other colour | counts |"
            .to_string(),
        "|---|---|---|---|---|---|---|---|".to_string(),
    ];
    let mut failed = Vec::new();
    let (mut renderer_a, mut renderer_b) = (String::new(), String::new());
    let (mut version, mut profiles) = (String::new(), String::new());
    for spec in cases(args.only.as_deref(), args.size) {
        let case = spec.name;
        let ours = load(&out.join(&case))?;
        let theirs = theirs.remove(&case).expect("check_against read every case");
        if ours.record.version != theirs.record.version && !args.any_commit {
            bail!(
                "{}: recorded by gpgpu-rt {}, this is {}: record both with the same build, or \
                 pass --any-commit",
                against.join(&case).display(),
                or_unknown(&theirs.record.version),
                ours.record.version
            );
        }
        renderer_a.clone_from(&ours.record.renderer);
        renderer_b.clone_from(&theirs.record.renderer);
        version.clone_from(&ours.record.version);
        profiles = format!("{} against {}", ours.record.profile, theirs.record.profile);
        let d = compare(&theirs, &ours)?;
        let allowed = (args.tolerance * d.pixels as f64).floor() as usize;
        let counts_ok = d.worst <= args.count_tolerance;
        let counts = match (d.counts.is_empty(), d.note.is_empty()) {
            (true, true) => "equal".to_string(),
            (true, false) => d.note.clone(),
            (false, _) if counts_ok => {
                format!("within {}: {}", args.count_tolerance, d.counts.join("; "))
            }
            (false, _) => d.counts.join("; "),
        };
        let colours = d.colours.unwrap_or(0);
        let pixels_ok =
            d.order_dependent || (d.hits <= allowed && d.shadows <= allowed && colours <= allowed);
        if !pixels_ok || !counts_ok {
            failed.push(case.clone());
        }
        let colour = d.colours.map_or("-".to_string(), |n| n.to_string());
        lines.push(format!(
            "| {case} | {} | {allowed} | {} | {} | {} | {colour} | {counts} |",
            d.pixels, d.hits, d.ties, d.shadows
        ));
    }
    let report = format!(
        "# Driver parity\n\ngpgpu-rt {version}, profiles {profiles}.\n\n`{}` (this run) against \
         `{}` (`{}`), {}² pixels where a case names \
         no other size; pixels that may differ (`allowed`, in first hit, shadow and colour \
         each): {} of each case's; a colour differs where a channel is off by more than {:.2e} \
         (a quarter of an 8-bit step); counts: within {} of each other.\n\n{}\n\n{}\n",
        renderer_a,
        renderer_b,
        against.display(),
        args.size,
        args.tolerance,
        COLOUR_TOLERANCE,
        args.count_tolerance,
        lines.join("\n"),
        if failed.is_empty() {
            "Every case agrees.".to_string()
        } else {
            format!("Differ: {}.", failed.join(", "))
        }
    );
    std::fs::write(out.join("report.md"), &report)
        .with_context(|| format!("cannot write {}", out.join("report.md").display()))?;
    outln!("{report}")?;
    if !failed.is_empty() {
        bail!(
            "{} of the cases differ between the drivers: {}",
            failed.len(),
            failed.join(", ")
        );
    }
    Ok(())
}

/// The folder `path` names, with its links resolved; a path not made yet (`--out`) resolved
/// through the nearest folder above it that exists.
fn resolved(path: &Path) -> PathBuf {
    let mut missing = Vec::new();
    let mut p = path.to_path_buf();
    loop {
        if let Ok(real) = std::fs::canonicalize(&p) {
            return missing.iter().rev().fold(real, |acc, part| acc.join(part));
        }
        match (p.file_name().map(|n| n.to_owned()), p.parent()) {
            (Some(name), Some(parent)) => {
                missing.push(name);
                p = if parent.as_os_str().is_empty() {
                    PathBuf::from(".")
                } else {
                    parent.to_path_buf()
                };
            }
            _ => return path.to_path_buf(),
        }
    }
}

/// Before anything renders: `--out` is not `--against` nor inside it or around it (the run
/// would overwrite the record it is compared with), and every case of `--against` is there
/// and readable — all that is wrong named at once. The cases read, by name.
fn check_against(
    args: &ParityArgs,
    out: &Path,
    against: &Path,
) -> Result<BTreeMap<String, Recorded>> {
    let (o, a) = (resolved(out), resolved(against));
    if o.starts_with(&a) || a.starts_with(&o) {
        bail!(
            "--out {} and --against {} are the same folder or one holds the other: the run would \
             overwrite the record it is compared with; record into another folder",
            out.display(),
            against.display()
        );
    }
    if !against.is_dir() {
        bail!("--against {}: no such folder", against.display());
    }
    let (mut read, mut broken) = (BTreeMap::new(), Vec::new());
    for c in cases(args.only.as_deref(), args.size) {
        match load(&against.join(&c.name)) {
            Err(e) => broken.push(format!("{}: {e:#}", c.name)),
            Ok(r)
                if r.record.skipped.is_empty()
                    && (r.record.width, r.record.height) != (c.how.width, c.how.height) =>
            {
                broken.push(format!(
                    "{}: recorded at {}x{}, this run renders {}x{}",
                    c.name, r.record.width, r.record.height, c.how.width, c.how.height
                ))
            }
            Ok(r) => {
                read.insert(c.name, r);
            }
        }
    }
    if !broken.is_empty() {
        bail!(
            "--against {}: {} of its cases cannot be compared (record them with the same \
             gpgpu-rt and --size):\n  {}",
            against.display(),
            broken.len(),
            broken.join("\n  ")
        );
    }
    Ok(read)
}

pub fn run(args: ParityArgs) -> Result<()> {
    if args.list {
        for c in cases(args.only.as_deref(), args.size) {
            outln!("{:44} {}", c.name, c.how.describe(&c.design))?;
        }
        return Ok(());
    }
    let out = args
        .out
        .clone()
        .expect("clap requires --out without --list");
    let theirs = match &args.against {
        Some(against) => Some(check_against(&args, &out, against)?),
        None => None,
    };
    let ctx = GlContext::headless(args.gpu.device)?;
    errln!(
        "parity on {} ({}), profile {}",
        ctx.info.renderer,
        ctx.info.version,
        ctx.info.profile.name.as_str()
    )?;
    record(&ctx, &args, &out)?;
    if let (Some(against), Some(theirs)) = (&args.against, theirs) {
        compare_all(&args, &out, against, theirs)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recorded(ids: &[i32], t: &[f32], shadow: &[f32], counts: &[(&str, u64)]) -> Recorded {
        Recorded {
            record: CaseRecord {
                renderer: "test".into(),
                width: ids.len() as u32,
                height: 1,
                counts: counts.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
                counts_depend_on_order: String::new(),
                skipped: String::new(),
                version: String::new(),
                profile: String::new(),
            },
            triangle_id: ids.to_vec(),
            hit_t: t.to_vec(),
            shadow: Some(shadow.to_vec()),
            color: None,
        }
    }

    #[test]
    fn ties_hits_shadows_and_counts_are_told_apart() {
        let a = recorded(
            &[1, 2, 3, -1, 5],
            &[1.0, 2.0, 3.0, f32::INFINITY, 5.0],
            &[1.0; 5],
            &[("n", 100)],
        );
        // pixel 1: another triangle at the same distance (a tie); pixel 2: another hit;
        // pixel 4: the same hit, another shadow
        let b = recorded(
            &[1, 7, 8, -1, 5],
            &[1.0, 2.0, 2.5, f32::INFINITY, 5.0],
            &[1.0, 1.0, 1.0, 1.0, 0.5],
            &[("n", 101)],
        );
        let d = compare(&a, &b).unwrap();
        assert_eq!((d.pixels, d.ties, d.hits, d.shadows), (5, 1, 1, 1));
        assert_eq!(d.counts, vec!["n 100 → 101".to_string()]);
        assert!((d.worst - 1.0 / 101.0).abs() < 1e-12);
        // counts a driver's batches or atomics decide are not compared
        let mut c = recorded(&[1, 2, 3, -1, 5], &[1.0; 5], &[1.0; 5], &[("n", 7)]);
        c.record.counts_depend_on_order = "atomics".into();
        let d = compare(&a, &c).unwrap();
        assert!(d.order_dependent && d.counts.is_empty(), "{d:?}");
        let mut e = recorded(
            &[1, 2, 3, -1, 5],
            &[1.0; 5],
            &[1.0; 5],
            &[("n", 7), ("ray_batches", 2)],
        );
        e.record.counts.insert("ray_batches".into(), 2);
        let d = compare(&a, &e).unwrap();
        assert!(d.counts.is_empty() && d.note.contains("batches"), "{d:?}");
    }

    #[test]
    fn a_case_folder_whose_arrays_miss_pixels_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let r = recorded(&[1, 2, 3, 4], &[1.0; 4], &[1.0; 4], &[]);
        let frame = Frame {
            width: 4,
            height: 1,
            color: vec![[0.0; 4]; 4],
            aovs: Some(gpgpu_rt::frame::Aovs {
                triangle_id: vec![1, 2, 3, 4],
                hit_t: vec![1.0; 4],
                ..Default::default()
            }),
            stats: Default::default(),
        };
        write_case(dir.path(), Some(&frame), &r.record, false).unwrap();
        // a folder cut short: three ids for the record's four pixels
        write_npy(&dir.path().join("triangle_id.npy"), &[3], [1, 2, 3]).unwrap();
        let e = load(dir.path())
            .err()
            .expect("3 values for 4 pixels")
            .to_string();
        assert!(
            e.contains("triangle_id.npy") && e.contains("3 values"),
            "{e}"
        );
    }
}
