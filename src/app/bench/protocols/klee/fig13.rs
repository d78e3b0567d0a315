//! `klee-fig13` (Klee 2016, Fig. 13): the shadows of the bunny vs the dragon on the GPU,
//! 2×2 … 10×10 rays.

use anyhow::Result;

use super::common::{klee, Measured, SAMPLES, SCENES};
use super::measure::{Row, Setup};
use crate::bench::common::format::{num, table};
use crate::bench::protocols::protocol::Protocol;
use crate::bench::published::klee as published;
use crate::bench::report::plots::{Chart, Figure, Series, Style};
use crate::bench::runner::config::Sizing;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;
use gpgpu_rt::scene::ShadowMode;

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
        let published = published::FIG13_DRAGON_EXTRA.iter().find(|p| p.0 == b.rays);
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
