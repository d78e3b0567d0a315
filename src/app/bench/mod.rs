//! `gpgpu-rt bench`: protocols that replicate published evaluations and put our numbers beside
//! the published ones.
//!
//! A run measures one or more protocols and writes into the output folder, per protocol, a
//! per-frame CSV (`<protocol>.csv`), a per-configuration CSV with median/min/max/mean
//! (`<protocol>_summary.csv`), PNG plots shaped like the paper's figures, the first frame of
//! every configuration (`frames/<protocol>/`), and one `report.md` with a section per protocol.
//!
//! # Structure
//!
//! - [`Protocol`]: a protocol's name (the command-line value), title and `run`, which measures
//!   and returns its [`Section`] of the report. [`ProtocolId`] is the registry: the command
//!   line's values and the protocol each one runs.
//! - [`runner::Bench`]: the session every protocol gets: the GL context, the options, the
//!   output folder, the scenes; [`runner::Bench::measure`] runs a list of [`runner::Config`]s
//!   (scene, tracer, image size, reflection depth, rotation angles, warm-up frames) with a
//!   progress bar and writes the two CSVs; [`runner::Bench::sizing`] and
//!   [`runner::Bench::grid_resolutions`] give a protocol's sizes at the chosen `--scale` with the
//!   command line's overrides applied.
//! - [`published`]: the published numbers, typed in as data with their figure numbers.
//! - [`plots`]: line charts as PNG; [`report`]: `report.md` and formatting helpers;
//!   [`stats`]: median/min/max/mean.
//!
//! # Adding a protocol (e.g. Klee 2016's `klee-table1`)
//!
//! 1. Put the published numbers into a module beside [`published`] (e.g. `published_klee.rs`),
//!    each with its table or figure number.
//! 2. Write `src/bench/klee_table1.rs` with a unit struct implementing [`Protocol`]. Its `run`
//!    usually builds the [`runner::Config`]s for `bench.scale()`, calls `bench.measure(name,
//!    &configs)` (CSV files come for free), draws its plots with [`plots::save`] and returns a
//!    [`Section`] whose markdown sets the published values beside ours (see
//!    [`thesis_5_3`] for a complete example). Work that is not a list of rendered frames (a CPU
//!    implementation, a build-time measurement) can use `bench.ctx`, `bench.scene(...)` and the
//!    CSV/plot helpers directly.
//! 3. Add a variant with `#[value(name = "klee-table1")]` to [`ProtocolId`] and its line in
//!    [`ProtocolId::protocol`]; mention it in the README's benchmark section.

pub mod klee;
pub mod machine;
pub mod plots;
pub mod published;
pub mod report;
pub mod runner;
pub mod stats;
pub mod sweep;
pub mod thesis_5_1;
pub mod thesis_5_2;
pub mod thesis_5_3;

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Result};

pub use report::Section;
pub use runner::Bench;

use gpgpu_rt::accel::GridVariant;

/// Default image size at `--scale quick`: small enough for Mesa llvmpipe.
pub const QUICK_SIZE: (u32, u32) = (64, 64);
/// Default image size at `--scale full`. The thesis does not state its image size.
pub const FULL_SIZE: (u32, u32) = (512, 512);

/// A benchmark protocol: what it measures, and how.
pub trait Protocol: Sync {
    /// The command-line name, e.g. `thesis-5.3`; also the CSV file names.
    fn name(&self) -> &'static str;
    /// The section title in `report.md`.
    fn title(&self) -> &'static str;
    /// Measure, write CSVs and plots into `bench.out`, and return the report section.
    fn run(&self, bench: &mut Bench) -> Result<Section>;
}

/// The protocols `gpgpu-rt bench` knows (the registry).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, clap::ValueEnum)]
pub enum ProtocolId {
    /// Müller 2015, ch. 5.1: the base tracer on 1, 3 and 6 teapots over a 360° rotation (Fig. 19, 20).
    #[value(name = "thesis-5.1")]
    Thesis51,
    /// Müller 2015, ch. 5.2: the grid tracer on six teapots at resolutions 4³…40³ (Fig. 21, 22).
    #[value(name = "thesis-5.2")]
    Thesis52,
    /// Müller 2015, ch. 5.3: bunny, base vs grid; dragon with the grid (Fig. 23, 24).
    #[value(name = "thesis-5.3")]
    Thesis53,
    /// Klee 2016, Table 1: primary rays, GPU rasterisation vs CPU ray casting (bunny, dragon).
    #[value(name = "klee-table1")]
    KleeTable1,
    /// Klee 2016, Table 2: triangle tests vs line-space lookups on the CPU (bunny, 4 rays).
    #[value(name = "klee-table2")]
    KleeTable2,
    /// Klee 2016, Table 3: coherent grid traversal vs 3D-DDA on the CPU (4/9/16/100 rays).
    #[value(name = "klee-table3")]
    KleeTable3,
    /// Klee 2016, Fig. 12: 2×2 … 10×10 shadow rays, CPU vs GPU (bunny).
    #[value(name = "klee-fig12")]
    KleeFig12,
    /// Klee 2016, Fig. 13: bunny vs dragon on the GPU, 2×2 … 10×10 shadow rays.
    #[value(name = "klee-fig13")]
    KleeFig13,
}

