//! The report of `accel-compare` ([`crate::bench::protocols::accel_compare`]): its CSV,
//! tables, figures and the analysis in the sources' terms.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Result;

use super::plots::{Chart, Figure, Series, Style};
use crate::bench::common::format::{int, num, ratio, table};
use crate::bench::runner::args::Scale;
use crate::bench::runner::config::Sizing;
use crate::bench::runner::csv_files::write_rows;
use gpgpu_rt::design::{self, Pipeline};

/// What the comparison compares, as the protocol chose it: the accelerators (the tables'
/// columns), the stadium (where the uniform grid is expected to break), the quick scale's
/// limits, the frames and the scale.
pub struct Plan {
    pub accelerators: &'static [Accelerator],
    pub stadium: &'static str,
    pub quick_base_max_triangles: usize,
    pub quick_wagner_max_triangles: usize,
    pub sizing: Sizing,
    pub scale: Scale,
}

/// An accelerator of the comparison: a point-light design of `design::REGISTRY`, with or
/// without proximity clouds where it takes them, and its name in the tables and figures.
#[derive(Debug, Clone, Copy)]
pub struct Accelerator {
    pub name: &'static str,
    pub row: &'static design::Row,
    pub proximity_clouds: bool,
}

impl Accelerator {
    /// The pipeline it runs in, as the tables name it.
    pub fn pipeline(&self) -> &'static str {
        match self.row.pipeline {
            Pipeline::Mueller2015 => "Müller 2015 (4 kernels)",
            Pipeline::Wagner2018 => "own: Wagner 2018 megakernel",
            Pipeline::Stream => "own: streaming tracer fragment passes",
            Pipeline::Klee2016 => "own: Klee 2016 soft shadows",
        }
    }
}

/// The work of one kind of rays (or of the whole frame) per frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Work {
    pub rays: f64,
    /// Mean GPU milliseconds over the measured frames.
    pub gpu_ms: f64,
    pub tests: f64,
    /// Voxels (grids) or BVH nodes visited.
    pub visits: f64,
}

impl Work {
    pub fn mrays_per_s(&self) -> Option<f64> {
        (self.gpu_ms > 0.0 && self.rays > 0.0).then(|| self.rays / self.gpu_ms / 1e3)
    }
    pub fn tests_per_ray(&self) -> Option<f64> {
        (self.rays > 0.0).then(|| self.tests / self.rays)
    }
    pub fn visits_per_ray(&self) -> Option<f64> {
        (self.rays > 0.0 && self.visits > 0.0).then(|| self.visits / self.rays)
    }
    fn add(&mut self, o: &Work) {
        self.rays += o.rays;
        self.gpu_ms += o.gpu_ms;
        self.tests += o.tests;
        self.visits += o.visits;
    }
}

/// One configuration's measurements.
#[derive(Debug, Clone)]
pub struct Row {
    pub scene: String,
    pub triangles: usize,
    pub lights: usize,
    pub accelerator: &'static Accelerator,
    /// "grid exact 24³", "stream pc 58": the tracer with its resolution.
    pub tracer: String,
    pub build_ms: Option<f64>,
    pub bytes: Option<f64>,
    /// Per kind of ray, [`RAY_KINDS`] order (Müller's pipeline and the stream; zero work in
    /// Wagner's megakernel).
    pub kinds: [Work; 4],
    /// Every ray of the frame over all of the frame's GPU time (builds included).
    pub frame: Work,
    /// Share of the pixels whose first hit agrees with the judge's, and the judge.
    pub agreement: Option<(f64, String)>,
    /// Triangle references and voxel ids the thesis grid's fixed lists could not hold.
    pub lost: u64,
    pub error: Option<String>,
}

impl Row {
    /// Whether the pipeline counted the kinds of ray apart (all but Wagner's megakernel).
    pub fn has_kinds(&self) -> bool {
        self.kinds[0].rays > 0.0
    }

