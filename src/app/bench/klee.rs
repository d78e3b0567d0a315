//! Klee 2016, ch. 5: the evaluation of soft shadows with the Cascaded Line Space, replicated.
//! N-tree N = 10, depth 3 as the thesis; the bunny (`bunny_area.toml`) and the dragon
//! (`dragon_area.toml`: 202520 triangles — the thesis' 871k dragon is not available). Shadow
//! times exclude the primary rays, as the thesis measures them; every time is the mean over
//! the frames (the thesis: ten). "CPU" is our CPU implementation (`src/reference/linespace.rs`,
//! one thread, primary hits from the G-buffer except in Table 1); "GPU" the shadow kernel's GL
//! timer-query time.
//!
//! - `klee-table1`: primary rays, GPU rasterisation (the G-buffer pass) vs CPU ray casting.
//! - `klee-table2`: CPU, bunny, 4 rays: triangle tests (`exact`) vs line-space lookups.
//! - `klee-table3`: CPU, bunny, CGT (`linespace`) vs DDA (`linespace-dda`), 4/9/16/100 rays.
//! - `klee-fig12`: bunny, 2×2 … 10×10 rays, CPU vs GPU (FPS and seconds).
//! - `klee-fig13`: GPU, bunny vs dragon, 2×2 … 10×10 rays.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, Result};
use glam::Vec3;

use super::plots::{self, Chart, Series, Style, BLACK_INDEX};
use super::report::{self, num, ratio, Section};
use super::runner::{Bench, Sizing};
use super::{Protocol, FULL_SIZE, QUICK_SIZE};
use gpgpu_rt::frame::FrameStats;
use gpgpu_rt::pipeline::softshadow::{SoftShadowOptions, SoftShadowRenderer};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::Scene;
use gpgpu_rt::scene::ShadowMode;

/// A soft-shadow frame's statistics and the G-buffer it was shaded from (the CPU
/// implementation shades the same points).
pub struct SoftShadowFrame {
    pub stats: FrameStats,
    pub gbuffer_position: Vec<[f32; 4]>,
    pub gbuffer_normal: Vec<[f32; 4]>,
}

pub const BUNNY: &str = "bunny_area.toml";
pub const DRAGON: &str = "dragon_area.toml";

/// Quick: 64², 2 frames (1 warm-up). Full: 512² as the thesis' test images, 10 frames.
/// (`angles` is the number of measured frames here.)
pub const QUICK: Sizing = Sizing {
    width: QUICK_SIZE.0,
    height: QUICK_SIZE.1,
    angles: 2,
    warmup: 1,
};
pub const FULL: Sizing = Sizing {
    width: FULL_SIZE.0,
    height: FULL_SIZE.1,
    angles: 10,
    warmup: 1,
};

/// Published: Table 1 (seconds): GPU bunny, CPU bunny, GPU dragon (871k), CPU dragon.
pub const TABLE1: [(&str, &str, f64); 4] = [
    ("bunny", "GPU", 0.000993448),
    ("bunny", "CPU", 0.178985),
    ("dragon", "GPU", 0.00189566),
    ("dragon", "CPU", 0.197976),
];
/// Published: Table 2 (seconds, CPU, bunny, 4 rays): triangle tests, line-space lookups.
pub const TABLE2: [(&str, f64); 2] = [
    ("triangle tests", 6.064665),
    ("line-space lookups", 0.448443),
];
/// Published: Table 3 (seconds, CPU, bunny): rays, CGT, DDA.
pub const TABLE3: [(u32, f64, f64); 4] = [
    (4, 0.628609, 0.356825),
    (9, 0.867256, 0.550786),
    (16, 1.18496, 0.829777),
    (100, 4.82775, 3.88766),
];
/// Published: Fig. 12 — the GPU takes 86 % less time than the CPU at every sample count.
pub const FIG12_GPU_SAVING: f64 = 0.86;
/// Published: Fig. 13 — the dragon (871k) takes 3 % longer than the bunny at 4 rays, 22 % at 100.
pub const FIG13_DRAGON_EXTRA: [(u32, f64); 2] = [(4, 0.03), (100, 0.22)];

