//! The SAH BVH beside Müller 2015's tracers — ours (issue 34): each thesis protocol (ch.
//! 5.1–5.3) measures `--tracer bvh` on its scenes too, turned as they are, in both of its
//! structures. With `--rotate objects` every frame moves every object: the one tree (the
//! default) is refitted on the GPU every frame and rebuilt on the CPU only when the refit grew
//! its SAH cost past `REBUILD_GROWTH`; with `--bvh-instances` (a tree per object, built once)
//! the frame rewrites only the instances' table (`docs/design/bvh.md`, "Moving objects" and
//! "Two levels"). The protocols' own tables and figures stay the thesis' (base and grids); this
//! module adds one table of the BVH beside them.

use crate::bench::common::format::{int, num, ratio, table};
use crate::bench::runner::config::{BvhVariant, Config, Sizing, Tracer};
use crate::bench::runner::outcome::{FrameRecord, Outcome};

/// The SAH BVH (the product's, not Wagner's) on each of `scenes`: one tree, then instances.
pub fn configs(scenes: &[&str], refl_depth: u32, s: Sizing) -> Vec<Config> {
    let tracers = [Tracer::bvh(BvhVariant::Sah), Tracer::bvh_instances()];
    let config = |(scene, tracer): (&&str, Tracer)| Config::new(scene, tracer, refl_depth, s);
    scenes
        .iter()
        .flat_map(|scene| tracers.clone().map(|t| (scene, t)))
        .map(config)
        .collect()
}

/// Whether `o` measured a BVH.
pub fn is_bvh(o: &Outcome) -> bool {
    o.config.tracer.row().name == "bvh"
}

/// The outcomes that are not the BVH's: those the thesis' tables and figures show.
pub fn thesis_outcomes(outcomes: &[Outcome]) -> Vec<Outcome> {
    outcomes.iter().filter(|o| !is_bvh(o)).cloned().collect()
}

/// The mean over the frames of the fact `name` (0 where a frame lacks it).
fn mean_fact(o: &Outcome, name: &str) -> f64 {
    let v = |f: &FrameRecord| {
        f.stats
            .facts
            .get(name)
            .and_then(|v| v.as_f64())
            .unwrap_or(0.0)
    };
    o.frames.iter().map(v).sum::<f64>() / o.frames.len().max(1) as f64
}

/// Frames of `o` whose fact `name` is `true`.
fn count_true(o: &Outcome, name: &str) -> usize {
    let yes = |f: &&FrameRecord| f.stats.facts.get(name).and_then(|v| v.as_bool()) == Some(true);
    o.frames.iter().filter(yes).count()
}

/// A row per BVH outcome: its structure, its run FPS and mean GPU time and tests beside the base
/// tracer's and the fastest grid's on the same scene, its mean update per frame (the one tree's
/// refit on the GPU, the instances' table written by the CPU), and its CPU builds during the
/// measured frames (the first build falls in the warm-up unless there is none).
pub fn table_text(outcomes: &[Outcome]) -> String {
    let same = |o: &Outcome, bvh: &Outcome| o.ok() && o.config.scene == bvh.config.scene;
    let fps = |o: Option<&Outcome>| o.and_then(Outcome::mean_fps);
    let rows: Vec<Vec<String>> = outcomes
        .iter()
        .filter(|o| is_bvh(o) && o.ok())
        .map(|b| {
            let base = outcomes
                .iter()
                .find(|o| same(o, b) && o.config.tracer.is_base());
            let grid = outcomes
                .iter()
                .filter(|o| same(o, b) && o.config.tracer.grid().is_some())
                .max_by(|x, y| fps(Some(x)).partial_cmp(&fps(Some(y))).expect("FPS"));
            let gpu = |o: Option<&Outcome>| o.and_then(|o| o.gpu_ms()).map(|s| s.mean);
            let tests = |o: Option<&Outcome>| o.and_then(|o| o.tests()).map(|s| s.mean);
            let cell = |v: Option<f64>, f: fn(f64) -> String| v.map_or("–".into(), f);
            // the update per frame: the refit's GPU time, or the instance table's CPU time
            let (structure, refit, table) = match b.config.tracer.variant_label() {
                Some("sah-instances") => (
                    "instances",
                    "–".into(),
                    num(mean_fact(b, "bvh_instances_ms")),
                ),
                _ => ("one tree", num(mean_fact(b, "bvh_refit_ms")), "–".into()),
            };
            vec![
                b.config.scene_name().to_string(),
                structure.to_string(),
                cell(fps(Some(b)), num),
                format!("{} / {}", cell(fps(base), num), cell(fps(grid), num)),
                cell(gpu(Some(b)), num),
                ratio(gpu(base).zip(gpu(Some(b))).map(|(a, b)| a / b)),
                format!("{} / {}", cell(tests(Some(b)), int), cell(tests(base), int)),
                refit,
                table,
                count_true(b, "bvh_rebuilt").to_string(),
            ]
        })
        .collect();
    if rows.is_empty() {
        return String::new();
    }
    let header = [
        "scene",
        "BVH",
        "BVH FPS (run)",
        "FPS base / best grid",
        "BVH GPU ms (mean)",
        "base GPU ms / BVH's",
        "tests per frame, BVH / base (mean)",
        "refit ms, GPU (mean per frame)",
        "instance table ms, CPU (mean per frame)",
        "BVH builds (frames)",
    ];
    "### The SAH BVH beside them (ours)\n\n`--tracer bvh` on the same scenes and frames, \
     one tree and a tree per object under instances (`--bvh-instances`). With `--rotate objects` \
     every frame moves the objects: the one tree is refitted on the GPU (`bvh_refit_ms`) and \
     rebuilt on the CPU only where a refit grew its SAH cost past `REBUILD_GROWTH`; the \
     instances' trees are built once and a frame rewrites their table (`bvh_instances_ms`) \
     (`docs/design/bvh.md`, \"Moving objects\", \"Two levels\").\n\n"
        .to_string()
        + &table(&header, &rows)
}