    /// The feelers towards every light: the first light's and the others'.
    pub fn shadow_all(&self) -> Work {
        let mut w = self.kinds[1];
        w.add(&self.kinds[2]);
        w
    }
}

/// The row's work of one kind of ray.
type KindOf = fn(&Row) -> Work;

/// The kinds of the tables: (column title, the row's work of that kind).
const KINDS: [(&str, KindOf); 5] = [
    ("primary", |r| r.kinds[0]),
    ("shadow, 1st light", |r| r.kinds[1]),
    ("shadow, all lights", |r| r.shadow_all()),
    ("reflection", |r| r.kinds[3]),
    ("frame", |r| r.frame),
];

/// `<out>/<protocol>_kinds.csv`: a line per configuration and kind of ray (the own pipelines:
/// the frame only).
pub fn write_csv(out: &Path, protocol: &str, rows: &[Row]) -> Result<PathBuf> {
    let file = PathBuf::from(format!("{protocol}_kinds.csv"));
    let header = [
        "scene",
        "triangles",
        "lights",
        "accelerator",
        "pipeline",
        "tracer",
        "kind",
        "rays",
        "gpu_ms",
        "mrays_per_s",
        "tests_per_ray",
        "visits_per_ray",
        "build_ms",
        "bytes",
        "first_hit_agreement",
        "judge",
    ]
    .map(String::from);
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v}"));
    let mut lines = Vec::new();
    for r in rows.iter().filter(|r| r.error.is_none()) {
        // Wagner's megakernel has only the frame's figures
        let frame_only = !r.has_kinds();
        for (kind, work) in KINDS.into_iter().filter(|k| !frame_only || k.0 == "frame") {
            let w = work(r);
            let (agreement, judge) = match &r.agreement {
                Some((a, j)) => (format!("{a}"), j.clone()),
                None => (String::new(), String::new()),
            };
            lines.push(vec![
                r.scene.clone(),
                r.triangles.to_string(),
                r.lights.to_string(),
                r.accelerator.name.into(),
                r.accelerator.pipeline().into(),
                r.tracer.clone(),
                kind.into(),
                format!("{}", w.rays),
                format!("{}", w.gpu_ms),
                opt(w.mrays_per_s()),
                opt(w.tests_per_ray()),
                opt(w.visits_per_ray()),
                opt(r.build_ms),
                opt(r.bytes),
                agreement,
                judge,
            ]);
        }
    }
    write_rows(&out.join(&file), &header, &lines)?;
    Ok(file)
}

/// The scenes in the order measured, with their triangle counts.
fn scenes(rows: &[Row]) -> Vec<(String, usize)> {
    let mut v: Vec<(String, usize)> = Vec::new();
    for r in rows {
        if !v.iter().any(|(s, _)| *s == r.scene) {
            v.push((r.scene.clone(), r.triangles));
        }
    }
    v
}

/// The row of `scene` and `accelerator`, if it was measured without error.
fn find<'a>(rows: &'a [Row], scene: &str, accelerator: &str) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.scene == scene && r.accelerator.name == accelerator && r.error.is_none())
}

fn opt_num(v: Option<f64>) -> String {
    v.map_or("–".into(), num)
}

pub fn markdown(plan: &Plan, rows: &[Row]) -> String {
    let mut md = intro(plan);
    md += "\n### Frame throughput (Mrays/s: all rays of the frame over all of its GPU time)\n\n";
    md += &throughput_matrix(plan, rows);
    md += "\n### Each kind of ray apart (Müller 2015's pipeline and the stream)\n\n";
    md += &kinds_table(rows);
    md += "\n### Build, memory, work per ray, agreement\n\n";
    md += &configs_table(rows);
    md += "\n### Analysis\n\n";
    md += &analysis(plan, rows);
    md
}

