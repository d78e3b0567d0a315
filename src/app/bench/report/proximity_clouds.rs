//! The report of `proximity-clouds-table1…3` (the streaming tracer, Tables 1–3): our best GPU
//! milliseconds beside the published ones, the pc/g ratios, the streaming tracer beside the compute
//! grid on the same frames, the work counts, and the paper's findings beside what we measured.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;

use super::plots::{Chart, Figure, Series, Style};
use crate::bench::common::format::{int, num, ratio, table};
use crate::bench::published::proximity_clouds::{self as pp, PaperScene};
use crate::bench::runner::config::{Sizing, Tracer};
use crate::bench::runner::csv_files::write_rows;
use crate::bench::runner::outcome::Outcome;

/// What a run of `proximity-clouds-table<n>` measures.
pub struct Plan {
    pub table: u32,
    /// Image sides (square images), ascending.
    pub sides: Vec<u32>,
    pub frames: Sizing,
    /// Table 1 adds the Stanford bunny at 512² (stream vs compute grid) unless the
    /// command line chose the sizes.
    pub bunny_512: bool,
    /// The scene added to the paper's (not in the paper), where skipping empty cells should
    /// pay.
    pub sparse: PaperScene,
    /// The side of the Stanford bunny's image that `bunny_512` adds.
    pub bunny_side: u32,
}

/// The paper's columns and ours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Column {
    StreamG,
    StreamPc,
    /// stream g with the naive shadow rays (Table 2)
    StreamNaive,
    /// stream g without the masking (Table 2)
    StreamNoMask,
    /// stream g with neither shadow optimisation (Table 2)
    StreamNaiveNoMask,
    GridG,
    GridPc,
}

impl Column {
    /// The CSV's name: the paper's g and pc for the stream tracer.
    pub fn name(self) -> &'static str {
        match self {
            Column::StreamG => "g",
            Column::StreamPc => "pc",
            Column::StreamNaive => "g-naive",
            Column::StreamNoMask => "g-nomask",
            Column::StreamNaiveNoMask => "g-naive-nomask",
            Column::GridG => "grid-g",
            Column::GridPc => "grid-pc",
        }
    }
    fn of(t: &Tracer) -> Option<Column> {
        if let Some(o) = t.stream_options() {
            return Some(match (o.naive_shadows, o.no_mask, o.proximity_clouds) {
                (true, false, _) => Column::StreamNaive,
                (false, true, _) => Column::StreamNoMask,
                (true, true, _) => Column::StreamNaiveNoMask,
                (false, false, true) => Column::StreamPc,
                (false, false, false) => Column::StreamG,
            });
        }
        match (t.grid(), t.proximity_clouds()) {
            (Some(_), _) => Some(Column::GridG),
            (None, true) => Some(Column::GridPc),
            _ => None,
        }
    }
}

/// The best (smallest) GPU milliseconds of `o`'s frames, as the paper took the best of its runs.
pub fn best_ms(o: &Outcome) -> Option<f64> {
    let ms = o.frames.iter().map(|f| f.gpu_ms());
    ms.filter(|m| m.is_finite()).reduce(f64::min)
}

/// The measured configuration of `scene` (a scene file) at `side`² in `column`.
fn find<'a>(outcomes: &'a [Outcome], scene: &str, side: u32, col: Column) -> Option<&'a Outcome> {
    outcomes.iter().find(|o| {
        let c = &o.config;
        c.scene == scene && c.width == side && Column::of(&c.tracer) == Some(col) && o.ok()
    })
}

/// Our best milliseconds of `scene` at `side`² in `col`.
pub fn ours(outcomes: &[Outcome], scene: &str, side: u32, col: Column) -> Option<f64> {
    find(outcomes, scene, side, col).and_then(best_ms)
}

fn div(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    Some(a? / b?)
}

fn cell(v: Option<f64>) -> String {
    v.map(num).unwrap_or_else(|| "–".into())
}

/// The paper's side that `side` stands for: the same rank among the measured sides (quick
/// scale measures 64, 128, 192 for 256, 512, 768); a side the paper has is itself.
fn paper_side(plan: &Plan, side: u32) -> Option<u32> {
    if pp::SIZES.contains(&side) {
        return Some(side);
    }
    let rank = plan.sides.iter().position(|&s| s == side)?;
    pp::SIZES.get(rank).copied()
}