/// Mean/min/max seconds of a measurement and its counts (per frame).
#[derive(Debug, Clone, Copy, Default)]
pub struct Meas {
    pub mean_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    pub frames: u32,
    pub triangle_tests: u64,
    pub linespace_lookups: u64,
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
    }
}

/// A scene with its soft-shadow renderer (the N-tree built once).
pub struct Setup {
    pub scene: Scene,
    pub renderer: SoftShadowRenderer,
    pub sizing: Sizing,
}

pub fn setup(bench: &mut Bench, scene: &str, s: Sizing) -> Result<Setup> {
    let scene = bench.scene(scene)?.clone();
    let opts = SoftShadowOptions {
        mode: ShadowMode::Linespace,
        samples_u: 2,
        samples_v: 2,
        ntree_n: 10,
        ntree_depth: 3,
        width: s.width,
        height: s.height,
        tile: bench.args.tile,
    };
    let renderer = SoftShadowRenderer::new(
        bench.ctx.gl.clone(),
        &bench.ctx.info,
        &scene,
        &bench.shaders,
        opts,
    )
    .with_context(|| format!("{}: soft-shadow renderer", scene.path.display()))?;
    Ok(Setup {
        scene,
        renderer,
        sizing: s,
    })
}

impl Setup {
    /// GPU: the shadow kernel's time per frame (and the G-buffer pass's), after warm-up.
    pub fn gpu(
        &mut self,
        bench: &Bench,
        mode: ShadowMode,
        su: u32,
        sv: u32,
    ) -> Result<(Meas, Meas, SoftShadowFrame)> {
        self.renderer.reconfigure(&bench.shaders, mode, su, sv)?;
        for _ in 0..self.sizing.warmup {
            self.renderer.draw(&self.scene.camera)?;
        }
        let (mut shadow, mut gbuf) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..self.sizing.angles.max(1) {
            let stats = self.renderer.draw(&self.scene.camera)?;
            let (gbuffer_position, gbuffer_normal) = self.renderer.read_gbuffer();
            let f = SoftShadowFrame {
                stats,
                gbuffer_position,
                gbuffer_normal,
            };
            shadow.push(
                f.stats
                    .gpu_ms
                    .iter()
                    .filter(|(k, _)| k.starts_with("shadow"))
                    .map(|(_, v)| v)
                    .sum::<f64>()
                    / 1e3,
            );
            gbuf.push(f.stats.gpu_ms.get("gbuffer").copied().unwrap_or(0.0) / 1e3);
            last = Some(f);
        }
        let f = last.expect("one frame");
        let m = meas(
            &shadow,
            f.stats.total_triangle_tests(),
            f.stats
                .events
                .get("linespace_lookups")
                .copied()
                .unwrap_or(0),
        );
        Ok((m, meas(&gbuf, 0, 0), f))
    }

    /// CPU: the shadow values of every pixel of `f`'s G-buffer, one thread.
    pub fn cpu(
        &self,
        f: &SoftShadowFrame,
        mode: ShadowMode,
        su: u32,
        sv: u32,
        frames: u32,
    ) -> Meas {
        let mut cpu = self.renderer.cpu();
        cpu.samples_u = su;
        cpu.samples_v = sv;
        let mut times = Vec::new();
        let mut counts = Default::default();
        for _ in 0..frames.max(1) {
            counts = gpgpu_rt::reference::linespace::ShadowCounts::default();
            let t = Instant::now();
            for (p, n) in f.gbuffer_position.iter().zip(&f.gbuffer_normal) {
                if p[3] > 0.0 {
                    let (_, c) = cpu.shadow(
                        mode,
                        Vec3::new(p[0], p[1], p[2]),
                        Vec3::new(n[0], n[1], n[2]).normalize(),
                    );
                    counts += c;
                }
            }
            times.push(t.elapsed().as_secs_f64());
        }
        meas(&times, counts.triangle_tests, counts.linespace_lookups)
    }