fn intro(plan: &Plan) -> String {
    let (s, scale) = (plan.sizing, plan.scale);
    let skipped = match scale {
        Scale::Quick => format!(
            " At this scale the base tracer runs on scenes of at most {} triangles and Wagner's \
             faithful (recursive) build on at most {} (the CPU reference judges every scene).",
            int(plan.quick_base_max_triangles as f64),
            int(plan.quick_wagner_max_triangles as f64)
        ),
        Scale::Full => String::new(),
    };
    format!(
        "{}, camera and objects fixed, {} frames after {} warm-up, each scene at its own \
         reflection depth. Grids at `--grid auto` (N = ∛(T/5)), the stream's at the paper's \
         ∛T per axis. Mrays/s = rays / GPU ms of the kind's dispatches (GL timer queries); \
         the stream's fragment passes are counted and timed per kind as Müller's kernels are; \
         Wagner's megakernel traces every ray in one dispatch, so it has only the frame's figure. \
         Every pipeline counts the rays it \
         traces; shadow rays are the feelers actually traced (N·L > 0). Wagner's kernel lights \
         with the scene's first light only and traces no reflection (as the thesis), so it \
         traces fewer rays of a scene than the others. Agreement: \
         pixels whose first hit is the judge's triangle, or a hit at the same distance (a shared \
         edge).{skipped}\n",
        s.size(),
        s.angles,
        s.warmup
    )
}

/// Scenes × accelerators: the frame's Mrays/s, the fastest in bold.
fn throughput_matrix(plan: &Plan, rows: &[Row]) -> String {
    let mut header = vec!["scene", "triangles"];
    header.extend(plan.accelerators.iter().map(|a| a.name));
    let lines: Vec<Vec<String>> = scenes(rows)
        .iter()
        .map(|(scene, t)| {
            let values: Vec<Option<f64>> = plan
                .accelerators
                .iter()
                .map(|a| find(rows, scene, a.name).and_then(|r| r.frame.mrays_per_s()))
                .collect();
            let best = values.iter().flatten().cloned().fold(0.0, f64::max);
            let cell = |v: &Option<f64>| match v {
                Some(v) if *v == best => format!("**{}**", num(*v)),
                v => opt_num(*v),
            };
            [scene.clone(), int(*t as f64)]
                .into_iter()
                .chain(values.iter().map(cell))
                .collect()
        })
        .collect();
    table(&header, &lines)
}

/// A line per scene and accelerator that counts the kinds apart (Müller's pipeline and the
/// stream): Mrays/s, tests and visits per ray of each kind.
fn kinds_table(rows: &[Row]) -> String {
    let header = [
        "scene",
        "accelerator",
        "primary Mrays/s",
        "shadow 1st light",
        "shadow all lights",
        "reflection",
        "tests/ray primary",
        "tests/ray shadow",
        "visits/ray primary",
        "visits/ray shadow",
    ];
    let mut lines = Vec::new();
    for r in rows.iter().filter(|r| r.has_kinds()) {
        if r.error.is_some() {
            continue;
        }
        let shadow = r.shadow_all();
        let mut line = vec![r.scene.clone(), r.tracer.clone()];
        line.extend(KINDS[..4].iter().map(|(_, w)| opt_num(w(r).mrays_per_s())));
        line.push(opt_num(r.kinds[0].tests_per_ray()));
        line.push(opt_num(shadow.tests_per_ray()));
        line.push(opt_num(r.kinds[0].visits_per_ray()));
        line.push(opt_num(shadow.visits_per_ray()));
        lines.push(line);
    }
    table(&header, &lines)
}

/// A line per configuration: pipeline, build, memory, work per ray of the frame, agreement.
fn configs_table(rows: &[Row]) -> String {
    let header = [
        "scene",
        "tracer",
        "pipeline",
        "build ms",
        "memory MB",
        "frame Mrays/s",
        "tests/ray",
        "visits/ray",
        "first hits agree %",
        "judge",
    ];
    let lines: Vec<Vec<String>> = rows
        .iter()
        .filter(|r| r.error.is_none())
        .map(|r| {
            let (agree, judge) = match &r.agreement {
                Some((a, j)) => (format!("{:.2}", 100.0 * a), j.clone()),
                None => ("–".into(), "–".into()),
            };
            vec![
                r.scene.clone(),
                r.tracer.clone(),
                r.accelerator.pipeline().into(),
                opt_num(r.build_ms),
                opt_num(r.bytes.map(|b| b / 1e6)),
                opt_num(r.frame.mrays_per_s()),
                opt_num(r.frame.tests_per_ray()),
                opt_num(r.frame.visits_per_ray()),
                agree,
                judge,
            ]
        })
        .collect();
    table(&header, &lines)
}

