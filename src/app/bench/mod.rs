//! `gpgpu-rt bench`: protocols that replicate published evaluations and put our numbers beside
//! the published ones.
//!
//! A run measures one or more protocols and writes into the output folder, per protocol, a
//! per-frame CSV (`<protocol>.csv`), a per-configuration CSV with median/min/max/mean
//! (`<protocol>_summary.csv`), PNG plots shaped like the paper's figures, the first frame of
//! every configuration (`frames/<protocol>/`), and one `report.md` with a section per protocol.
//!
//! # Structure
//!
//! Every protocol reads as **configure → measure → report**; the folders hold those parts:
//!
//! - [`protocols`]: one file per published evaluation it replicates (Müller 2015's ch. 5.1–5.3,
//!   Klee 2016's tables and figures, Wagner 2018's Tables A.1/A.2, the streaming tracer's
//!   Tables 1–3) and `accel-compare`: its configurations and what it compares. [`Protocol`] is
//!   a protocol's name (the command-line value), title and `run`, which measures and returns its
//!   [`Section`] of the report; [`protocol_of`] is the registry that says which protocol each
//!   [`runner::args::ProtocolId`] runs.
//! - [`published`]: the published numbers, typed in as data with their table or figure
//!   numbers, one file per source.
//! - [`report`]: `report.md`, the protocols' reports that outgrow their protocol's file, the
//!   CSVs ([`report::csv_files`]), numbers and markdown tables ([`report::format`]) and the PNG
//!   plots ([`report::plots`], [`report::plots::Figure`]).
//! - [`runner`]: the session every protocol gets ([`runner::Bench`]: the GPU, the options, the
//!   output folder, the scenes) and its measuring loop ([`runner::Bench::measure`] renders a
//!   list of configurations with a progress bar into [`runner::outcome::Outcome`]s and writes
//!   the two CSVs); the command line ([`runner::args`]); the configurations
//!   ([`runner::config`]: [`runner::config::Sizing`] and [`runner::config::Config`]; the
//!   protocol's choices at the chosen `--scale`, with the command line's overrides applied,
//!   come from [`runner::Bench::sizing`], [`runner::Bench::grid_resolutions`] and
//!   [`runner::Bench::variants`]); [`runner::adapter`], the only module that uses the library's
//!   renderers (the GL context, the ray tracers and the soft-shadow renderer), so the rest
//!   speaks the bench's own terms; the CPU reference's judgement of first hits
//!   ([`runner::judge`]); median/min/max/mean ([`runner::stats`]); the machine
//!   ([`runner::machine`]); and [`runner::shard`]: the units of work (a configuration, or a
//!   whole protocol: [`Units`]) that `--list` prints, `--shard K/N` measures a part of and
//!   `bench merge` replays from the shards' records; [`Bench`]'s [`runner::shard::Mode`] says
//!   which, so a protocol's `run` is the same in all.
//!
//! This file runs the protocols of the command line: the whole run, `--list`, a shard, a merge.
//!
//! # Adding a protocol (e.g. a new table of Klee 2016)
//!
//! 1. Put the published numbers into [`published`] (or beside the protocol when few), each
//!    with its table or figure number.
//! 2. Write the protocol, a file in [`protocols`]: a `const` [`Protocol`] whose `run`
//!    configures (the [`runner::config::Config`]s for the scale), measures
//!    (`bench.measure(p.name, &configs)`: the CSV files come for free) and reports (a
//!    [`Section`] whose markdown sets the published values beside ours, with its
//!    [`report::plots::Figure`]s: [`Protocol::sweep_section`]); see [`protocols::thesis_5_3`] for a
//!    complete example. Work that is not a list of rendered frames (a CPU implementation, a
//!    build-time measurement) goes through [`runner::adapter`] and
//!    [`protocols::klee::measure`] or helpers like them.
//! 3. Say what its units are: `Units::Configs` when everything it measures goes through
//!    `bench.measure` (then `--shard` and `bench merge` work unchanged), `Units::Whole` when its
//!    measurements depend on each other.
//! 4. Add a variant with `#[value(name = "...")]` to [`runner::args::ProtocolId`] and its line in
//!    [`protocol_of`]; mention it in `docs/bench.md`.

pub mod common;
pub mod protocols;
pub mod published;
pub mod report;
pub mod runner;

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::Parser as _;
use gpgpu_rt::errln;
use gpgpu_rt::output::Batch;

pub use common::section::Section;
pub use protocols::{protocol_of, Protocol};
pub use runner::args::{BenchArgs, BenchCommand, MergeArgs};
use runner::shard::{self, Mode};
use runner::units::{Shard, Units};
pub use runner::{Bench, NotMeasuredHere};