/// "512²", or "128² (paper 512²)" where a measured side stands for another of the paper's.
fn side_cell(plan: &Plan, side: u32) -> String {
    match paper_side(plan, side) {
        Some(p) if p != side => format!("{side}² (paper {p}²)"),
        _ => format!("{side}²"),
    }
}

/// The scenes of the report, with the sides each was measured at.
fn scenes_and_sides(plan: &Plan, outcomes: &[Outcome]) -> Vec<(PaperScene, Vec<u32>)> {
    let all = pp::SCENES.iter().chain(std::iter::once(&plan.sparse));
    all.filter_map(|s| {
        let mut sides: Vec<u32> = outcomes
            .iter()
            .filter(|o| o.config.scene == s.file)
            .map(|o| o.config.width)
            .collect();
        sides.sort();
        sides.dedup();
        (!sides.is_empty()).then_some((*s, sides))
    })
    .collect()
}

/// `<protocol>_paper.csv`: per measured configuration its column (g, pc, grid-g, grid-pc),
/// the paper's side it stands for, the published milliseconds there (empty where the paper has
/// none) and our best GPU milliseconds.
pub fn write_csv(out: &Path, protocol: &str, plan: &Plan, outcomes: &[Outcome]) -> Result<PathBuf> {
    let file = PathBuf::from(format!("{protocol}_paper.csv"));
    let header: Vec<String> = [
        "table",
        "scene",
        "triangles",
        "width",
        "column",
        "grid",
        "paper_width",
        "paper_ms",
        "best_gpu_ms",
    ]
    .map(String::from)
    .to_vec();
    let cell = |v: Option<f64>| v.map(|v| format!("{v:.6}")).unwrap_or_default();
    let rows: Vec<Vec<String>> = outcomes
        .iter()
        .filter_map(|o| {
            let c = &o.config;
            let col = Column::of(&c.tracer)?;
            let side = paper_side(plan, c.width);
            let pc = col == Column::StreamPc;
            let paper = match col {
                Column::StreamG | Column::StreamPc => pp::ms(plan.table, &c.scene, side?, pc),
                _ => None,
            };
            Some(vec![
                plan.table.to_string(),
                c.scene_name().to_string(),
                o.triangles.to_string(),
                c.width.to_string(),
                col.name().to_string(),
                c.tracer.grid_label().unwrap_or_default(),
                side.map(|s| s.to_string()).unwrap_or_default(),
                cell(paper),
                cell(best_ms(o)),
            ])
        })
        .collect();
    write_rows(&out.join(&file), &header, &rows)?;
    Ok(file)
}

/// The report section's markdown.
pub fn markdown(plan: &Plan, outcomes: &[Outcome]) -> String {
    let mut s = intro(plan);
    s.push_str(&times_table(plan, outcomes));
    s.push_str(&counts_table(outcomes));
    s.push_str(&findings(plan, outcomes));
    s
}

fn intro(plan: &Plan) -> String {
    let rays = match plan.table {
        1 => "eye rays only (the scenes' lights removed: ambient shading, no shadow rays)",
        2 => "eye and shadow rays (no reflection)",
        _ => "eye, shadow and reflection rays, two levels of recursion (`refl_depth` 2)",
    };
    let sides: Vec<String> = plan.sides.iter().map(|s| format!("{s}²")).collect();
    format!(
        "The streaming tracer, Table {}: {rays}. Ours: `--tracer stream` at the paper's grids (g; pc = \
         `--proximity-clouds`) and the compute exact grid (`--tracer grid`, cubic: the paper's \
         largest axis, so 16³ for Knight's 14×16×14) on the same frames; sides {}, the best GPU \
         milliseconds (sum of the kernels' GL timer queries) of {} frames after {} warm-up, as \
         the paper took \"best values of multiple test runs\". The paper's hardware: {}. Only \
         ratios compare across machines (on Mesa llvmpipe, only ratios are meaningful at all); \
         at quick scale each measured side stands for the paper's side of the same rank \
         (64 → 256, 128 → 512, 192 → 768).\n\n",
        plan.table,
        sides.join(", "),
        plan.frames.angles,
        plan.frames.warmup,
        pp::GPU
    )
}

