//! Benchmark sweeps that outgrow one machine, in the shape Slurm job arrays run them
//! (`scripts/slurm-bench.sh`): `bench P… --list` names every unit of work with a stable id,
//! `bench P… --shard K/N` measures the units whose index ≡ K−1 (mod N) and records them in
//! `shard.json`, and `bench merge DIR… --out DIR` checks that the shards are one complete run
//! and replays the protocols on the recorded measurements, which regenerates the CSVs,
//! summaries, plots and `report.md` as one unsharded run would write them.
//!
//! A unit is one configuration of the protocols that measure rendered frames
//! ([`super::Bench::measure`]: warm-up included, so a shard's timings are as good as
//! an unsharded run's), or a whole protocol where its measurements depend on each other (the
//! Klee 2016 protocols time the CPU on the GPU's G-buffer): [`super::units::Units::Whole`].

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use clap::Parser as _;
use serde::{Deserialize, Serialize};

use super::machine::Machine;
use super::outcome::{FrameRecord, Outcome};
use super::units::Shard;
use crate::bench::common::section::Section;
use gpgpu_rt::frame::FrameStats;

/// The version of `shard.json`'s layout.
pub const FORMAT: u32 = 1;
/// The file a shard writes into its `--out`.
pub const MANIFEST: &str = "shard.json";

/// What the bench does with each unit.
pub enum Mode {
    /// Measure every unit, or with a shard the units it takes.
    Measure(Option<Shard>),
    /// Print the units and measure nothing (`--list`).
    List,
    /// Replay recorded measurements (`bench merge`).
    Replay(Box<Recorded>),
}

/// What `--list` prints for a unit: its 1-based index and its id, tab-separated.
pub fn list_line(index: usize, id: &str, label: &str) -> String {
    format!("{}\t{id}\t{label}", index + 1)
}

/// Print a `--list` line to standard output (a reader that stopped reading, `bench --list |
/// head`, ends the program quietly: `output::console`).
pub fn print_list_line(
    index: usize,
    id: &str,
    label: &str,
) -> Result<(), gpgpu_rt::output::console::ConsoleError> {
    gpgpu_rt::outln!("{}", list_line(index, id, label))
}

/// A configuration as a shard measured it (its [`super::config::Config`] comes back from the
/// protocol when it is replayed).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Measured {
    pub triangles: usize,
    pub lights: usize,
    pub setup_ms: f64,
    pub frames: Vec<(f64, FrameStats)>,
    pub error: Option<String>,
    pub image: Option<PathBuf>,
}

impl Measured {
    pub fn of(o: &Outcome) -> Measured {
        Measured {
            triangles: o.triangles,
            lights: o.lights,
            setup_ms: o.setup_ms,
            frames: o
                .frames
                .iter()
                .map(|f| (f.angle, f.stats.clone()))
                .collect(),
            error: o.error.clone(),
            image: o.image.clone(),
        }
    }

    /// The outcome of `config` as this measured it.
    pub fn outcome(&self, config: &super::config::Config) -> Outcome {
        Outcome {
            config: config.clone(),
            triangles: self.triangles,
            lights: self.lights,
            setup_ms: self.setup_ms,
            frames: (self.frames.iter())
                .map(|(angle, stats)| FrameRecord {
                    angle: *angle,
                    stats: stats.clone(),
                })
                .collect(),
            error: self.error.clone(),
            image: self.image.clone(),
        }
    }
}

/// A shard's record of its run: `shard.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Manifest {
    pub format: u32,
    pub shard: Shard,
    /// The bench's command line without `--shard` and `--out`: every shard of one run has the
    /// same, and the merge replays it.
    pub argv: Vec<String>,
    /// All units of the run, every shard's.
    pub units: usize,
    pub machine: Machine,
    pub wall_s: f64,
    /// The configurations it measured, by id.
    pub configs: BTreeMap<String, Measured>,
    /// The whole protocols it ran, by id (the protocol's name).
    pub sections: BTreeMap<String, Section>,
    /// The protocols it had yet to run when this was written: empty for a shard that ran
    /// whole; else it was cut short (an interrupt, a killed job) after the others.
    #[serde(default)]
    pub pending: Vec<String>,
}

/// The shards' records, merged, and the folder each unit's files are in.
pub struct Recorded {
    pub configs: HashMap<String, (Measured, PathBuf)>,
    pub sections: HashMap<String, (Section, PathBuf)>,
}

/// The command line a shard records: without `--shard K/N` and `--out DIR` (in either form).
pub fn recorded_argv(argv: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    let mut skip = false;
    for a in argv.iter().skip(1) {
        if std::mem::take(&mut skip) {
            continue;
        }
        match a.as_str() {
            "--shard" | "--out" => skip = true,
            _ if a.starts_with("--shard=") || a.starts_with("--out=") => {}
            _ => out.push(a.clone()),
        }
    }
    out
}

