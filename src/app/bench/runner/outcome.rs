//! What measuring a configuration gives: its frames with their statistics, or why it could not
//! be measured; and the per-configuration figures the reports read from them.

use std::path::PathBuf;

use super::adapter::FrameStats;
use super::config::Config;
use crate::bench::common::format::{int, mmm, num};
use crate::bench::common::stats::Stats;

/// The report's columns of a measured configuration (see [`Outcome::measured_cells`]).
pub const MEASURED_COLUMNS: [&str; 5] = [
    "FPS",
    "FPS (run)",
    "GPU ms",
    "triangle tests per frame",
    "mean tests",
];

/// One measured frame.
#[derive(Debug, Clone)]
pub struct FrameRecord {
    pub angle: f64,
    pub stats: FrameStats,
}

impl FrameRecord {
    /// Frames per second from the host's wall-clock time of the frame (what a user sees).
    pub fn fps(&self) -> f64 {
        1e3 / self.stats.wall_ms
    }
    /// All ray–triangle tests of the frame, every kernel's.
    pub fn tests(&self) -> u64 {
        self.stats.triangle_tests.values().sum()
    }
    /// The GPU time of every kernel of the frame, in milliseconds.
    pub fn gpu_ms(&self) -> f64 {
        self.stats.gpu_ms.values().sum()
    }
    pub fn voxels(&self) -> Option<u64> {
        self.stats.events.get("voxels_visited").copied()
    }
}

/// The result of one configuration: its frames, or why it could not be measured.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub config: Config,
    pub triangles: usize,
    pub lights: usize,
    /// Making the tracer: compiling kernels, uploading the scene (ms).
    pub setup_ms: f64,
    pub frames: Vec<FrameRecord>,
    /// The error that ended the configuration early; frames before it are kept.
    pub error: Option<String>,
    /// The first measured frame as a PNG, relative to the output folder.
    pub image: Option<PathBuf>,
}

impl Outcome {
    pub fn ok(&self) -> bool {
        self.error.is_none() && !self.frames.is_empty()
    }
    fn series(&self, f: impl Fn(&FrameRecord) -> f64) -> Option<Stats> {
        Stats::of(&self.frames.iter().map(f).collect::<Vec<_>>())
    }
    /// Per-frame FPS (wall clock).
    pub fn fps(&self) -> Option<Stats> {
        self.series(|f| f.fps())
    }
    /// FPS over the whole run: frames / total wall time (the thesis' "durchschnittliche FPS").
    pub fn mean_fps(&self) -> Option<f64> {
        let total: f64 = self.frames.iter().map(|f| f.stats.wall_ms).sum();
        (total > 0.0).then(|| self.frames.len() as f64 * 1e3 / total)
    }
    pub fn wall_ms(&self) -> Option<Stats> {
        self.series(|f| f.stats.wall_ms)
    }
    pub fn gpu_ms(&self) -> Option<Stats> {
        self.series(|f| f.gpu_ms())
    }
    pub fn tests(&self) -> Option<Stats> {
        self.series(|f| f.tests() as f64)
    }
    pub fn voxels(&self) -> Option<Stats> {
        if self.frames.iter().any(|f| f.voxels().is_none()) {
            return None;
        }
        self.series(|f| f.voxels().unwrap_or(0) as f64)
    }

    /// The cells of [`MEASURED_COLUMNS`]: FPS, FPS (run), GPU ms, tests per frame, mean tests.
    pub fn measured_cells(&self) -> [String; 5] {
        [
            mmm(self.fps(), num),
            self.mean_fps().map(num).unwrap_or("–".into()),
            mmm(self.gpu_ms(), num),
            mmm(self.tests(), int),
            self.tests().map(|t| int(t.mean)).unwrap_or("–".into()),
        ]
    }

    /// A design fact of the first frame (grid: grid_bytes, ...).
    pub fn fact(&self, name: &str) -> Option<f64> {
        self.frames
            .first()
            .and_then(|f| f.stats.facts.get(name))
            .and_then(|v| v.as_f64())
    }

    /// Non-zero design events over all frames (grid: dropped_triangle_refs,
    /// ray_list_overflows, ...), e.g. "dropped_triangle_refs 1,204 (max 310/frame)"; "–" when
    /// none.
    pub fn event_summary(&self) -> String {
        let mut names: Vec<&String> = self
            .frames
            .iter()
            .flat_map(|f| f.stats.events.keys())
            .filter(|k| *k != "voxels_visited")
            .collect();
        names.sort();
        names.dedup();
        let parts: Vec<String> = names
            .into_iter()
            .filter_map(|k| self.event_total(k))
            .collect();
        if parts.is_empty() {
            "–".into()
        } else {
            parts.join("; ")
        }
    }

    /// "name total (max per frame)" of one event, `None` when it never happened.
    fn event_total(&self, name: &str) -> Option<String> {
        let v: Vec<u64> = self
            .frames
            .iter()
            .map(|f| f.stats.events.get(name).copied().unwrap_or(0))
            .collect();
        let total: u64 = v.iter().sum();
        let max = v.iter().max().copied().unwrap_or(0);
        (total > 0).then(|| {
            format!(
                "{name} {} (max {}/frame)",
                int(total as f64),
                int(max as f64)
            )
        })
    }

    /// The progress line of the configuration: frames, FPS and tests, or its error.
    pub fn summary_line(&self) -> String {
        let c = &self.config;
        let what = format!("{} {}x{}", c.label(), c.width, c.height);
        match (&self.error, self.fps(), self.tests()) {
            (Some(e), _, _) => format!("{what}: FAILED after {} frames: {e}", self.frames.len()),
            (None, Some(fps), Some(t)) => format!(
                "{what}: {} frames, median {:.3} FPS [{:.3}–{:.3}], median {} triangle tests",
                fps.n,
                fps.median,
                fps.min,
                fps.max,
                int(t.median)
            ),
            _ => format!("{}: no frames", c.label()),
        }
    }
}
