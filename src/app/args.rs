//! Command-line options shared by `render`, `view` and `bench`: the GL device, the kernels'
//! folder, and the design with its options ([`DesignArgs`]), parsed into one
//! [`gpgpu_rt::design::Design`] — with the options that do not belong to it refused.

use std::path::PathBuf;

use anyhow::Result;
use clap::parser::ValueSource;
use clap::{ArgMatches, Parser as _, ValueEnum};

use gpgpu_rt::accel::{
    Accel, BvhLevels, BvhOptions, BvhPasses, BvhVariant, ExactGridOptions, GridVariant,
    ThesisGridOptions,
};
use gpgpu_rt::design::{self, defaults, Design, Pipeline, Row};
use gpgpu_rt::limits;
use gpgpu_rt::pipeline::klee2016::{KleeShading, LinespaceBuild, SoftShadowOptions};
use gpgpu_rt::pipeline::mueller2015::{RenderOptions, ShadowFlags};
use gpgpu_rt::pipeline::stream::StreamOptions;
use gpgpu_rt::pipeline::wagner2018::WagnerOptions;
use gpgpu_rt::scene::{parse_samples, RenderSettings, Scene, ShadowMode};

#[derive(clap::Args, Debug, Clone)]
pub struct GpuArgs {
    /// EGL device index (default: the first that gives an OpenGL 4.5 core context).
    #[arg(long)]
    pub device: Option<usize>,
    /// Load the GLSL kernels from this directory instead of the copies built into the binary.
    #[arg(long, value_name = "DIR")]
    pub glsl_dir: Option<PathBuf>,
}

/// `--grid N|GXxGYxGZ|auto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridResolution {
    Auto,
    N(u32),
    /// gx×gy×gz cells (the streaming tracer's grid need not be cubic: `14x16x14`)
    Axes([u32; 3]),
}

impl std::str::FromStr for GridResolution {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(GridResolution::Auto);
        }
        let in_range = |n: &u32| limits::GRID_RES.contains(n);
        if s.contains('x') {
            let axes: Vec<Option<u32>> = s.split('x').map(|a| a.parse().ok()).collect();
            return match axes[..] {
                [Some(x), Some(y), Some(z)] if [x, y, z].iter().all(in_range) => {
                    Ok(GridResolution::Axes([x, y, z]))
                }
                _ => Err(format!(
                    "`{s}` is not GXxGYxGZ with three cell counts from 1 to {}",
                    limits::GRID_RES.end()
                )),
            };
        }
        match s.parse::<u32>() {
            Ok(n) if limits::GRID_RES.contains(&n) => Ok(GridResolution::N(n)),
            _ => Err(format!(
                "`{s}` is neither `auto` nor a voxel count per axis from 1 to {}",
                limits::GRID_RES.end()
            )),
        }
    }
}

/// The grid tracer's command-line options (`render`, `view`, `bench`).
#[derive(Debug, Clone, clap::Args)]
pub struct GridArgs {
    /// Grid resolution N (N³ voxels, N from 1 to 1024), or `auto`: N = cbrt(triangles / 5),
    /// within 4..=64 (--tracer stream: ∛triangles per axis, as the streaming tracer's paper).
    /// --tracer stream also takes GXxGYxGZ cells, e.g. 14x16x14.
    #[arg(long, default_value = "auto", value_name = "N|GXxGYxGZ|auto")]
    pub grid: GridResolution,
    /// --tracer stream and --tracer grid --grid-variant exact: skip empty cells by their
    /// proximity-cloud distance (Chebyshev distance, in cells, to the nearest non-empty cell;
    /// the exact grid computes it on the GPU after every per-frame build).
    #[arg(long)]
    pub proximity_clouds: bool,
    /// `thesis`: edge-registered fixed-size lists as Müller 2015; `exact`: overlap test,
    /// compact lists, 3D-DDA.
    #[arg(long, value_enum, default_value = "exact")]
    pub grid_variant: GridVariant,
    /// Thesis variant: triangle ids per voxel list, 1 to 65536 (Listing 17: 512).
    #[arg(long, default_value_t = 512, value_name = "L", value_parser = limits::parser(limits::VOXEL_ARRAY_LENGTH))]
    pub voxel_array_length: u32,
    /// Thesis variant: voxel ids per ray list, 1 to 65536 (default 3·N, as Listing 17).
    #[arg(long, value_name = "R", value_parser = limits::parser(limits::RAY_ARRAY_LENGTH))]
    pub ray_array_length: Option<u32>,
}

