//! What every protocol is ([`Protocol`]) and how it makes its [`Section`] of `report.md`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::bench::common::section::Section;
use crate::bench::report::plots::Figure;
use crate::bench::runner::csv_files;
use crate::bench::runner::outcome::Outcome;
use crate::bench::runner::units::Units;
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

impl Protocol {
    /// Its section: `markdown` and the `files` (relative to the output folder) it wrote.
    pub fn section(&self, markdown: String, files: Vec<PathBuf>) -> Section {
        Section::new(self.name, self.title, markdown, files)
    }

    /// Its section when it failed as a whole.
    pub fn failed(&self, e: &anyhow::Error) -> Section {
        Section {
            failures: 1,
            measured: 0,
            ..self.section(format!("**The protocol failed:** `{e:#}`\n"), vec![])
        }
    }

    /// Its section after it measured `outcomes` (see [`Bench::measure`]): the `markdown`, the
    /// `figures` drawn into `out`, and the failed configurations; its files are the two CSVs,
    /// the figures and each configuration's first frame.
    pub fn sweep_section(
        &self,
        out: &Path,
        markdown: String,
        outcomes: &[Outcome],
        figures: &[Figure],
    ) -> Result<Section> {
        let mut s = self.figure_section(out, markdown, csv_files::names(self.name), figures)?;
        s.markdown.push_str(&failures(outcomes));
        s.files
            .extend(outcomes.iter().filter_map(|o| o.image.clone()));
        s.failures = outcomes.iter().filter(|o| o.error.is_some()).count();
        s.measured = outcomes.len() - s.failures;
        Ok(s)
    }

    /// Its section with `figures` drawn into `out`, each shown after the markdown and listed
    /// as a file after `files`.
    pub fn figure_section(
        &self,
        out: &Path,
        markdown: String,
        files: Vec<PathBuf>,
        figures: &[Figure],
    ) -> Result<Section> {
        let mut s = self.section(markdown, files);
        for f in figures {
            f.save(out)?;
            s.markdown.push('\n');
            s.markdown.push_str(&f.markdown());
            s.files.push(f.file.clone());
        }
        Ok(s)
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
