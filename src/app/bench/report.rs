//! `report.md`: the machine, the settings, and one section per protocol with our numbers
//! beside the published ones. Also the small formatting helpers the protocols share.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};

use super::published;
use super::runner::{Bench, Outcome};
use super::stats::Stats;
use super::{Protocol, Rotation, Scale};

/// A protocol's part of the report.
#[derive(Debug, Clone, Default)]
pub struct Section {
    pub protocol: String,
    pub title: String,
    pub markdown: String,
    /// Configurations that failed (their errors are in the markdown).
    pub failures: usize,
    /// Files written, relative to the output folder.
    pub files: Vec<PathBuf>,
}

impl Section {
    /// The section of a protocol that measured `outcomes`: `markdown`, then the `figures` (path,
    /// caption) and the failed configurations; its files are the protocol's CSV and summary
    /// CSV, the figures and each configuration's first frame.
    pub fn of_sweep(
        protocol: &dyn Protocol,
        mut markdown: String,
        outcomes: &[Outcome],
        figures: Vec<(PathBuf, &str)>,
    ) -> Section {
        let name = protocol.name();
        let mut files = vec![
            PathBuf::from(format!("{name}.csv")),
            PathBuf::from(format!("{name}_summary.csv")),
        ];
        for (k, (fig, caption)) in figures.into_iter().enumerate() {
            if k > 0 {
                markdown.push('\n');
            }
            markdown.push_str(&image(&fig, caption));
            files.push(fig);
        }
        markdown.push_str(&failures(outcomes));
        files.extend(outcomes.iter().filter_map(|o| o.image.clone()));
        Section {
            protocol: name.into(),
            title: protocol.title().into(),
            markdown,
            failures: outcomes.iter().filter(|o| o.error.is_some()).count(),
            files,
        }
    }
}

/// An integer with thousands separators: 1,137,720,816.
pub fn int(v: f64) -> String {
    let neg = v < 0.0;
    let digits = format!("{:.0}", v.abs().round());
    let mut out = String::new();
    for (i, ch) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(ch);
    }
    if neg {
        format!("-{out}")
    } else {
        out
    }
}

/// A number with a sensible number of significant digits for a table.
pub fn num(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        "–".into()
    } else if a >= 1e5 {
        int(v)
    } else if a >= 100.0 {
        format!("{v:.1}")
    } else if a >= 1.0 {
        format!("{v:.3}")
    } else {
        format!("{v:.4}")
    }
}

/// "median [min–max]" with the given formatter, "–" without data.
pub fn mmm(s: Option<Stats>, f: fn(f64) -> String) -> String {
    match s {
        Some(s) => format!("{} [{}–{}]", f(s.median), f(s.min), f(s.max)),
        None => "–".into(),
    }
}

/// "×5.49".
pub fn ratio(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("×{v:.2}"),
        _ => "–".into(),
    }
}

/// A markdown table.
pub fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "| {} |", header.join(" | "));
    let _ = writeln!(
        s,
        "|{}|",
        header.iter().map(|_| "---").collect::<Vec<_>>().join("|")
    );
    for r in rows {
        let cells: Vec<String> = r
            .iter()
            .map(|c| c.replace('|', "\\|").replace('\n', " "))
            .collect();
        let _ = writeln!(s, "| {} |", cells.join(" | "));
    }
    s
}

/// The configurations that failed, as a list (empty string when none did).
pub fn failures(outcomes: &[Outcome]) -> String {
    let mut s = String::new();
    for o in outcomes.iter().filter(|o| o.error.is_some()) {
        let _ = writeln!(
            s,
            "- **{} failed** after {} measured frames: `{}`",
            o.config.label(),
            o.frames.len(),
            o.error.as_deref().unwrap_or("")
        );
    }
    if !s.is_empty() {
        s.insert_str(0, "\nFailed configurations:\n\n");
    }
    s
}

/// Non-zero design events over all frames (grid: dropped_triangle_refs, ray_list_overflows,
/// ...), e.g. "dropped_triangle_refs 1,204 (max 310/frame)"; "–" when none.
pub fn event_summary(o: &Outcome) -> String {
    let mut names: Vec<&String> = o
        .frames
        .iter()
        .flat_map(|f| f.stats.events.keys())
        .filter(|k| *k != "voxels_visited")
        .collect();
    names.sort();
    names.dedup();
    let parts: Vec<String> = names
        .into_iter()
        .filter_map(|k| {
            let v: Vec<u64> = o
                .frames
                .iter()
                .map(|f| f.stats.events.get(k).copied().unwrap_or(0))
                .collect();
            let total: u64 = v.iter().sum();
            (total > 0).then(|| {
                format!(
                    "{k} {} (max {}/frame)",
                    int(total as f64),
                    int(*v.iter().max().unwrap_or(&0) as f64)
                )
            })
        })
        .collect();
    if parts.is_empty() {
        "–".into()
    } else {
        parts.join("; ")
    }
}

