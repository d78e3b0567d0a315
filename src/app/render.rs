//! `gpgpu-rt render`: one scene, one renderer (the ray tracer with an accelerator, or the
//! soft-shadow pipeline), the PNG, the AOVs and the statistics of the last frame.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::parser::ValueSource;
use clap::ArgMatches;
use serde_json::json;

use crate::args::{GpuArgs, GridArgs, SoftShadowArgs};
use gpgpu_rt::accel::{BvhVariant, TracerKind};
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::output::{Format, Staging, Target};
use gpgpu_rt::pipeline::klee2016::SoftShadowRenderer;
use gpgpu_rt::pipeline::mueller2015::{RenderOptions, ShadowFlags};
use gpgpu_rt::pipeline::{self, Renderer};
use gpgpu_rt::scene::{Scene, ShadowMode};
use gpgpu_rt::{limits, output};

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene file (TOML), e.g. scenes/teapot1.toml.
    scene: PathBuf,
    /// Output image: PNG, or JPEG for a name ending in .jpg or .jpeg.
    #[arg(short, long, default_value = "out.png")]
    output: PathBuf,
    /// Image width, 1 to 16384 (default: the scene's render.width).
    #[arg(long, value_parser = limits::parser(limits::IMAGE_SIDE))]
    width: Option<u32>,
    /// Image height, 1 to 16384 (default: the scene's render.height).
    #[arg(long, value_parser = limits::parser(limits::IMAGE_SIDE))]
    height: Option<u32>,
    /// The accelerator of Müller 2015's four-kernel pipeline: `bvh` (ours: an SAH BVH, the
    /// fastest), `base` (the thesis' base tracer, every ray against every triangle) or `grid`
    /// (the thesis' uniform grid, see --grid-variant); or `stream`, seed 004's streaming tracer
    /// (fragment-program kernels, a static grid, occlusion-query halting).
    #[arg(long, value_enum, default_value = "bvh")]
    tracer: TracerKind,
    /// With --tracer bvh: `sah` (ours, in the four-kernel pipeline) or `wagner` (Wagner 2018
    /// faithful: his BVH build, three textures, one kernel per pixel, one light, Lambert, hard
    /// shadows, no reflection).
    #[arg(long, value_enum, default_value = "sah")]
    bvh_variant: BvhVariant,
    /// Reflection passes after the primary pass, REFL_DEPTH of Fig. 8, 0 to 16 (default: the
    /// scene's).
    #[arg(long, value_parser = limits::parser(limits::REFL_DEPTH))]
    refl_depth: Option<u32>,
    /// Shadow flags: `rgba` as the thesis (4 lights) or `bits` (128 lights).
    #[arg(long, value_enum, default_value = "bits")]
    shadow_flags: ShadowFlags,
    /// Split every dispatch into tiles of at most N×N pixels (multiple of 8; 0: no tiling),
    /// so that no dispatch runs long enough for a driver watchdog.
    #[arg(long, default_value_t = 256, value_name = "N")]
    tile: u32,
    /// Write NumPy AOVs (ray_origin, ray_direction, hit_t, triangle_id, normal, shadow) here.
    #[arg(long, value_name = "DIR")]
    aov_dir: Option<PathBuf>,
    /// Write the statistics of the frame as JSON.
    #[arg(long, value_name = "FILE.json")]
    stats: Option<PathBuf>,
    /// Render the frame this many times (1 to 100000) and report the last (the first ones
    /// warm up: shader compilation on first use, caches).
    #[arg(long, default_value_t = 1, value_name = "N", value_parser = limits::parser(limits::FRAMES))]
    frames: u32,
    #[command(flatten)]
    grid: GridArgs,
    #[command(flatten)]
    soft: SoftShadowArgs,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// The options among `ids` (clap ids: the field names) that the command line gave
/// explicitly, as `--long-name`.
fn given_options(m: Option<&ArgMatches>, ids: &[&str]) -> Vec<String> {
    let Some(m) = m else { return Vec::new() };
    ids.iter()
        .filter(|id| m.value_source(id) == Some(ValueSource::CommandLine))
        .map(|id| format!("--{}", id.replace('_', "-")))
        .collect()
}