/// The least-squares slope of log y over log x: 0 where y does not grow with x, 1 where it
/// grows in proportion.
pub fn log_log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if p.len() < 3 {
        return None;
    }
    let n = p.len() as f64;
    let (mx, my) = (
        p.iter().map(|q| q.0).sum::<f64>() / n,
        p.iter().map(|q| q.1).sum::<f64>() / n,
    );
    let sxx: f64 = p.iter().map(|q| (q.0 - mx).powi(2)).sum();
    let sxy: f64 = p.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The geometric mean of `values`.
fn geo_mean(values: &[f64]) -> Option<f64> {
    let v: Vec<f64> = values.iter().copied().filter(|v| *v > 0.0).collect();
    (!v.is_empty()).then(|| (v.iter().map(|x| x.ln()).sum::<f64>() / v.len() as f64).exp())
}

fn median(values: &mut [f64]) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    (!values.is_empty()).then(|| values[values.len() / 2])
}

/// (triangles, primary tests per ray) of an accelerator over the scenes but the stadium.
fn tests_per_primary_ray(plan: &Plan, rows: &[Row], accelerator: &str) -> Vec<(f64, f64)> {
    let r = rows.iter().filter(|r| {
        r.accelerator.name == accelerator && r.error.is_none() && r.scene != stem(plan.stadium)
    });
    let work = |r: &Row| match r.has_kinds() {
        true => r.kinds[0].tests_per_ray(),
        false => r.frame.tests_per_ray(),
    };
    r.filter_map(|r| Some((r.triangles as f64, work(r)?)))
        .collect()
}

fn stem(scene: &str) -> &str {
    scene.strip_suffix(".toml").unwrap_or(scene)
}

/// The findings: who wins where, whether tests per ray stay constant, where the grid breaks,
/// and each accelerator against the SAH BVH (the peer table's yardstick against Embree).
fn analysis(plan: &Plan, rows: &[Row]) -> String {
    wins(rows)
        + &constancy(plan, rows)
        + &stadium(plan, rows)
        + &agreement(rows)
        + &versus_bvh(plan, rows)
}

/// The configurations whose first hits differ from the judge's, with what their lists lost.
fn agreement(rows: &[Row]) -> String {
    let off: Vec<&Row> = rows
        .iter()
        .filter(|r| r.agreement.as_ref().is_some_and(|(a, _)| *a < 0.999))
        .collect();
    let judged = rows.iter().filter(|r| r.agreement.is_some()).count();
    if off.is_empty() {
        return format!(
            "- **First hits**: all {judged} configurations agree with the CPU reference on at \
             least 99.9 % of the pixels.\n"
        );
    }
    let list: Vec<String> = off
        .iter()
        .map(|r| {
            let a = r.agreement.as_ref().map_or(0.0, |a| a.0);
            let why = match (r.lost, r.accelerator.name) {
                (0, "grid thesis") => "nothing lost: the holes of big triangles".to_string(),
                (0, _) => "nothing lost".to_string(),
                (n, _) => format!("{} lost", int(n as f64)),
            };
            format!("{} `{}` {:.1} % ({why})", r.scene, r.tracer, 100.0 * a)
        })
        .collect();
    let thesis_only = off.iter().all(|r| r.accelerator.name == "grid thesis");
    let why = if thesis_only {
        "All are the thesis grid: its fixed lists (Listing 17: 512 triangles per voxel, 3·N \
         voxels per ray) drop what does not fit (lost references or voxel ids), and its build \
         (Algorithm 2) enters a triangle into the voxels its edges cross only, so a triangle \
         larger than a voxel has holes (the floors and the closed box)."
    } else {
        "Besides the thesis grid's lost references and holes, these differ: compare their frames."
    };
    format!(
        "- **First hits**: of {judged} configurations, these agree with the CPU reference on \
         less than 99.9 % of the pixels: {}. {why}\n",
        list.join("; ")
    )
}

