//! Müller 2015, ch. 5.1 "Einfluss der Anzahl der Dreiecke": the base tracer on the scenes with
//! 1, 3 and 6 reflective teapots on a floor (14592, 27392, 46592 triangles), one light,
//! reflection depth 1, the scene rotated through 360° with one frame per degree; FPS (Fig. 19)
//! and triangle tests (Fig. 20) per frame.

use anyhow::Result;

use super::protocol::Protocol;
use super::thesis_bvh;
use crate::bench::common::format::{int, percent, ratio, table};
use crate::bench::common::section::Section;
use crate::bench::published::thesis::{self, TEAPOT_TRIANGLES};
use crate::bench::report::plots::{self, Chart, Figure, Series, Style};
use crate::bench::runner::config::{Config, Sizing, Tracer};
use crate::bench::runner::outcome::{FrameRecord, Outcome, MEASURED_COLUMNS};
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;

pub const PROTOCOL: Protocol = Protocol {
    name: "thesis-5.1",
    title: "influence of the number of triangles, base tracer (Müller 2015, ch. 5.1, Fig. 19, 20)",
    run,
    units: Units::Configs,
};

/// Quick: 8 angles (every 45°), 1 warm-up frame. Full: 360 angles (every degree), 5 warm-up.
pub const QUICK: Sizing = Sizing::quick(8, 1);
pub const FULL: Sizing = Sizing::full(360, 5);

fn run(p: &Protocol, bench: &mut Bench) -> Result<Section> {
    // configure: the base tracer on the three teapot scenes, reflection depth 1
    let s = bench.sizing(QUICK, FULL);
    let scenes: Vec<String> = TEAPOT_TRIANGLES
        .iter()
        .map(|(name, _)| format!("{name}.toml"))
        .collect();
    let mut configs: Vec<Config> = scenes
        .iter()
        .map(|scene| Config::new(scene, Tracer::base(), 1, s))
        .collect();
    let names: Vec<&str> = scenes.iter().map(String::as_str).collect();
    configs.extend(thesis_bvh::configs(&names, 1, s));
    // measure
    let outcomes = bench.measure(p.name, &configs)?;
    // report: the thesis' tracer in its table and figures, the BVH beside it
    let base = thesis_bvh::thesis_outcomes(&outcomes);
    let markdown = setup_text(s)
        + &results_table(&base)
        + &findings(&base)
        + &thesis_bvh::table_text(&outcomes);
    p.sweep_section(&bench.out, markdown, &outcomes, &figures(s, &base))
}

/// Fig. 19 and 20: one curve per scene over the rotation.
fn figures(s: Sizing, outcomes: &[Outcome]) -> Vec<Figure> {
    let size = s.size();
    let style = if s.angles > 60 {
        Style::Line
    } else {
        Style::LinePoints
    };
    let figure = |file, caption, title: String, y_label, f: fn(&FrameRecord) -> f64| {
        let curves = outcomes.iter().enumerate().map(|(i, o)| {
            let name = format!(
                "{} ({} triangles)",
                o.config.scene_name(),
                int(o.triangles as f64)
            );
            let points = o.frames.iter().map(|fr| (fr.angle, f(fr))).collect();
            Series::new(name, points, style, i)
        });
        let chart = Chart::new(
            title,
            "rotation of the scene (degrees)",
            y_label,
            curves.collect(),
        );
        Figure::new(file, caption, (900, 480), vec![chart.x_range(0.0, 360.0)])
    };
    vec![
        figure(
            "fig19_fps.png",
            "Fig. 19 (ours)",
            format!("Fig. 19 (ours): FPS of the base tracer over the rotation, {size}"),
            "FPS",
            FrameRecord::fps,
        ),
        figure(
            "fig20_tests.png",
            "Fig. 20 (ours)",
            format!("Fig. 20 (ours): triangle tests per frame, base tracer, {size}"),
            "triangle tests per frame",
            |f| f.tests() as f64,
        ),
    ]
}

