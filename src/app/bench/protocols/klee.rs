//! Klee 2016, ch. 5: the evaluation of soft shadows with the Cascaded Line Space, replicated.
//! N-tree N = 10, 3 levels counting the root (reading A of the thesis' depth 3; table 2, 3 and
//! Fig. 12 also at 4 levels, reading B); the bunny (`bunny_area.toml`) and the dragon
//! (`dragon_area.toml`: 202520 triangles — the thesis' 871k dragon is not available). Shadow
//! times exclude the primary rays, as the thesis measures them; every time is the mean over
//! the frames (the thesis: ten). "CPU" is our CPU implementation (`src/reference/linespace.rs`,
//! one thread, primary hits from the G-buffer except in Table 1); "GPU" the shadow kernel's GL
//! timer-query time. The measuring is in [`super::klee_measure`].
//!
//! - `klee-table1`: primary rays, GPU rasterisation (the G-buffer pass) vs CPU ray casting.
//! - `klee-table2`: CPU, bunny, 4 rays: triangle tests (`exact`, `variant1`) vs line-space
//!   lookups (`linespace`, `variant2`), at both readings of the N-tree depth, and how much of
//!   the gap to the published saving each explains.
//! - `klee-table3`: CPU, bunny, CGT (`linespace`) vs DDA (`linespace-dda`), 4/9/16/100 rays, and
//!   the error of each against `exact`, at both readings.
//! - `klee-fig12`: bunny, 2×2 … 10×10 rays, CPU vs GPU (FPS and seconds), and the error
//!   against `exact`, at both readings.
//! - `klee-fig13`: GPU, bunny vs dragon, 2×2 … 10×10 rays.

use anyhow::Result;

use super::klee_measure::{section, Row, Setup, READINGS};
use super::protocol::Protocol;
use crate::bench::common::format::{int, num, percent, ratio, table};
use crate::bench::common::section::Section;
use crate::bench::report::plots::{Chart, Figure, Series, Style, BLACK_INDEX};
use crate::bench::runner::config::Sizing;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;
use gpgpu_rt::scene::ShadowMode;

pub const BUNNY: &str = "bunny_area.toml";
pub const DRAGON: &str = "dragon_area.toml";
/// The scenes of Table 1 and Fig. 13 with their names in the tables.
const SCENES: [(&str, &str); 2] = [(BUNNY, "bunny"), (DRAGON, "dragon")];
/// Fig. 12 and 13: k × k shadow rays per pixel.
const SAMPLES: std::ops::RangeInclusive<u32> = 2..=10;

/// Quick: 64², 2 frames (1 warm-up). Full: 512² as the thesis' test images, 10 frames.
/// (`angles` is the number of measured frames here.)
pub const QUICK: Sizing = Sizing::quick(2, 1);
pub const FULL: Sizing = Sizing::full(10, 1);

/// Published: Table 1 (seconds): scene, GPU, CPU (the dragon: 871k triangles).
pub const TABLE1: [(&str, f64, f64); 2] = [
    ("bunny", 0.000993448, 0.178985),
    ("dragon", 0.00189566, 0.197976),
];
/// Published: Table 2 (seconds, CPU, bunny, 4 rays): triangle tests, line-space lookups.
pub const TABLE2: [(&str, f64); 2] = [
    ("triangle tests", 6.064665),
    ("line-space lookups", 0.448443),
];
/// Published: Table 3 (seconds, CPU, bunny): rays, CGT, DDA.
pub const TABLE3: [(u32, f64, f64); 4] = [
    (4, 0.628609, 0.356825),
    (9, 0.867256, 0.550786),
    (16, 1.18496, 0.829777),
    (100, 4.82775, 3.88766),
];
/// Published: Fig. 12 — the GPU takes 86 % less time than the CPU at every sample count.
pub const FIG12_GPU_SAVING: f64 = 0.86;
/// Published: Fig. 13 — the dragon (871k) takes 3 % longer than the bunny at 4 rays, 22 % at 100.
pub const FIG13_DRAGON_EXTRA: [(u32, f64); 2] = [(4, 0.03), (100, 0.22)];

/// What a Klee protocol measured and says: the CSV rows, the markdown that sets them beside the
/// published numbers, and its figures.
struct Measured {
    rows: Vec<Row>,
    markdown: String,
    figures: Vec<Figure>,
}

impl Measured {
    /// A table without figures.
    fn table(rows: Vec<Row>, markdown: String) -> Measured {
        Measured {
            rows,
            markdown,
            figures: vec![],
        }
    }
}