/// The fastest accelerator of each scene (frame Mrays/s).
fn wins(rows: &[Row]) -> String {
    let mut wins: BTreeMap<&str, Vec<String>> = BTreeMap::new();
    for (scene, _) in scenes(rows) {
        let best = rows
            .iter()
            .filter(|r| r.scene == scene && r.error.is_none())
            .filter_map(|r| Some((r.accelerator.name, r.frame.mrays_per_s()?)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((name, _)) = best {
            wins.entry(name).or_default().push(scene);
        }
    }
    let mut s = String::from("- **Where each structure wins** (highest frame Mrays/s): ");
    let parts: Vec<String> = wins
        .iter()
        .map(|(a, scenes)| format!("`{a}` on {} ({})", scenes.len(), scenes.join(", ")))
        .collect();
    s += &parts.join("; ");
    s + ".\n"
}

/// Szirmay-Kalos et al. 2002: with a grid of ~T cells the expected tests per ray are O(1).
fn constancy(plan: &Plan, rows: &[Row]) -> String {
    let mut s = String::from(
        "- **Do the tests per ray stay constant?** Szirmay-Kalos et al. (2002) expect O(1) \
         tests and steps per ray for a uniform grid with cells in proportion to the triangles. \
         The log–log slope of primary-ray triangle tests per ray over the triangle count \
         (0: constant, 1: in proportion; every scene but the stadium): ",
    );
    let parts: Vec<String> = plan
        .accelerators
        .iter()
        .filter_map(|a| {
            let p = tests_per_primary_ray(plan, rows, a.name);
            let slope = log_log_slope(&p)?;
            let ys: Vec<f64> = p.iter().map(|q| q.1).collect();
            let lo = ys.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = ys.iter().cloned().fold(0.0, f64::max);
            Some(format!(
                "`{}` {slope:.2} ({} … {} tests)",
                a.name,
                num(lo),
                num(hi)
            ))
        })
        .collect();
    s += &parts.join(", ");
    s + ".\n"
}

/// The stadium against the other scenes, for the grids and the BVH.
fn stadium(plan: &Plan, rows: &[Row]) -> String {
    let scene = stem(plan.stadium);
    let mut s = String::from(
        "- **The teapot in a stadium** (the whole teapot falls into a few of the grid's cells): \
         primary tests per ray there vs the median over the other scenes, and the frame \
         throughput relative to `bvh sah` there vs the median elsewhere: ",
    );
    let bvh = |scene: &str| find(rows, scene, "bvh sah").and_then(|r| r.frame.mrays_per_s());
    let parts: Vec<String> = plan
        .accelerators
        .iter()
        .filter(|a| a.name != "bvh sah")
        .filter_map(|a| {
            let here = find(rows, scene, a.name)?;
            let tests = match here.has_kinds() {
                true => here.kinds[0].tests_per_ray(),
                false => here.frame.tests_per_ray(),
            }?;
            let mut others: Vec<f64> = tests_per_primary_ray(plan, rows, a.name)
                .iter()
                .map(|p| p.1)
                .collect();
            let rel = |r: &Row| Some(r.frame.mrays_per_s()? / bvh(&r.scene)?);
            let mut rel_others: Vec<f64> = rows
                .iter()
                .filter(|r| r.accelerator.name == a.name && r.scene != scene)
                .filter(|r| r.error.is_none())
                .filter_map(rel)
                .collect();
            Some(format!(
                "`{}` {} tests (elsewhere {}), {} of `bvh sah` (elsewhere {})",
                a.name,
                num(tests),
                opt_num(median(&mut others)),
                ratio(rel(here)),
                ratio(median(&mut rel_others)),
            ))
        })
        .collect();
    s += &parts.join("; ");
    s + ".\n"
}

/// Each accelerator's frame throughput relative to the SAH BVH, over the scenes both ran.
fn versus_bvh(plan: &Plan, rows: &[Row]) -> String {
    let mut s = String::from(
        "- **Against the SAH BVH, and so against Embree**: the geometric mean over the scenes of \
         each accelerator's frame Mrays/s divided by `bvh sah`'s on the same scene: ",
    );
    let parts: Vec<String> = plan
        .accelerators
        .iter()
        .map(|a| {
            let ratios: Vec<f64> = rows
                .iter()
                .filter(|r| r.accelerator.name == a.name && r.error.is_none())
                .filter_map(|r| {
                    let b = find(rows, &r.scene, "bvh sah")?.frame.mrays_per_s()?;
                    Some(r.frame.mrays_per_s()? / b)
                })
                .collect();
            format!("`{}` {}", a.name, ratio(geo_mean(&ratios)))
        })
        .collect();
    s += &parts.join(", ");
    s + ". How far each accelerator of Müller's pipeline is from Intel Embree on the very same \
         rays, in one run, is the peer table: `python3 tools/embree_peer.py --tracer bvh` (the \
         BVH issue's, docs/results/embree_peer.md), `--tracer grid-exact`, `grid-exact+pc`, \
         `grid-thesis` or `base` (docs/results/embree_peer_accel.md).\n"
}

/// Points (triangles, y) of an accelerator, sorted by the triangle count.
fn series_points(rows: &[Row], name: &str, y: impl Fn(&Row) -> Option<f64>) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.accelerator.name == name && r.error.is_none())
        .filter_map(|r| Some((r.triangles as f64, y(r)?)))
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    p
}