/// Published g, pc, pc/g beside ours (stream g, pc, pc/g; compute grid g; stream/grid).
fn times_table(plan: &Plan, outcomes: &[Outcome]) -> String {
    let grid_pc = outcomes
        .iter()
        .any(|o| Column::of(&o.config.tracer) == Some(Column::GridPc));
    let mut header = vec![
        "scene (n)",
        "side",
        "paper g",
        "paper pc",
        "paper pc/g",
        "stream g",
        "stream pc",
        "stream pc/g",
        "grid g",
        "stream g / grid g",
    ];
    if grid_pc {
        header.extend(["grid pc", "grid pc/g"]);
    }
    let mut rows = Vec::new();
    for (scene, sides) in scenes_and_sides(plan, outcomes) {
        for side in sides {
            let paper = |pc| pp::ms(plan.table, scene.file, paper_side(plan, side)?, pc);
            let o = |c| ours(outcomes, scene.file, side, c);
            let (pg, ppc) = (paper(false), paper(true));
            let (g, pc, gg) = (o(Column::StreamG), o(Column::StreamPc), o(Column::GridG));
            let mut row = vec![
                format!("{} ({})", scene.name, scene.triangles),
                side_cell(plan, side),
                cell(pg),
                cell(ppc),
                ratio(div(ppc, pg)),
                cell(g),
                cell(pc),
                ratio(div(pc, g)),
                cell(gg),
                ratio(div(g, gg)),
            ];
            if grid_pc {
                let gp = o(Column::GridPc);
                row.extend([cell(gp), ratio(div(gp, gg))]);
            }
            rows.push(row);
        }
    }
    format!(
        "Milliseconds per frame (paper: its Table {}; ours: best GPU ms):\n\n{}\n",
        plan.table,
        table(&header, &rows)
    )
}

/// The work behind the times, from each configuration's first measured frame.
fn counts_table(outcomes: &[Outcome]) -> String {
    let header = [
        "scene",
        "side",
        "tracer",
        "triangle tests",
        "cells entered",
        "cloud jumps",
        "traverse calls",
    ];
    let rows: Vec<Vec<String>> = outcomes
        .iter()
        .filter(|o| o.ok())
        .map(|o| {
            let f = &o.frames[0];
            let event = |k: &str| f.stats.events.get(k).map(|&v| int(v as f64));
            let cells = event("cells_visited").or_else(|| event("voxels_visited"));
            vec![
                o.config.scene_name().to_string(),
                format!("{}²", o.config.width),
                o.config.tracer.label(),
                int(f.tests() as f64),
                cells.unwrap_or_else(|| "–".into()),
                event("cloud_jumps").unwrap_or_else(|| "–".into()),
                event("kernel_calls").unwrap_or_else(|| "–".into()),
            ]
        })
        .collect();
    format!(
        "\nWork per frame (first measured frame; cells entered: the stream walk's \
         `cells_visited`, the compute grid's `voxels_visited`):\n\n{}\n",
        table(&header, &rows)
    )
}

/// pc/g over the dense scenes: how many (scene, side) pairs pc was slower, of how many.
pub fn pc_slower(plan: &Plan, outcomes: &[Outcome], paper: bool) -> (usize, usize) {
    let mut slower = (0, 0);
    for (scene, sides) in scenes_and_sides(plan, outcomes) {
        if !scene.pc || scene.file == plan.sparse.file {
            continue;
        }
        for side in sides {
            let (g, pc) = if paper {
                let ps = paper_side(plan, side);
                let at = |pc| pp::ms(plan.table, scene.file, ps?, pc);
                (at(false), at(true))
            } else {
                let at = |c| ours(outcomes, scene.file, side, c);
                (at(Column::StreamG), at(Column::StreamPc))
            };
            if let (Some(g), Some(pc)) = (g, pc) {
                slower.1 += 1;
                slower.0 += (pc > g) as usize;
            }
        }
    }
    slower
}

/// At every side: is the 1764-triangle bunny faster than Knight and Torus knot (g)?
pub fn bunny_fastest(plan: &Plan, outcomes: &[Outcome], paper: bool) -> Vec<(u32, Option<bool>)> {
    plan.sides
        .iter()
        .map(|&side| {
            let at = |s: &PaperScene| match paper {
                true => pp::ms(plan.table, s.file, paper_side(plan, side)?, false),
                false => ours(outcomes, s.file, side, Column::StreamG),
            };
            let fastest = (|| {
                let b = at(&pp::BUNNY)?;
                Some(b < at(&pp::KNIGHT)? && b < at(&pp::TORUS_KNOT)?)
            })();
            (side, fastest)
        })
        .collect()
}