impl GridArgs {
    /// N of the uniform grids' N³ voxels (`None`: auto; the streaming tracer's axes are its own).
    fn cubic(&self) -> Option<u32> {
        match self.grid {
            GridResolution::N(n) => Some(n),
            _ => None,
        }
    }

    /// The thesis grid's options.
    pub fn thesis(&self) -> ThesisGridOptions {
        ThesisGridOptions {
            resolution: self.cubic(),
            voxel_array_length: self.voxel_array_length,
            ray_array_length: self.ray_array_length,
        }
    }

    /// The exact grid's options.
    pub fn exact(&self) -> ExactGridOptions {
        ExactGridOptions {
            resolution: self.cubic(),
            proximity_clouds: self.proximity_clouds,
        }
    }
}

/// The streaming tracer's own options (its grid: [`GridArgs`]'s `--grid` and
/// `--proximity-clouds`).
#[derive(Debug, Clone, clap::Args)]
pub struct StreamArgs {
    /// --tracer stream: steps (one triangle test or one move to the next cell) per call of
    /// the traverse kernel, 1 to 4096.
    #[arg(long, default_value_t = StreamOptions::STEPS_PER_CALL, value_name = "N", value_parser = limits::parser(limits::STREAM_STEPS))]
    pub stream_steps: u32,
    /// --tracer stream: traverse calls per traversal at most, 1 to 1000000 (rays still
    /// walking then make the frame fail).
    #[arg(long, default_value_t = StreamOptions::MAX_CALLS, value_name = "N", value_parser = limits::parser(limits::STREAM_CALLS))]
    pub stream_max_calls: u32,
    /// --tracer stream: trace shadow rays naively — the closest hit anywhere along the ray,
    /// a blocker when it lies before the light — instead of the paper's any hit closer than
    /// the light (the streaming tracer, ch. 3): the same shadows, for measuring what the
    /// optimisation saves.
    #[arg(long)]
    pub stream_naive_shadows: bool,
    /// --tracer stream: switch off the masking of rays that need no work (the streaming
    /// tracer, ch. 3: "rays missed the scene AABB, shadow rays for rays not intersecting any
    /// objects") — the traverse kernel's first call finds them instead, and the shadow rays of
    /// surfaces facing away from the light are traced (their verdict unused): the same image,
    /// for measuring what the masking saves.
    #[arg(long)]
    pub stream_no_mask: bool,
    /// --tracer stream: the paper's single-sided Möller–Trumbore test ("the fastest known
    /// single sided algorithm", the streaming tracer, ch. 3): a triangle seen from its back is
    /// no hit. Default: two-sided, as every tracer here.
    #[arg(long)]
    pub stream_single_sided: bool,
}

impl StreamArgs {
    /// The streaming tracer with these options and `grid`'s for a `width`×`height` image.
    pub fn options(
        &self,
        grid: &GridArgs,
        (width, height): (u32, u32),
        refl_depth: u32,
        aovs: bool,
    ) -> StreamOptions {
        StreamOptions {
            dims: match grid.grid {
                GridResolution::Auto => None,
                GridResolution::N(n) => Some([n; 3]),
                GridResolution::Axes(a) => Some(a),
            },
            proximity_clouds: grid.proximity_clouds,
            steps_per_call: self.stream_steps,
            max_calls: self.stream_max_calls,
            naive_shadows: self.stream_naive_shadows,
            no_mask: self.stream_no_mask,
            single_sided: self.stream_single_sided,
            aovs,
            ..StreamOptions::new(width, height, refl_depth)
        }
    }
}

