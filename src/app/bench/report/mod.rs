//! `report.md`: the machine, the settings, and one section per protocol with our numbers
//! beside the published ones.
//!
//! Beside it, what the reports are made of: numbers and markdown tables ([`format`]), the CSVs
//! ([`csv_files`]), PNG line charts shaped like the papers' figures ([`plots`], with the font
//! they draw in, `fonts/`), and the reports of the protocols whose tables and figures outgrow
//! their protocol's file ([`accel_compare`], [`proximity_clouds`], [`wagner`]).

pub mod accel_compare;
pub mod plots;
pub mod proximity_clouds;
pub mod wagner;

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;

use crate::bench::common::format::table;
use crate::bench::common::section::Section;
use crate::bench::published::thesis;
use crate::bench::runner::adapter::grid_list_defaults;
use crate::bench::runner::args::{BenchArgs, Rotation, Scale};
use crate::bench::runner::config::{FULL_SIZE, QUICK_SIZE};
use crate::bench::runner::machine::Machine;
use crate::bench::runner::units::Shard;
use crate::bench::runner::Bench;

/// A published work a report sets our numbers beside: the short name every page uses
/// (docs/references.md), what the work is, and the part of it the protocols replicate.
struct Source {
    name: &'static str,
    citation: &'static str,
    part: &'static str,
}

const MULLER: Source = Source {
    name: "Müller 2015",
    citation: "B.Sc. thesis, *Entwicklung eines GPGPU-basierten Ray Tracers*, Universität \
               Koblenz-Landau, 2015",
    part: "ch. 5",
};
const KLEE: Source = Source {
    name: "Klee 2016",
    citation: "B.Sc. thesis, *Darstellung von Halbschatten durch Verwendung des \"Cascaded \
               Linespace\"-Verfahrens*, Koblenz, 2016",
    part: "ch. 5",
};
const STREAMING: Source = Source {
    name: "the streaming tracer",
    citation: "a paper on a streaming GPU ray tracer with a uniform grid and proximity clouds; \
               its title, authors and venue are not in the available text, see \
               docs/references.md",
    part: "Tables 1–3",
};
const WAGNER: Source = Source {
    name: "Wagner 2018",
    citation: "B.Sc. thesis, *Potenzialanalyse der GPU-Beschleunigung beim Raytracing*, \
               Hochschule für Angewandte Wissenschaften Hamburg, 2018",
    part: "ch. 5 and appendix A",
};

/// Write `<out>/report.md`.
/// `pending`: the protocols of the command line not run yet (a report written as each protocol
/// ends says which are still to come, so a run cut short leaves a report true to its files).
pub fn write(
    bench: &Bench,
    sections: &[Section],
    wall_s: f64,
    pending: &[&str],
) -> Result<PathBuf> {
    // the sources whose protocols ran: the Müller-specific settings only where they apply
    let ran = |prefix: &str| sections.iter().any(|x| x.protocol.starts_with(prefix));
    let (muller, klee, wagner) = (ran("thesis-"), ran("klee-"), ran("wagner-"));
    let sources = [
        (muller, MULLER),
        (klee, KLEE),
        (wagner, WAGNER),
        (ran("proximity-clouds-"), STREAMING),
    ];
    let cited: Vec<&Source> = sources.iter().filter(|s| s.0).map(|s| &s.1).collect();
    let command = bench.command.clone();
    let command = command.unwrap_or_else(|| std::env::args().collect::<Vec<_>>().join(" "));
    let mut s = heading(&cited, &command, &bench.machine, wall_s);
    if !pending.is_empty() {
        let _ = writeln!(
            s,
            "**Unfinished run:** the sections below are the protocols it finished; it had yet to \
             run {}.\n",
            pending.join(", ")
        );
    }
    s.push_str(&machine(&bench.machine, muller));
    s.push_str(&shards(&bench.contributors));
    if muller {
        s.push_str(&muller_settings(&bench.args));
    }
    for sec in sections {
        s.push_str(&section(sec));
    }
    let path = bench.out.join("report.md");
    gpgpu_rt::output::write_file(&path, |w| Ok(w.write_all(s.as_bytes())?))?;
    Ok(path)
}