    /// CPU: the primary rays ray cast through the N-tree, one thread.
    pub fn cpu_primary(&self, frames: u32) -> Meas {
        let cpu = self.renderer.cpu();
        let (w, h) = (self.sizing.width, self.sizing.height);
        let rays = self.scene.camera.rays(w, h);
        let mut times = Vec::new();
        let mut counts = gpgpu_rt::reference::linespace::ShadowCounts::default();
        for _ in 0..frames.max(1) {
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
pub struct Row {
    pub scene: String,
    pub variant: String,
    pub device: String,
    pub rays: u32,
    pub m: Meas,
}

fn write_csv(bench: &Bench, name: &str, rows: &[Row], w: u32, h: u32) -> Result<PathBuf> {
    let rel = PathBuf::from(format!("{name}.csv"));
    let path = bench.out.join(&rel);
    let mut wr = csv::Writer::from_path(&path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    wr.write_record([
        "scene",
        "variant",
        "device",
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
    ])?;
    for r in rows {
        wr.write_record([
            r.scene.clone(),
            r.variant.clone(),
            r.device.clone(),
            w.to_string(),
            h.to_string(),
            r.rays.to_string(),
            r.m.frames.to_string(),
            format!("{:.6}", r.m.mean_s),
            format!("{:.6}", r.m.min_s),
            format!("{:.6}", r.m.max_s),
            format!("{:.4}", 1.0 / r.m.mean_s),
            r.m.triangle_tests.to_string(),
            r.m.linespace_lookups.to_string(),
        ])?;
    }
    wr.flush()?;
    Ok(rel)
}

fn header(bench: &Bench, s: Sizing) -> String {
    format!(
        "{}×{} pixels, N-tree N = 10, depth 3, mean over {} frames (after {} warm-up); GPU: {}; CPU: one \
         thread of this machine. Published: NVIDIA GTX 760 / Xeon E3-1230 v3, 512×512. Compare ratios, \
         not seconds.\n\n",
        s.width, s.height, s.angles, s.warmup, bench.machine.gl_renderer
    )
}

fn section(p: &dyn Protocol, markdown: String, files: Vec<PathBuf>) -> Section {
    Section {
        protocol: p.name().into(),
        title: p.title().into(),
        markdown,
        failures: 0,
        files,
    }
}

fn sec(v: f64) -> String {
    num(v)
}

/// `klee-table1`.
pub struct KleeTable1;
impl Protocol for KleeTable1 {
    fn name(&self) -> &'static str {
        "klee-table1"
    }
    fn title(&self) -> &'static str {
        "primary rays: GPU rasterisation vs CPU ray casting (Klee 2016, Table 1)"
    }
    fn run(&self, bench: &mut Bench) -> Result<Section> {
        let s = bench.sizing(QUICK, FULL);
        let mut rows = Vec::new();
        let mut md = header(bench, s);
        let mut table = Vec::new();
        for (scene, label) in [(BUNNY, "bunny"), (DRAGON, "dragon")] {
            let mut st = setup(bench, scene, s)?;
            let (_, gbuf, _) = st.gpu(bench, ShadowMode::Linespace, 2, 2)?;
            let cpu = st.cpu_primary(if s.angles > 2 { 3 } else { 1 });
            for (dev, m) in [("GPU", gbuf), ("CPU", cpu)] {
                let published = TABLE1
                    .iter()
                    .find(|t| t.0 == label && t.1 == dev)
                    .map(|t| t.2)
                    .unwrap();
                table.push(vec![
                    format!("{dev} {label}"),
                    sec(published),
                    sec(m.mean_s),
                ]);
                rows.push(Row {
                    scene: label.into(),
                    variant: "primary".into(),
                    device: dev.into(),
                    rays: 1,
                    m,
                });
            }
            let ours = rows[rows.len() - 1].m.mean_s / rows[rows.len() - 2].m.mean_s;
            let theirs = TABLE1
                .iter()
                .find(|t| t.0 == label && t.1 == "CPU")
                .unwrap()
                .2
                / TABLE1
                    .iter()
                    .find(|t| t.0 == label && t.1 == "GPU")
                    .unwrap()
                    .2;
            table.push(vec![
                format!("CPU / GPU {label}"),
                ratio(Some(theirs)),
                ratio(Some(ours)),
            ]);
        }
        md += &report::table(&["variant", "published (s)", "ours (s)"], &table);
        md += "\nGPU: the G-buffer pass (rasterisation into the FBO). CPU: a hierarchical 3D-DDA through the \
               N-tree testing the leaves' triangles. The thesis' dragon had 871k triangles, ours 202520.\n";
        let f = write_csv(bench, self.name(), &rows, s.width, s.height)?;
        Ok(section(self, md, vec![f]))
    }
}

/// `klee-table2`.
pub struct KleeTable2;
impl Protocol for KleeTable2 {
    fn name(&self) -> &'static str {
        "klee-table2"
    }
    fn title(&self) -> &'static str {
        "triangle tests vs line-space lookups, CPU, bunny, 4 rays (Klee 2016, Table 2)"
    }
    fn run(&self, bench: &mut Bench) -> Result<Section> {
        let s = bench.sizing(QUICK, FULL);
        let mut st = setup(bench, BUNNY, s)?;
        let (_, _, f) = st.gpu(bench, ShadowMode::Linespace, 2, 2)?;
        let frames = if s.angles > 2 { 3 } else { 1 };
        let exact = st.cpu(&f, ShadowMode::Exact, 2, 2, frames);
        let ls = st.cpu(&f, ShadowMode::Linespace, 2, 2, frames);
        let mut md = header(bench, s);
        md += &report::table(
            &[
                "variant",
                "published (s)",
                "ours (s)",
                "triangle tests",
                "line-space lookups",
            ],
            &[
                vec![
                    "CPU triangle tests (`exact`)".into(),
                    sec(TABLE2[0].1),
                    sec(exact.mean_s),
                    report::int(exact.triangle_tests as f64),
                    report::int(exact.linespace_lookups as f64),
                ],
                vec![
                    "CPU line-space lookups (`linespace`)".into(),
                    sec(TABLE2[1].1),
                    sec(ls.mean_s),
                    report::int(ls.triangle_tests as f64),
                    report::int(ls.linespace_lookups as f64),
                ],
                vec![
                    "saving".into(),
                    format!("{:.1} %", 100.0 * (1.0 - TABLE2[1].1 / TABLE2[0].1)),
                    format!("{:.1} %", 100.0 * (1.0 - ls.mean_s / exact.mean_s)),
                    String::new(),
                    String::new(),
                ],
            ],
        );
        md += "\nOur `exact` uses the line spaces to skip empty shafts on the way down (the thesis' \
               variant 1 had no such help, hence its 92.6 % saving); our `linespace` tests the triangles \
               of the leaves near the ray origin exactly (see the README), hence its triangle tests.\n";
        let rows = vec![
            Row {
                scene: "bunny".into(),
                variant: "exact".into(),
                device: "CPU".into(),
                rays: 4,
                m: exact,
            },
            Row {
                scene: "bunny".into(),
                variant: "linespace".into(),
                device: "CPU".into(),
                rays: 4,
                m: ls,
            },
        ];
        let f = write_csv(bench, self.name(), &rows, s.width, s.height)?;
        Ok(section(self, md, vec![f]))
    }
}

