//! `klee-table3` (Klee 2016, Table 3): the bunny's shadows on the CPU, coherent grid traversal
//! (`linespace`) vs 3D-DDA (`linespace-dda`), 4/9/16/100 rays, and the error of each against
//! `exact`, at both readings of the N-tree depth.

use anyhow::Result;

use super::common::{
    bunny_on_cpu, klee, mean_error, memory_line, reading, readings, Measured, Measured1,
};
use crate::bench::common::format::{int, num, ratio, table};
use crate::bench::protocols::protocol::Protocol;
use crate::bench::published::klee as published;
use crate::bench::runner::config::Sizing;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;
use gpgpu_rt::scene::ShadowMode;

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
    let modes: Vec<(&str, ShadowMode, u32)> = published::TABLE3
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
    let mut lines: Vec<Vec<String>> = published::TABLE3
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
