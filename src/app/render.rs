//! `gpgpu-rt render`: one scene, one renderer (the ray tracer with an accelerator, or the
//! soft-shadow pipeline), the PNG, the AOVs and the statistics of the last frame.

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::ArgMatches;
use serde_json::json;

use crate::args::{DesignArgs, GpuArgs};
use crate::bench::runner::args::Rotation;
use crate::bench::runner::Turntable;
use gpgpu_rt::design::Design;
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::output::{AovFormat, Format, Staging, Target};
use gpgpu_rt::pipeline::mueller2015::gpu_scene;
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::progress;
use gpgpu_rt::scene::Camera;
use gpgpu_rt::scene::Scene;
use gpgpu_rt::{limits, output};

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene file: TOML (e.g. scenes/teapot1.toml) or glTF 2.0 (.gltf, .glb).
    scene: PathBuf,
    /// Output image: PNG; JPEG for a name ending in .jpg or .jpeg; OpenEXR (linear float RGB,
    /// not clamped) for .exr.
    #[arg(short, long, default_value = "out.png")]
    output: PathBuf,
    /// Image width, 1 to 16384 (default: the scene's render.width).
    #[arg(long, value_parser = limits::parser(limits::IMAGE_SIDE))]
    width: Option<u32>,
    /// Image height, 1 to 16384 (default: the scene's render.height).
    #[arg(long, value_parser = limits::parser(limits::IMAGE_SIDE))]
    height: Option<u32>,
    /// Write the AOVs (ray_origin, ray_direction, hit_t, triangle_id, normal, shadow) here.
    #[arg(long, value_name = "DIR")]
    aov_dir: Option<PathBuf>,
    /// How --aov-dir writes them: `npy`, a NumPy file each; `exr`, one OpenEXR file
    /// `aovs.exr` whose channels are named as the npy files (normal.X, …; triangle_id a UINT
    /// channel with the npy's bits, a miss 4294967295).
    #[arg(long, value_enum, default_value_t = AovFormat::Npy, requires = "aov_dir")]
    aov_format: AovFormat,
    /// Write the statistics of the frame as JSON.
    #[arg(long, value_name = "FILE.json")]
    stats: Option<PathBuf>,
    /// Render the frame this many times (1 to 100000) and report the last (the first ones
    /// warm up: shader compilation on first use, caches).
    #[arg(long, default_value_t = 1, value_name = "N", value_parser = limits::parser(limits::FRAMES))]
    frames: u32,
    /// Turn the scene from frame to frame, `--turn` degrees a frame (the first frame already
    /// turned once): every object about the vertical axis through the scene's centre
    /// (`objects`, moving objects as `bench --rotate objects` does) or the camera around it.
    #[arg(long, value_enum, value_name = "HOW")]
    rotate: Option<Rotation>,
    /// Degrees the scene turns a frame with `--rotate`.
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "DEG",
        requires = "rotate",
        allow_negative_numbers = true,
        value_parser = crate::args::finite_f32
    )]
    turn: f32,
    /// No progress line (one appears on a terminal when a render takes more than 2 s).
    #[arg(long)]
    quiet: bool,
    #[command(flatten)]
    design: DesignArgs,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// The statistics document of a frame (the keys of `render --stats`).
pub fn stats_doc(ctx: &GlContext, scene: &Scene, r: &dyn Renderer, f: &Frame) -> serde_json::Value {
    let s = &f.stats;
    let mut doc = json!({
        "scene": scene.path,
        "renderer": ctx.info.renderer,
        "gl_version": ctx.info.version,
        "vendor": ctx.info.vendor,
        "tracer": r.name(),
        "width": f.width,
        "height": f.height,
        "triangles": scene.triangle_count(),
        "triangle_tests": s.triangle_tests,
        "triangle_tests_total": s.total_triangle_tests(),
        "events": s.events,
        "truncated_rays": s.truncated_rays,
        "gpu_ms": s.gpu_ms,
        "gpu_ms_total": s.total_gpu_ms(),
        "wall_ms": s.wall_ms,
        "gpgpu_rt_version": gpgpu_rt::VERSION,
        "profile": ctx.info.profile.name.as_str(),
    });
    if !s.ray_kinds.is_empty() {
        doc["ray_kinds"] = json!(s.ray_kinds);
    }
    for (k, v) in r.settings() {
        doc[k] = v;
    }
    for (k, v) in &s.facts {
        doc[k] = v.clone();
    }
    for (k, v) in &s.events {
        doc[k] = json!(v);
    }
    doc
}

/// The output files of a render: the image, the AOVs (`--aov-dir`), the statistics (`--stats`).
fn targets(args: &RenderArgs) -> Vec<Target> {
    let mut t = vec![Target::file("-o", &args.output, Format::ColorImage)];
    if let Some(dir) = &args.aov_dir {
        let (files, format) = match args.aov_format {
            AovFormat::Npy => (&output::AOV_FILES[..], Format::Npy),
            AovFormat::Exr => (&[output::AOV_EXR][..], Format::Exr),
        };
        t.extend(Target::in_folder("--aov-dir", dir, files, format));
    }
    if let Some(path) = &args.stats {
        t.push(Target::file("--stats", path, Format::Json));
    }
    t
}