/// A log–log chart of `y` over the triangle count, a series per accelerator with data.
fn chart(
    plan: &Plan,
    rows: &[Row],
    title: &str,
    y_label: &str,
    y: fn(&Row) -> Option<f64>,
) -> Chart {
    let series = plan
        .accelerators
        .iter()
        .enumerate()
        .map(|(i, a)| Series::new(a.name, series_points(rows, a.name, y), Style::LinePoints, i))
        .filter(|s| !s.points.is_empty())
        .collect();
    Chart::new(title, "triangles", y_label, series)
        .log_x()
        .log_y()
}

pub fn figures(plan: &Plan, rows: &[Row]) -> Vec<Figure> {
    let throughput = chart(plan, rows, "Frame throughput", "Mrays/s", |r| {
        r.frame.mrays_per_s()
    });
    let tests = chart(plan, rows, "Triangle tests per ray", "tests per ray", |r| {
        r.frame.tests_per_ray()
    });
    let build = chart(plan, rows, "Build", "build ms", |r| r.build_ms);
    vec![Figure::new(
        "accel-compare.png",
        "Mrays/s, tests per ray and build time over the triangle count (log–log)",
        (560, 420),
        vec![throughput, tests, build],
    )]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_log_slope_reads_growth() {
        let line = |k: f64| -> Vec<(f64, f64)> {
            [10.0, 100.0, 1e3, 1e4]
                .map(|x: f64| (x, 3.0 * x.powf(k)))
                .to_vec()
        };
        assert!((log_log_slope(&line(1.0)).unwrap() - 1.0).abs() < 1e-9);
        assert!(log_log_slope(&line(0.0)).unwrap().abs() < 1e-9);
        assert!((log_log_slope(&line(0.5)).unwrap() - 0.5).abs() < 1e-9);
        assert_eq!(log_log_slope(&line(1.0)[..2]), None, "too few points");
        assert_eq!(geo_mean(&[2.0, 8.0]), Some(4.0));
    }
}
