//! What the five Klee 2016 protocols share beyond the measuring ([`super::measure`]): the
//! scenes, sizes and sample counts, the skeleton every one runs ([`klee`]: configure, measure,
//! report), the bunny's shadows on the CPU at one reading of the N-tree depth, and the error
//! and memory lines their tables print.

use anyhow::Result;

use super::measure::{section, Row, Setup, READINGS};
use crate::bench::common::section::Section;
use crate::bench::protocols::protocol::Protocol;
use crate::bench::report::plots::Figure;
use crate::bench::runner::config::Sizing;
use crate::bench::runner::Bench;
use gpgpu_rt::scene::ShadowMode;

pub const BUNNY: &str = "bunny_area.toml";
pub const DRAGON: &str = "dragon_area.toml";
/// The scenes of Table 1 and Fig. 13 with their names in the tables.
pub const SCENES: [(&str, &str); 2] = [(BUNNY, "bunny"), (DRAGON, "dragon")];
/// Fig. 12 and 13: k × k shadow rays per pixel.
pub const SAMPLES: std::ops::RangeInclusive<u32> = 2..=10;

/// Quick: 64², 2 frames (1 warm-up). Full: 512² as the thesis' test images, 10 frames.
/// (`angles` is the number of measured frames here.)
pub const QUICK: Sizing = Sizing::quick(2, 1);
pub const FULL: Sizing = Sizing::full(10, 1);

/// What a Klee protocol measured and says: the CSV rows, the markdown that sets them beside the
/// published numbers, and its figures.
pub struct Measured {
    pub rows: Vec<Row>,
    pub markdown: String,
    pub figures: Vec<Figure>,
}

impl Measured {
    /// A table without figures.
    pub fn table(rows: Vec<Row>, markdown: String) -> Measured {
        Measured {
            rows,
            markdown,
            figures: vec![],
        }
    }
}

/// Run a Klee protocol: configure (the sizes at the scale), `measure` (which also says what
/// the numbers mean), report (the section with the CSV and the figures).
pub fn klee(
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
pub fn bunny_on_cpu(
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
pub type Memory = (usize, usize);
/// A row and the shadow values of its pixels.
pub type Measured1 = (Row, Vec<f32>);

/// The readings of the N-tree depth to measure: `--ntree-levels`, or both [`READINGS`].
pub fn readings(bench: &Bench) -> Vec<(&'static str, u32)> {
    let chosen = bench.args.klee.ntree_levels.as_ref();
    let wanted = |r: &(&str, u32)| chosen.is_none_or(|c| c.contains(&r.1));
    READINGS.into_iter().filter(wanted).collect()
}

/// The reading's letter for `levels` (see [`READINGS`]).
pub fn reading(levels: u32) -> &'static str {
    READINGS.iter().find(|r| r.1 == levels).map_or("?", |r| r.0)
}

/// Mean |a − b| over the pixels.
pub fn mean_error(a: &[f32], b: &[f32]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(x, y)| (x - y).abs() as f64).sum();
    sum / a.len().max(1) as f64
}

/// A table line of `width` cells: `label`, and in cell `at` the bytes of the N-tree's node pool
/// and line spaces ("1.6 MB + 3.2 MB").
pub fn memory_line(
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
