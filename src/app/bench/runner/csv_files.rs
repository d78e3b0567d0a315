//! The CSVs of a list of measured configurations: one row per frame (`<protocol>.csv`) and one
//! per configuration (`<protocol>_summary.csv`).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use anyhow::Result;

use super::args::Rotation;
use super::outcome::{FrameRecord, Outcome};
use crate::bench::common::stats::Stats;

/// The two CSV files of `protocol`, relative to the output folder.
pub fn names(protocol: &str) -> Vec<PathBuf> {
    vec![
        PathBuf::from(format!("{protocol}.csv")),
        PathBuf::from(format!("{protocol}_summary.csv")),
    ]
}

/// Write both CSVs of `protocol` into `out`.
pub fn write(out: &Path, protocol: &str, outcomes: &[Outcome], rotate: Rotation) -> Result<()> {
    let files = names(protocol);
    write_frames_csv(&out.join(&files[0]), protocol, outcomes, rotate)?;
    write_summary_csv(&out.join(&files[1]), protocol, outcomes, rotate)
}

/// Write `rows` under `header` to `path`.
pub fn write_rows(path: &Path, header: &[String], rows: &[Vec<String>]) -> Result<()> {
    gpgpu_rt::output::write_file(path, |out| {
        let mut w = csv::Writer::from_writer(out);
        w.write_record(header)?;
        for row in rows {
            w.write_record(row)?;
        }
        w.flush()?;
        Ok(())
    })
}

fn strings(names: &[&str]) -> Vec<String> {
    names.iter().map(|s| s.to_string()).collect()
}

const COMMON_HEADER: [&str; 12] = [
    "protocol",
    "scene",
    "level",
    "triangles",
    "lights",
    "tracer",
    "variant",
    "grid_resolution",
    "width",
    "height",
    "refl_depth",
    "rotation",
];

fn common_columns(protocol: &str, o: &Outcome, rotate: Rotation) -> Vec<String> {
    let c = &o.config;
    let variant = c.tracer.variant_label().unwrap_or("");
    let level = c.overrides.level.map(|l| l.to_string());
    let resolution = c.tracer.grid_label();
    let rotation = match rotate {
        Rotation::Objects => "objects",
        Rotation::Camera => "camera",
    };
    vec![
        protocol.to_string(),
        c.scene_name().to_string(),
        level.unwrap_or_default(),
        o.triangles.to_string(),
        o.lights.to_string(),
        c.tracer.name().to_string(),
        variant.to_string(),
        resolution.unwrap_or_default(),
        c.width.to_string(),
        c.height.to_string(),
        c.refl_depth.to_string(),
        rotation.to_string(),
    ]
}

/// The per-kernel columns of the frames CSV: the union over all frames of the kernels with
/// triangle tests, with GPU times, the events and the facts.
#[derive(Default)]
struct KernelColumns {
    tests: BTreeSet<String>,
    gpu: BTreeSet<String>,
    events: BTreeSet<String>,
    facts: BTreeSet<String>,
}

impl KernelColumns {
    fn of(outcomes: &[Outcome]) -> KernelColumns {
        let mut k = KernelColumns::default();
        for s in outcomes.iter().flat_map(|o| &o.frames).map(|f| &f.stats) {
            k.tests.extend(s.triangle_tests.keys().cloned());
            k.gpu.extend(s.gpu_ms.keys().cloned());
            let events = s.events.keys().filter(|k| *k != "voxels_visited");
            k.events.extend(events.cloned());
            k.facts.extend(s.facts.keys().cloned());
        }
        k
    }

    fn header(&self) -> Vec<String> {
        let mut h = Vec::new();
        h.extend(self.tests.iter().map(|k| format!("tests_{k}")));
        h.extend(self.gpu.iter().map(|k| format!("gpu_ms_{k}")));
        h.extend(self.events.iter().map(|k| format!("event_{k}")));
        h.extend(self.facts.iter().map(|k| format!("fact_{k}")));
        h
    }

