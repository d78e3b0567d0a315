//! The `gpgpu-rt` command line: the application (CLI, viewer, bench protocols) on top of the
//! `gpgpu_rt` library.

mod bench;
mod soft_cli;
mod view;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context as _, Result};
use clap::parser::ValueSource;
use clap::{ArgMatches, CommandFactory, FromArgMatches, Subcommand};
use serde_json::json;

use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::output;
use gpgpu_rt::scene::Scene;
use gpgpu_rt::tracer::{self, GridArgs, RenderOptions, ShadowFlags, TracerKind};

#[derive(clap::Parser)]
#[command(
    name = "gpgpu-rt",
    version,
    about = "GPU ray tracing in OpenGL 4.5 compute shaders (after Müller 2015 and related works)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args)]
struct GpuArgs {
    /// EGL device index (default: the first that gives an OpenGL 4.5 core context).
    #[arg(long)]
    device: Option<usize>,
    /// Load the GLSL kernels from this directory instead of the copies built into the binary.
    #[arg(long, value_name = "DIR")]
    glsl_dir: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a PNG.
    Render {
        /// Scene file (TOML), e.g. scenes/teapot1.toml.
        scene: PathBuf,
        /// Output PNG.
        #[arg(short, long, default_value = "out.png")]
        output: PathBuf,
        /// Image width (default: the scene's render.width).
        #[arg(long)]
        width: Option<u32>,
        /// Image height (default: the scene's render.height).
        #[arg(long)]
        height: Option<u32>,
        #[arg(long, value_enum, default_value = "base")]
        tracer: TracerKind,
        /// Reflection passes after the primary pass, REFL_DEPTH of Fig. 8 (default: the scene's).
        #[arg(long)]
        refl_depth: Option<u32>,
        /// Shadow flags: `rgba` as the thesis (4 lights) or `bits` (128 lights).
        #[arg(long, value_enum, default_value = "bits")]
        shadow_flags: ShadowFlags,
        /// Split every dispatch into tiles of at most N×N pixels (multiple of 8; 0: no tiling),
        /// so that no dispatch runs long enough for a driver watchdog.
        #[arg(long, default_value_t = 256, value_name = "N")]
        tile: u32,
        /// Write NumPy AOVs (ray_origin, ray_direction, hit_t, triangle_id, normal) here.
        #[arg(long, value_name = "DIR")]
        aov_dir: Option<PathBuf>,
        /// Write the statistics of the frame as JSON.
        #[arg(long, value_name = "FILE.json")]
        stats: Option<PathBuf>,
        /// Render the frame this many times and report the last (the first ones warm up:
        /// shader compilation on first use, caches).
        #[arg(long, default_value_t = 1, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
        frames: u32,
        #[command(flatten)]
        grid: GridArgs,
        #[command(flatten)]
        soft: soft_cli::SoftShadowArgs,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// Write the scene's world-space triangles as f32 [T,3,3] in triangle-id order.
    ExportTriangles {
        scene: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Open a window that shows the scene live (orbit, pan, zoom; live-editable kernels with
    /// --glsl-dir); --screenshot FILE.png --frames N saves the N-th frame and exits.
    View(view::ViewArgs),
    /// Replicate a published evaluation (thesis-5.x: Müller 2015, ch. 5; klee-*: Klee 2016,
    /// ch. 5): CSVs, plots and report.md with our numbers beside the published ones.
    Bench(bench::BenchArgs),
    /// Print the GL implementation's vendor, renderer, version and limits, and a scene's counts.
    Info {
        scene: Option<PathBuf>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        gpu: GpuArgs,
    },
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let matches = Cli::command().get_matches();
    let cli = match Cli::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    match run(cli, &matches) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
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

fn load_scene(path: &Path) -> Result<Scene> {
    Ok(Scene::load(path)?)
}

fn run(cli: Cli, matches: &ArgMatches) -> Result<()> {
    match cli.command {
        Command::Render {
            scene,
            output,
            width,
            height,
            tracer,
            refl_depth,
            shadow_flags,
            tile,
            aov_dir,
            stats,
            frames,
            grid,
            soft,
            gpu,
        } => {
            let scene = load_scene(&scene)?;
            let shaders = ShaderSource::from_dir(gpu.glsl_dir)?;
            let soft = soft.with_scene_defaults(&scene.settings);
            // options of the pipeline this render does not use are refused, not ignored
            let given = |ids: &[&str]| given_options(matches.subcommand_matches("render"), ids);
            if let Some(mode) = soft.shadows {
                let ray_tracer_only = given(&[
                    "tracer",
                    "refl_depth",
                    "shadow_flags",
                    "grid",
                    "grid_variant",
                    "voxel_array_length",
                    "ray_array_length",
                ]);
                if !ray_tracer_only.is_empty() {
                    bail!(
                        "{} {} not apply: {} of the point-light ray tracers, and this render uses the \
                         soft-shadow pipeline (`{}`, from {})",
                        ray_tracer_only.join(", "),
                        if ray_tracer_only.len() == 1 { "does" } else { "do" },
                        if ray_tracer_only.len() == 1 { "an option" } else { "options" },
                        mode.name(),
                        if given(&["shadows"]).is_empty() {
                            format!("render.shadows in {}", scene.path.display())
                        } else {
                            "--shadows".to_string()
                        }
                    );
                }
            } else {
                let soft_only = given(&["light_samples", "ntree_n", "ntree_depth"]);
                if !soft_only.is_empty() {
                    bail!(
                        "{} {} not apply without soft shadows: add --shadows \
                         exact|linespace|linespace-dda (the scene needs an [[area_light]])",
                        soft_only.join(", "),
                        if soft_only.len() == 1 { "does" } else { "do" }
                    );
                }
            }
            let ctx = GlContext::headless(gpu.device)?;
            if let Some(mode) = soft.shadows {
                // Klee 2016: G-buffer, soft-shadow compute pass, screen-filling quad
                let (w, h) = (
                    width.unwrap_or(scene.settings.width),
                    height.unwrap_or(scene.settings.height),
                );
                let opts = soft.options(mode, w, h, tile);
                return soft_cli::render(
                    &ctx,
                    &scene,
                    &shaders,
                    opts,
                    frames,
                    &output,
                    aov_dir.as_deref(),
                    stats.as_deref(),
                );
            }
            let options = RenderOptions {
                width: width.unwrap_or(scene.settings.width),
                height: height.unwrap_or(scene.settings.height),
                refl_depth: refl_depth.unwrap_or(scene.settings.refl_depth),
                tile,
                shadow_flags,
                aovs: aov_dir.is_some(),
                grid: grid.options(),
            };
            let mut t = tracer::create(
                tracer,
                ctx.gl.clone(),
                &ctx.info,
                &scene,
                &shaders,
                options.clone(),
            )?;
            let mut frame = t.render(&scene.camera)?;
            for _ in 1..frames {
                frame = t.render(&scene.camera)?;
            }
            let name = t.name();
            output::write_png(&output, &frame)?;
            if let (Some(dir), Some(aovs)) = (&aov_dir, &frame.aovs) {
                output::write_aovs(dir, frame.width, frame.height, aovs)?;
            }
            let s = &frame.stats;
            if let Some(path) = stats {
                let doc = json!({
                    "scene": scene.path,
                    "renderer": ctx.info.renderer,
                    "gl_version": ctx.info.version,
                    "vendor": ctx.info.vendor,
                    "tracer": name,
                    "width": frame.width,
                    "height": frame.height,
                    "triangles": scene.triangle_count(),
                    "lights": scene.lights.len(),
                    "refl_depth": options.refl_depth,
                    "shadow_flags": options.shadow_flags,
                    "tile": options.tile,
                    "triangle_tests": s.triangle_tests,
                    "triangle_tests_total": s.total_triangle_tests(),
                    "events": s.events,
                    "truncated_rays": s.truncated_rays,
                    "gpu_ms": s.gpu_ms,
                    "gpu_ms_total": s.total_gpu_ms(),
                    "wall_ms": s.wall_ms,
                });
                let mut doc = doc;
                for (k, v) in &s.facts {
                    doc[k] = v.clone();
                }
                for (k, v) in &s.events {
                    doc[k] = json!(v);
                }
                std::fs::write(&path, serde_json::to_string_pretty(&doc)? + "\n")
                    .with_context(|| format!("cannot write {}", path.display()))?;
            }
            eprintln!(
                "{}: {}x{}, {} triangles, {} lights, {} tracer on {}: {:.1} GPU ms, {} triangle tests -> {}",
                scene.path.display(),
                frame.width,
                frame.height,
                scene.triangle_count(),
                scene.lights.len(),
                name,
                ctx.info.renderer,
                s.total_gpu_ms(),
                s.total_triangle_tests(),
                output.display()
            );
            Ok(())
        }
        Command::View(args) => view::run(args),
        Command::Bench(args) => bench::run(args),
        Command::ExportTriangles { scene, output } => {
            let scene = load_scene(&scene)?;
            let tris = scene.world_triangles();
            output::write_npy(
                &output,
                &[tris.len() as u64, 3, 3],
                tris.iter()
                    .flat_map(|t| t.iter().flat_map(|v| v.to_array())),
            )
        }
        Command::Info { scene, json, gpu } => {
            let scene = scene.as_deref().map(load_scene).transpose()?;
            if gpu.glsl_dir.is_some() {
                bail!("--glsl-dir has no effect on info");
            }
            let ctx = GlContext::headless(gpu.device)?;
            let mut doc = serde_json::to_value(&ctx.info)?;
            if let Some(s) = &scene {
                doc["scene"] = json!(s.path);
                doc["triangles"] = json!(s.triangle_count());
                doc["lights"] = json!(s.lights.len());
                doc["area_lights"] = json!(s.area_lights.len());
                doc["objects"] = json!(s.objects.len());
                doc["materials"] = json!(s.materials.len());
                doc["textures"] = json!(s.textures.len());
            }
            if json {
                println!("{}", serde_json::to_string_pretty(&doc)?);
            } else if let serde_json::Value::Object(m) = doc {
                for (k, v) in m {
                    println!("{k:36} {v}");
                }
            }
            Ok(())
        }
    }
}