/// Our SAH BVH's options (`--tracer bvh`, `--bvh-variant sah`): its variants.
#[derive(Debug, Clone, clap::Args)]
pub struct BvhArgs {
    /// With --tracer bvh (sah): Müller 2015's four kernels (eye rays, intersect1, intersect2 per
    /// light, shading, through the ray-state textures) instead of the default fused pass, which
    /// runs each pass of Fig. 8 in one kernel (ours, `glsl/bvh/fused_pass.comp`: the same image
    /// and counts, faster).
    #[arg(long, conflicts_with = "fused_passes")]
    pub four_kernels: bool,
    /// With --tracer bvh (sah): the fused pass, which is the default (the option stays for
    /// command lines that name it).
    #[arg(long)]
    pub fused_passes: bool,
    /// With --tracer bvh (sah): `one` tree over the world-space scene, refitted when objects
    /// move; `two` levels, a tree per object built once in object space under the objects'
    /// instances (ours), which a moving object updates without a refit; `auto`: two where the
    /// objects move from frame to frame (`render --rotate objects`), where they are faster,
    /// else one.
    #[arg(long, value_enum, default_value_t = BvhLevelsArg::Auto, conflicts_with = "bvh_instances")]
    pub bvh_levels: BvhLevelsArg,
    /// With --tracer bvh (sah): the same as --bvh-levels two.
    #[arg(long)]
    pub bvh_instances: bool,
}

/// `--bvh-levels`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BvhLevelsArg {
    Auto,
    One,
    Two,
}

impl BvhArgs {
    /// The SAH BVH's options (`--bvh-levels auto`: one tree; [`BvhArgs::objects_move`] says
    /// where two).
    pub fn options(&self) -> BvhOptions {
        BvhOptions {
            passes: match self.four_kernels {
                true => BvhPasses::FourKernels,
                false => BvhPasses::Fused,
            },
            levels: match (self.bvh_levels, self.bvh_instances) {
                (BvhLevelsArg::Two, _) | (_, true) => BvhLevels::Two,
                _ => BvhLevels::One,
            },
        }
    }

    /// These options where the objects move from frame to frame: `--bvh-levels auto` takes
    /// the two levels, which update a moving object's instance where one tree is refitted
    /// every frame — the faster frame on both drivers (docs/design/bvh.md, "The default").
    pub fn objects_move(self) -> BvhArgs {
        let levels = match self.bvh_levels {
            BvhLevelsArg::Auto => BvhLevelsArg::Two,
            given => given,
        };
        BvhArgs {
            bvh_levels: levels,
            ..self
        }
    }
}

/// The soft-shadow options of `render` and `view`.
#[derive(clap::Args, Debug, Clone)]
pub struct SoftShadowArgs {
    /// Soft shadows from the scene's `[[area_light]]` with the Cascaded Line Space (Klee 2016):
    /// G-buffer, shadow compute pass, screen-filling quad. `exact`: triangle tests (the
    /// reference); `linespace`: packet traversal, the line-space bit decides a hit;
    /// `linespace-fast`: linespace's values, far nodes first and triangles culled per packet
    /// (ours, the fast one); `linespace-dda`: one 3D-DDA per ray with the same line-space termination; `variant1`,
    /// `variant2`: Table 2's "Variante 1/2" as defined (exact / linespace without our
    /// near-origin rule).
    /// [default: the scene's render.shadows, else the point-light ray tracer]
    #[arg(long, value_enum)]
    pub shadows: Option<ShadowMode>,
    /// Uniform samples of the area light, UxV (2x2 … 10x10 in the thesis) [default: the
    /// scene's render.light_samples, else 4x4].
    #[arg(long, value_parser = parse_samples, value_name = "UxV")]
    pub light_samples: Option<(u32, u32)>,
    /// Cells per axis of every N-tree node (N; 10 in the thesis).
    #[arg(long, default_value_t = defaults::NTREE_N, value_name = "N")]
    pub ntree_n: u32,
    /// Levels of the N-tree counting the root: 3 (reading A of the thesis' "maximale Tiefe von
    /// 3": root, nodes of 1/N, leaves of 1/N²; only one level of line spaces is asked, no
    /// cascade) or 4 (reading B: "Tiefe null ist die Tiefe der Kinder des Wurzelknotens", so
    /// depths 0, 1, 2 below the root; leaves of 1/N³, a cascade of two line-space levels).
    /// The number counts levels with the root, not the thesis' depth index (docs/klee2016.md,
    /// "where we differ").
    #[arg(long, default_value_t = defaults::NTREE_DEPTH, value_name = "LEVELS")]
    pub ntree_depth: u32,
    /// How the shadow value s lights a pixel: `lit` (ours: diffuse · (ambient + light · s ·
    /// N·L)) or `fig7` (Klee 2016's Fig. 7: s · diffuse).
    #[arg(long, value_enum, default_value_t = KleeShading::Lit)]
    pub klee_shading: KleeShading,
    /// Where the N-tree's line spaces are computed: `gpu` (a compute kernel), `cpu`, or
    /// `auto` (the GPU unless GL is a software rasteriser, where the CPU build is faster).
    #[arg(long, value_enum, default_value_t = LinespaceBuild::Auto)]
    pub linespace_build: LinespaceBuild,
}