/// `klee-table3`.
pub struct KleeTable3;
impl Protocol for KleeTable3 {
    fn name(&self) -> &'static str {
        "klee-table3"
    }
    fn title(&self) -> &'static str {
        "CGT vs DDA on the CPU, bunny, 4/9/16/100 rays (Klee 2016, Table 3)"
    }
    fn run(&self, bench: &mut Bench) -> Result<Section> {
        let s = bench.sizing(QUICK, FULL);
        let mut st = setup(bench, BUNNY, s)?;
        let (_, _, f) = st.gpu(bench, ShadowMode::Linespace, 2, 2)?;
        let frames = if s.angles > 2 { 3 } else { 1 };
        let mut rows = Vec::new();
        let mut table = Vec::new();
        for &(rays, p_cgt, p_dda) in &TABLE3 {
            let k = (rays as f64).sqrt() as u32;
            let cgt = st.cpu(&f, ShadowMode::Linespace, k, k, frames);
            let dda = st.cpu(&f, ShadowMode::LinespaceDda, k, k, frames);
            table.push(vec![
                rays.to_string(),
                sec(p_cgt),
                sec(p_dda),
                ratio(Some(p_cgt / p_dda)),
                sec(cgt.mean_s),
                sec(dda.mean_s),
                ratio(Some(cgt.mean_s / dda.mean_s)),
            ]);
            rows.push(Row {
                scene: "bunny".into(),
                variant: "cgt".into(),
                device: "CPU".into(),
                rays,
                m: cgt,
            });
            rows.push(Row {
                scene: "bunny".into(),
                variant: "dda".into(),
                device: "CPU".into(),
                rays,
                m: dda,
            });
        }
        let mut md = header(bench, s);
        md += &report::table(
            &[
                "rays",
                "published CGT (s)",
                "published DDA (s)",
                "CGT/DDA",
                "ours CGT (s)",
                "ours DDA (s)",
                "CGT/DDA",
            ],
            &table,
        );
        let file = write_csv(bench, self.name(), &rows, s.width, s.height)?;
        Ok(section(self, md, vec![file]))
    }
}