/// A design fact of the first frame (grid: grid_bytes, ...), formatted.
pub fn fact(o: &Outcome, name: &str) -> Option<f64> {
    o.frames
        .first()
        .and_then(|f| f.stats.facts.get(name))
        .and_then(|v| v.as_f64())
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

/// Write `<out>/report.md`.
pub fn write(bench: &Bench, sections: &[Section], wall_s: f64) -> Result<PathBuf> {
    let m = &bench.machine;
    let a = &bench.args;
    let mut s = String::new();
    // the sources whose protocols ran: the Müller-specific settings only where they apply
    let muller = sections.iter().any(|x| x.protocol.starts_with("thesis-"));
    let klee = sections.iter().any(|x| x.protocol.starts_with("klee-"));
    let mut sources = Vec::new();
    let mut cited = Vec::new();
    if muller || !klee {
        sources.push("Müller 2015, ch. 5");
        cited.push(
            "Müller 2015 (B.Sc. thesis, *GPGPU ray tracing with OpenGL 4.5 compute shaders and a per-frame \
             uniform grid*), ch. 5",
        );
    }
    if klee {
        sources.push("Klee 2016, ch. 5");
        cited.push(
            "Klee 2016 (B.Sc. thesis, *Darstellung von Halbschatten durch Verwendung des \"Cascaded \
             Linespace\"-Verfahrens*), ch. 5",
        );
    }
    let _ = writeln!(s, "# {}, replicated with gpgpu-rt\n", sources.join("; "));
    let _ = writeln!(
        s,
        "Our numbers beside the published ones of {}. The hardware differs, so absolute times are not \
         comparable: compare the **ratios** (speed-up, test reduction, time relative to another scene or \
         method). Triangle-test counts do not depend on the hardware, but on the image size, the camera and \
         the scene files, which the theses do not fully state.\n",
        cited.join(" and ")
    );
    let args: Vec<String> = std::env::args().collect();
    let _ = writeln!(
        s,
        "Command: `{}`  \nDate: {}  \nTotal wall time: {:.1} s\n",
        args.join(" "),
        m.date,
        wall_s
    );

    let _ = writeln!(s, "## Machine\n");
    let rows = vec![
        vec![
            "GL renderer".into(),
            m.gl_renderer.clone(),
            published::GPU.into(),
        ],
        vec![
            "GL version".into(),
            m.gl_version.clone(),
            "OpenGL 4.5".into(),
        ],
        vec!["GL vendor".into(), m.gl_vendor.clone(), "NVIDIA".into()],
        vec!["GLSL".into(), m.glsl_version.clone(), "4.50".into()],
        vec![
            "EGL device".into(),
            m.egl_device.clone(),
            "– (a window)".into(),
        ],
        vec![
            "CPU".into(),
            format!("{} ({} logical CPUs)", m.cpu, m.logical_cpus),
            published::CPU.into(),
        ],
        vec!["OS".into(), m.os.clone(), published::OS.into()],
        vec!["gpgpu-rt".into(), m.gpgpu_rt_version.clone(), "–".into()],
    ];
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

    if muller {
        muller_settings(&mut s, a);
    }
    sections_markdown(&mut s, sections);
    let path = bench.out.join("report.md");
    std::fs::write(&path, s).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path)
}