impl SoftShadowArgs {
    /// The scene file's `render.shadows` and `render.light_samples` where the command line
    /// gives none.
    pub fn with_scene_defaults(mut self, settings: &RenderSettings) -> SoftShadowArgs {
        self.shadows = self.shadows.or(settings.shadows);
        self.light_samples = self.light_samples.or(settings.light_samples);
        self
    }

    /// The light samples: the option, else 4x4.
    pub fn samples(&self) -> (u32, u32) {
        self.light_samples.unwrap_or(defaults::LIGHT_SAMPLES)
    }

    pub fn options(
        &self,
        mode: ShadowMode,
        width: u32,
        height: u32,
        tile: u32,
    ) -> SoftShadowOptions {
        SoftShadowOptions {
            mode,
            samples_u: self.samples().0,
            samples_v: self.samples().1,
            ntree_n: self.ntree_n,
            ntree_depth: self.ntree_depth,
            shading: self.klee_shading,
            linespace_build: self.linespace_build,
            width,
            height,
            tile,
        }
    }
}

/// `--tracer`: an accelerator of Müller 2015's pipeline, or the streaming tracer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TracerArg {
    /// The thesis' base tracer: every ray against every triangle (Müller 2015, ch. 3.1, 4.1).
    Base,
    /// The uniform grid rebuilt every frame (Müller 2015, ch. 3.2, 4.2); see `--grid-variant`.
    Grid,
    /// A BVH: ours (SAH, in Müller 2015's pipeline) or Wagner 2018's; see `--bvh-variant`.
    Bvh,
    /// The streaming tracer (a paper's streaming grid tracer with proximity clouds):
    /// fragment-program kernels over a viewport-sized quad, a static grid built once on the
    /// CPU, an occlusion query as the halting condition.
    Stream,
}

/// The command-line name of a value (`base`, `linespace-dda`).
/// A command-line number that is finite: NaN and ±inf (also "1e39", infinite as an f32) are
/// refused with what was given, before anything uses them (clap names the option).
pub fn finite_f32(text: &str) -> Result<f32, String> {
    let v: f32 = text
        .trim()
        .parse()
        .map_err(|_| format!("{text:?} is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{text:?} is not a finite number"))
    }
}

/// [`finite_f32`] for a share between 0 and 1.
pub fn share_f64(text: &str) -> Result<f64, String> {
    let v = finite_f32(text)? as f64;
    if (0.0..=1.0).contains(&v) {
        Ok(text.trim().parse().unwrap_or(v))
    } else {
        Err(format!("{text} is not between 0 and 1"))
    }
}

pub fn value_name<T: ValueEnum>(v: T) -> String {
    v.to_possible_value()
        .map(|v| v.get_name().to_string())
        .expect("no value is skipped")
}

/// The design and its options, as `render` and `view` take them.
#[derive(clap::Args, Debug, Clone)]
pub struct DesignArgs {
    /// The accelerator of Müller 2015's pipeline: `bvh` (ours: an SAH BVH, the fastest; or
    /// Wagner 2018's with --bvh-variant wagner), `base` (the thesis' base tracer, every ray
    /// against every triangle) or `grid` (the thesis' uniform grid, see --grid-variant); or
    /// `stream`, the streaming tracer (fragment-program kernels, a static grid,
    /// occlusion-query halting).
    #[arg(long, value_enum, default_value = "bvh")]
    pub tracer: TracerArg,
    /// With --tracer bvh: `sah` (ours, in the four-kernel pipeline) or `wagner` (Wagner 2018
    /// faithful: his BVH build, three textures, one kernel per pixel, one light, Lambert, hard
    /// shadows, no reflection).
    #[arg(long, value_enum, default_value = "sah")]
    pub bvh_variant: BvhVariant,
    #[command(flatten)]
    pub bvh: BvhArgs,
    /// Reflection passes after the primary pass, REFL_DEPTH of Fig. 8, 0 to 16 (default: the
    /// scene's).
    #[arg(long, value_parser = limits::parser(limits::REFL_DEPTH))]
    pub refl_depth: Option<u32>,
    /// Shadow flags: `rgba` as the thesis (4 lights) or `bits` (128 lights).
    #[arg(long, value_enum, default_value = "bits")]
    pub shadow_flags: ShadowFlags,
    /// Split every dispatch into tiles of at most N×N pixels (multiple of 8; 0: no tiling),
    /// so that no dispatch runs long enough for a driver watchdog.
    #[arg(long, default_value_t = defaults::TILE, value_name = "N")]
    pub tile: u32,
    #[command(flatten)]
    pub grid: GridArgs,
    #[command(flatten)]
    pub stream: StreamArgs,
    #[command(flatten)]
    pub soft: SoftShadowArgs,
}

