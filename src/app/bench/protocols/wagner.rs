//! Wagner 2018, ch. 5 "Performanceanalyse": FPS of a BVH ray tracer with one light from above,
//! the object in the centre, a fixed camera, hard shadows and no reflection.
//!
//! - `wagner-a1` (ch. 5.1, Table A.1, Fig. 5.1): a square subdivided into 8 … 32768 triangles
//!   (`scenes/square.toml` at levels 1 … 7) at 320×240 … 1680×1050.
//! - `wagner-a2` (ch. 5.2, Table A.2, Table 5.1, Fig. 5.4): the sphere of 720 triangles and the
//!   cow of 5804 at the same sizes; and the BVH build of `dragon.toml` (210,712 triangles)
//!   beside the thesis' remark that a build over 100k triangles took five minutes.
//!
//! Every configuration names its BVH variant (`sah`, ours; `wagner`, the faithful megakernel):
//! which variants run is `adapter::BVH_VARIANTS` (or `--bvh-variants`). Hardware-independent
//! comparisons: FPS(n)/FPS(8) per size (A.1), FPS(size)/FPS(320×240) per object (A.2), each
//! configuration beside its reference ([`ratios`]). The tables and figures are in
//! [`crate::bench::report::wagner`].

use anyhow::Result;

use super::protocol::Protocol;
use crate::bench::common::section::Section;
use crate::bench::published::wagner as pw;
use crate::bench::report::wagner::{self as report, size, Plan, RatioRow, Ratios};
use crate::bench::runner::args::Scale;
use crate::bench::runner::config::{BvhVariant, Config, Sizing, Tracer};
use crate::bench::runner::outcome::Outcome;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;

pub const SQUARE: &str = "square.toml";
pub const SPHERE: &str = "sphere.toml";
pub const COW: &str = "cow.toml";
pub const DRAGON: &str = "dragon.toml";

/// Quick: the three sizes of Fig. 5.1, 2 frames after 1 warm-up frame (both protocols in about
/// a minute on llvmpipe). Full: the five sizes of the tables, 10 frames after 3 (the thesis
/// does not say how many frames it averaged). `angles` is the number of measured frames here.
pub const QUICK: Sizing = Sizing::quick(2, 1);
pub const FULL: Sizing = Sizing::full(10, 3);
pub const QUICK_SIZES: &[(u32, u32)] = &pw::FIG_5_1_SIZES;
pub const FULL_SIZES: &[(u32, u32)] = &pw::SIZES;
/// The square's levels: 8, 128, 2048, 32768 triangles quick; all seven of Table A.1 full.
pub const QUICK_LEVELS: &[u32] = &[1, 3, 5, 7];
pub const FULL_LEVELS: &[u32] = &[1, 2, 3, 4, 5, 6, 7];
/// The reference of FPS(n)/FPS(8): the square of 8 triangles.
pub const REFERENCE_LEVEL: u32 = 1;

pub const WAGNER_A1: Protocol = Protocol {
    name: "wagner-a1",
    title:
        "FPS by triangle count and image size, subdivided square (Wagner 2018, Table A.1, Fig. 5.1)",
    run: run_a1,
    units: Units::Configs,
};

pub const WAGNER_A2: Protocol = Protocol {
    name: "wagner-a2",
    title: "FPS by image size, sphere and cow; BVH build of the dragon (Wagner 2018, Table A.2, \
            Table 5.1, Fig. 5.4)",
    run: run_a2,
    units: Units::Configs,
};

impl Plan {
    fn of(bench: &Bench) -> Plan {
        let mut sizes = bench.sizes(QUICK_SIZES, FULL_SIZES);
        sizes.push(pw::REFERENCE_SIZE);
        sizes.sort_by_key(|&(w, h)| (w as u64 * h as u64, w));
        sizes.dedup();
        let mut levels = bench.levels(QUICK_LEVELS, FULL_LEVELS);
        levels.push(REFERENCE_LEVEL);
        levels.sort();
        levels.dedup();
        let mut variants = bench.bvh_variants();
        variants.sort();
        variants.dedup();
        Plan {
            sizes,
            levels,
            variants,
            frames: bench.sizing(QUICK, FULL),
            scale: bench.scale(),
        }
    }

    /// `scene` with every variant at every size, camera and objects fixed, no reflection.
    fn configs(&self, scene: &str, level: Option<u32>) -> Vec<Config> {
        let mut v = Vec::new();
        for &variant in &self.variants {
            for &size in &self.sizes {
                let c = Config::fixed(scene, Tracer::bvh(variant), size, self.frames);
                v.push(match level {
                    Some(l) => c.with_level(l),
                    None => c,
                });
            }
        }
        v
    }

    /// Table A.1: the square at every level, variant and size.
    fn a1_configs(&self) -> Vec<Config> {
        let levels = self.levels.iter();
        levels
            .flat_map(|&l| self.configs(SQUARE, Some(l)))
            .collect()
    }