/// The image, the AOVs (`--aov-dir`) and the statistics (`--stats`) of `frame`: all of them
/// or, when one cannot be written, none (the old files stay as they were).
fn write_outputs(
    args: &RenderArgs,
    ctx: &GlContext,
    scene: &Scene,
    r: &dyn Renderer,
    frame: &Frame,
) -> Result<()> {
    let mut s = Staging::new();
    s.file(&args.output, |w| {
        output::encode_color(frame, &args.output, w)
    })?;
    if let (Some(dir), Some(aovs)) = (&args.aov_dir, &frame.aovs) {
        let size = (frame.width, frame.height);
        output::stage_aovs_as(&mut s, args.aov_format, dir, size, aovs)?;
    }
    if let Some(path) = &args.stats {
        let doc = stats_doc(ctx, scene, r, frame);
        output::stage_text(&mut s, path, &(serde_json::to_string_pretty(&doc)? + "\n"))?;
    }
    s.commit()
}

/// What was rendered, in one line on stderr.
fn summary(
    ctx: &GlContext,
    scene: &Scene,
    design: &Design,
    args: &RenderArgs,
    f: &Frame,
) -> String {
    let s = &f.stats;
    let what = match design {
        Design::Klee2016(o) => format!(
            "soft shadows `{}` with {}x{} samples",
            o.mode.name(),
            o.samples_u,
            o.samples_v
        ),
        Design::Wagner2018(_) => "1 light, Wagner 2018's bvh tracer".to_string(),
        d => {
            let n = scene.lights.len();
            let plural = if n == 1 { "" } else { "s" };
            format!("{n} light{plural}, {} tracer", d.row().name)
        }
    };
    let mut line = format!(
        "{}: {}x{}, {} triangles, {what} on {}: {:.1} GPU ms, {} triangle tests",
        scene.path.display(),
        f.width,
        f.height,
        scene.triangle_count(),
        ctx.info.renderer,
        s.total_gpu_ms(),
        s.total_triangle_tests(),
    );
    if let Some(n) = s.events.get("linespace_lookups") {
        line += &format!(", {n} line-space lookups");
    }
    line + &format!(" -> {}", args.output.display())
}

/// `render`: load, parse the design (refusing the options that do not belong to it), render
/// `--frames` frames, write the last.
pub fn run(args: RenderArgs, matches: Option<&ArgMatches>) -> Result<()> {
    let targets = targets(&args);
    output::check(&targets)?;
    let ticker = progress::Ticker::start(args.quiet);
    progress::stage("loading the scene");
    // the GL limits from the scene file's counts, before its meshes take the memory
    let (triangles, settings) = Scene::count_triangles(&args.scene)?;
    let ctx = GlContext::headless(args.gpu.device)?;
    if args.design.uses_scene_buffers(&settings) {
        gpu_scene::check_counts(&ctx.info, &args.scene, triangles)?;
    }
    let scene = Scene::load(&args.scene)?;
    output::refuse_inputs(&targets, &output::scene_inputs(&scene))?;
    let shaders = ShaderSource::from_dir(args.gpu.glsl_dir.clone())?;
    let size = (
        args.width.unwrap_or(scene.settings.width),
        args.height.unwrap_or(scene.settings.height),
    );
    let design_args = match args.rotate {
        // the objects move every frame: the SAH BVH's two levels where it may choose
        Some(Rotation::Objects) => DesignArgs {
            bvh: args.design.bvh.clone().objects_move(),
            ..args.design.clone()
        },
        _ => args.design.clone(),
    };
    let design = design_args.design(&scene, size, args.aov_dir.is_some(), matches)?;
    progress::stage(format!("building the {}", design.row().name));
    let mut r = design.renderer(ctx.gl.clone(), &ctx.info, &scene, &shaders)?;
    // `--frames N`: N − 1 warm-up frames (shader compilation on first use), the last reported
    let table = args.rotate.map(|how| Turntable::new(&scene, how));
    let n = args.frames;
    for i in 1..n {
        progress::stage(format!("frame {i} of {n}"));
        let camera = turn(&args, &scene, &table, r.as_mut(), i)?;
        r.draw(&camera)?;
    }
    progress::stage(format!("frame {n} of {n}"));
    let camera = turn(&args, &scene, &table, r.as_mut(), n)?;
    let frame = r.render(&camera)?;
    progress::stage("writing the outputs");
    write_outputs(&args, &ctx, &scene, r.as_ref(), &frame)?;
    drop(ticker);
    gpgpu_rt::errln!("{}", summary(&ctx, &scene, &design, &args, &frame))?;
    Ok(())
}

/// The camera of frame `i` (from 1): with `--rotate`, the scene turned by `i` × `--turn`
/// degrees on `table` (the objects' model matrices set in `r`, or the camera orbited).
fn turn(
    args: &RenderArgs,
    scene: &Scene,
    table: &Option<Turntable>,
    r: &mut dyn Renderer,
    i: u32,
) -> Result<Camera> {
    match table {
        Some(t) => t.turn(&mut |k, m| r.set_model(k, m), args.turn as f64 * i as f64),
        None => Ok(scene.camera),
    }
}

/// `export-triangles`: the scene's world-space triangles as f32 [T,3,3].
pub fn export_triangles(scene: &Path, out: &Path) -> Result<()> {
    let targets = [Target::file("-o", out, Format::Npy)];
    output::check(&targets)?;
    let scene = Scene::load(scene)?;
    output::refuse_inputs(&targets, &output::scene_inputs(&scene))?;
    let tris = scene.world_triangles();
    output::write_npy(
        out,
        &[tris.len() as u64, 3, 3],
        tris.iter()
            .flat_map(|t| t.iter().flat_map(|v| v.to_array())),
    )
}