/// `klee-fig12`.
pub struct KleeFig12;
impl Protocol for KleeFig12 {
    fn name(&self) -> &'static str {
        "klee-fig12"
    }
    fn title(&self) -> &'static str {
        "2×2 … 10×10 rays, CPU vs GPU, bunny (Klee 2016, Fig. 12)"
    }
    fn run(&self, bench: &mut Bench) -> Result<Section> {
        let s = bench.sizing(QUICK, FULL);
        let mut st = setup(bench, BUNNY, s)?;
        let frames = if s.angles > 2 { 3 } else { 1 };
        let mut rows = Vec::new();
        let mut table = Vec::new();
        let (mut gpu_pts, mut cpu_pts, mut gpu_fps, mut cpu_fps) = (vec![], vec![], vec![], vec![]);
        for k in 2..=10u32 {
            let (g, _, f) = st.gpu(bench, ShadowMode::Linespace, k, k)?;
            let c = st.cpu(&f, ShadowMode::Linespace, k, k, frames);
            let rays = k * k;
            table.push(vec![
                format!("{k}×{k}"),
                sec(c.mean_s),
                sec(g.mean_s),
                num(1.0 / c.mean_s),
                num(1.0 / g.mean_s),
                format!("{:.0} %", 100.0 * (1.0 - g.mean_s / c.mean_s)),
            ]);
            gpu_pts.push((rays as f64, g.mean_s));
            cpu_pts.push((rays as f64, c.mean_s));
            gpu_fps.push((rays as f64, 1.0 / g.mean_s));
            cpu_fps.push((rays as f64, 1.0 / c.mean_s));
            rows.push(Row {
                scene: "bunny".into(),
                variant: "linespace".into(),
                device: "GPU".into(),
                rays,
                m: g,
            });
            rows.push(Row {
                scene: "bunny".into(),
                variant: "linespace".into(),
                device: "CPU".into(),
                rays,
                m: c,
            });
        }
        let mut md = header(bench, s);
        md += &format!(
            "Published: the GPU takes {:.0} % less time than the CPU at every sample count, never below \
             1 FPS; the CPU needs several seconds beyond 36 rays.\n\n",
            100.0 * FIG12_GPU_SAVING
        );
        md += &report::table(
            &[
                "rays",
                "CPU (s)",
                "GPU (s)",
                "CPU FPS",
                "GPU FPS",
                "GPU saving",
            ],
            &table,
        );
        let plot = PathBuf::from(format!("{}.png", self.name()));
        let charts = [
            Chart {
                title: "Fig. 12(a): FPS".into(),
                x_label: "shadow rays per pixel".into(),
                y_label: "FPS".into(),
                series: vec![
                    Series::new("GPU", gpu_fps, Style::LinePoints, 0),
                    Series::new("CPU", cpu_fps, Style::LinePoints, 1),
                ],
                log_y: true,
                ..Default::default()
            },
            Chart {
                title: "Fig. 12(b): seconds".into(),
                x_label: "shadow rays per pixel".into(),
                y_label: "s".into(),
                series: vec![
                    Series::new("GPU", gpu_pts, Style::LinePoints, 0),
                    Series::new("CPU", cpu_pts.clone(), Style::LinePoints, 1),
                    Series::new(
                        "published ratio × our CPU",
                        cpu_pts
                            .iter()
                            .map(|&(x, y)| (x, y * (1.0 - FIG12_GPU_SAVING)))
                            .collect(),
                        Style::Crosses,
                        BLACK_INDEX,
                    ),
                ],
                log_y: true,
                ..Default::default()
            },
        ];
        plots::save(&bench.out.join(&plot), 640, 420, &charts)?;
        let _ = writeln!(md, "\n{}", report::image(&plot, "Fig. 12"));
        let file = write_csv(bench, self.name(), &rows, s.width, s.height)?;
        Ok(section(self, md, vec![file, plot]))
    }
}