/// "does"/"do" and "an option"/"options" for a list of options.
fn verb(options: &[String]) -> (&'static str, &'static str) {
    match options.len() {
        1 => ("does", "an option"),
        _ => ("do", "options"),
    }
}

/// Options of the pipeline this render does not use are refused, not ignored.
fn refuse_other_pipeline(
    args: &RenderArgs,
    scene: &Scene,
    matches: Option<&ArgMatches>,
) -> Result<()> {
    let given = |ids: &[&str]| given_options(matches, ids);
    if let Some(mode) = args.soft.shadows {
        let ray_tracer_only = given(&[
            "tracer",
            "bvh_variant",
            "refl_depth",
            "shadow_flags",
            "grid",
            "grid_variant",
            "voxel_array_length",
            "ray_array_length",
            "proximity_clouds",
            "stream_steps",
            "stream_max_calls",
        ]);
        if !ray_tracer_only.is_empty() {
            let (does, an_option) = verb(&ray_tracer_only);
            bail!(
                "{} {does} not apply: {an_option} of the point-light ray tracers, and this render uses the \
                 soft-shadow pipeline (`{}`, from {})",
                ray_tracer_only.join(", "),
                mode.name(),
                if given(&["shadows"]).is_empty() {
                    format!("render.shadows in {}", scene.path.display())
                } else {
                    "--shadows".to_string()
                }
            );
        }
    } else {
        refuse_for_bvh_variant(args, &given)?;
        refuse_for_stream(args, &given)?;
        let soft_only = given(&["light_samples", "ntree_n", "ntree_depth"]);
        if !soft_only.is_empty() {
            bail!(
                "{} {} not apply without soft shadows: add --shadows \
                 exact|linespace|linespace-dda (the scene needs an [[area_light]])",
                soft_only.join(", "),
                verb(&soft_only).0
            );
        }
    }
    Ok(())
}

/// `--bvh-variant` only with `--tracer bvh`; Wagner 2018's kernel has no reflection passes and
/// no shadow-flag texture, so their options are refused with it.
fn refuse_for_bvh_variant(args: &RenderArgs, given: &dyn Fn(&[&str]) -> Vec<String>) -> Result<()> {
    if args.tracer != TracerKind::Bvh && !given(&["bvh_variant"]).is_empty() {
        bail!(
            "--bvh-variant applies to --tracer bvh only (this render uses --tracer {})",
            args.tracer.name()
        );
    }
    if args.tracer == TracerKind::Bvh && args.bvh_variant == BvhVariant::Wagner {
        let not_wagner = given(&["refl_depth", "shadow_flags"]);
        if !not_wagner.is_empty() {
            let (does, an_option) = verb(&not_wagner);
            bail!(
                "{} {does} not apply: {an_option} of Müller 2015's pipeline, and --bvh-variant wagner \
                 renders with Wagner 2018's kernel (one light, hard shadows, no reflection)",
                not_wagner.join(", ")
            );
        }
    }
    Ok(())
}

/// The streaming tracer's options only with `--tracer stream`, and the options of Müller's
/// pipeline that it has no use for (its grid is always exact, it has no shadow-flag texture and
/// no tiles) refused with it.
fn refuse_for_stream(args: &RenderArgs, given: &dyn Fn(&[&str]) -> Vec<String>) -> Result<()> {
    let stream_only = given(&["stream_steps", "stream_max_calls"]);
    if args.tracer != TracerKind::Stream && !stream_only.is_empty() {
        bail!(
            "{} {} to --tracer stream only (this render uses --tracer {})",
            stream_only.join(", "),
            if stream_only.len() == 1 {
                "applies"
            } else {
                "apply"
            },
            args.tracer.name()
        );
    }
    let not_stream = given(&[
        "grid_variant",
        "voxel_array_length",
        "ray_array_length",
        "shadow_flags",
        "tile",
    ]);
    if args.tracer == TracerKind::Stream && !not_stream.is_empty() {
        let (does, an_option) = verb(&not_stream);
        bail!(
            "{} {does} not apply: {an_option} of the compute pipelines, and --tracer stream renders \
             with seed 004's fragment programs (its own grid, no tiles, no shadow-flag texture)",
            not_stream.join(", ")
        );
    }
    Ok(())
}

