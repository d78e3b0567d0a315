//! `gpgpu-rt bench`'s command line: the protocols to run, the scale, and the overrides of the
//! protocols' sizes and of the tracers' options.

use std::path::PathBuf;

use anyhow::{bail, Result};
use gpgpu_rt::limits;

use super::config::{BvhVariant, GridVariant};
use super::units::{parse_shard, Shard};

/// The protocols `gpgpu-rt bench` knows: the command line's values
/// (`crate::bench::protocols::protocol_of` says which protocol each one runs).
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
    /// Wagner 2018, Table A.1 / Fig. 5.1: the square of 8 … 32768 triangles × 5 resolutions.
    #[value(name = "wagner-a1")]
    WagnerA1,
    /// Wagner 2018, Table A.2 / Table 5.1 / Fig. 5.4: sphere and cow × 5 resolutions.
    #[value(name = "wagner-a2")]
    WagnerA2,
    /// The streaming tracer, Table 1: ray casting (eye rays), grid g and pc vs the compute grid.
    #[value(name = "proximity-clouds-table1", alias = "purcell-table1")]
    ProximityCloudsTable1,
    /// The streaming tracer, Table 2: shadow casting (eye, shadow rays), g and pc vs compute grid.
    #[value(name = "proximity-clouds-table2", alias = "purcell-table2")]
    ProximityCloudsTable2,
    /// The streaming tracer, Table 3: ray tracing (eye, shadow, reflection rays), g and pc vs
    /// the compute grid.
    #[value(name = "proximity-clouds-table3", alias = "purcell-table3")]
    ProximityCloudsTable3,
    /// Ours: every accelerator on every scene and kind of ray (and the stadium).
    #[value(name = "accel-compare")]
    AccelCompare,
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
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub command: Option<BenchCommand>,
    /// Protocols to run, one or more.
    #[arg(required = true, value_enum, value_name = "PROTOCOL")]
    pub protocols: Vec<ProtocolId>,
    #[command(flatten)]
    pub split: SplitArgs,
    /// `quick`: few angles, a small image (minutes on Mesa); `full`: the thesis' protocol.
    #[arg(long, value_enum, default_value = "quick")]
    pub scale: Scale,
    /// Output folder for the CSVs, plots and report.md (created if missing).
    #[arg(long, value_name = "DIR", default_value = "bench-results")]
    pub out: PathBuf,
    /// Image width, 1 to 16384 (default: 64 quick, 512 full; the thesis does not state its
    /// size).
    #[arg(long, value_parser = limits::parser(limits::IMAGE_SIDE))]
    pub width: Option<u32>,
    /// Image height, 1 to 16384 (default: 64 quick, 512 full).
    #[arg(long, value_parser = limits::parser(limits::IMAGE_SIDE))]
    pub height: Option<u32>,
    /// Number of rotation angles, 1 to 3600, evenly spaced over 360° (default: the protocol's
    /// for the scale).
    #[arg(long, value_name = "N", value_parser = limits::parser(limits::ANGLES))]
    pub angles: Option<u32>,
    /// Warm-up frames per configuration, 0 to 1000, not counted (default: the protocol's for
    /// the scale).
    #[arg(long, value_name = "N", value_parser = limits::parser(limits::WARMUP))]
    pub warmup: Option<u32>,
    #[command(flatten)]
    pub grid: GridArgs,
    #[command(flatten)]
    pub wagner: WagnerArgs,
    #[command(flatten)]
    pub klee: KleeArgs,
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
    #[command(flatten)]
    pub gpu: crate::args::GpuArgs,
    /// No progress bar (it shows only on a terminal anyway).
    #[arg(long)]
    pub quiet: bool,
}

/// A bench command line on its own, `bench` first: `bench merge` parses the shards' with it.
#[derive(clap::Parser, Debug)]
#[command(name = "bench")]
pub struct Standalone {
    #[command(flatten)]
    pub args: BenchArgs,
}

/// How the run's units of work are divided (see `super::shard`).
#[derive(clap::Args, Debug, Clone)]
pub struct SplitArgs {
    /// Print the units of work (configurations; a Klee protocol is one unit) with their
    /// index and stable id, one per line, and measure nothing.
    #[arg(long, conflicts_with = "shard")]
    pub list: bool,
    /// Measure only the units whose index ≡ K−1 (mod N) (the `--list` index minus 1), warm-up
    /// included, write their rows and `shard.json` into --out, and no report: `bench merge`
    /// makes it from all N shards (one per Slurm array task: scripts/slurm-bench.sh).
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,
}

/// `gpgpu-rt bench`'s subcommands.
#[derive(clap::Subcommand, Debug, Clone)]
pub enum BenchCommand {
    /// Merge the output folders of `bench … --shard K/N` for K = 1..N into one: the CSVs,
    /// summaries, plots and report.md of the whole run (refused if a shard is missing or given
    /// twice, or the folders are of different runs).
    Merge(MergeArgs),
}