/// Run the protocols of `args` and write the report (or list their units, or measure one
/// shard of them, or merge shards). Fails (after writing everything) when a configuration or
/// protocol failed.
pub fn run(args: BenchArgs) -> Result<()> {
    if let Some(BenchCommand::Merge(m)) = &args.command {
        return merge(m);
    }
    let mode = match (args.split.list, args.split.shard) {
        (true, _) => Mode::List,
        (false, shard) => Mode::Measure(shard),
    };
    let start = Instant::now();
    let mut bench = Bench::new(args, mode)?;
    match bench.mode {
        Mode::List => list(&mut bench),
        Mode::Measure(Some(shard)) => measure_shard(&mut bench, shard, start),
        _ => report(&mut bench, start, 0.0),
    }
}

/// Put the files of a run that measured something in place; a run that measured nothing
/// (every configuration failed) writes only files that replace none, so the previous run's
/// report, CSVs and plots stay as they were.
fn keep_if_measured(batch: Batch, measured: usize, failed: usize, out: &Path) -> Result<()> {
    if measured > 0 {
        return batch.commit();
    }
    batch.commit_new_files()?;
    bail!(
        "nothing was measured ({failed} failure(s), see above); files an earlier run wrote in \
         {} are left as they were",
        out.display()
    );
}

/// The protocols of the command line, each once, in a fixed order (the units' order).
fn protocols(bench: &Bench) -> Vec<&'static Protocol> {
    let mut ids = bench.args.protocols.clone();
    ids.sort();
    ids.dedup();
    ids.into_iter().map(protocol_of).collect()
}

/// Measure (or replay) every protocol and write `report.md`; its wall time is this run's plus
/// `earlier_s` (a merge: the shards').
fn report(bench: &mut Bench, start: Instant, earlier_s: f64) -> Result<()> {
    errln!(
        "bench on {} ({}), writing to {}",
        bench.machine.gl_renderer,
        bench.machine.gl_version,
        bench.out.display()
    )?;
    let batch = Batch::begin();
    let all = protocols(bench);
    let mut sections: Vec<Section> = Vec::new();
    for (n, p) in all.iter().enumerate() {
        sections.push(run_protocol(p, bench)?);
        // a finished protocol that measured something is put in place now, with a report of
        // the protocols so far: an interrupt or a crash later loses only the unfinished one
        let pending: Vec<&str> = all[n + 1..].iter().map(|p| p.name).collect();
        if !pending.is_empty() && sections[n].measured > 0 {
            let wall_s = earlier_s + start.elapsed().as_secs_f64();
            report::write(bench, &sections, wall_s, &pending)?;
            batch.commit_so_far()?;
        }
    }
    let wall_s = earlier_s + start.elapsed().as_secs_f64();
    let path = report::write(bench, &sections, wall_s, &[])?;
    let failed: usize = sections.iter().map(|s| s.failures).sum();
    let measured: usize = sections.iter().map(|s| s.measured).sum();
    keep_if_measured(batch, measured, failed, &bench.out)?;
    errln!("wrote {}", path.display())?;
    if failed > 0 {
        bail!("{failed} configuration(s) failed; see {}", path.display());
    }
    Ok(())
}

/// `--list`: every unit, one per line (index, id, what it is).
fn list(bench: &mut Bench) -> Result<()> {
    for p in protocols(bench) {
        match p.units {
            Units::Whole => {
                let (i, id) = bench.next_unit(p.name.to_string());
                shard::print_list_line(i, &id, p.title)?;
            }
            Units::Configs => match (p.run)(p, bench) {
                Err(e) if e.is::<NotMeasuredHere>() => {}
                Err(e) => {
                    return Err(e.context(format!("{}: cannot list its configurations", p.name)))
                }
                Ok(_) => bail!("{}: measured while listing", p.name),
            },
        }
    }
    Ok(())
}

/// `--shard K/N`: measure the units the shard takes, write their rows and `shard.json`.
fn measure_shard(bench: &mut Bench, shard: Shard, start: Instant) -> Result<()> {
    errln!(
        "bench shard {shard} on {}, writing to {}",
        bench.machine.gl_renderer,
        bench.out.display()
    )?;
    let batch = Batch::begin();
    let (mut failed, mut measured) = (0, 0);
    let all = protocols(bench);
    for (n, p) in all.iter().enumerate() {
        let section = run_protocol(p, bench)?;
        failed += section.failures;
        measured += section.measured;
        // a finished protocol is kept with a manifest that names the protocols still to come
        // (the merge refuses it as cut short until the shard is run whole)
        let pending: Vec<String> = all[n + 1..].iter().map(|p| p.name.to_string()).collect();
        if !pending.is_empty() {
            shard::write_manifest(&bench.out, &shard_manifest(bench, shard, start, pending))?;
            batch.commit_so_far()?;
        }
    }
    let failed_configs = bench
        .measured
        .values()
        .filter(|m| m.error.is_some())
        .count();
    let manifest = shard_manifest(bench, shard, start, Vec::new());
    let path = shard::write_manifest(&bench.out, &manifest)?;
    // a shard that took no unit still writes its manifest: the merge needs every shard's
    let ok_configs = manifest.configs.len() - failed_configs;
    let (measured, all_failed) = (measured + ok_configs, failed + failed_configs);
    match (measured, all_failed) {
        (0, 0) => batch.commit()?,
        _ => keep_if_measured(batch, measured, all_failed, &bench.out)?,
    }
    let done = manifest.configs.len() + manifest.sections.len();
    errln!(
        "shard {shard}: {done} of {} units measured; wrote {} (merge all {} shards with `gpgpu-rt bench merge DIR… --out DIR`)",
        manifest.units,
        path.display(),
        shard.n
    )?;
    let failed = failed + failed_configs;
    if failed > 0 {
        bail!(
            "{failed} unit(s) of shard {shard} failed; see {}",
            path.display()
        );
    }
    Ok(())
}