fn yes_no(v: &[(u32, Option<bool>)]) -> String {
    let each: Vec<String> = v
        .iter()
        .map(|(side, b)| {
            let w = match b {
                Some(true) => "yes",
                Some(false) => "no",
                None => "–",
            };
            format!("{side}²: {w}")
        })
        .collect();
    each.join(", ")
}

fn findings(plan: &Plan, outcomes: &[Outcome]) -> String {
    let mut s = String::from("\nThe paper's findings beside ours:\n\n");
    let (ps, pn) = pc_slower(plan, outcomes, true);
    let (os, on) = pc_slower(plan, outcomes, false);
    let _ = writeln!(
        s,
        "- Proximity clouds on the dense scenes — paper: \"{}\"; its Table {}: pc slower than g \
         in {ps} of {pn} cells. Ours (stream): pc slower in {os} of {on}.",
        pp::FINDING_PC,
        plan.table
    );
    let _ = writeln!(
        s,
        "- Sparse scene — paper: \"{}\". Ours, `sparse_room.toml` (32³): {}.",
        pp::FINDING_SPARSE,
        sparse_line(plan, outcomes)
    );
    let _ = writeln!(
        s,
        "- The low-poly bunny — paper: \"{}\". Bunny faster than Knight and Torus knot (g), \
         paper: {}; ours: {}.",
        pp::FINDING_BUNNY,
        yes_no(&bunny_fastest(plan, outcomes, true)),
        yes_no(&bunny_fastest(plan, outcomes, false))
    );
    let _ = writeln!(
        s,
        "- Shadow rays — paper: \"{}\". {}",
        pp::FINDING_SHADOWS,
        shadow_line(plan, outcomes)
    );
    let _ = writeln!(
        s,
        "- Streaming tracer vs compute grid on the same frames: {}.",
        bunny_line(plan, outcomes)
    );
    s
}

/// The shadow rays' triangle tests of `scene` at `side`² in `col` (its first frame: the
/// counts do not change between frames).
fn shadow_tests(outcomes: &[Outcome], scene: &str, side: u32, col: Column) -> Option<u64> {
    let o = find(outcomes, scene, side, col)?;
    o.frames
        .first()?
        .stats
        .triangle_tests
        .get("shadow")
        .copied()
}

/// Table 2: what each of the paper's shadow-ray optimisations saves, switched off beside
/// stream g — the any-hit search (g-naive), the masking (g-nomask), both (g-naive-nomask) —
/// per dense scene and side, in time (1 − g / other) and, at the largest side, in shadow-ray
/// triangle tests (exact, hardware-independent).
fn shadow_line(plan: &Plan, outcomes: &[Outcome]) -> String {
    if plan.table != 2 {
        return "Measured in Table 2 (`proximity-clouds-table2`: stream g with \
                `--stream-naive-shadows`, `--stream-no-mask` and both beside it)."
            .into();
    }
    let largest = plan.sides.iter().copied().max().unwrap_or(0);
    let per = |col: Column| -> String {
        let per_scene: Vec<String> = pp::SCENES
            .iter()
            .map(|scene| {
                let saved: Vec<String> = (plan.sides.iter())
                    .map(|&side| {
                        let at = |c| ours(outcomes, scene.file, side, c);
                        let saving = div(at(Column::StreamG), at(col)).map(|r| 1.0 - r);
                        saving.map_or("–".into(), |v| format!("{:.0} %", 100.0 * v))
                    })
                    .collect();
                let tests = |c| shadow_tests(outcomes, scene.file, largest, c);
                let fewer = match (tests(Column::StreamG), tests(col)) {
                    (Some(g), Some(o)) if o > 0 => {
                        format!("{:.0} %", 100.0 * (1.0 - g as f64 / o as f64))
                    }
                    _ => "–".into(),
                };
                format!("{} {} (tests {fewer})", scene.name, saved.join(" / "))
            })
            .collect();
        per_scene.join("; ")
    };
    let sides = plan
        .sides
        .iter()
        .map(|s| format!("{s}²"))
        .collect::<Vec<_>>()
        .join(" / ");
    format!(
        "Ours, the paper's shadow-ray optimisations each switched off beside stream g: time \
         saved per frame (1 − g / other) at {sides}, and in brackets the shadow rays' triangle \
         tests saved at {largest}² (exact). The any-hit search against the naive shadow rays \
         (`--stream-naive-shadows`: the closest hit anywhere, then compared with the light; \
         1 − g / g-naive): {}. The masking against none (`--stream-no-mask`: the traverse \
         kernel finds the rays that need no work, and the shadow rays of surfaces facing away \
         from the light are traced; 1 − g / g-nomask): {}. Both (1 − g / g-naive-nomask): {}. \
         The paper: about 20 % on the Knight and the bunnies, none on the Torus knot, \"because \
         all shadow rays are originated inside the box, thus their paths always intersect the \
         walls\".",
        per(Column::StreamNaive),
        per(Column::StreamNoMask),
        per(Column::StreamNaiveNoMask),
    )
}