/// `gpgpu-rt bench merge DIR… --out DIR`.
#[derive(clap::Args, Debug, Clone)]
pub struct MergeArgs {
    /// The shards' output folders.
    #[arg(required = true, value_name = "DIR")]
    pub dirs: Vec<PathBuf>,
    /// Output folder of the merged run (created if missing; not one of the shards').
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// The options of the grid protocols (Müller 2015, ch. 5.2, 5.3).
#[derive(clap::Args, Debug, Clone)]
pub struct GridArgs {
    /// Grid resolutions N (N³ voxels), comma-separated (default: the protocol's for the scale).
    #[arg(long, value_delimiter = ',', value_name = "N,N,...", value_parser = limits::parser(limits::GRID_RES))]
    pub grid_res: Option<Vec<u32>>,
    /// Grid variants to measure, comma-separated (default: both).
    #[arg(long, value_enum, value_delimiter = ',', value_name = "VARIANT,...")]
    pub variants: Option<Vec<GridVariant>>,
    /// Thesis grid variant: triangle ids per voxel list, 1 to 65536 (default: the tracer's,
    /// Listing 17: 512).
    #[arg(long, value_name = "L", value_parser = limits::parser(limits::VOXEL_ARRAY_LENGTH))]
    pub voxel_array_length: Option<u32>,
    /// Thesis grid variant: voxel ids per ray list, 1 to 65536 (default: the tracer's, 3·N as
    /// Listing 17).
    #[arg(long, value_name = "R", value_parser = limits::parser(limits::RAY_ARRAY_LENGTH))]
    pub ray_array_length: Option<u32>,
}

/// The options of the Klee 2016 protocols.
#[derive(clap::Args, Debug, Clone)]
pub struct KleeArgs {
    /// The readings of the thesis' N-tree depth to measure in klee-table2, klee-table3 and
    /// klee-fig12, as levels counting the root, comma-separated: 3 (reading A), 4 (reading B,
    /// the cascade; its bunny tree takes minutes to build on one core). Default: both.
    #[arg(long, value_delimiter = ',', value_name = "3,4")]
    pub ntree_levels: Option<Vec<u32>>,
}

/// The options of the Wagner 2018 protocols.
#[derive(clap::Args, Debug, Clone)]
pub struct WagnerArgs {
    /// Image sizes of the Wagner 2018 protocols, comma-separated, e.g. 320x240,640x480
    /// (default: the protocol's for the scale; 320x240 is always measured, the reference); of
    /// proximity-clouds-table1…3 too, which render square images W×W.
    #[arg(long, value_delimiter = ',', value_name = "WxH,...", value_parser = parse_size)]
    pub sizes: Option<Vec<(u32, u32)>>,
    /// Subdivision levels of the square for wagner-a1, comma-separated: level L has 2·4^L
    /// triangles (default: the protocol's for the scale; level 1 is always measured).
    #[arg(long, value_delimiter = ',', value_name = "L,...")]
    pub levels: Option<Vec<u32>>,
    /// BVH variants of the Wagner 2018 protocols, comma-separated: `sah` (ours, in Müller 2015's
    /// pipeline), `wagner` (Wagner 2018's megakernel). Default: both.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "VARIANT,...")]
    pub bvh_variants: Option<Vec<BvhVariant>>,
}

/// The finest square `--levels` takes: 2·4^12 = 33,554,432 triangles, within the scene
/// loader's limit for a procedural object.
pub const MAX_LEVEL: u32 = 12;

/// "640x480" → (640, 480).
fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let parsed = s.split_once(['x', 'X', '×']).and_then(|(w, h)| {
        let (w, h) = (w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?);
        let side = &limits::IMAGE_SIDE;
        (side.contains(&w) && side.contains(&h)).then_some((w, h))
    });
    parsed.ok_or_else(|| {
        format!(
            "{s:?} is not an image size WxH with W, H from 1 to {}, e.g. 640x480",
            limits::IMAGE_SIDE.end()
        )
    })
}

impl BenchArgs {
    /// Refuse values no protocol can use, naming the option.
    pub fn validate(&self) -> Result<()> {
        // the ranges of single values are the parsers' (gpgpu_rt::limits)
        if let Some(r) = &self.grid.grid_res {
            if r.is_empty() {
                bail!("--grid-res needs resolutions of at least 1, e.g. --grid-res 8,16,24");
            }
        }
        if self.grid.variants.as_ref().is_some_and(|v| v.is_empty()) {
            bail!("--variants needs at least one of thesis, exact");
        }
        if self
            .wagner
            .bvh_variants
            .as_ref()
            .is_some_and(|v| v.is_empty())
        {
            bail!("--bvh-variants needs at least one of sah, wagner");
        }
        if let Some(l) = &self.wagner.levels {
            if l.is_empty() || l.iter().any(|l| !(1..=MAX_LEVEL).contains(l)) {
                bail!(
                    "--levels takes subdivision levels 1 to {MAX_LEVEL} of the square (2·4^L triangles), \
                     e.g. --levels 1,3,5"
                );
            }
        }
        if let Some(l) = &self.klee.ntree_levels {
            if l.is_empty() || l.iter().any(|l| !(3..=4).contains(l)) {
                bail!(
                    "--ntree-levels takes 3 (reading A) and/or 4 (reading B), e.g. --ntree-levels 3"
                );
            }
        }
        if !self.tile.is_multiple_of(8) {
            bail!(
                "--tile {} must be a multiple of 8 (the kernels' work group size)",
                self.tile
            );
        }
        Ok(())
    }
}