    /// Table A.2: the sphere and the cow at every variant and size; then the dragon, one frame
    /// at 320×240 for its BVH build (ours only at quick scale: the faithful build of 210k
    /// triangles may take minutes, as the thesis' did).
    fn a2_configs(&self) -> Vec<Config> {
        let mut v = self.configs(SPHERE, None);
        v.extend(self.configs(COW, None));
        let one = Sizing {
            angles: 1,
            ..self.frames
        };
        for &variant in &self.variants {
            if self.scale == Scale::Full || variant == BvhVariant::Sah {
                let bvh = Tracer::bvh(variant);
                v.push(Config::fixed(DRAGON, bvh, pw::REFERENCE_SIZE, one));
            }
        }
        v
    }
}

/// Whether `r` is the reference of `o` in Table A.1: the 8-triangle square of the same variant
/// at the same size.
fn a1_reference(o: &Outcome, r: &Outcome) -> bool {
    let (c, d) = (&o.config, &r.config);
    d.overrides.level == Some(REFERENCE_LEVEL)
        && (c.tracer.label(), c.width, c.height) == (d.tracer.label(), d.width, d.height)
}

/// Whether `r` is the reference of `o` in Table A.2: the same object and variant at 320×240.
fn a2_reference(o: &Outcome, r: &Outcome) -> bool {
    let (c, d) = (&o.config, &r.config);
    (d.width, d.height) == pw::REFERENCE_SIZE && c.scene == d.scene && c.tracer == d.tracer
}

/// The comparison of `outcomes`: the rows of `outcomes`: each one's FPS divided by that of the outcome `is_reference`
/// picks, and `published` (the published FPS of the configuration and of its reference).
fn ratios(
    outcomes: &[Outcome],
    reference: &'static str,
    is_reference: fn(&Outcome, &Outcome) -> bool,
    published: impl Fn(&Outcome) -> (Option<f64>, Option<f64>),
) -> Ratios {
    let fps = |o: &Outcome| o.ok().then(|| o.mean_fps()).flatten();
    let rows = outcomes.iter().map(|o| {
        let reference = outcomes.iter().find(|r| is_reference(o, r));
        let (p, p_ref) = published(o);
        let over = |a: Option<f64>, b: Option<f64>| Some(a? / b?);
        RatioRow {
            variant: o.config.tracer.variant_label().unwrap_or(""),
            object: o.config.scene_name().to_string(),
            level: o.config.overrides.level,
            triangles: o.triangles,
            size: size(o),
            fps: fps(o),
            ratio: over(fps(o), reference.and_then(fps)),
            published: p,
            published_ratio: over(p, p_ref),
            gpu_ms: o.gpu_ms().map(|s| s.median),
            build_ms: o.fact("bvh_build_ms"),
            nodes: o.fact("bvh_nodes"),
        }
    });
    Ratios {
        reference,
        rows: rows.collect(),
    }
}

fn run_a1(p: &Protocol, bench: &mut Bench) -> Result<Section> {
    let plan = Plan::of(bench);
    let outcomes = bench.measure(p.name, &plan.a1_configs())?;
    let ratios = ratios(&outcomes, "FPS(8)", a1_reference, |o| {
        let published = |triangles| pw::a1_fps(triangles, size(o));
        (published(o.triangles), published(8))
    });
    let file = ratios.write(&bench.out, p.name)?;
    let markdown = report::a1_markdown(&plan, &ratios);
    let figures = report::a1_figures(&ratios);
    let mut s = p.sweep_section(&bench.out, markdown, &outcomes, &figures)?;
    s.files.push(file);
    Ok(s)
}

fn run_a2(p: &Protocol, bench: &mut Bench) -> Result<Section> {
    let plan = Plan::of(bench);
    let outcomes = bench.measure(p.name, &plan.a2_configs())?;
    let objects: Vec<Outcome> = outcomes
        .iter()
        .filter(|o| o.config.scene != DRAGON)
        .cloned()
        .collect();
    let ratios = ratios(&objects, "FPS(320×240)", a2_reference, |o| {
        let published = |size| pw::a2_fps(o.config.scene_name(), size);
        (published(size(o)), published(pw::REFERENCE_SIZE))
    });
    let file = ratios.write(&bench.out, p.name)?;
    let dragon: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.config.scene == DRAGON)
        .collect();
    let markdown = report::a2_markdown(&plan, &ratios, dragon_mesh(bench), &dragon);
    let figures = report::a2_figures(&ratios);
    let mut s = p.sweep_section(&bench.out, markdown, &outcomes, &figures)?;
    s.files.push(file);
    Ok(s)
}

/// The dragon scene's triangles, and the dragon mesh's alone (its largest object).
fn dragon_mesh(bench: &mut Bench) -> (usize, usize) {
    let scene = bench.scene(DRAGON);
    let counts = scene.map(|s| {
        let mesh = s.objects.iter().map(|o| o.mesh.triangle_count()).max();
        (s.triangle_count(), mesh.unwrap_or(0))
    });
    counts.unwrap_or((0, 0))
}