/// `klee-fig13`.
pub struct KleeFig13;
impl Protocol for KleeFig13 {
    fn name(&self) -> &'static str {
        "klee-fig13"
    }
    fn title(&self) -> &'static str {
        "bunny vs dragon on the GPU, 2×2 … 10×10 rays (Klee 2016, Fig. 13)"
    }
    fn run(&self, bench: &mut Bench) -> Result<Section> {
        let s = bench.sizing(QUICK, FULL);
        let mut rows = Vec::new();
        let mut series = Vec::new();
        let mut by_scene = Vec::new();
        for (i, (scene, label)) in [(BUNNY, "bunny"), (DRAGON, "dragon")]
            .into_iter()
            .enumerate()
        {
            let mut st = setup(bench, scene, s)?;
            let mut pts = Vec::new();
            for k in 2..=10u32 {
                let (g, _, _) = st.gpu(bench, ShadowMode::Linespace, k, k)?;
                pts.push((k as f64 * k as f64, g.mean_s));
                rows.push(Row {
                    scene: label.into(),
                    variant: "linespace".into(),
                    device: "GPU".into(),
                    rays: k * k,
                    m: g,
                });
            }
            series.push(Series::new(
                format!("{label} ({} triangles)", st.scene.triangle_count()),
                pts.clone(),
                Style::LinePoints,
                i,
            ));
            by_scene.push(pts);
        }
        let mut table = Vec::new();
        for (&(rays, b), &(_, d)) in by_scene[0].iter().zip(&by_scene[1]) {
            let published = FIG13_DRAGON_EXTRA
                .iter()
                .find(|p| p.0 as f64 == rays)
                .map(|p| format!("+{:.0} %", 100.0 * p.1));
            table.push(vec![
                format!("{rays}"),
                sec(b),
                sec(d),
                format!("{:+.0} %", 100.0 * (d / b - 1.0)),
                published.unwrap_or_else(|| "–".into()),
            ]);
        }
        let mut md = header(bench, s);
        md += &report::table(
            &[
                "rays",
                "bunny GPU (s)",
                "dragon GPU (s)",
                "dragon vs bunny",
                "published",
            ],
            &table,
        );
        md +=
            "\nThe thesis' dragon had 871k triangles, ours 202520 (Stanford's res2 decimation).\n";
        let plot = PathBuf::from(format!("{}.png", self.name()));
        plots::save(
            &bench.out.join(&plot),
            640,
            420,
            &[Chart {
                title: "Fig. 13: shadow time on the GPU".into(),
                x_label: "shadow rays per pixel".into(),
                y_label: "s".into(),
                series,
                ..Default::default()
            }],
        )?;
        let _ = writeln!(md, "\n{}", report::image(&plot, "Fig. 13"));
        let file = write_csv(bench, self.name(), &rows, s.width, s.height)?;
        Ok(section(self, md, vec![file, plot]))
    }
}