fn setup_text(s: Sizing) -> String {
    let angles = if s.angles == 360 {
        "one per degree, as the thesis".to_string()
    } else {
        format!("every {}°", plots::si(360.0 / s.angles as f64))
    };
    format!(
        "Setup (thesis): {}. Ours: `scenes/teapot1.toml`, `teapot3.toml`, `teapot6.toml`, reflection depth \
         1, one light, {} pixels, {} angles ({angles}), {} warm-up frame(s) per scene.\n\n",
        thesis::SEC51_SETUP,
        s.size(),
        s.angles,
        s.warmup
    )
}

/// A row per scene: triangles (ours and the thesis'), FPS, tests, and the FPS's spread.
fn results_table(outcomes: &[Outcome]) -> String {
    let rows: Vec<Vec<String>> = outcomes
        .iter()
        .map(|o| {
            let scene = o.config.scene_name();
            let thesis = TEAPOT_TRIANGLES
                .iter()
                .find(|t| t.0 == scene)
                .map_or(0, |t| t.1);
            let mut row = vec![
                scene.to_string(),
                format!("{} / {}", int(o.triangles as f64), int(thesis as f64)),
            ];
            row.extend(o.measured_cells());
            row.push(o.fps().map_or("–".into(), |f| percent(f.spread())));
            row
        })
        .collect();
    let mut header = vec!["scene", "triangles (ours / thesis)"];
    header.extend(MEASURED_COLUMNS);
    header.push("FPS spread (max−min)/median");
    table(&header, &rows)
}

/// "teapot1 <f(teapot1)>, teapot3 ..." over the scenes `f` has a value for.
fn per_scene(ok: &[&Outcome], f: impl Fn(&Outcome) -> Option<String>) -> String {
    let parts: Vec<String> = ok
        .iter()
        .filter_map(|o| Some(format!("{} {}", o.config.scene_name(), f(o)?)))
        .collect();
    parts.join(", ")
}

/// The thesis' findings (its text; Fig. 19 and 20 are plots) beside ours.
fn findings(outcomes: &[Outcome]) -> String {
    let ok: Vec<&Outcome> = outcomes.iter().filter(|o| o.ok()).collect();
    let [proportional, fluctuates, test_phases, reflections] = thesis::SEC51_FINDINGS;
    let mut rows = Vec::new();
    if let Some(ours) = inverse_proportion(&ok) {
        rows.push((proportional, ours));
    }
    let fps_spread = per_scene(&ok, |o| Some(percent(o.fps()?.spread())));
    rows.push((
        fluctuates,
        format!("FPS spread (max−min)/median: {fps_spread}"),
    ));
    let tests_spread = per_scene(&ok, |o| Some(percent(o.tests()?.spread())));
    let per_triangle = per_scene(&ok, |o| Some(int(o.tests()?.median / o.triangles as f64)));
    rows.push((
        test_phases,
        format!(
            "tests spread (max−min)/median: {tests_spread}; tests per frame / triangles (rays that tested \
             every triangle): {per_triangle}"
        ),
    ));
    rows.push((
        reflections,
        "see the curves of Fig. 20 (ours); with reflection depth 1 a ray reflects once".to_string(),
    ));
    thesis::beside_findings("Fig. 19 and 20", rows)
}

/// FPS of the first scene over the last beside their triangles' ratio, and FPS × triangles per
/// scene (constant if FPS is inversely proportional to the triangles).
fn inverse_proportion(ok: &[&Outcome]) -> Option<String> {
    let (first, last) = (ok.first()?, ok.last()?);
    if first.config.scene == last.config.scene {
        return None;
    }
    let (f1, f6) = (first.fps()?, last.fps()?);
    let (n1, n6) = (first.config.scene_name(), last.config.scene_name());
    Some(format!(
        "FPS {n1} / {n6} = {} (median), triangles {n6} / {n1} = {}; FPS × triangles: {}",
        ratio(Some(f1.median / f6.median)),
        ratio(Some(last.triangles as f64 / first.triangles as f64)),
        per_scene(ok, |o| Some(int(o.fps()?.median * o.triangles as f64)))
    ))
}