impl ProtocolId {
    pub fn protocol(self) -> &'static dyn Protocol {
        match self {
            ProtocolId::Thesis51 => &thesis_5_1::Thesis51,
            ProtocolId::Thesis52 => &thesis_5_2::Thesis52,
            ProtocolId::Thesis53 => &thesis_5_3::Thesis53,
            ProtocolId::KleeTable1 => &klee::KleeTable1,
            ProtocolId::KleeTable2 => &klee::KleeTable2,
            ProtocolId::KleeTable3 => &klee::KleeTable3,
            ProtocolId::KleeFig12 => &klee::KleeFig12,
            ProtocolId::KleeFig13 => &klee::KleeFig13,
        }
    }
}

/// `--scale`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Scale {
    /// Few angles and a small image: minutes on Mesa llvmpipe.
    Quick,
    /// The published protocol (one frame per degree, larger images): for a GPU.
    Full,
}

/// `--rotate`: how "the scene rotated through 360°" is done.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Rotation {
    /// Turn every object about the vertical axis through the scene's centre (model matrices);
    /// camera and light stay.
    Objects,
    /// Orbit the camera about that axis instead; the light stays fixed to the objects.
    Camera,
}

/// `gpgpu-rt bench`'s command line.
#[derive(clap::Args, Debug, Clone)]
pub struct BenchArgs {
    /// Protocols to run, one or more.
    #[arg(required = true, value_enum, value_name = "PROTOCOL")]
    pub protocols: Vec<ProtocolId>,
    /// `quick`: few angles, a small image (minutes on Mesa); `full`: the thesis' protocol.
    #[arg(long, value_enum, default_value = "quick")]
    pub scale: Scale,
    /// Output folder for the CSVs, plots and report.md (created if missing).
    #[arg(long, value_name = "DIR", default_value = "bench-results")]
    pub out: PathBuf,
    /// Image width (default: 64 quick, 512 full; the thesis does not state its size).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (default: 64 quick, 512 full).
    #[arg(long)]
    pub height: Option<u32>,
    /// Number of rotation angles, evenly spaced over 360° (default: the protocol's for the scale).
    #[arg(long, value_name = "N")]
    pub angles: Option<u32>,
    /// Warm-up frames per configuration, not counted (default: the protocol's for the scale).
    #[arg(long, value_name = "N")]
    pub warmup: Option<u32>,
    /// Grid resolutions N (N³ voxels), comma-separated (default: the protocol's for the scale).
    #[arg(long, value_delimiter = ',', value_name = "N,N,...")]
    pub grid_res: Option<Vec<u32>>,
    /// Grid variants to measure, comma-separated (default: both).
    #[arg(long, value_enum, value_delimiter = ',', value_name = "VARIANT,...")]
    pub variants: Option<Vec<GridVariant>>,
    /// Thesis grid variant: triangle ids per voxel list (default: the tracer's, Listing 17: 512).
    #[arg(long, value_name = "L")]
    pub voxel_array_length: Option<u32>,
    /// Thesis grid variant: voxel ids per ray list (default: the tracer's, 3·N as Listing 17).
    #[arg(long, value_name = "R")]
    pub ray_array_length: Option<u32>,
    /// How the scene turns: its objects (default) or the camera around them.
    #[arg(long, value_enum, default_value = "objects")]
    pub rotate: Rotation,
    /// Split dispatches into tiles of at most N×N pixels (multiple of 8; 0: one dispatch per
    /// kernel as the thesis).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub tile: u32,
    /// Folder with the scene files (default: ./scenes, else the source tree's).
    #[arg(long, value_name = "DIR")]
    pub scenes: Option<PathBuf>,
    /// EGL device index (default: the first that gives an OpenGL 4.5 core context).
    #[arg(long)]
    pub device: Option<usize>,
    /// Load the GLSL kernels from this directory instead of the copies built into the binary.
    #[arg(long, value_name = "DIR")]
    pub glsl_dir: Option<PathBuf>,
    /// No progress bar (it shows only on a terminal anyway).
    #[arg(long)]
    pub quiet: bool,
}

/// Run the protocols of `args` and write the report. Fails (after writing everything) when a
/// configuration or protocol failed.
pub fn run(args: BenchArgs) -> Result<()> {
    let mut ids = args.protocols.clone();
    ids.sort();
    ids.dedup();
    let start = Instant::now();
    let mut bench = Bench::new(args)?;
    eprintln!(
        "bench on {} ({}), writing to {}",
        bench.machine.gl_renderer,
        bench.machine.gl_version,
        bench.out.display()
    );
    let mut sections = Vec::new();
    for id in ids {
        let p = id.protocol();
        eprintln!("{}: {}", p.name(), p.title());
        match p.run(&mut bench) {
            Ok(s) => sections.push(s),
            Err(e) => {
                eprintln!("{}: failed: {e:#}", p.name());
                sections.push(Section {
                    protocol: p.name().into(),
                    title: p.title().into(),
                    markdown: format!("**The protocol failed:** `{e:#}`\n"),
                    failures: 1,
                    files: vec![],
                });
            }
        }
    }
    let path = report::write(&bench, &sections, start.elapsed().as_secs_f64())?;
    eprintln!("wrote {}", path.display());
    let failed: usize = sections.iter().map(|s| s.failures).sum();
    if failed > 0 {
        bail!("{failed} configuration(s) failed; see {}", path.display());
    }
    Ok(())
}