/// The title, what the report compares (the works `cited`), the command, the date and the wall
/// time.
fn heading(cited: &[&Source], command: &str, m: &Machine, wall_s: f64) -> String {
    // "Müller 2015, ch. 5": the short name and the part replicated
    let sources: Vec<String> = cited
        .iter()
        .map(|c| format!("{}, {}", c.name, c.part))
        .collect();
    let full: Vec<String> = cited
        .iter()
        .map(|c| format!("{} ({}), {}", c.name, c.citation, c.part))
        .collect();
    let mut s = String::new();
    if cited.is_empty() {
        // protocols of ours only (accel-compare): nothing published to set beside
        let _ = writeln!(
            s,
            "# gpgpu-rt benchmarks\n\nAbsolute times depend on the hardware: compare the \
             **ratios** between configurations of this run. Triangle-test counts do not depend \
             on the hardware.\n"
        );
    } else {
        let title = sources.join("; ");
        // a short name starting in lower case ("the streaming tracer") opens the title capitalised
        let mut first = title.chars();
        let title: String = first
            .next()
            .map_or(String::new(), |c| c.to_uppercase().chain(first).collect());
        let _ = writeln!(s, "# {title}, replicated with gpgpu-rt\n");
        let _ = writeln!(
            s,
            "Our numbers beside the published ones of {}. The hardware differs, so absolute times \
             are not comparable: compare the **ratios** (speed-up, test reduction, time relative \
             to another scene or method). Triangle-test counts do not depend on the hardware, but \
             on the image size, the camera and the scene files, which the sources do not fully \
             state.\n",
            full.join(" and ")
        );
    }
    let _ = writeln!(
        s,
        "Command: `{command}`  \nDate: {}  \nTotal wall time: {wall_s:.1} s\n",
        m.date
    );
    s
}

/// A merged run (`bench merge`): the shards and the machine each ran on. The machine above is
/// the first shard's; the total wall time is the sum of the shards'.
fn shards(contributors: &[(Shard, Machine)]) -> String {
    if contributors.is_empty() {
        return String::new();
    }
    let rows: Vec<Vec<String>> = contributors
        .iter()
        .map(|(s, m)| {
            let cpu = format!("{} ({} logical CPUs)", m.cpu, m.logical_cpus);
            vec![
                s.to_string(),
                m.gl_renderer.clone(),
                m.gl_version.clone(),
                cpu,
                m.date.clone(),
            ]
        })
        .collect();
    let mut s = format!(
        "\nMerged from {} shards (`bench … --shard K/N`, `bench merge`); the table above is the first \
         shard's machine, the wall time the sum of the shards':\n\n",
        contributors.len()
    );
    s.push_str(&table(
        &["shard", "GL renderer", "GL version", "CPU", "date"],
        &rows,
    ));
    s
}

/// The machine, beside Müller 2015's where its protocols ran.
fn machine(m: &Machine, muller: bool) -> String {
    let row = |what: &str, ours: String, theirs: &str| vec![what.into(), ours, theirs.into()];
    let cpu = format!("{} ({} logical CPUs)", m.cpu, m.logical_cpus);
    let rows = vec![
        row("GL renderer", m.gl_renderer.clone(), thesis::GPU),
        row("GL version", m.gl_version.clone(), "OpenGL 4.5"),
        row("GL vendor", m.gl_vendor.clone(), "NVIDIA"),
        row("GLSL", m.glsl_version.clone(), "4.50"),
        row("EGL device", m.egl_device.clone(), "– (a window)"),
        row("CPU", cpu, thesis::CPU),
        row("OS", m.os.clone(), thesis::OS),
        row("gpgpu-rt", m.gpgpu_rt_version.clone(), "–"),
    ];
    let mut s = String::from("## Machine\n\n");
    if muller {
        s.push_str(&table(&["", "ours", "Müller 2015 (ch. 5)"], &rows));
    } else {
        let ours: Vec<Vec<String>> = rows.into_iter().map(|r| r[..2].to_vec()).collect();
        s.push_str(&table(&["", "ours"], &ours));
    }
    if m.is_software() {
        let _ = writeln!(
            s,
            "\n**{} is a software rasterizer on the CPU**: its timings say nothing about GPUs and are shared \
             with whatever else runs on the machine; only ratios between configurations measured in the same \
             run mean something.",
            m.gl_renderer
        );
    }
    s
}

fn rotation_text(r: Rotation) -> &'static str {
    match r {
        Rotation::Objects => {
            "objects: every object's model matrix is turned about the vertical axis through the centre of \
             the scene's bounding box (the thesis' \"Drehung der Szene\"; the transform pass applies it every \
             frame, the grid is rebuilt for it); camera and light stay where the scene file puts them, so \
             shadows move over the objects as the scene turns"
        }
        Rotation::Camera => {
            "camera: the camera orbits the vertical axis through the centre of the scene's bounding box by −θ \
             (the same view of the objects as turning them by θ, but the light stays fixed to the objects)"
        }
    }
}