/// Read the manifests of `dirs` and check that they are the N shards of one run, each once.
pub fn read_shards(dirs: &[PathBuf]) -> Result<Vec<(Manifest, PathBuf)>> {
    let mut shards = Vec::new();
    for d in dirs {
        let path = d.join(MANIFEST);
        let text = gpgpu_rt::scene::file::read_text(&path).map_err(|e| {
            anyhow::anyhow!(
                "{}: cannot read (is it the --out of `bench --shard K/N`?): {e}",
                path.display()
            )
        })?;
        let m: Manifest = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a shard manifest", path.display()))?;
        if m.format != FORMAT {
            bail!(
                "{}: format {} (this gpgpu-rt reads {FORMAT})",
                path.display(),
                m.format
            );
        }
        shards.push((m, d.clone()));
    }
    check_complete(&shards)?;
    Ok(shards)
}

/// What a shard's command line `argv` measures, parsed: the protocols as a set, and neither
/// where it wrote nor whether it was quiet — two shards of one run may spell their options
/// differently (`--width 8`, `--width=8`, another order) and still measure the same units.
fn settings(argv: &[String]) -> Result<String> {
    let mut args = super::args::Standalone::try_parse_from(argv)
        .map_err(|e| anyhow::anyhow!("the shard's command line `{}`: {e}", argv.join(" ")))?
        .args;
    args.protocols.sort();
    args.protocols.dedup();
    args.out = PathBuf::new();
    args.quiet = false;
    args.split.shard = None;
    Ok(format!("{args:?}"))
}

/// One run (the same settings and N everywhere), every shard 1..=N exactly once.
fn check_complete(shards: &[(Manifest, PathBuf)]) -> Result<()> {
    let Some((first, first_dir)) = shards.first() else {
        bail!("bench merge needs the output folders of the shards");
    };
    let mut seen: BTreeMap<u32, &Path> = BTreeMap::new();
    for (m, dir) in shards {
        let same_run = settings(&m.argv)? == settings(&first.argv)?;
        if !same_run || m.shard.n != first.shard.n || m.units != first.units {
            bail!(
                "{} and {} are shards of different runs: `{}` ({} shards, {} units) vs `{}` ({} shards, {} units)",
                first_dir.display(),
                dir.display(),
                first.argv.join(" "),
                first.shard.n,
                first.units,
                m.argv.join(" "),
                m.shard.n,
                m.units
            );
        }
        if !m.pending.is_empty() {
            bail!(
                "{}: shard {} was cut short before {}; run it again (`bench … --shard {}`)",
                dir.display(),
                m.shard,
                m.pending.join(", "),
                m.shard
            );
        }
        if let Some(other) = seen.insert(m.shard.k, dir) {
            bail!(
                "shard {} is given twice: {} and {}",
                m.shard,
                other.display(),
                dir.display()
            );
        }
    }
    let missing: Vec<String> = (1..=first.shard.n)
        .filter(|k| !seen.contains_key(k))
        .map(|k| format!("{k}/{}", first.shard.n))
        .collect();
    if !missing.is_empty() {
        bail!(
            "shard(s) {} missing: nothing was merged",
            missing.join(", ")
        );
    }
    Ok(())
}

/// Every shard's records in one place, each unit recorded once.
pub fn recorded(shards: &[(Manifest, PathBuf)]) -> Result<Recorded> {
    let mut r = Recorded {
        configs: HashMap::new(),
        sections: HashMap::new(),
    };
    for (m, dir) in shards {
        for (id, c) in &m.configs {
            if r.configs
                .insert(id.clone(), (c.clone(), dir.clone()))
                .is_some()
            {
                bail!("configuration {id} was measured by two shards");
            }
        }
        for (id, s) in &m.sections {
            if r.sections
                .insert(id.clone(), (s.clone(), dir.clone()))
                .is_some()
            {
                bail!("protocol {id} was run by two shards");
            }
        }
    }
    Ok(r)
}

/// Copy `rel` (relative to a shard's folder) into the merged folder.
pub fn copy_file(from_dir: &Path, rel: &Path, out: &Path) -> Result<()> {
    let (from, to) = (from_dir.join(rel), out.join(rel));
    if let Some(parent) = to.parent() {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create {}", parent.display()))?;
    }
    let bytes = gpgpu_rt::scene::file::read(&from)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", from.display()))?;
    gpgpu_rt::output::write_file(&to, |w| Ok(w.write_all(&bytes)?))
}

/// Write the shard's manifest into its output folder.
pub fn write_manifest(out: &Path, m: &Manifest) -> Result<PathBuf> {
    let path = out.join(MANIFEST);
    let text = serde_json::to_string_pretty(m)?;
    gpgpu_rt::output::write_file(&path, |w| Ok(w.write_all(text.as_bytes())?))?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_recorded_command_line_drops_shard_and_out() {
        let argv: Vec<String> = "gpgpu-rt bench thesis-5.1 --shard 1/2 --out a --width=32 --out=b"
            .split(' ')
            .map(String::from)
            .collect();
        assert_eq!(recorded_argv(&argv), ["bench", "thesis-5.1", "--width=32"]);
    }
}