/// The shard's record of what it measured so far; `pending`: the protocols it has yet to run.
fn shard_manifest(
    bench: &Bench,
    shard: Shard,
    start: Instant,
    pending: Vec<String>,
) -> shard::Manifest {
    shard::Manifest {
        format: shard::FORMAT,
        shard,
        argv: shard::recorded_argv(&std::env::args().collect::<Vec<_>>()),
        units: bench.units(),
        machine: bench.machine.clone(),
        wall_s: start.elapsed().as_secs_f64(),
        configs: bench.measured.clone(),
        sections: bench.sections.clone(),
        pending,
    }
}

/// `bench merge`: check the shards, replay the run on their records, write its report.
fn merge(m: &MergeArgs) -> Result<()> {
    let start = Instant::now();
    for d in &m.dirs {
        if d.exists() && m.out.exists() && same_folder(d, &m.out) {
            bail!(
                "--out {} is one of the shards' folders; merge into a new folder",
                m.out.display()
            );
        }
    }
    let shards = shard::read_shards(&m.dirs)?;
    let recorded = shard::recorded(&shards)?;
    let first = &shards[0].0;
    let mut args = runner::args::Standalone::try_parse_from(&first.argv)
        .map_err(|e| anyhow::anyhow!("the shards' command line `{}`: {e}", first.argv.join(" ")))?
        .args;
    args.out = m.out.clone();
    let mut bench = Bench::replay(args, recorded, first.machine.clone())?;
    bench.command = Some(format!("gpgpu-rt {}", first.argv.join(" ")));
    bench.contributors = shards
        .iter()
        .map(|(s, _)| (s.shard, s.machine.clone()))
        .collect();
    bench.contributors.sort_by_key(|(s, _)| s.k);
    let wall: f64 = shards.iter().map(|(s, _)| s.wall_s).sum();
    report(&mut bench, start, wall)
}

/// Do `a` and `b` name the same folder?
fn same_folder(a: &std::path::Path, b: &std::path::Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Run one protocol; a protocol that fails as a whole gets a section that says why. A whole
/// protocol is one unit of work: a shard runs it or not, a merge takes its recorded section.
/// Fails only when the terminal cannot be written (`output::console`).
fn run_protocol(p: &Protocol, bench: &mut Bench) -> Result<Section> {
    if p.units == Units::Whole {
        let (i, id) = bench.next_unit(p.name.to_string());
        match &bench.mode {
            Mode::Measure(Some(s)) if !s.takes(i) => return Ok(p.section(String::new(), vec![])),
            Mode::Replay(r) => return Ok(replayed_section(p, r, &id, &bench.out)),
            _ => {}
        }
    }
    errln!("{}: {}", p.name, p.title)?;
    let section = match (p.run)(p, bench) {
        Ok(s) => s,
        Err(e) if e.is::<NotMeasuredHere>() => p.section(String::new(), vec![]),
        Err(e) if is_console(&e) => return Err(e),
        Err(e) => {
            errln!("{}: failed: {e:#}", p.name)?;
            p.failed(&e)
        }
    };
    if p.units == Units::Whole && matches!(bench.mode, Mode::Measure(Some(_))) {
        bench.sections.insert(p.name.to_string(), section.clone());
    }
    Ok(section)
}

/// Did `e` come from writing to the terminal? Such a protocol did not fail: the run ends.
fn is_console(e: &anyhow::Error) -> bool {
    e.chain()
        .any(|c| c.is::<gpgpu_rt::output::console::ConsoleError>())
}

/// A whole protocol's section as a shard recorded it, its files copied into `out`.
fn replayed_section(p: &Protocol, r: &shard::Recorded, id: &str, out: &std::path::Path) -> Section {
    let copy = || -> Result<Section> {
        let Some((section, dir)) = r.sections.get(id) else {
            bail!("{id} was run by none of the shards");
        };
        for f in &section.files {
            shard::copy_file(dir, f, out)?;
        }
        Ok(section.clone())
    };
    copy().unwrap_or_else(|e| p.failed(&e))
}