/// Run a Klee protocol: configure (the sizes at the scale), `measure` (which also says what
/// the numbers mean), report (the section with the CSV and the figures).
fn klee(
    p: &Protocol,
    bench: &mut Bench,
    measure: fn(&mut Bench, Sizing) -> Result<Measured>,
) -> Result<Section> {
    let s = bench.sizing(QUICK, FULL);
    let m = measure(bench, s)?;
    section(p, bench, s, &m.markdown, &m.rows, &m.figures)
}

/// The bunny's shadows on the CPU with an N-tree of `levels` levels: a row per (variant, mode,
/// rays per pixel) and its shadow values, for the pixels of its G-buffer from the GPU (2×2
/// samples), at least `min_cpu_frames` frames each; and the bytes of the node pool and of the
/// line spaces.
fn bunny_on_cpu(
    bench: &mut Bench,
    s: Sizing,
    levels: u32,
    min_cpu_frames: u32,
    runs: &[(&str, ShadowMode, u32)],
) -> Result<(Vec<Measured1>, Memory)> {
    let mut st = Setup::new(bench, BUNNY, s, levels)?;
    st.min_cpu_frames = min_cpu_frames;
    let frame = st.gpu(bench, ShadowMode::Linespace, 2, 2)?.last;
    let row = |&(variant, mode, rays): &(&str, ShadowMode, u32)| {
        let k = (rays as f64).sqrt() as u32;
        let (m, values) = st.cpu_values(&frame, mode, k, k);
        let row = Row::new("bunny", variant, "CPU", rays, m).levels(levels);
        (row, values)
    };
    Ok((runs.iter().map(row).collect(), st.memory()))
}

/// Bytes of an N-tree's node pool and of its line spaces.
type Memory = (usize, usize);
/// A row and the shadow values of its pixels.
type Measured1 = (Row, Vec<f32>);

/// The readings of the N-tree depth to measure: `--ntree-levels`, or both [`READINGS`].
fn readings(bench: &Bench) -> Vec<(&'static str, u32)> {
    let chosen = bench.args.klee.ntree_levels.as_ref();
    let wanted = |r: &(&str, u32)| chosen.is_none_or(|c| c.contains(&r.1));
    READINGS.into_iter().filter(wanted).collect()
}

/// The reading's letter for `levels` (see [`READINGS`]).
fn reading(levels: u32) -> &'static str {
    READINGS.iter().find(|r| r.1 == levels).map_or("?", |r| r.0)
}

/// Mean |a − b| over the pixels.
fn mean_error(a: &[f32], b: &[f32]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(x, y)| (x - y).abs() as f64).sum();
    sum / a.len().max(1) as f64
}

pub const KLEE_TABLE1: Protocol = Protocol {
    name: "klee-table1",
    title: "primary rays: GPU rasterisation vs CPU ray casting (Klee 2016, Table 1)",
    run: |p, bench| klee(p, bench, table1),
    units: Units::Whole,
};

/// Table 1: per scene, the G-buffer pass on the GPU and the primary rays cast on the CPU.
fn table1(bench: &mut Bench, s: Sizing) -> Result<Measured> {
    let mut rows = Vec::new();
    for (scene, label) in SCENES {
        let mut st = Setup::new(bench, scene, s, 3)?;
        let gpu = st.gpu(bench, ShadowMode::Linespace, 2, 2)?.gbuffer;
        rows.push(Row::new(label, "primary", "GPU", 1, gpu));
        rows.push(Row::new(label, "primary", "CPU", 1, st.cpu_primary()));
    }
    let mut lines = Vec::new();
    for ((label, p_gpu, p_cpu), pair) in TABLE1.into_iter().zip(rows.chunks(2)) {
        let (gpu, cpu) = (pair[0].m.mean_s, pair[1].m.mean_s);
        let [p_ratio, ours_ratio] = [p_cpu / p_gpu, cpu / gpu].map(|r| ratio(Some(r)));
        lines.push(vec![format!("GPU {label}"), num(p_gpu), num(gpu)]);
        lines.push(vec![format!("CPU {label}"), num(p_cpu), num(cpu)]);
        lines.push(vec![format!("CPU / GPU {label}"), p_ratio, ours_ratio]);
    }
    let markdown = table(&["variant", "published (s)", "ours (s)"], &lines)
        + "\nGPU: the G-buffer pass (rasterisation into the FBO). CPU: a hierarchical 3D-DDA through the \
           N-tree testing the leaves' triangles. The thesis' dragon had 871k triangles, ours 202520.\n";
    Ok(Measured::table(rows, markdown))
}