fn sparse_line(plan: &Plan, outcomes: &[Outcome]) -> String {
    let parts: Vec<String> = plan
        .sides
        .iter()
        .map(|&side| {
            let at = |c| ours(outcomes, plan.sparse.file, side, c);
            let (g, pc) = (at(Column::StreamG), at(Column::StreamPc));
            let (gg, gpc) = (at(Column::GridG), at(Column::GridPc));
            format!(
                "{side}²: stream pc/g {}, grid pc/g {}, stream g / grid g {}",
                ratio(div(pc, g)),
                ratio(div(gpc, gg)),
                ratio(div(g, gg))
            )
        })
        .collect();
    parts.join("; ")
}

fn bunny_line(plan: &Plan, outcomes: &[Outcome]) -> String {
    let file = pp::STANFORD_BUNNY.file;
    let side = plan.bunny_side;
    let at = |c| ours(outcomes, file, side, c);
    match (at(Column::StreamG), at(Column::GridG)) {
        (Some(g), Some(gg)) => format!(
            "the Stanford bunny at {side}², 128³: stream {} ms, compute grid {} ms (its per-frame \
             GPU rebuild included; the stream grid is built once on the CPU), stream / grid {}",
            num(g),
            num(gg),
            ratio(Some(g / gg))
        ),
        _ => format!("the Stanford bunny at {side}² was not measured in this table"),
    }
}

/// One panel per scene: ms relative to the scene's stream g at the smallest side, against
/// the side relative to the smallest (1, 2, 3), ours and the paper's.
pub fn figures(protocol: &str, plan: &Plan, outcomes: &[Outcome]) -> Vec<Figure> {
    let scenes = [pp::KNIGHT, pp::TORUS_KNOT, pp::BUNNY, plan.sparse];
    let charts: Vec<Chart> = scenes.iter().map(|s| chart(plan, outcomes, s)).collect();
    let caption = format!(
        "The streaming tracer, Table {}: milliseconds relative to stream g at the smallest side, by side \
         relative to the smallest (ours: lines; the paper's: crosses)",
        plan.table
    );
    let file = format!("{protocol}.png");
    vec![Figure::new(&file, &caption, (420, 320), charts)]
}

fn chart(plan: &Plan, outcomes: &[Outcome], scene: &PaperScene) -> Chart {
    let first = plan.sides.first().copied().unwrap_or(1) as f64;
    let ours_series = |c: Column| -> Vec<(f64, f64)> {
        let base = ours(outcomes, scene.file, first as u32, Column::StreamG);
        let pts = plan.sides.iter().filter_map(|&side| {
            Some((
                side as f64 / first,
                ours(outcomes, scene.file, side, c)? / base?,
            ))
        });
        pts.collect()
    };
    let paper_series = |pc: bool| -> Vec<(f64, f64)> {
        let base = pp::ms(plan.table, scene.file, pp::SIZES[0], false);
        let pts = pp::SIZES.iter().filter_map(|&side| {
            let v = pp::ms(plan.table, scene.file, side, pc)?;
            Some((side as f64 / pp::SIZES[0] as f64, v / base?))
        });
        pts.collect()
    };
    let series = vec![
        Series::new(
            "stream g",
            ours_series(Column::StreamG),
            Style::LinePoints,
            0,
        ),
        Series::new(
            "stream pc",
            ours_series(Column::StreamPc),
            Style::LinePoints,
            1,
        ),
        Series::new(
            "compute grid g",
            ours_series(Column::GridG),
            Style::LinePoints,
            2,
        ),
        Series::new("paper g", paper_series(false), Style::Crosses, 0),
        Series::new("paper pc", paper_series(true), Style::Crosses, 1),
    ];
    let title = format!("{} ({})", scene.name, scene.triangles);
    let series = series
        .into_iter()
        .filter(|s| !s.points.is_empty())
        .collect();
    Chart::new(
        title,
        "side / smallest side",
        "ms / stream g at the smallest",
        series,
    )
}
