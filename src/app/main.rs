//! The `gpgpu-rt` command line: the application (CLI, viewer, bench protocols) on top of the
//! `gpgpu_rt` library.

mod args;
mod bench;
mod parity;
mod render;
mod view;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Result};
use clap::{ArgMatches, CommandFactory, FromArgMatches, Subcommand};
use serde_json::json;

use gpgpu_rt::gl::GlContext;
use gpgpu_rt::outln;
use gpgpu_rt::output::console;
use gpgpu_rt::scene::Scene;

#[derive(clap::Parser)]
#[command(
    name = "gpgpu-rt",
    version = gpgpu_rt::VERSION,
    about = "GPU ray tracing in OpenGL 4.5 compute shaders (after Müller 2015 and related works)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// The OpenGL driver: the first device that gives a 4.5 core context (auto), Mesa's
    /// llvmpipe, or Mesa's zink (OpenGL on Vulkan; Debian: mesa-vulkan-drivers). The same as
    /// GPGPU_RT_DRIVER=NAME in the environment (docs/drivers.md).
    #[arg(long, global = true, value_enum, value_name = "NAME")]
    driver: Option<gpgpu_rt::gl::driver::Driver>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a PNG.
    Render(render::RenderArgs),
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
    /// ch. 5; wagner-*: Wagner 2018, appendix A; proximity-clouds-*: the streaming tracer,
    /// Tables 1–3): CSVs, plots and report.md with our numbers beside the published ones.
    Bench(bench::BenchArgs),
    /// Render every design and accelerator on a few scenes and write their first hits, shadows
    /// and exact counts to --out; with --against, compare them with another driver's
    /// (docs/drivers.md, "Parity").
    Parity(parity::ParityArgs),
    /// Print the GL implementation's vendor, renderer, version, limits and profile, and a
    /// scene's counts (with its point lights' positions and shadow offset).
    Info {
        scene: Option<PathBuf>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        gpu: args::GpuArgs,
    },
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    gpgpu_rt::gl::crash::install();
    gpgpu_rt::output::interrupt::install();
    let parsed = Cli::command()
        .try_get_matches()
        .and_then(|m| Ok((Cli::from_arg_matches(&m)?, m)));
    let (cli, matches) = match parsed {
        Ok(p) => p,
        Err(e) => return usage_exit(&e),
    };
    if let Some(d) = cli.driver {
        // before any thread or GL call: Mesa reads its variables when it loads the driver
        std::env::set_var(gpgpu_rt::gl::driver::DRIVER_ENV, d.name());
    }
    if let Err(e) = gpgpu_rt::scene::budget::check_limit_var() {
        return console::exit_for(&anyhow::anyhow!(e));
    }
    match run(cli, &matches) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => console::exit_for(&e),
    }
}

/// `--help`, `--version` or a usage error: clap's text, with its exit status; a text that
/// cannot be written is a write error as any other (`output::console`).
fn usage_exit(e: &clap::Error) -> ExitCode {
    match e.print() {
        Ok(()) => ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(1)),
        Err(source) => {
            let stream = match e.use_stderr() {
                true => console::Stream::Stderr,
                false => console::Stream::Stdout,
            };
            console::exit_for(&console::ConsoleError { stream, source }.into())
        }
    }
}

fn run(cli: Cli, matches: &ArgMatches) -> Result<()> {
    match cli.command {
        Command::Render(args) => render::run(args, matches.subcommand_matches("render")),
        Command::View(args) => view::run(args),
        Command::Bench(args) => bench::run(args),
        Command::ExportTriangles { scene, output } => render::export_triangles(&scene, &output),
        Command::Info { scene, json, gpu } => info(scene, json, gpu),
        Command::Parity(args) => parity::run(args),
    }
}

/// `info`: the GL implementation and, for a scene, its counts.
fn info(scene: Option<PathBuf>, json: bool, gpu: args::GpuArgs) -> Result<()> {
    let scene = scene.as_deref().map(Scene::load_counts).transpose()?;
    if gpu.glsl_dir.is_some() {
        bail!("--glsl-dir has no effect on info");
    }
    let ctx = GlContext::headless(gpu.device)?;
    let mut doc = serde_json::to_value(&ctx.info)?;
    doc["egl_devices"] = json!(gpgpu_rt::gl::context::egl_devices());
    if let Some(s) = &scene {
        doc["scene"] = json!(s.path);
        doc["triangles"] = json!(s.triangle_count());
        doc["lights"] = json!(s.lights.len());
        // where the shadow feelers of intersect2 go, and where they start (tools/embree_peer.py)
        let positions: Vec<[f32; 3]> = s.lights.iter().map(|l| l.position.to_array()).collect();
        doc["light_positions"] = json!(positions);
        doc["shadow_offset"] = json!(s.settings.shadow_offset);
        doc["area_lights"] = json!(s.area_lights.len());
        doc["objects"] = json!(s.objects.len());
        doc["materials"] = json!(s.materials.len());
        doc["textures"] = json!(s.textures.len());
    }
    if json {
        outln!("{}", serde_json::to_string_pretty(&doc)?)?;
    } else if let serde_json::Value::Object(m) = doc {
        for (k, v) in m.iter().filter(|(k, _)| *k != "profile") {
            outln!("{k:36} {v}")?;
        }
        // the adaptations to the implementation, one a line (GPGPU_RT_PROFILE overrides them)
        for line in ctx.info.profile.describe() {
            outln!("{line}")?;
        }
    }
    Ok(())
}