/// The settings of the Müller 2015 protocols (the Klee sections state their own).
fn muller_settings(s: &mut String, a: &super::BenchArgs) {
    let _ = writeln!(s, "\n## Settings\n");
    let scale = match a.scale {
        Scale::Quick => "quick (few angles, a small image: minutes on Mesa llvmpipe)",
        Scale::Full => "full (the thesis' protocol; for a GPU)",
    };
    let _ = writeln!(s, "- Scale: {scale}.");
    let _ = writeln!(
        s,
        "- Image size: the thesis does not state it. Defaults here: {}×{} at `--scale quick`, {}×{} at \
         `--scale full`; `--width`/`--height` override (this run: {}). Each section gives the size it used.",
        super::QUICK_SIZE.0,
        super::QUICK_SIZE.1,
        super::FULL_SIZE.0,
        super::FULL_SIZE.1,
        match (a.width, a.height) {
            (None, None) => "the defaults".to_string(),
            (w, h) => format!("width {}, height {}", w.map_or("default".into(), |v| v.to_string()), h.map_or("default".into(), |v| v.to_string())),
        }
    );
    let _ = writeln!(
        s,
        "  The published base-tracer count for the bunny, 1,137,720,816 tests per frame, is {:.1} × 69451: \
         were it a complete count, every ray's test of all triangles included, the thesis' image would have had \
         fewer than 16382 pixels (less than 128×128), since the primary rays alone test W·H·69451 times. If its \
         counter was 32-bit and wrapped, the number says nothing about the size. The thesis does not say how it \
         counted.",
        published::bunny_base_tests_per_triangle()
    );
    let _ = writeln!(
        s,
        "- Rotation ({}): {}.",
        match a.rotate {
            Rotation::Objects => "`--rotate objects`",
            Rotation::Camera => "`--rotate camera`",
        },
        rotation_text(a.rotate)
    );
    let _ = writeln!(
        s,
        "- Warm-up: the first frames of every configuration are rendered at its first angle and not counted \
         (each section gives how many)."
    );
    let _ = writeln!(
        s,
        "- FPS = 1000 / wall-clock ms of a frame on the host (the whole render loop of Fig. 8 until the image \
         is read back; the thesis drew it to a window instead). `FPS (run)` = frames / total wall time, the \
         thesis' \"durchschnittliche FPS\". GPU ms = the sum of the GL timer queries of all kernels of a frame. \
         Tables give the median [min–max] over the measured frames."
    );
    let _ = writeln!(
        s,
        "- Triangle tests = all ray–triangle tests of a frame (intersect1 + intersect2: primary, reflection \
         and shadow rays), exact 64-bit counts from the kernels."
    );
    let _ = writeln!(
        s,
        "- Dispatches: `--tile {}` ({}); shadow flags in an RGBA texture as the thesis (`rgba`, at most 4 \
         lights; every scene here has one).",
        a.tile,
        if a.tile == 0 { "one dispatch per kernel and pass, as the thesis" } else { "tiles of at most this many pixels squared" }
    );
    let d = gpgpu_rt::accel::GridOptions::default();
    let _ = writeln!(
        s,
        "- Grid list lengths of the thesis variant: voxel_array_length {}, ray_array_length {} \
         (`--voxel-array-length`, `--ray-array-length`).",
        a.voxel_array_length.unwrap_or(d.voxel_array_length),
        match (a.ray_array_length, d.ray_array_length) {
            (Some(r), _) | (None, Some(r)) => r.to_string(),
            (None, None) => "3·N (Listing 17)".to_string(),
        }
    );
    let _ = writeln!(
        s,
        "- Müller 2015's test system: {}. It measured {}.",
        published::HARDWARE,
        published::MEASURES
    );
}

/// Every protocol's section with the files it wrote.
fn sections_markdown(s: &mut String, sections: &[Section]) {
    for sec in sections {
        let _ = writeln!(s, "\n## {}: {}\n", sec.protocol, sec.title);
        s.push_str(&sec.markdown);
        if !sec.files.is_empty() {
            let _ = writeln!(
                s,
                "\nFiles: {}",
                sec.files
                    .iter()
                    .map(|f| format!("[`{0}`]({0})", f.display()))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
}

/// Markdown image link for a plot.
pub fn image(path: &Path, alt: &str) -> String {
    format!("![{alt}]({})\n", path.display())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_numbers() {
        assert_eq!(int(1_137_720_816.0), "1,137,720,816");
        assert_eq!(int(999.0), "999");
        assert_eq!(int(1000.0), "1,000");
        assert_eq!(int(-1234.4), "-1,234");
        assert_eq!(num(0.8804), "0.8804");
        assert_eq!(num(4.83391), "4.834");
        assert_eq!(ratio(Some(5.4906)), "×5.49");
        assert_eq!(ratio(None), "–");
        let t = table(&["a", "b"], &[vec!["1".into(), "x|y".into()]]);
        assert_eq!(t, "| a | b |\n|---|---|\n| 1 | x\\|y |\n");
    }
}