pub const KLEE_TABLE2: Protocol = Protocol {
    name: "klee-table2",
    title: "triangle tests vs line-space lookups, CPU, bunny, 4 rays (Klee 2016, Table 2)",
    run: |p, bench| klee(p, bench, table2),
    units: Units::Whole,
};

/// Table 2: frames timed on the CPU per mode (the fastest counts: milliseconds at the quick
/// size on a shared machine).
const TABLE2_FRAMES: u32 = 5;

/// Table 2's modes: ours and the thesis' two variants, with the published time each compares to.
const TABLE2_MODES: [(&str, ShadowMode, f64); 5] = [
    ("exact", ShadowMode::Exact, TABLE2[0].1),
    ("variant1", ShadowMode::Variant1, TABLE2[0].1),
    ("linespace", ShadowMode::Linespace, TABLE2[1].1),
    ("variant2", ShadowMode::Variant2, TABLE2[1].1),
    ("linespace-fast", ShadowMode::LinespaceFast, TABLE2[1].1),
];

/// Table 2: the bunny's 2×2 shadows on the CPU, with triangle tests and with line-space lookups,
/// ours and the thesis' variants, at both readings of the N-tree depth.
fn table2(bench: &mut Bench, s: Sizing) -> Result<Measured> {
    let runs = TABLE2_MODES.map(|(name, mode, _)| (name, mode, 4));
    let (mut rows, mut lines, mut savings) = (Vec::new(), Vec::new(), Vec::new());
    for (letter, levels) in readings(bench) {
        let (measured, (tree_b, ls_b)) = bunny_on_cpu(bench, s, levels, TABLE2_FRAMES, &runs)?;
        let exact = &measured[0].1;
        for ((row, values), (_, _, published)) in measured.iter().zip(TABLE2_MODES) {
            let m = &row.m;
            let depths = m.lookups_by_depth.map(|v| int(v as f64)).join(" / ");
            lines.push(vec![
                format!("{} ({letter})", row.variant),
                num(published),
                num(m.min_s),
                int(m.triangle_tests as f64),
                depths,
                format!("{:.4}", mean_error(values, exact)),
            ]);
        }
        let t = |i: usize| measured[i].0.m.min_s;
        let saving = |a: usize, b: usize| 1.0 - t(a) / t(b);
        let tests = |i: usize| measured[i].0.m.triangle_tests as f64;
        savings.push(Savings {
            letter,
            linespace: saving(2, 0),
            variants: saving(3, 1),
            fast: saving(4, 0),
            fast_tests: tests(4) / tests(0).max(1.0),
        });
        let label = format!("memory ({letter}): node pool + line spaces");
        lines.push(memory_line(label, (tree_b, ls_b), 6, 2));
        rows.extend(measured.into_iter().map(|(r, _)| r));
    }
    let header = [
        "variant (reading)",
        "published (s)",
        "ours (s, fastest frame)",
        "triangle tests",
        "lookups at depth 0 / 1 / 2",
        "mean |s − exact|",
    ];
    let markdown = table(&header, &lines) + &table2_gap(&savings);
    Ok(Measured::table(rows, markdown))
}

/// Table 2's savings at one reading of the N-tree depth: the share of the time saved by
/// `linespace` and `linespace-fast` over `exact`, and by `variant2` over `variant1`.
struct Savings {
    letter: &'static str,
    linespace: f64,
    variants: f64,
    fast: f64,
    /// `linespace-fast`'s triangle tests over `exact`'s
    fast_tests: f64,
}