/// A command line of design options alone, for [`DesignArgs::of_row`].
#[derive(clap::Parser)]
struct DesignLine {
    #[command(flatten)]
    design: DesignArgs,
}

impl DesignArgs {
    /// The options that select `row`, `extra` options, and the command line's defaults for
    /// the rest: what `render` would parse from `--tracer grid --grid-variant exact …`.
    pub fn of_row(row: &Row, extra: &[&str]) -> Result<DesignArgs> {
        let words = row
            .select
            .iter()
            .flat_map(|(o, v)| [format!("--{o}"), v.to_string()])
            .chain(extra.iter().map(|w| w.to_string()));
        let line = DesignLine::try_parse_from(std::iter::once("design".to_string()).chain(words))?;
        Ok(line.design)
    }

    /// The value of a selecting option of [`Row::select`] (long name), given or default.
    fn value(&self, option: &str) -> String {
        match option {
            "tracer" => value_name(self.tracer),
            "bvh-variant" => value_name(self.bvh_variant),
            "grid-variant" => value_name(self.grid.grid_variant),
            _ => String::new(),
        }
    }

    /// The point-light design these options select (Klee 2016's is chosen by `--shadows`).
    pub fn tracer_row(&self) -> &'static Row {
        design::select(false, |o| self.value(o)).expect("every --tracer has a design")
    }

    /// Does the design the command line selects for a scene with `settings` upload Müller
    /// 2015's scene buffers?
    pub fn uses_scene_buffers(&self, settings: &gpgpu_rt::scene::RenderSettings) -> bool {
        let soft = self.soft.clone().with_scene_defaults(settings);
        soft.shadows.is_none() && self.tracer_row().pipeline == design::Pipeline::Mueller2015
    }

    /// The design for `scene`: Klee 2016's soft shadows with `--shadows` (or the scene's
    /// render.shadows), else the point-light design `--tracer` selects; `size` and `aovs`
    /// as the command asks. `matches` (the command's): the options given explicitly, refused
    /// where they do not belong to the design.
    pub fn design(
        &self,
        scene: &Scene,
        size: (u32, u32),
        aovs: bool,
        matches: Option<&ArgMatches>,
    ) -> Result<Design> {
        let mut settings = scene.settings;
        let tracer_given =
            matches.is_some_and(|m| m.value_source("tracer") == Some(ValueSource::CommandLine));
        if let (Some(mode), true, None) = (settings.shadows, tracer_given, self.soft.shadows) {
            // an explicit --tracer asks for the point-light tracer: it wins over the scene's
            // default soft shadows, said aloud
            let unlit = match scene.lights.is_empty() {
                true => "; the scene has no [[light]], so only its ambient light shows",
                false => "",
            };
            gpgpu_rt::errln!(
                "note: --tracer {} renders the point lights; the soft shadows {} sets \
                 (render.shadows = \"{}\") are not drawn{unlit}",
                value_name(self.tracer),
                scene.path.display(),
                mode.name()
            )?;
            settings.shadows = None;
        }
        let soft = self.soft.clone().with_scene_defaults(&settings);
        let row = match soft.shadows {
            Some(_) => design::row("linespace")?,
            None => self.tracer_row(),
        };
        let chosen = match (soft.shadows, self.soft.shadows) {
            (Some(_), None) => format!("from render.shadows in {}", scene.path.display()),
            (Some(_), Some(_)) => "from --shadows".to_string(),
            (None, _) => format!("from {}", row.command_line()),
        };
        design::refuse_foreign(row, &given(matches), &chosen)?;
        if let Some(mode) = soft.shadows {
            return Ok(Design::Klee2016(
                soft.options(mode, size.0, size.1, self.tile),
            ));
        }
        let refl_depth = self.refl_depth.unwrap_or(scene.settings.refl_depth);
        // the scene's light samples where the command line gives none
        let this = DesignArgs {
            soft,
            ..self.clone()
        };
        Ok(this.tracer_design(row, size, refl_depth, aovs))
    }

    /// The point-light design `row` with these options.
    pub fn tracer_design(
        &self,
        row: &Row,
        (width, height): (u32, u32),
        refl_depth: u32,
        aovs: bool,
    ) -> Design {
        match row.pipeline {
            Pipeline::Wagner2018 => Design::Wagner2018(WagnerOptions {
                width,
                height,
                tile: self.tile,
                aovs,
            }),
            Pipeline::Stream => {
                Design::Stream(
                    self.stream
                        .options(&self.grid, (width, height), refl_depth, aovs),
                )
            }
            _ => Design::Mueller2015(RenderOptions {
                tile: self.tile,
                shadow_flags: self.shadow_flags,
                aovs,
                light_samples: self.soft.samples(),
                ..RenderOptions::new(self.accel(row), width, height, refl_depth)
            }),
        }
    }

    /// The accelerator of Müller 2015's row `row` with its group's options: each takes only
    /// its own (the viewer's keys and `parity` switch rows with the command line's options,
    /// which refuse an option beside any other row).
    fn accel(&self, row: &Row) -> Accel {
        let entry = row
            .accel
            .expect("Müller 2015's rows name their accelerator");
        match entry.plain {
            Accel::Base => Accel::Base,
            Accel::ThesisGrid(_) => Accel::ThesisGrid(self.grid.thesis()),
            Accel::ExactGrid(_) => Accel::ExactGrid(self.grid.exact()),
            Accel::Bvh(_) => Accel::Bvh(self.bvh.options()),
        }
    }
}

