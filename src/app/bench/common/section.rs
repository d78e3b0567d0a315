//! A protocol's part of `report.md`: what the protocol returns, the runner keeps (and a merge
//! replays), and the report prints.

use std::path::PathBuf;

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
    /// The section of the protocol named `protocol` with `title`: `markdown` and the `files`
    /// (relative to the output folder) it wrote.
    pub fn new(protocol: &str, title: &str, markdown: String, files: Vec<PathBuf>) -> Section {
        Section {
            protocol: protocol.into(),
            title: title.into(),
            measured: usize::from(!markdown.trim().is_empty()),
            markdown,
            failures: 0,
            files,
        }
    }
}