/// What Table 2's savings say: ours vs the variants, reading A vs B, against the published
/// 92.6 %.
fn table2_gap(savings: &[Savings]) -> String {
    let published = 1.0 - TABLE2[1].1 / TABLE2[0].1;
    let mut text = format!(
        "\nPublished saving of the line-space lookups over the triangle tests: {}.\n\n",
        pct(published)
    );
    for s in savings {
        text += &format!(
            "- reading {}: `linespace` vs `exact` saves {}, `linespace-fast` vs `exact` {} (with {} \
             of `exact`'s triangle tests), `variant2` vs `variant1` {}.\n",
            s.letter,
            pct(s.linespace),
            pct(s.fast),
            pct(s.fast_tests),
            pct(s.variants)
        );
    }
    if let [a, b] = savings {
        let gap = published - a.linespace;
        let share = |x: f64| pct(x / gap);
        let closes = |x: f64| {
            format!(
                "{} points ({})",
                pp(x - a.linespace),
                share(x - a.linespace)
            )
        };
        text += &format!(
            "\nOf the gap between `linespace` at reading A and the published saving ({} points), \
             the depth reading (A → B, `linespace` vs `exact`) closes {}, the variants as defined \
             (at A) {}, both together (`variant2` vs `variant1` at B) {}, and `linespace-fast` (at \
             A) {}.\n",
            pp(gap),
            closes(b.linespace),
            closes(a.variants),
            closes(b.variants),
            closes(a.fast),
        );
    }
    text += "\nWhat stands between `linespace` and the published saving: Table 2 compares the thesis' \
             variants, which we reproduce as defined (`variant1`, `variant2`), and their saving is \
             the published one's order — but `variant2` never tests the node its rays start in, \
             so every surface shadows itself (its error). Ours keeps that node's exact tests (the \
             near-origin rule), and they are most of `exact`'s: `linespace` keeps them all, \
             `linespace-fast` culls them per packet. With 4 rays a pixel's time is then mostly the \
             walk — node fetches and line-space lookups, which `linespace-fast` does not reduce — not \
             the triangle tests, so cutting the tests saves less time than it removes tests; with 25 or 100 rays \
             per pixel on the GPU the tests dominate (docs/results/linespace-shadows.md).\n";
    text +=
        "\nAt the quick size these CPU times are milliseconds: the split of the gap moves by tens \
             of points between runs on a shared machine; the triangle tests, lookups and errors do \
             not.\n";
    text + "\n`variant1` is `exact` without our near-origin rule: the line space of the node holding \
            the origin is asked too (its shaft reaches back behind the origin, so it is conservative \
            and the image equals `exact`). `variant2` is `linespace` without it: the deepest level \
            is never visited, no triangle is tested — and the shaft of the origin's own node holds \
            the surface the rays start on, so surfaces shadow themselves (see its error). Depth 0 \
            is the root's children (\"Tiefe null ist die Tiefe der Kinder des Wurzelknotens\"); \
            reading A (3 levels counting the root) asks line spaces at depth 0 only, reading B (4 \
            levels) at depths 0 and 1: the cascade.\n"
}

/// Percentage points.
fn pp(x: f64) -> String {
    format!("{:.1}", 100.0 * x)
}

