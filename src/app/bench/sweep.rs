//! What the grid-resolution protocols (ch. 5.2, 5.3) share: configurations over resolutions
//! and variants, the table per resolution, and the curves per variant.

use super::plots::{Series, Style};
use super::report::{self, int, mmm, num, ratio};
use super::runner::{variant_name, Config, Outcome, Sizing, TracerSpec};
use gpgpu_rt::accel::GridVariant;

/// Grid configurations for every variant × resolution of `scene`.
pub fn grid_configs(
    scene: &str,
    refl_depth: u32,
    s: Sizing,
    angles: &[f64],
    variants: &[GridVariant],
    resolutions: &[u32],
) -> Vec<Config> {
    let mut v = Vec::new();
    for &variant in variants {
        for &resolution in resolutions {
            v.push(Config {
                scene: scene.into(),
                tracer: TracerSpec::Grid {
                    variant,
                    resolution,
                },
                refl_depth,
                width: s.width,
                height: s.height,
                angles: angles.to_vec(),
                warmup: s.warmup,
            });
        }
    }
    v
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
        .find(|o| o.config.scene == scene && o.config.tracer == TracerSpec::Base)
}

/// A markdown table with a row per grid configuration (and the base tracer first, if given).
pub fn resolution_table(grid: &[&Outcome], base: Option<&Outcome>) -> String {
    let mut rows = Vec::new();
    if let Some(b) = base {
        rows.push(vec![
            "base".into(),
            "–".into(),
            mmm(b.fps(), num),
            b.mean_fps().map(num).unwrap_or("–".into()),
            mmm(b.gpu_ms(), num),
            mmm(b.tests(), int),
            b.tests().map(|t| int(t.mean)).unwrap_or("–".into()),
            "–".into(),
            "×1".into(),
            "×1".into(),
            "–".into(),
            if b.error.is_some() {
                "failed".into()
            } else {
                "–".into()
            },
        ]);
    }
    for o in grid {
        let TracerSpec::Grid {
            variant,
            resolution,
        } = o.config.tracer
        else {
            continue;
        };
        rows.push(vec![
            format!("grid {}", variant_name(variant)),
            format!("{resolution}³"),
            mmm(o.fps(), num),
            o.mean_fps().map(num).unwrap_or("–".into()),
            mmm(o.gpu_ms(), num),
            mmm(o.tests(), int),
            o.tests().map(|t| int(t.mean)).unwrap_or("–".into()),
            o.voxels().map(|v| int(v.median)).unwrap_or("–".into()),
            ratio(speedup(o, base)),
            ratio(test_reduction(o, base)),
            report::fact(o, "grid_bytes")
                .map(|b| format!("{:.1}", b / (1024.0 * 1024.0)))
                .unwrap_or("–".into()),
            if o.error.is_some() {
                "failed".into()
            } else {
                report::event_summary(o)
            },
        ]);
    }
    report::table(
        &[
            "tracer",
            "grid",
            "FPS",
            "FPS (run)",
            "GPU ms",
            "triangle tests per frame",
            "mean tests",
            "voxels visited",
            "speed-up",
            "test reduction",
            "grid MiB",
            "events",
        ],
        &rows,
    )
}

/// One curve per variant: (resolution, f(outcome)) over the successful configurations.
pub fn variant_curves(grid: &[&Outcome], f: impl Fn(&Outcome) -> Option<f64>) -> Vec<Series> {
    let mut out = Vec::new();
    for (i, variant) in [GridVariant::Thesis, GridVariant::Exact]
        .into_iter()
        .enumerate()
    {
        let pts: Vec<(f64, f64)> = grid
            .iter()
            .filter(|o| o.ok() && o.config.tracer.variant() == Some(variant))
            .filter_map(|o| Some((o.config.tracer.resolution()? as f64, f(o)?)))
            .collect();
        if !pts.is_empty() {
            out.push(Series::new(
                format!("grid, {} variant", variant_name(variant)),
                pts,
                Style::LinePoints,
                i,
            ));
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

/// The resolution with the highest FPS (run) per variant: "thesis 16³, exact 20³".
pub fn best_resolutions(grid: &[&Outcome]) -> Vec<(GridVariant, u32, f64)> {
    let mut out = Vec::new();
    for variant in [GridVariant::Thesis, GridVariant::Exact] {
        let best = grid
            .iter()
            .filter(|o| o.ok() && o.config.tracer.variant() == Some(variant))
            .filter_map(|o| Some((o.config.tracer.resolution()?, o.mean_fps()?)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((r, fps)) = best {
            out.push((variant, r, fps));
        }
    }
    out
}