/// The settings of the Müller 2015 protocols (the Klee sections state their own).
fn muller_settings(a: &BenchArgs) -> String {
    let mut s = String::from("\n## Settings\n\n");
    let scale = match a.scale {
        Scale::Quick => "quick (few angles, a small image: minutes on Mesa llvmpipe)",
        Scale::Full => "full (the thesis' protocol; for a GPU)",
    };
    let _ = writeln!(s, "- Scale: {scale}.");
    s.push_str(&image_size_settings(a));
    let rotate = match a.rotate {
        Rotation::Objects => "`--rotate objects`",
        Rotation::Camera => "`--rotate camera`",
    };
    let _ = writeln!(s, "- Rotation ({rotate}): {}.", rotation_text(a.rotate));
    s.push_str(
        "- Warm-up: the first frames of every configuration are rendered at its first angle and not counted \
         (each section gives how many).\n\
         - FPS = 1000 / wall-clock ms of a frame on the host (the whole render loop of Fig. 8 until the image \
         is read back; the thesis drew it to a window instead). `FPS (run)` = frames / total wall time, the \
         thesis' \"durchschnittliche FPS\". GPU ms = the sum of the GL timer queries of all kernels of a frame. \
         Tables give the median [min–max] over the measured frames.\n\
         - Triangle tests = all ray–triangle tests of a frame (intersect1 + intersect2: primary, reflection \
         and shadow rays), exact 64-bit counts from the kernels.\n",
    );
    s.push_str(&tracer_settings(a));
    let _ = writeln!(
        s,
        "- Müller 2015's test system: {}. It measured {}.",
        thesis::HARDWARE,
        thesis::MEASURES
    );
    s
}

/// The image size, and what the thesis' published count says about its size.
fn image_size_settings(a: &BenchArgs) -> String {
    let this_run = match (a.width, a.height) {
        (None, None) => "the defaults".to_string(),
        (w, h) => {
            let or_default = |v: Option<u32>| v.map_or("default".into(), |v| v.to_string());
            format!("width {}, height {}", or_default(w), or_default(h))
        }
    };
    format!(
        "- Image size: the thesis does not state it. Defaults here: {}×{} at `--scale quick`, {}×{} at \
         `--scale full`; `--width`/`--height` override (this run: {this_run}). Each section gives the size it \
         used.\n  The published base-tracer count for the bunny, 1,137,720,816 tests per frame, is {:.1} × \
         69451: were it a complete count, every ray's test of all triangles included, the thesis' image would \
         have had fewer than 16382 pixels (less than 128×128), since the primary rays alone test W·H·69451 \
         times. If its counter was 32-bit and wrapped, the number says nothing about the size. The thesis does \
         not say how it counted.\n",
        QUICK_SIZE.0,
        QUICK_SIZE.1,
        FULL_SIZE.0,
        FULL_SIZE.1,
        thesis::bunny_base_tests_per_triangle()
    )
}

/// Dispatches, shadow flags and the thesis grid's list lengths.
fn tracer_settings(a: &BenchArgs) -> String {
    let dispatch = if a.tile == 0 {
        "one dispatch per kernel and pass, as the thesis"
    } else {
        "tiles of at most this many pixels squared"
    };
    let (voxel_default, ray_default) = grid_list_defaults();
    let ray = match a.grid.ray_array_length.or(ray_default) {
        Some(r) => r.to_string(),
        None => "3·N (Listing 17)".to_string(),
    };
    format!(
        "- Dispatches: `--tile {}` ({dispatch}); shadow flags in an RGBA texture as the thesis (`rgba`, at most \
         4 lights; every scene here has one).\n\
         - Grid list lengths of the thesis variant: voxel_array_length {}, ray_array_length {ray} \
         (`--voxel-array-length`, `--ray-array-length`).\n",
        a.tile,
        a.grid.voxel_array_length.unwrap_or(voxel_default),
    )
}

/// A protocol's section with the files it wrote.
fn section(sec: &Section) -> String {
    let mut s = format!("\n## {}: {}\n\n{}", sec.protocol, sec.title, sec.markdown);
    if !sec.files.is_empty() {
        let links: Vec<String> = sec
            .files
            .iter()
            .map(|f| format!("[`{0}`]({0})", f.display()))
            .collect();
        let _ = writeln!(s, "\nFiles: {}", links.join(", "));
    }
    s
}
