//! Müller 2015, ch. 5.2 "Einfluss der Auflösung des Uniform Grids": the grid tracer on the
//! six-teapot scene of ch. 5.1 at resolutions 4³ … 40³, both grid variants; FPS (Fig. 21) and
//! mean triangle tests per frame (Fig. 22) per resolution. The base tracer on the same scene is
//! measured too, as the reference for speed-ups (the thesis' figures show the grid only).

use anyhow::Result;

use super::protocol::Protocol;
use super::sweep::{self, resolution_chart};
use super::thesis_bvh;
use crate::bench::common::format::{int, num};
use crate::bench::common::section::Section;
use crate::bench::published::thesis;
use crate::bench::report::plots::Figure;
use crate::bench::runner::config::{variant_name, Config, GridVariant, Sizing, Tracer};
use crate::bench::runner::outcome::Outcome;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;

pub const PROTOCOL: Protocol = Protocol {
    name: "thesis-5.2",
    title: "influence of the grid resolution (Müller 2015, ch. 5.2, Fig. 21, 22)",
    run,
    units: Units::Configs,
};

pub const SCENE: &str = "teapot6.toml";
pub const QUICK_RESOLUTIONS: &[u32] = &[4, 8, 12, 16, 20, 24, 32, 40];
pub const FULL_RESOLUTIONS: &[u32] = &[4, 8, 12, 16, 20, 24, 28, 32, 36, 40];

fn run(p: &Protocol, bench: &mut Bench) -> Result<Section> {
    // configure: the base tracer, then every variant × resolution, reflection depth 1
    let s = bench.sizing(sweep::QUICK, sweep::FULL);
    let resolutions = bench.grid_resolutions(QUICK_RESOLUTIONS, FULL_RESOLUTIONS);
    let variants = bench.variants();
    let mut configs = vec![Config::new(SCENE, Tracer::base(), 1, s)];
    configs.extend(sweep::grid_configs(SCENE, 1, s, &variants, &resolutions));
    configs.extend(thesis_bvh::configs(&[SCENE], 1, s));
    // measure
    let outcomes = bench.measure(p.name, &configs)?;
    // report
    let base = sweep::base_outcome(&outcomes, SCENE);
    let grid = sweep::grid_outcomes(&outcomes, SCENE);
    let markdown = setup_text(s, &resolutions, &variants)
        + &sweep::resolution_table(&grid, base)
        + &findings(&grid)
        + &thesis_bvh::table_text(&outcomes);
    let figures = figures(s, &grid, base);
    p.sweep_section(&bench.out, markdown, &outcomes, &figures)
}

/// Fig. 21 (FPS, with the base tracer as a line) and Fig. 22 (mean tests) by resolution.
fn figures(s: Sizing, grid: &[&Outcome], base: Option<&Outcome>) -> Vec<Figure> {
    let size = s.size();
    let fps = sweep::variant_curves(grid, |o| o.mean_fps());
    let fps = sweep::with_base_line(fps, base.and_then(|b| b.mean_fps()));
    let tests = sweep::variant_curves(grid, |o| o.tests().map(|t| t.mean));
    let fig21 = resolution_chart(
        format!("Fig. 21 (ours): FPS by grid resolution, six teapots, {size}"),
        "FPS (frames / total time)",
        fps,
    );
    let fig22 = resolution_chart(
        format!("Fig. 22 (ours): mean triangle tests per frame by grid resolution, {size}"),
        "mean triangle tests per frame",
        tests,
    );
    vec![
        Figure::new(
            "fig21_fps_vs_resolution.png",
            "Fig. 21 (ours)",
            (900, 480),
            vec![fig21],
        ),
        Figure::new(
            "fig22_tests_vs_resolution.png",
            "Fig. 22 (ours)",
            (900, 480),
            vec![fig22],
        ),
    ]
}

fn setup_text(s: Sizing, resolutions: &[u32], variants: &[GridVariant]) -> String {
    format!(
        "Setup (thesis): {}; the text does not say how many frames per resolution. Ours: \
         `scenes/{SCENE}`, reflection depth 1, {} pixels, {} angles of the rotation, {} warm-up \
         frame(s) per configuration, resolutions {}, variants {}; the base tracer on the same frames \
         as the reference for speed-up (FPS (run) ratio) and test reduction (mean tests ratio).\n\n",
        thesis::SEC52_SETUP,
        s.size(),
        s.angles,
        s.warmup,
        sweep::resolutions_text(resolutions),
        sweep::variants_text(variants)
    )
}

/// The thesis' findings (its text; Fig. 21 and 22 are plots) beside ours.
fn findings(grid: &[&Outcome]) -> String {
    let [optimum, fewer_tests, memory] = thesis::SEC52_FINDINGS;
    let memory_ours =
        "see the grid MiB column (the thesis variant's fixed lists: voxels × list length × 4 bytes)";
    let rows = vec![
        (optimum, best_text(grid)),
        (fewer_tests, tests_trend(grid)),
        (memory, memory_ours.to_string()),
    ];
    thesis::beside_findings("Fig. 21 and 22", rows)
}

/// The best resolution per variant, inside or outside the thesis' optimum.
fn best_text(grid: &[&Outcome]) -> String {
    let (lo, hi) = thesis::SEC52_OPTIMUM;
    let best = sweep::best_resolutions(grid);
    if best.is_empty() {
        return "no grid configuration was measured".to_string();
    }
    let parts: Vec<String> = best
        .iter()
        .map(|(v, r, fps)| {
            let side = if (lo..=hi).contains(r) {
                "inside"
            } else {
                "outside"
            };
            let v = variant_name(*v);
            format!(
                "{v} variant: best at {r}³ ({} FPS), {side} 12³–20³",
                num(*fps)
            )
        })
        .collect();
    parts.join("; ")
}

/// Per variant: mean tests at the coarsest and finest resolution, and how often they rose.
fn tests_trend(grid: &[&Outcome]) -> String {
    let trend = |v: GridVariant| {
        let t = sweep::variant_points(grid, v, |o| Some(o.tests()?.mean));
        let (first, last) = (t.first()?, t.last()?);
        let rises = t.windows(2).filter(|w| w[1].1 > w[0].1).count();
        (t.len() >= 2).then(|| {
            format!(
                "{} variant: mean tests {} → {} from {}³ to {}³, rising in {rises} of {} steps",
                variant_name(v),
                int(first.1),
                int(last.1),
                first.0,
                last.0,
                t.len() - 1
            )
        })
    };
    let parts: Vec<String> = sweep::VARIANTS.into_iter().filter_map(trend).collect();
    if parts.is_empty() {
        "–".into()
    } else {
        parts.join("; ")
    }
}
