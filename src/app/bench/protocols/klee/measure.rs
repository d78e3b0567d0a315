//! What the Klee 2016 protocols share: a scene with its soft-shadow renderer, the shadow pass
//! timed on the GPU and the same shadows (or the primary rays) timed on the CPU, the CSV of
//! the measurements, and the section's opening paragraph.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use glam::Vec3;

use crate::bench::common::section::Section;
use crate::bench::protocols::protocol::Protocol;
use crate::bench::report::plots::Figure;
use crate::bench::runner::adapter::{ShadowFrame, SoftShadows};
use crate::bench::runner::config::Sizing;
use crate::bench::runner::csv_files::write_rows;
use crate::bench::runner::Bench;
use gpgpu_rt::reference::linespace::ShadowCounts;
use gpgpu_rt::scene::{Scene, ShadowMode};

/// Mean/min/max seconds of a measurement and its counts (per frame).
#[derive(Debug, Clone, Copy, Default)]
pub struct Meas {
    pub mean_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    pub frames: u32,
    pub triangle_tests: u64,
    pub linespace_lookups: u64,
    /// CPU only: the line-space lookups per stack depth (0: the root's children).
    pub lookups_by_depth: [u64; 3],
}

fn meas(times: &[f64], tests: u64, lookups: u64) -> Meas {
    let n = times.len().max(1) as f64;
    Meas {
        mean_s: times.iter().sum::<f64>() / n,
        min_s: times.iter().copied().fold(f64::INFINITY, f64::min),
        max_s: times.iter().copied().fold(0.0, f64::max),
        frames: times.len() as u32,
        triangle_tests: tests,
        linespace_lookups: lookups,
        lookups_by_depth: [0; 3],
    }
}

/// The two readings of the thesis' N-tree depth, as levels counting the root (`--ntree-depth`):
/// A = 3 (root, 1/10, leaves at 1/100: the line spaces of one level are asked, no cascade),
/// B = 4 ("Tiefe null ist die Tiefe der Kinder des Wurzelknotens", "maximale Tiefe von 3":
/// three levels below the root, leaves at 1/1000, a cascade of two line-space levels).
pub const READINGS: [(&str, u32); 2] = [("A", 3), ("B", 4)];

/// The shadow pass on the GPU: its time per frame, the G-buffer pass's, and the last frame.
pub struct GpuRun {
    pub shadow: Meas,
    pub gbuffer: Meas,
    pub last: ShadowFrame,
}

/// A scene with its soft-shadow renderer (the N-tree built once).
pub struct Setup {
    pub scene: Scene,
    shadows: SoftShadows,
    sizing: Sizing,
    /// At least this many frames timed on the CPU (Table 2's runs take milliseconds at the
    /// quick size: one frame is mostly noise on a shared machine).
    pub min_cpu_frames: u32,
}

impl Setup {
    pub fn new(bench: &mut Bench, scene: &str, s: Sizing, levels: u32) -> Result<Setup> {
        let scene = bench.scene(scene)?.clone();
        let shadows = SoftShadows::new(bench.gpu()?, &scene, s, bench.args.tile, levels)?;
        Ok(Setup {
            scene,
            shadows,
            sizing: s,
            min_cpu_frames: 1,
        })
    }

    /// Bytes of the N-tree's node pool and of its line spaces.
    pub fn memory(&self) -> (usize, usize) {
        self.shadows.memory()
    }

    /// GPU: the shadow kernel's time per frame (and the G-buffer pass's), after warm-up.
    pub fn gpu(&mut self, bench: &Bench, mode: ShadowMode, su: u32, sv: u32) -> Result<GpuRun> {
        self.shadows.configure(bench.gpu()?, mode, su, sv)?;
        for _ in 0..self.sizing.warmup {
            self.shadows.render(&self.scene.camera)?;
        }
        let (mut shadow, mut gbuf) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..self.sizing.angles.max(1) {
            let f = self.shadows.render(&self.scene.camera)?;
            let gpu_s = |kernel: &dyn Fn(&str) -> bool| {
                let ms = f.stats.gpu_ms.iter().filter(|(k, _)| kernel(k));
                ms.map(|(_, v)| v).sum::<f64>() / 1e3
            };
            shadow.push(gpu_s(&|k| k.starts_with("shadow")));
            gbuf.push(gpu_s(&|k| k == "gbuffer"));
            last = Some(f);
        }
        let last = last.expect("one frame");
        let tests = last.stats.triangle_tests.values().sum();
        let lookups = last.stats.events.get("linespace_lookups").copied();
        Ok(GpuRun {
            shadow: meas(&shadow, tests, lookups.unwrap_or(0)),
            gbuffer: meas(&gbuf, 0, 0),
            last,
        })
    }

    /// Frames timed on the CPU: 3 where the GPU has more than 2, else 1; at least
    /// `min_cpu_frames`.
    fn cpu_frames(&self) -> u32 {
        let frames = if self.sizing.angles > 2 { 3 } else { 1 };
        frames.max(self.min_cpu_frames)
    }