/// The renderer the options choose: Klee 2016's soft shadows with `--shadows` (or the scene's
/// render.shadows), else the point-light ray tracer: Müller 2015's with the `--tracer` accelerator, or
/// Wagner 2018's with `--tracer bvh --bvh-variant wagner`.
fn make_renderer(
    ctx: &GlContext,
    scene: &Scene,
    shaders: &ShaderSource,
    args: &RenderArgs,
) -> Result<Box<dyn Renderer>> {
    let width = args.width.unwrap_or(scene.settings.width);
    let height = args.height.unwrap_or(scene.settings.height);
    if let Some(mode) = args.soft.shadows {
        let opts = args.soft.options(mode, width, height, args.tile);
        let r = SoftShadowRenderer::new(ctx.gl.clone(), &ctx.info, scene, shaders, opts)?;
        return Ok(Box::new(r));
    }
    let options = RenderOptions {
        tracer: args.tracer,
        width,
        height,
        refl_depth: args.refl_depth.unwrap_or(scene.settings.refl_depth),
        tile: args.tile,
        shadow_flags: args.shadow_flags,
        aovs: args.aov_dir.is_some(),
        grid: args.grid.options(),
        bvh_variant: args.bvh_variant,
    };
    pipeline::ray_tracer(ctx.gl.clone(), &ctx.info, scene, shaders, options)
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
    let mut t = vec![Target::file("-o", &args.output, Format::Image)];
    if let Some(dir) = &args.aov_dir {
        t.extend(Target::in_folder(
            "--aov-dir",
            dir,
            &output::AOV_FILES,
            Format::Npy,
        ));
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
    let img = output::frame_image(frame);
    s.file(&args.output, |w| {
        output::encode_image(&img, &args.output, w)
    })?;
    if let (Some(dir), Some(aovs)) = (&args.aov_dir, &frame.aovs) {
        output::stage_aovs(&mut s, dir, frame.width, frame.height, aovs)?;
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
    mode: Option<ShadowMode>,
    args: &RenderArgs,
    f: &Frame,
) -> String {
    let s = &f.stats;
    let what = match mode {
        Some(mode) => {
            let (u, v) = args.soft.samples();
            format!("soft shadows `{}` with {u}x{v} samples", mode.name())
        }
        None if args.tracer == TracerKind::Bvh && args.bvh_variant == BvhVariant::Wagner => {
            "1 light, Wagner 2018's bvh tracer".to_string()
        }
        None => format!(
            "{} lights, {} tracer",
            scene.lights.len(),
            args.tracer.name()
        ),
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

/// `render`: load, check the options, render `--frames` frames, write the last.
pub fn run(mut args: RenderArgs, matches: Option<&ArgMatches>) -> Result<()> {
    let targets = targets(&args);
    output::check(&targets)?;
    let scene = Scene::load(&args.scene)?;
    output::refuse_inputs(&targets, &output::scene_inputs(&scene))?;
    let shaders = ShaderSource::from_dir(args.gpu.glsl_dir.clone())?;
    args.soft = args.soft.clone().with_scene_defaults(&scene.settings);
    refuse_other_pipeline(&args, &scene, matches)?;
    let ctx = GlContext::headless(args.gpu.device)?;
    let mut r = make_renderer(&ctx, &scene, &shaders, &args)?;
    // `--frames N`: N − 1 warm-up frames (shader compilation on first use), the last reported
    for _ in 1..args.frames {
        r.draw(&scene.camera)?;
    }
    let frame = r.render(&scene.camera)?;
    write_outputs(&args, &ctx, &scene, r.as_ref(), &frame)?;
    eprintln!(
        "{}",
        summary(&ctx, &scene, args.soft.shadows, &args, &frame)
    );
    Ok(())
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
