//! The protocols, one file per published evaluation it replicates (its configurations, what it
//! compares, the published values it sets ours beside), and what they share: [`Protocol`], the
//! [`Section`] of `report.md` a protocol returns, and the registry [`protocol_of`].
//!
//! - [`thesis_5_1`], [`thesis_5_2`], [`thesis_5_3`]: Müller 2015, ch. 5.1–5.3; [`sweep`] is
//!   what the grid-resolution protocols (5.2, 5.3) share.
//! - [`klee`]: Klee 2016, Tables 1–3 and Fig. 12–13; [`klee_measure`] times its soft shadows
//!   on the GPU and the CPU.
//! - [`wagner`]: Wagner 2018, Tables A.1 and A.2.
//! - [`proximity_clouds`]: the streaming tracer, Tables 1–3.
//! - [`accel_compare`]: every accelerator under the same conditions (ours; nothing published).

pub mod accel_compare;
pub mod klee;
pub mod klee_measure;
pub mod proximity_clouds;
pub mod sweep;
pub mod thesis_5_1;
pub mod thesis_5_2;
pub mod thesis_5_3;
pub mod thesis_bvh;
pub mod wagner;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::bench::report::csv_files;
use crate::bench::report::plots::Figure;
use crate::bench::runner::args::ProtocolId;
use crate::bench::runner::outcome::Outcome;
pub use crate::bench::runner::shard::Units;
use crate::bench::runner::Bench;

/// A benchmark protocol: what it measures, and how.
pub struct Protocol {
    /// The command-line name, e.g. `thesis-5.3`; also the CSV file names.
    pub name: &'static str,
    /// The section title in `report.md`.
    pub title: &'static str,
    /// Configure, measure (CSVs and plots into `bench.out`) and report: the section.
    pub run: fn(&Protocol, &mut Bench) -> Result<Section>,
    /// Its units of work for `--list`, `--shard` and `bench merge`.
    pub units: Units,
}

/// A protocol's part of the report.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct Section {
    pub protocol: String,
    pub title: String,
    pub markdown: String,
    /// Configurations that failed (their errors are in the markdown).
    pub failures: usize,
    /// Files written, relative to the output folder.
    pub files: Vec<PathBuf>,
    /// Configurations measured (a whole protocol: 1 when it reported): a run whose sections
    /// measured nothing keeps the previous run's files.
    #[serde(default)]
    pub measured: usize,
}

impl Section {
    /// The section of `p`: `markdown` and the `files` (relative to the output folder) it wrote.
    pub fn new(p: &Protocol, markdown: String, files: Vec<PathBuf>) -> Section {
        Section {
            protocol: p.name.into(),
            title: p.title.into(),
            measured: usize::from(!markdown.trim().is_empty()),
            markdown,
            failures: 0,
            files,
        }
    }

    /// The section of a protocol that failed as a whole.
    pub fn failed(p: &Protocol, e: &anyhow::Error) -> Section {
        Section {
            failures: 1,
            measured: 0,
            ..Section::new(p, format!("**The protocol failed:** `{e:#}`\n"), vec![])
        }
    }

    /// The section of a protocol that measured `outcomes` (see [`Bench::measure`]): the
    /// `markdown`, the `figures` drawn into `out`, and the failed configurations; its files are
    /// the two CSVs, the figures and each configuration's first frame.
    pub fn of_sweep(
        p: &Protocol,
        out: &Path,
        markdown: String,
        outcomes: &[Outcome],
        figures: &[Figure],
    ) -> Result<Section> {
        let mut s =
            Section::new(p, markdown, csv_files::names(p.name)).with_figures(out, figures)?;
        s.markdown.push_str(&failures(outcomes));
        s.files
            .extend(outcomes.iter().filter_map(|o| o.image.clone()));
        s.failures = outcomes.iter().filter(|o| o.error.is_some()).count();
        s.measured = outcomes.len() - s.failures;
        Ok(s)
    }

    /// Draw `figures` into `out`, show each after the markdown, and list it as a file.
    pub fn with_figures(mut self, out: &Path, figures: &[Figure]) -> Result<Section> {
        for f in figures {
            f.save(out)?;
            self.markdown.push('\n');
            self.markdown.push_str(&f.markdown());
            self.files.push(f.file.clone());
        }
        Ok(self)
    }
}

/// The configurations that failed, as a list (empty string when none did).
fn failures(outcomes: &[Outcome]) -> String {
    let mut s = String::new();
    for o in outcomes.iter().filter(|o| o.error.is_some()) {
        let _ = writeln!(
            s,
            "- **{} at {}×{} failed** after {} measured frames: `{}`",
            o.config.label(),
            o.config.width,
            o.config.height,
            o.frames.len(),
            o.error.as_deref().unwrap_or("")
        );
    }
    if !s.is_empty() {
        s.insert_str(0, "\nFailed configurations:\n\n");
    }
    s
}

/// The registry: the protocol each command-line value runs.
pub fn protocol_of(id: ProtocolId) -> &'static Protocol {
    match id {
        ProtocolId::Thesis51 => &thesis_5_1::PROTOCOL,
        ProtocolId::Thesis52 => &thesis_5_2::PROTOCOL,
        ProtocolId::Thesis53 => &thesis_5_3::PROTOCOL,
        ProtocolId::KleeTable1 => &klee::KLEE_TABLE1,
        ProtocolId::KleeTable2 => &klee::KLEE_TABLE2,
        ProtocolId::KleeTable3 => &klee::KLEE_TABLE3,
        ProtocolId::KleeFig12 => &klee::KLEE_FIG12,
        ProtocolId::KleeFig13 => &klee::KLEE_FIG13,
        ProtocolId::WagnerA1 => &wagner::WAGNER_A1,
        ProtocolId::WagnerA2 => &wagner::WAGNER_A2,
        ProtocolId::ProximityCloudsTable1 => &proximity_clouds::PROXIMITY_CLOUDS_TABLE1,
        ProtocolId::ProximityCloudsTable2 => &proximity_clouds::PROXIMITY_CLOUDS_TABLE2,
        ProtocolId::ProximityCloudsTable3 => &proximity_clouds::PROXIMITY_CLOUDS_TABLE3,
        ProtocolId::AccelCompare => &accel_compare::ACCEL_COMPARE,
    }
}