/// A percentage with one decimal.
fn pct(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

pub const KLEE_TABLE3: Protocol = Protocol {
    name: "klee-table3",
    title: "CGT vs DDA on the CPU, bunny, 4/9/16/100 rays (Klee 2016, Table 3)",
    run: |p, bench| klee(p, bench, table3),
    units: Units::Whole,
};

/// Table 3's modes per ray count: the two traversals, and `exact` for their error.
const TABLE3_MODES: [(&str, ShadowMode); 3] = [
    ("cgt", ShadowMode::Linespace),
    ("dda", ShadowMode::LinespaceDda),
    ("exact", ShadowMode::Exact),
];

/// Table 3: the bunny's shadows on the CPU, coherent grid traversal vs 3D-DDA, 4 to 100 rays,
/// at both readings of the N-tree depth, each with its error against `exact`.
fn table3(bench: &mut Bench, s: Sizing) -> Result<Measured> {
    let modes: Vec<(&str, ShadowMode, u32)> = TABLE3
        .iter()
        .flat_map(|t| TABLE3_MODES.map(|(name, mode)| (name, mode, t.0)))
        .collect();
    let (mut rows, mut lines) = (Vec::new(), Vec::new());
    for (_, levels) in readings(bench) {
        let (measured, memory) = bunny_on_cpu(bench, s, levels, 1, &modes)?;
        lines.extend(table3_lines(&measured, memory));
        rows.extend(measured.into_iter().map(|(r, _)| r));
    }
    let header = [
        "rays (reading)",
        "published CGT (s)",
        "published DDA (s)",
        "CGT/DDA",
        "ours CGT (s)",
        "ours DDA (s)",
        "CGT/DDA",
        "CGT lookups at depth 0 / 1 / 2",
        "mean |CGT − exact|",
        "mean |DDA − exact|",
    ];
    let markdown = table(&header, &lines)
        + "\nReading A: 3 levels counting the root, line spaces asked at depth 0 only; B: 4 levels, \
           the cascade (depths 0 and 1). See klee-table2 for the readings. The errors: the mean \
           over the pixels of the difference of the shadow values from `exact`'s (triangle tests, \
           the same rays), on the CPU.\n";
    Ok(Measured::table(rows, markdown))
}

/// Table 3's lines of one reading (measured: cgt, dda, exact per ray count) and its memory line.
fn table3_lines(measured: &[Measured1], (tree_b, ls_b): (usize, usize)) -> Vec<Vec<String>> {
    let letter = reading(measured[0].0.levels);
    let mut lines: Vec<Vec<String>> = TABLE3
        .iter()
        .zip(measured.chunks(TABLE3_MODES.len()))
        .map(|(&(rays, p_cgt, p_dda), m)| {
            let ([cgt, dda, exact], depths) = (
                [0, 1, 2].map(|i| &m[i]),
                m[0].0.m.lookups_by_depth.map(|v| int(v as f64)),
            );
            let (t_cgt, t_dda) = (cgt.0.m.mean_s, dda.0.m.mean_s);
            vec![
                format!("{rays} ({letter})"),
                num(p_cgt),
                num(p_dda),
                ratio(Some(p_cgt / p_dda)),
                num(t_cgt),
                num(t_dda),
                ratio(Some(t_cgt / t_dda)),
                depths.join(" / "),
                format!("{:.4}", mean_error(&cgt.1, &exact.1)),
                format!("{:.4}", mean_error(&dda.1, &exact.1)),
            ]
        })
        .collect();
    lines.push(memory_line(
        format!("memory ({letter})"),
        (tree_b, ls_b),
        10,
        4,
    ));
    lines
}

/// A table line of `width` cells: `label`, and in cell `at` the bytes of the N-tree's node pool
/// and line spaces ("1.6 MB + 3.2 MB").
fn memory_line(
    label: String,
    (tree_b, ls_b): (usize, usize),
    width: usize,
    at: usize,
) -> Vec<String> {
    let mut line = vec![String::new(); width];
    line[0] = label;
    line[at] = format!(
        "{:.1} MB + {:.1} MB",
        tree_b as f64 / 1e6,
        ls_b as f64 / 1e6
    );
    line
}

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
        100.0 * FIG12_GPU_SAVING,
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
    let published = points(rows, "CPU", |s| s * (1.0 - FIG12_GPU_SAVING));
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

pub const KLEE_FIG13: Protocol = Protocol {
    name: "klee-fig13",
    title: "bunny vs dragon on the GPU, 2×2 … 10×10 rays (Klee 2016, Fig. 13)",
    run: |p, bench| klee(p, bench, fig13),
    units: Units::Whole,
};

/// Fig. 13: the shadows of the bunny and of the dragon on the GPU, 2×2 … 10×10 rays.
fn fig13(bench: &mut Bench, s: Sizing) -> Result<Measured> {
    let mut rows = Vec::new();
    let mut series = Vec::new();
    for (i, (scene, label)) in SCENES.into_iter().enumerate() {
        let mut st = Setup::new(bench, scene, s, 3)?;
        for k in SAMPLES {
            let gpu = st.gpu(bench, ShadowMode::Linespace, k, k)?.shadow;
            rows.push(Row::new(label, "linespace", "GPU", k * k, gpu));
        }
        let name = format!("{label} ({} triangles)", st.scene.triangle_count());
        let pts = rows.iter().filter(|r| r.scene == label);
        let pts = pts.map(|r| (r.rays as f64, r.m.mean_s)).collect();
        series.push(Series::new(name, pts, Style::LinePoints, i));
    }
    let chart = Chart::new(
        "Fig. 13: shadow time on the GPU",
        "shadow rays per pixel",
        "s",
        series,
    );
    let markdown = fig13_table(&rows)
        + "\nThe thesis' dragon had 871k triangles, ours 202520 (Stanford's res2 decimation).\n";
    Ok(Measured {
        rows,
        markdown,
        figures: vec![Figure::new(
            "klee-fig13.png",
            "Fig. 13",
            (640, 420),
            vec![chart],
        )],
    })
}

/// The dragon's time beside the bunny's per sample count, and the published difference.
fn fig13_table(rows: &[Row]) -> String {
    let (bunny, dragon) = rows.split_at(rows.len() / 2);
    let line = |(b, d): (&Row, &Row)| {
        let published = FIG13_DRAGON_EXTRA.iter().find(|p| p.0 == b.rays);
        let published = published.map(|p| format!("+{:.0} %", 100.0 * p.1));
        let extra = d.m.mean_s / b.m.mean_s - 1.0;
        vec![
            b.rays.to_string(),
            num(b.m.mean_s),
            num(d.m.mean_s),
            format!("{:+.0} %", 100.0 * extra),
            published.unwrap_or_else(|| "–".into()),
        ]
    };
    let lines: Vec<Vec<String>> = bunny.iter().zip(dragon).map(line).collect();
    let header = [
        "rays",
        "bunny GPU (s)",
        "dragon GPU (s)",
        "dragon vs bunny",
        "published",
    ];
    table(&header, &lines)
}