    /// The frame's value in every column, empty where its tracer has no such kernel.
    fn cells(&self, f: &FrameRecord) -> Vec<String> {
        let s = &f.stats;
        let cell = |v: Option<String>| v.unwrap_or_default();
        let mut row = Vec::new();
        row.extend(
            self.tests
                .iter()
                .map(|k| cell(s.triangle_tests.get(k).map(u64::to_string))),
        );
        row.extend(
            self.gpu
                .iter()
                .map(|k| cell(s.gpu_ms.get(k).map(|v| format!("{v:.4}")))),
        );
        row.extend(
            self.events
                .iter()
                .map(|k| cell(s.events.get(k).map(u64::to_string))),
        );
        row.extend(
            self.facts
                .iter()
                .map(|k| cell(s.facts.get(k).map(fact_string))),
        );
        row
    }
}

fn fact_string(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// One row per measured frame. Kernel columns are the union over the configurations:
/// `tests_<kernel>`, `gpu_ms_<kernel>`, `event_<name>`, `fact_<name>` (empty where a tracer has
/// no such kernel).
pub fn write_frames_csv(
    path: &Path,
    protocol: &str,
    outcomes: &[Outcome],
    rotate: Rotation,
) -> Result<()> {
    let kernels = KernelColumns::of(outcomes);
    let mut header = strings(&COMMON_HEADER);
    header.extend(strings(&[
        "angle_deg",
        "frame",
        "wall_ms",
        "fps",
        "gpu_ms_total",
        "triangle_tests",
        "voxels_visited",
    ]));
    header.extend(kernels.header());
    let mut rows = Vec::new();
    for o in outcomes {
        let common = common_columns(protocol, o, rotate);
        for (i, f) in o.frames.iter().enumerate() {
            let mut row = common.clone();
            row.extend([
                format!("{}", f.angle),
                i.to_string(),
                format!("{:.4}", f.stats.wall_ms),
                format!("{:.4}", f.fps()),
                format!("{:.4}", f.gpu_ms()),
                f.tests().to_string(),
                f.voxels().map(|v| v.to_string()).unwrap_or_default(),
            ]);
            row.extend(kernels.cells(f));
            rows.push(row);
        }
    }
    write_rows(path, &header, &rows)
}

/// Median, min, max and mean: integers without decimals where they are whole (medians of an
/// even count and means may be fractional), else one decimal; others with four.
fn stat_cells(s: Option<Stats>, integer: bool) -> Vec<String> {
    let Some(s) = s else {
        return vec![String::new(); 4];
    };
    [s.median, s.min, s.max, s.mean]
        .into_iter()
        .enumerate()
        .map(|(i, v)| {
            if integer && i != 3 && v.fract() == 0.0 {
                format!("{v:.0}")
            } else if integer {
                format!("{v:.1}")
            } else {
                format!("{v:.4}")
            }
        })
        .collect()
}

fn summary_row(protocol: &str, o: &Outcome, rotate: Rotation) -> Vec<String> {
    let mut row = common_columns(protocol, o, rotate);
    row.extend([
        o.frames.len().to_string(),
        o.config.warmup.to_string(),
        format!("{:.1}", o.setup_ms),
        o.mean_fps().map(|v| format!("{v:.4}")).unwrap_or_default(),
    ]);
    row.extend(stat_cells(o.fps(), false));
    row.extend(stat_cells(o.wall_ms(), false));
    row.extend(stat_cells(o.gpu_ms(), false));
    row.extend(stat_cells(o.tests(), true));
    row.extend(stat_cells(o.voxels(), true));
    let image = o.image.as_ref().map(|p| p.display().to_string());
    row.push(image.unwrap_or_default());
    row.push(o.error.clone().unwrap_or_default());
    row
}

/// One row per configuration: median, min, max (and mean) over its measured frames.
pub fn write_summary_csv(
    path: &Path,
    protocol: &str,
    outcomes: &[Outcome],
    rotate: Rotation,
) -> Result<()> {
    let mut header = strings(&COMMON_HEADER);
    header.extend(strings(&["frames", "warmup", "setup_ms", "fps_run"]));
    for name in [
        "fps",
        "wall_ms",
        "gpu_ms",
        "triangle_tests",
        "voxels_visited",
    ] {
        header.extend(["median", "min", "max", "mean"].map(|s| format!("{name}_{s}")));
    }
    header.extend(strings(&["image", "error"]));
    let rows: Vec<Vec<String>> = outcomes
        .iter()
        .map(|o| summary_row(protocol, o, rotate))
        .collect();
    write_rows(path, &header, &rows)
}
