//! What the grid-resolution protocols (ch. 5.2, 5.3) share: configurations over resolutions
//! and variants, the table per resolution, and the curves per variant.

use crate::bench::common::format::{int, ratio, table};
use crate::bench::report::plots::{Chart, Series, Style};
use crate::bench::runner::config::{variant_name, Config, GridVariant, Sizing, Tracer};
use crate::bench::runner::outcome::{Outcome, MEASURED_COLUMNS};

/// The sizing of both resolution sweeps. Quick: 4 angles, 1 warm-up frame. Full: 36 angles
/// (every 10°), 3 warm-up frames.
pub const QUICK: Sizing = Sizing::quick(4, 1);
pub const FULL: Sizing = Sizing::full(36, 3);

/// Grid configurations for every variant × resolution of `scene`.
pub fn grid_configs(
    scene: &str,
    refl_depth: u32,
    s: Sizing,
    variants: &[GridVariant],
    resolutions: &[u32],
) -> Vec<Config> {
    let mut v = Vec::new();
    for &variant in variants {
        for &resolution in resolutions {
            let tracer = Tracer::uniform_grid(variant, resolution);
            v.push(Config::new(scene, tracer, refl_depth, s));
        }
    }
    v
}

/// "4³, 8³, 12³".
pub fn resolutions_text(resolutions: &[u32]) -> String {
    let r: Vec<String> = resolutions.iter().map(|r| format!("{r}³")).collect();
    r.join(", ")
}

/// "thesis, exact".
pub fn variants_text(variants: &[GridVariant]) -> String {
    let v: Vec<&str> = variants.iter().map(|v| variant_name(*v)).collect();
    v.join(", ")
}

/// The speed-up of `o` over `base`: ratio of the FPS over the whole runs (frames / total time,
/// the thesis' mean FPS).
pub fn speedup(o: &Outcome, base: Option<&Outcome>) -> Option<f64> {
    Some(o.mean_fps()? / base.filter(|b| b.ok())?.mean_fps()?)
}

/// The test reduction of `o` against `base`: ratio of the mean tests per frame.
pub fn test_reduction(o: &Outcome, base: Option<&Outcome>) -> Option<f64> {
    let g = o.tests()?.mean;
    (g > 0.0).then_some(())?;
    Some(base.filter(|b| b.ok())?.tests()?.mean / g)
}

/// The grid outcomes of `scene` (in configuration order).
pub fn grid_outcomes<'a>(outcomes: &'a [Outcome], scene: &str) -> Vec<&'a Outcome> {
    outcomes
        .iter()
        .filter(|o| o.config.scene == scene && o.config.tracer.resolution().is_some())
        .collect()
}

/// The base outcome of `scene`, if measured.
pub fn base_outcome<'a>(outcomes: &'a [Outcome], scene: &str) -> Option<&'a Outcome> {
    outcomes
        .iter()
        .find(|o| o.config.scene == scene && o.config.tracer.is_base())
}

/// A markdown table with a row per grid configuration (and the base tracer first, if given).
pub fn resolution_table(grid: &[&Outcome], base: Option<&Outcome>) -> String {
    let failed_or = |o: &Outcome, events: String| match o.error {
        Some(_) => "failed".to_string(),
        None => events,
    };
    let mut rows = Vec::new();
    if let Some(b) = base {
        let mut row = vec!["base".into(), "–".into()];
        row.extend(b.measured_cells());
        row.extend(["–", "×1", "×1", "–"].map(String::from));
        row.push(failed_or(b, "–".into()));
        rows.push(row);
    }
    for o in grid {
        let Some((variant, resolution)) = o.config.tracer.grid() else {
            continue;
        };
        let mut row = vec![
            format!("grid {}", variant_name(variant)),
            format!("{resolution}³"),
        ];
        row.extend(o.measured_cells());
        row.extend([
            o.voxels().map(|v| int(v.median)).unwrap_or("–".into()),
            ratio(speedup(o, base)),
            ratio(test_reduction(o, base)),
            o.fact("grid_bytes")
                .map(|b| format!("{:.1}", b / (1024.0 * 1024.0)))
                .unwrap_or("–".into()),
            failed_or(o, o.event_summary()),
        ]);
        rows.push(row);
    }
    let mut header = vec!["tracer", "grid"];
    header.extend(MEASURED_COLUMNS);
    header.extend([
        "voxels visited",
        "speed-up",
        "test reduction",
        "grid MiB",
        "events",
    ]);
    table(&header, &rows)
}

/// Both grid variants, in the order of the tables and the colours of the curves.
pub const VARIANTS: [GridVariant; 2] = [GridVariant::Thesis, GridVariant::Exact];

/// (resolution, f(outcome)) of `variant` over the successful configurations.
pub fn variant_points(
    grid: &[&Outcome],
    variant: GridVariant,
    f: impl Fn(&Outcome) -> Option<f64>,
) -> Vec<(u32, f64)> {
    grid.iter()
        .filter(|o| o.ok() && o.config.tracer.variant() == Some(variant))
        .filter_map(|o| Some((o.config.tracer.resolution()?, f(o)?)))
        .collect()
}

/// One curve per variant: (resolution, f(outcome)) over the successful configurations.
pub fn variant_curves(grid: &[&Outcome], f: impl Fn(&Outcome) -> Option<f64>) -> Vec<Series> {
    let mut out = Vec::new();
    for (i, variant) in VARIANTS.into_iter().enumerate() {
        let pts: Vec<(f64, f64)> = variant_points(grid, variant, &f)
            .into_iter()
            .map(|(r, y)| (r as f64, y))
            .collect();
        if !pts.is_empty() {
            let name = format!("grid, {} variant", variant_name(variant));
            out.push(Series::new(name, pts, Style::LinePoints, i));
        }
    }
    out
}

/// A horizontal dashed line at `y` over the x range of `curves` (the base tracer).
pub fn reference_line(name: &str, y: f64, curves: &[Series], color: usize) -> Option<Series> {
    let xs = curves.iter().flat_map(|s| s.points.iter().map(|p| p.0));
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    (lo.is_finite() && y.is_finite())
        .then(|| Series::new(name, vec![(lo, y), (hi, y)], Style::Dashed, color))
}

/// `curves` and, where the base tracer was measured (`base_y`), its value as a dashed line.
pub fn with_base_line(curves: Vec<Series>, base_y: Option<f64>) -> Vec<Series> {
    let line = base_y.and_then(|y| reference_line("base tracer", y, &curves, 2));
    curves.into_iter().chain(line).collect()
}

/// A panel over the grid resolution with a logarithmic y axis.
pub fn resolution_chart(title: impl Into<String>, y_label: &str, series: Vec<Series>) -> Chart {
    Chart::new(title, "grid resolution N (N³ voxels)", y_label, series).log_y()
}

/// The resolution with the highest FPS (run) per variant: "thesis 16³, exact 20³".
pub fn best_resolutions(grid: &[&Outcome]) -> Vec<(GridVariant, u32, f64)> {
    let best = |v| {
        variant_points(grid, v, |o| o.mean_fps())
            .into_iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
    };
    VARIANTS
        .into_iter()
        .filter_map(|v| best(v).map(|(r, fps)| (v, r, fps)))
        .collect()
}