/// The design options the command line gave explicitly (long names): those of every row of
/// the registry, looked up in `matches`.
fn given(matches: Option<&ArgMatches>) -> Vec<String> {
    let Some(m) = matches else { return Vec::new() };
    let mut all: Vec<&str> = design::REGISTRY.iter().flat_map(|r| r.options()).collect();
    all.sort_unstable();
    all.dedup();
    all.into_iter()
        .filter(|o| m.value_source(&o.replace('-', "_")) == Some(ValueSource::CommandLine))
        .map(str::to_string)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The SAH BVH runs the fused pass unless `--four-kernels` asks for the thesis' kernels;
    /// the BVH's options reach its design only: the viewer switching to another tracer with
    /// them set gets that tracer, not a refusal.
    #[test]
    fn the_bvh_options_reach_the_sah_bvh_only() {
        let accel = |name: &str, extra: &[&str]| {
            let row = design::row(name).unwrap();
            let args = DesignArgs::of_row(row, extra).unwrap();
            match args.tracer_design(row, (8, 8), 0, false) {
                Design::Mueller2015(o) => o.accel,
                _ => panic!("{name}: not Müller 2015's pipeline"),
            }
        };
        assert!(accel("bvh", &[]).fused());
        assert!(accel("bvh", &["--fused-passes"]).fused());
        assert!(!accel("bvh", &["--four-kernels"]).fused());
        assert!(accel("bvh", &["--bvh-instances"]).instances());
        assert_eq!(
            accel("grid-exact", &["--four-kernels"]),
            design::row("grid-exact").unwrap().accel.unwrap().plain
        );
        assert_eq!(accel("base", &["--bvh-instances"]), Accel::Base);
    }

    /// `--bvh-levels auto` is one tree, or two levels where the objects move; a level the
    /// command line names stays.
    #[test]
    fn moving_objects_take_two_levels_unless_told() {
        let levels = |extra: &[&str], moving: bool| {
            let row = design::row("bvh").unwrap();
            let args = DesignArgs::of_row(row, extra).unwrap();
            let bvh = match moving {
                true => args.bvh.objects_move(),
                false => args.bvh,
            };
            bvh.options().levels
        };
        assert_eq!(levels(&[], false), BvhLevels::One);
        assert_eq!(levels(&[], true), BvhLevels::Two);
        assert_eq!(levels(&["--bvh-levels", "one"], true), BvhLevels::One);
        assert_eq!(levels(&["--bvh-levels", "two"], false), BvhLevels::Two);
        assert_eq!(levels(&["--bvh-instances"], false), BvhLevels::Two);
    }
}
