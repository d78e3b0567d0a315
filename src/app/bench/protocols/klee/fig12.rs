//! `klee-fig12` (Klee 2016, Fig. 12): the bunny's shadows with 2×2 … 10×10 rays, CPU vs GPU
//! (FPS and seconds), and the error against `exact`, at both readings of the N-tree depth.

use anyhow::Result;

use super::common::{klee, mean_error, memory_line, readings, Measured, BUNNY, SAMPLES};
use super::measure::{Row, Setup};
use crate::bench::common::format::{int, num, percent, table};
use crate::bench::protocols::protocol::Protocol;
use crate::bench::published::klee as published;
use crate::bench::report::plots::{Chart, Figure, Series, Style, BLACK_INDEX};
use crate::bench::runner::config::Sizing;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;
use gpgpu_rt::scene::ShadowMode;

pub const KLEE_FIG12: Protocol = Protocol {
    name: "klee-fig12",
    title: "2×2 … 10×10 rays, CPU vs GPU, bunny (Klee 2016, Fig. 12)",
    run: |p, bench| klee(p, bench, fig12),
    units: Units::Whole,
};

/// Fig. 12: the bunny's shadows with 2×2 … 10×10 rays on the GPU and on the CPU, at both
/// readings of the N-tree depth.
fn fig12(bench: &mut Bench, s: Sizing) -> Result<Measured> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    for (letter, levels) in readings(bench) {
        let mut st = Setup::new(bench, BUNNY, s, levels)?;
        let (first, mut errors) = (rows.len(), Vec::new());
        for k in SAMPLES {
            let gpu = st.gpu(bench, ShadowMode::Linespace, k, k)?;
            let (cpu, values) = st.cpu_values(&gpu.last, ShadowMode::Linespace, k, k);
            let (_, exact) = st.cpu_values(&gpu.last, ShadowMode::Exact, k, k);
            errors.push(mean_error(&values, &exact));
            rows.push(Row::new("bunny", "linespace", "GPU", k * k, gpu.shadow).levels(levels));
            rows.push(Row::new("bunny", "linespace", "CPU", k * k, cpu).levels(levels));
        }
        lines.extend(fig12_lines(letter, &rows[first..], &errors, st.memory()));
    }
    let header = [
        "rays (reading)",
        "CPU (s)",
        "GPU (s)",
        "CPU FPS",
        "GPU FPS",
        "GPU saving",
        "CPU lookups at depth 0 / 1 / 2",
        "mean |s − exact|",
    ];
    let markdown = format!(
        "Published: the GPU takes {:.0} % less time than the CPU at every sample count, never below \
         1 FPS; the CPU needs several seconds beyond 36 rays. Reading A: 3 levels counting the \
         root; B: 4 levels, the cascade (see klee-table2); the figure shows A. The error: the \
         mean over the pixels of the difference of the CPU's `linespace` shadow values from its \
         `exact` ones (triangle tests) with the same rays; the GPU's values equal the CPU's \
         (tests/linespace.rs).\n\n{}",
        100.0 * published::FIG12_GPU_SAVING,
        table(&header, &lines)
    );
    let a: Vec<Row> = rows.iter().filter(|r| r.levels == 3).cloned().collect();
    let figures = vec![fig12_figure(&a)];
    Ok(Measured {
        rows,
        markdown,
        figures,
    })
}

/// Fig. 12's lines of one reading (rows: GPU, CPU per sample count; `errors`: the CPU's against
/// `exact` per sample count) and its memory line.
fn fig12_lines(
    letter: &str,
    rows: &[Row],
    errors: &[f64],
    (tree_b, ls_b): (usize, usize),
) -> Vec<Vec<String>> {
    let mut lines: Vec<Vec<String>> = rows
        .chunks(2)
        .zip(SAMPLES)
        .zip(errors)
        .map(|((pair, k), error)| {
            let (g, c) = (pair[0].m.mean_s, pair[1].m.mean_s);
            let depths = pair[1].m.lookups_by_depth.map(|v| int(v as f64));
            let cells = [
                num(c),
                num(g),
                num(1.0 / c),
                num(1.0 / g),
                percent(1.0 - g / c),
                depths.join(" / "),
                format!("{error:.4}"),
            ];
            [format!("{k}×{k} ({letter})")]
                .into_iter()
                .chain(cells)
                .collect()
        })
        .collect();
    lines.push(memory_line(
        format!("memory ({letter})"),
        (tree_b, ls_b),
        8,
        1,
    ));
    lines
}

/// (rays, f(seconds)) of the rows measured on `device`.
fn points(rows: &[Row], device: &str, f: fn(f64) -> f64) -> Vec<(f64, f64)> {
    rows.iter()
        .filter(|r| r.device == device)
        .map(|r| (r.rays as f64, f(r.m.mean_s)))
        .collect()
}

/// Fig. 12: FPS and seconds of the GPU and the CPU, with the published saving applied to ours.
fn fig12_figure(rows: &[Row]) -> Figure {
    let devices = |f: fn(f64) -> f64| {
        vec![
            Series::new("GPU", points(rows, "GPU", f), Style::LinePoints, 0),
            Series::new("CPU", points(rows, "CPU", f), Style::LinePoints, 1),
        ]
    };
    let mut seconds = devices(|s| s);
    let published = points(rows, "CPU", |s| s * (1.0 - published::FIG12_GPU_SAVING));
    seconds.push(Series::new(
        "published ratio × our CPU",
        published,
        Style::Crosses,
        BLACK_INDEX,
    ));
    let rays = "shadow rays per pixel";
    let charts = vec![
        Chart::new("Fig. 12(a): FPS", rays, "FPS", devices(|s| 1.0 / s)).log_y(),
        Chart::new("Fig. 12(b): seconds", rays, "s", seconds).log_y(),
    ];
    Figure::new("klee-fig12.png", "Fig. 12", (640, 420), charts)
}