    /// CPU: the shadow values of every pixel of `f`'s G-buffer, one thread: its measurement
    /// and the values of the pixels that hit geometry.
    pub fn cpu_values(
        &self,
        f: &ShadowFrame,
        mode: ShadowMode,
        su: u32,
        sv: u32,
    ) -> (Meas, Vec<f32>) {
        let mut cpu = self.shadows.cpu();
        cpu.samples_u = su;
        cpu.samples_v = sv;
        let mut times = Vec::new();
        let mut counts = Default::default();
        let mut values = Vec::new();
        for _ in 0..self.cpu_frames() {
            counts = ShadowCounts::default();
            values.clear();
            let t = Instant::now();
            for (p, n) in f.gbuffer_position.iter().zip(&f.gbuffer_normal) {
                if p[3] > 0.0 {
                    let (v, c) = cpu.shadow(
                        mode,
                        Vec3::new(p[0], p[1], p[2]),
                        Vec3::new(n[0], n[1], n[2]).normalize(),
                    );
                    counts += c;
                    values.push(v);
                }
            }
            times.push(t.elapsed().as_secs_f64());
        }
        let mut m = meas(&times, counts.triangle_tests, counts.linespace_lookups);
        m.lookups_by_depth = counts.lookups_by_depth;
        (m, values)
    }

    /// CPU: the primary rays ray cast through the N-tree, one thread.
    pub fn cpu_primary(&self) -> Meas {
        let cpu = self.shadows.cpu();
        let (w, h) = (self.sizing.width, self.sizing.height);
        let rays = self.scene.camera.rays(w, h);
        let mut times = Vec::new();
        let mut counts = ShadowCounts::default();
        for _ in 0..self.cpu_frames() {
            counts = Default::default();
            let t = Instant::now();
            for y in 0..h {
                for x in 0..w {
                    let (o, d) = rays.primary_ray(x, y);
                    std::hint::black_box(cpu.closest_hit(o, d, &mut counts));
                }
            }
            times.push(t.elapsed().as_secs_f64());
        }
        meas(&times, counts.triangle_tests, 0)
    }
}

/// One CSV row.
#[derive(Clone)]
pub struct Row {
    pub scene: String,
    pub variant: String,
    pub device: String,
    pub rays: u32,
    pub m: Meas,
    /// N-tree levels counting the root (3: reading A, 4: reading B).
    pub levels: u32,
}

impl Row {
    pub fn new(scene: &str, variant: &str, device: &str, rays: u32, m: Meas) -> Row {
        Row {
            scene: scene.into(),
            variant: variant.into(),
            device: device.into(),
            rays,
            m,
            levels: 3,
        }
    }

    /// The row measured with an N-tree of `levels` levels (root included).
    pub fn levels(mut self, levels: u32) -> Row {
        self.levels = levels;
        self
    }
}

/// `<out>/<name>.csv`: one line per row; its path relative to the output folder.
fn write_csv(bench: &Bench, name: &str, rows: &[Row], s: Sizing) -> Result<PathBuf> {
    let rel = PathBuf::from(format!("{name}.csv"));
    let header = [
        "scene",
        "variant",
        "device",
        "ntree_levels",
        "width",
        "height",
        "rays",
        "frames",
        "mean_s",
        "min_s",
        "max_s",
        "fps",
        "triangle_tests",
        "linespace_lookups",
        "lookups_depth0",
        "lookups_depth1",
        "lookups_depth2",
    ];
    let lines: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut line = vec![r.scene.clone(), r.variant.clone(), r.device.clone()];
            line.push(r.levels.to_string());
            line.extend([s.width, s.height, r.rays, r.m.frames].map(|v| v.to_string()));
            line.extend([r.m.mean_s, r.m.min_s, r.m.max_s].map(|v| format!("{v:.6}")));
            line.push(format!("{:.4}", 1.0 / r.m.mean_s));
            line.extend([r.m.triangle_tests, r.m.linespace_lookups].map(|v| v.to_string()));
            line.extend(r.m.lookups_by_depth.map(|v| v.to_string()));
            line
        })
        .collect();
    let header: Vec<String> = header.map(String::from).to_vec();
    write_rows(&bench.out.join(&rel), &header, &lines)?;
    Ok(rel)
}

/// The section of a Klee protocol: the common opening paragraph, `markdown`, the `figures`,
/// and the CSV of `rows`.
pub fn section(
    p: &Protocol,
    bench: &Bench,
    s: Sizing,
    markdown: &str,
    rows: &[Row],
    figures: &[Figure],
) -> Result<Section> {
    let csv = write_csv(bench, p.name, rows, s)?;
    let opening = format!(
        "{} pixels, N-tree N = 10, 3 levels counting the root (reading A) unless a row says \
         B (4 levels), mean over {} frames (after {} warm-up); GPU: {}; CPU: one \
         thread of this machine. Published: NVIDIA GTX 760 / Xeon E3-1230 v3, 512×512. Compare ratios, \
         not seconds.\n\n",
        s.size(),
        s.angles,
        s.warmup,
        bench.machine.gl_renderer
    );
    p.figure_section(&bench.out, opening + markdown, vec![csv], figures)
}
