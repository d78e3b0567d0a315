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
//! Every protocol reads as **configure → measure → report**, with the pieces shared:
//!
//! - [`Protocol`] (in [`protocol`]): a protocol's name (the command-line value), title and
//!   `run`, which measures and returns its [`Section`] of the report. [`ProtocolId`] (in
//!   [`args`], with the rest of the command line) lists the command line's values;
//!   [`protocol_of`] is the registry that says which protocol each one runs.
//! - configure: [`config`]: [`config::Sizing`] (image size, angles, warm-up at a scale) and
//!   [`config::Config`] (scene, tracer, image size, reflection depth, rotation angles, warm-up
//!   frames); [`runner::Bench::sizing`], [`runner::Bench::grid_resolutions`] and
//!   [`runner::Bench::variants`] give a protocol's choices at the chosen `--scale` with the
//!   command line's overrides applied.
//! - measure: [`runner::Bench`], the session every protocol gets (the GPU, the options, the
//!   output folder, the scenes); [`runner::Bench::measure`] renders a list of configurations
//!   with a progress bar into [`outcome::Outcome`]s and writes the two CSVs ([`csv_files`]).
//!   [`klee_measure`] times Klee 2016's soft shadows on the GPU and the CPU.
//! - report: [`format`] (numbers, markdown tables), [`plots`] (line charts as PNG,
//!   [`plots::Figure`]), [`sweep`] (what the grid-resolution protocols share), [`published`]
//!   (the published numbers, typed in as data with their figure numbers), [`report`]
//!   (`report.md`), [`stats`] (median/min/max/mean), [`machine`].
//! - [`adapter`]: the only module that uses the library's renderers (the GL context, the ray
//!   tracers and the soft-shadow renderer); the rest speaks the bench's own terms.
//!
//! No module here imports one that imports it; only this file imports the protocols.
//!
//! # Adding a protocol (e.g. a new table of Klee 2016)
//!
//! 1. Put the published numbers beside the protocol or into [`published`], each with its table
//!    or figure number.
//! 2. Write the protocol: a `const` [`Protocol`] whose `run` configures (the
//!    [`config::Config`]s for the scale), measures (`bench.measure(p.name, &configs)`: the CSV
//!    files come for free) and reports (a [`Section`] whose markdown sets the published values
//!    beside ours, with its [`plots::Figure`]s: [`Section::of_sweep`]); see [`thesis_5_3`] for
//!    a complete example. Work that is not a list of rendered frames (a CPU implementation, a
//!    build-time measurement) goes through [`adapter`] and [`klee_measure`] or helpers like them.
//! 3. Add a variant with `#[value(name = "...")]` to [`ProtocolId`] and its line in
//!    [`protocol_of`]; mention it in the README's benchmark section.

pub mod adapter;
pub mod args;
pub mod config;
pub mod csv_files;
pub mod format;
pub mod klee;
pub mod klee_measure;
pub mod machine;
pub mod outcome;
pub mod plots;
pub mod protocol;
pub mod published;
pub mod published_purcell;
pub mod published_wagner;
pub mod purcell;
pub mod purcell_report;
pub mod report;
pub mod runner;
pub mod stats;
pub mod sweep;
pub mod thesis_5_1;
pub mod thesis_5_2;
pub mod thesis_5_3;
pub mod wagner;
pub mod wagner_report;

use std::time::Instant;

use anyhow::{bail, Result};

pub use args::{BenchArgs, ProtocolId};
pub use protocol::{Protocol, Section};
pub use runner::Bench;

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
        ProtocolId::PurcellTable1 => &purcell::PURCELL_TABLE1,
        ProtocolId::PurcellTable2 => &purcell::PURCELL_TABLE2,
        ProtocolId::PurcellTable3 => &purcell::PURCELL_TABLE3,
    }
}

/// Run the protocols of `args` and write the report. Fails (after writing everything) when a
/// configuration or protocol failed.
pub fn run(args: BenchArgs) -> Result<()> {
    let mut ids = args.protocols.clone();
    ids.sort();
    ids.dedup();
    let start = Instant::now();
    let mut bench = Bench::new(args)?;
    eprintln!(
        "bench on {} ({}), writing to {}",
        bench.machine.gl_renderer,
        bench.machine.gl_version,
        bench.out.display()
    );
    let sections: Vec<Section> = ids
        .into_iter()
        .map(|id| run_protocol(protocol_of(id), &mut bench))
        .collect();
    let path = report::write(&bench, &sections, start.elapsed().as_secs_f64())?;
    eprintln!("wrote {}", path.display());
    let failed: usize = sections.iter().map(|s| s.failures).sum();
    if failed > 0 {
        bail!("{failed} configuration(s) failed; see {}", path.display());
    }
    Ok(())
}

/// Run one protocol; a protocol that fails as a whole gets a section that says why.
fn run_protocol(p: &Protocol, bench: &mut Bench) -> Section {
    eprintln!("{}: {}", p.name, p.title);
    (p.run)(p, bench).unwrap_or_else(|e| {
        eprintln!("{}: failed: {e:#}", p.name);
        Section::failed(p, &e)
    })
}
