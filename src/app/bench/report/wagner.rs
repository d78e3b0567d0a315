//! The report of the Wagner 2018 protocols: what a run measured (its [`Plan`]) and our FPS
//! beside the published ones with the hardware-independent ratios (a CSV and markdown tables),
//! the published tables as typed in, the dragon's BVH build beside the thesis' remark, and
//! figures shaped like Fig. 5.1 and Fig. 5.4.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;

use super::plots::{Chart, Figure, Series, Style};
use crate::bench::common::format::{int, num, ratio, table};
use crate::bench::published::wagner as pw;
use crate::bench::runner::args::Scale;
use crate::bench::runner::config::{BvhVariant, Sizing};
use crate::bench::runner::csv_files::write_rows;
use crate::bench::runner::outcome::Outcome;

/// What a run of a Wagner protocol measures.
pub struct Plan {
    /// Image sizes by pixel count, the reference 320×240 always among them.
    pub sizes: Vec<(u32, u32)>,
    /// The square's levels, ascending, level 1 always among them (A.1 only).
    pub levels: Vec<u32>,
    pub variants: Vec<BvhVariant>,
    /// Measured frames (`angles`) and warm-up frames per configuration.
    pub frames: Sizing,
    pub scale: Scale,
}

/// The size of `o`'s configuration.
pub fn size(o: &Outcome) -> (u32, u32) {
    (o.config.width, o.config.height)
}

/// One measured configuration beside the published numbers.
#[derive(Debug, Clone)]
pub struct RatioRow {
    pub variant: &'static str,
    /// The scene's name: "square", "sphere", "cow".
    pub object: String,
    pub level: Option<u32>,
    pub triangles: usize,
    pub size: (u32, u32),
    /// Ours: FPS (run) = frames / total wall time; its ratio to the reference configuration's.
    pub fps: Option<f64>,
    pub ratio: Option<f64>,
    /// Wagner 2018's FPS of the same configuration, and its ratio to the same reference.
    pub published: Option<f64>,
    pub published_ratio: Option<f64>,
    pub gpu_ms: Option<f64>,
    pub build_ms: Option<f64>,
    pub nodes: Option<f64>,
}

/// The comparison of one protocol: every measured configuration as a [`RatioRow`].
pub struct Ratios {
    /// The denominator of the ratios: "FPS(8)", "FPS(320×240)".
    pub reference: &'static str,
    pub rows: Vec<RatioRow>,
}

impl Ratios {
    /// Write `<protocol>_ratios.csv` into `out`; the file name, relative to `out`.
    pub fn write(&self, out: &Path, protocol: &str) -> Result<PathBuf> {
        let file = PathBuf::from(format!("{protocol}_ratios.csv"));
        let header = [
            "variant",
            "scene",
            "level",
            "triangles",
            "width",
            "height",
            "fps_run",
            "fps_ratio",
            "published_fps",
            "published_ratio",
            "ratio_of",
            "gpu_ms_median",
            "bvh_build_ms",
            "bvh_nodes",
        ];
        let cell = |v: Option<f64>| v.map(|v| format!("{v:.6}")).unwrap_or_default();
        let rows: Vec<Vec<String>> = self
            .rows
            .iter()
            .map(|r| {
                let level = r.level.map(|l| l.to_string()).unwrap_or_default();
                let mut row = vec![r.variant.to_string(), r.object.clone(), level];
                row.extend(
                    [r.triangles, r.size.0 as usize, r.size.1 as usize].map(|v| v.to_string()),
                );
                row.extend([r.fps, r.ratio, r.published, r.published_ratio].map(cell));
                row.push(self.reference.to_string());
                row.extend([r.gpu_ms, r.build_ms, r.nodes].map(cell));
                row
            })
            .collect();
        let header: Vec<String> = header.iter().map(|s| s.to_string()).collect();
        write_rows(&out.join(&file), &header, &rows)?;
        Ok(file)
    }

    /// The rows of `variant`, in measuring order.
    fn of_variant(&self, variant: &str) -> impl Iterator<Item = &RatioRow> {
        let variant = variant.to_string();
        self.rows.iter().filter(move |r| r.variant == variant)
    }

    /// The variants measured, in order.
    fn variants(&self) -> Vec<&'static str> {
        let mut v: Vec<&'static str> = Vec::new();
        for r in &self.rows {
            if !v.contains(&r.variant) {
                v.push(r.variant);
            }
        }
        v
    }
}

/// "640×480".
pub fn size_text((w, h): (u32, u32)) -> String {
    format!("{w}×{h}")
}

fn opt(v: Option<f64>, f: fn(f64) -> String) -> String {
    v.map(f).unwrap_or_else(|| "–".into())
}

/// "**×0.53**".
fn bold_ratio(v: Option<f64>) -> String {
    match v {
        Some(_) => format!("**{}**", ratio(v)),
        None => "–".into(),
    }
}

/// The comparison table: a row per measured configuration, `first` naming it.
fn comparison(r: &Ratios, first: (&str, fn(&RatioRow) -> String)) -> String {
    let ours = format!("ours {} / {}", "FPS", r.reference);
    let theirs = format!("Wagner FPS / {}", r.reference);
    let header = [
        "variant",
        first.0,
        "size",
        "Wagner 2018 FPS (GTX 1060)",
        "ours FPS (run)",
        theirs.as_str(),
        ours.as_str(),
        "ours GPU ms (median)",
        "bvh_build_ms",
        "BVH nodes",
    ];
    let rows: Vec<Vec<String>> = r
        .rows
        .iter()
        .map(|row| {
            vec![
                row.variant.to_string(),
                (first.1)(row),
                size_text(row.size),
                opt(row.published, |v| format!("{v:.2}")),
                opt(row.fps, num),
                bold_ratio(row.published_ratio),
                bold_ratio(row.ratio),
                opt(row.gpu_ms, num),
                opt(row.build_ms, num),
                opt(row.nodes, int),
            ]
        })
        .collect();
    table(&header, &rows)
}

/// "8, 128, 2048 and 32768 triangles (levels 1, 3, 5, 7)".
fn levels_text(levels: &[u32]) -> String {
    let t: Vec<String> = levels
        .iter()
        .map(|&l| int(2.0 * 4f64.powi(l as i32)))
        .collect();
    let l: Vec<String> = levels.iter().map(u32::to_string).collect();
    format!("{} triangles (levels {})", t.join(", "), l.join(", "))
}

fn sizes_text(sizes: &[(u32, u32)]) -> String {
    let s: Vec<String> = sizes.iter().map(|&s| size_text(s)).collect();
    s.join(", ")
}

/// What the thesis did and what this run did.
fn setup(plan: &Plan, what: &str) -> String {
    let v: Vec<&str> = plan.variants.iter().map(|v| v.name()).collect();
    format!(
        "Setup (thesis, ch. 5): {}; the object in the centre of the scene, exactly one light lighting it \
         from above, only hard shadows (no reflection or refraction), the camera not moved while the FPS \
         were taken; average FPS. Ours: {what} at {}; {} measured frame(s) after {} warm-up frame(s) per \
         configuration, camera and objects fixed (the BVH is built once, before the measured frames: \
         `bvh_build_ms` is that build, not part of the FPS); REFL_DEPTH 0, one point light, `--tracer bvh`, \
         variant(s) {} — `sah` is ours, an accelerator of Müller 2015's four-kernel pipeline, \
         `wagner` the thesis' own design: Listings 4.3/4.4, the three textures of Fig. 4.3 and one \
         kernel per pixel.\n\n",
        pw::GPU,
        sizes_text(&plan.sizes),
        plan.frames.angles,
        plan.frames.warmup,
        v.join(", ")
    )
}

/// The thesis' findings as a list.
fn findings(list: &[&str]) -> String {
    let mut s = String::from("\nThe thesis' findings (to hold against the ratios above):\n\n");
    for f in list {
        let _ = writeln!(s, "- {f}");
    }
    s
}

/// wagner-a1's markdown: setup, the comparison, Table A.1 as published, the findings.
pub fn a1_markdown(plan: &Plan, r: &Ratios) -> String {
    let what = format!(
        "`scenes/square.toml` (a square of side 2 in the xz plane, 2×2 quads at level 1, each level \
         subdividing every quad into four) with {}",
        levels_text(&plan.levels)
    );
    setup(plan, &what)
        + &comparison(r, ("triangles", |row| int(row.triangles as f64)))
        + "\nBold columns are the hardware-independent comparison: FPS of n triangles over FPS of 8 at the \
           same size. Absolute FPS compare a GTX 1060 with this machine and say little.\n\n"
        + &published_a1()
        + &findings(&pw::FINDINGS_A1)
}

/// Table A.1 as published, each cell with its ratio to the 8-triangle square.
fn published_a1() -> String {
    let mut header = vec!["triangles".to_string()];
    header.extend(pw::SIZES.iter().map(|&s| size_text(s)));
    let rows: Vec<Vec<String>> = pw::TABLE_A1
        .iter()
        .map(|(t, fps)| {
            let mut row = vec![int(*t as f64)];
            row.extend(fps.iter().zip(pw::TABLE_A1[0].1).map(|(f, f8)| match f {
                Some(f) => format!("{f:.2} ({})", ratio(Some(f / f8.unwrap_or(f64::NAN)))),
                None => "–".into(),
            }));
            row
        })
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    format!(
        "Wagner 2018, Table A.1 as published: average FPS (and FPS / FPS(8)):\n\n{}",
        table(&header, &rows)
    )
}

/// wagner-a2's markdown: setup, the comparison, cow / sphere, Tables A.2 and 5.1 as
/// published, the dragon's build, the findings.
pub fn a2_markdown(
    plan: &Plan,
    r: &Ratios,
    dragon: (usize, usize),
    dragon_outcomes: &[&Outcome],
) -> String {
    let what = format!(
        "`scenes/sphere.toml` (blue, {} triangles: 16 stacks × 24 slices) and `scenes/cow.toml` (purple, \
         {} triangles)",
        pw::SPHERE_TRIANGLES,
        pw::COW_TRIANGLES
    );
    setup(plan, &what)
        + &comparison(r, ("object", |row| row.object.clone()))
        + "\nBold columns are the hardware-independent comparison: FPS at a size over FPS at 320×240, per \
           object.\n\n"
        + &cow_over_sphere(r)
        + &published_a2()
        + &dragon_build(dragon, dragon_outcomes)
        + &findings(&pw::FINDINGS_A2)
}

/// Cow FPS / sphere FPS per size and variant, beside the thesis'.
fn cow_over_sphere(r: &Ratios) -> String {
    let mut header = vec!["size".to_string(), "Wagner 2018 cow / sphere".to_string()];
    let variants = r.variants();
    header.extend(variants.iter().map(|v| format!("ours ({v}) cow / sphere")));
    let sizes = sizes_of(r);
    let fps = |v: &str, object: &str, size| {
        let row = r
            .of_variant(v)
            .find(|x| x.object == object && x.size == size);
        row.and_then(|x| x.fps)
    };
    let rows: Vec<Vec<String>> = sizes
        .iter()
        .map(|&s| {
            let theirs = pw::a2_fps("cow", s).and_then(|c| Some(c / pw::a2_fps("sphere", s)?));
            let mut row = vec![size_text(s), bold_ratio(theirs)];
            row.extend(variants.iter().map(|v| {
                let ours = fps(v, "cow", s).and_then(|c| Some(c / fps(v, "sphere", s)?));
                bold_ratio(ours)
            }));
            row
        })
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    format!(
        "The cost of the cow's 5804 triangles against the sphere's 720, per size:\n\n{}\n",
        table(&header, &rows)
    )
}

/// Tables A.2 and 5.1 as published.
fn published_a2() -> String {
    let rows: Vec<Vec<String>> = pw::TABLE_A2
        .iter()
        .map(|&(s, pixels, sphere, cow)| {
            let t51 = pw::TABLE_5_1.iter().find(|t| t.size == s);
            let t51 = t51.map_or("–".into(), |t| {
                let [sf, sc, cf, cc] = [t.sphere[0], t.sphere[1], t.cow[0], t.cow[1]];
                format!("{sf} ({sc}) / {cf} ({cc})")
            });
            let (s0, c0) = (pw::TABLE_A2[0].2, pw::TABLE_A2[0].3);
            vec![
                size_text(s),
                int(pixels as f64),
                format!("{sphere:.2} ({})", ratio(Some(sphere / s0))),
                format!("{cow:.2} ({})", ratio(Some(cow / c0))),
                t51,
            ]
        })
        .collect();
    let header = [
        "size",
        "pixels",
        "sphere FPS (/ 320×240)",
        "cow FPS (/ 320×240)",
        "Table 5.1: sphere FPS (Kamera) / cow FPS (Kamera)",
    ];
    format!(
        "Wagner 2018, Table A.2 as published, with Table 5.1 beside it. Table 5.1's whole numbers are not \
         Table A.2's rounded (18 vs 20.12, 6 vs 7.17, 2 vs 3.39 for the sphere): presumably other runs, the \
         thesis does not say; nor what its \"Kamera\" values measure (it tested how usable the interactive \
         camera was: below 10 FPS it can hardly be steered smoothly).\n\n{}\n",
        table(&header, &rows)
    )
}

/// The dragon's BVH build beside the thesis' remark.
fn dragon_build((scene, mesh): (usize, usize), outcomes: &[&Outcome]) -> String {
    let mut s = format!(
        "### BVH build of a large mesh\n\n`scenes/dragon.toml`: {} triangles (Stanford's dragon, {} \
         triangles, on a floor of 8,192), rendered at 320×240 once its BVH is built. Wagner 2018: {}.\n\n",
        int(scene as f64),
        int(mesh as f64),
        pw::BUILD_REMARK
    );
    let rows: Vec<Vec<String>> = outcomes
        .iter()
        .map(|o| {
            let fact = |k| opt(o.fact(k), int);
            vec![
                o.config.tracer.variant_label().unwrap_or("").to_string(),
                opt(o.fact("bvh_build_ms"), num),
                fact("bvh_nodes"),
                fact("bvh_depth"),
                fact("bvh_bytes"),
                opt(o.ok().then(|| o.mean_fps()).flatten(), num),
                o.error.clone().unwrap_or_else(|| "–".into()),
            ]
        })
        .collect();
    let header = [
        "variant",
        "bvh_build_ms (transform, build, upload)",
        "nodes",
        "depth",
        "bytes",
        "FPS (run)",
        "error",
    ];
    s.push_str(&table(&header, &rows));
    s.push_str("\nWagner 2018's build of over 100k triangles: about 300,000 ms, and no upload.\n");
    s
}

/// The palette index of a size: its column in the thesis' tables, other sizes after them.
fn size_color(s: (u32, u32)) -> usize {
    pw::size_index(s).unwrap_or(5)
}

/// Our series' style per variant: ours `sah` solid, `wagner` dashed.
fn variant_style(v: &str) -> Style {
    if v == "wagner" {
        Style::Dashed
    } else {
        Style::LinePoints
    }
}

/// Fig. 5.1's x range: "0 … 3,584" triangles (it shows 8 … 2048).
const FIG_5_1_X_MAX: f64 = 3584.0;

/// Fig. 5.1 (ours): the thesis' FPS by triangles, ours, and the ratios FPS(n)/FPS(8) over all
/// levels, ours beside the thesis'.
pub fn a1_figures(r: &Ratios) -> Vec<Figure> {
    let published: Vec<Series> = pw::FIG_5_1_SIZES
        .iter()
        .map(|&s| {
            let points = pw::TABLE_A1
                .iter()
                .filter(|t| (t.0 as f64) <= FIG_5_1_X_MAX);
            let points = points.filter_map(|t| Some((t.0 as f64, pw::a1_fps(t.0 as usize, s)?)));
            Series::new(
                size_text(s),
                points.collect(),
                Style::LinePoints,
                size_color(s),
            )
        })
        .collect();
    let ours = curves(r, |row| {
        let t = row.triangles as f64;
        (t <= FIG_5_1_X_MAX).then_some((t, row.fps?))
    });
    let level = |row: &RatioRow| row.level.unwrap_or(0) as f64;
    let mut ratios = curves(r, |row| Some((level(row), row.ratio?)));
    ratios.extend(published_points(r, |row| {
        Some((level(row), row.published_ratio?))
    }));
    let (x, y) = ("triangles", "average FPS");
    let charts = vec![
        Chart::new("Fig. 5.1: Wagner 2018 (GTX 1060)", x, y, published).x_range(0.0, FIG_5_1_X_MAX),
        Chart::new("Fig. 5.1 (ours)", x, y, ours).x_range(0.0, FIG_5_1_X_MAX),
        Chart::new(
            "FPS(n) / FPS(8): ours (lines), Wagner 2018 (crosses)",
            "subdivision level (2·4^level triangles: 1 = 8 … 7 = 32768)",
            "FPS / FPS(8 triangles)",
            ratios,
        ),
    ];
    vec![Figure::new(
        "fig5_1_triangles_fps.png",
        "Fig. 5.1 (ours): FPS by triangle count",
        (560, 440),
        charts,
    )]
}

/// Fig. 5.4 (ours): FPS by pixels for the sphere and the cow, the thesis' and ours, and the
/// ratios FPS/FPS(320×240).
pub fn a2_figures(r: &Ratios) -> Vec<Figure> {
    let published: Vec<Series> = [("sphere", "Sphere"), ("cow", "Kuh")]
        .iter()
        .map(|&(o, label)| {
            let points = pw::TABLE_A2
                .iter()
                .map(|t| (t.1 as f64, pw::a2_fps(o, t.0).unwrap_or(0.0)));
            Series::new(label, points.collect(), Style::LinePoints, object_color(o))
        })
        .collect();
    let mut ratios = object_curves(r, |row| row.ratio);
    for o in ["sphere", "cow"] {
        let first = r.variants()[0];
        let rows = r
            .rows
            .iter()
            .filter(|row| row.object == o && row.variant == first);
        let points = rows.filter_map(|row| Some((pixels(row), row.published_ratio?)));
        let name = format!("Wagner {o}");
        ratios.push(Series::new(
            name,
            points.collect(),
            Style::Crosses,
            object_color(o),
        ));
    }
    let (x, y) = ("resolution (width × height, pixels)", "average FPS");
    let charts = vec![
        Chart::new("Fig. 5.4: Wagner 2018 (GTX 1060)", x, y, published).x_range(0.0, 2e6),
        Chart::new("Fig. 5.4 (ours)", x, y, object_curves(r, |row| row.fps)),
        Chart::new(
            "FPS / FPS(320×240): ours (lines), Wagner 2018 (crosses)",
            x,
            "FPS / FPS(320×240)",
            ratios,
        ),
    ];
    vec![Figure::new(
        "fig5_4_resolution_fps.png",
        "Fig. 5.4 (ours): FPS by resolution, sphere and cow",
        (560, 440),
        charts,
    )]
}

/// The palette index of an object of Fig. 5.4: the sphere blue, the cow purple.
fn object_color(object: &str) -> usize {
    if object == "cow" {
        4
    } else {
        0
    }
}

/// The pixels of a row's image.
fn pixels(row: &RatioRow) -> f64 {
    row.size.0 as f64 * row.size.1 as f64
}

/// Our curves of the sphere and the cow by pixels: per variant and object, `f` of each size.
fn object_curves(r: &Ratios, f: fn(&RatioRow) -> Option<f64>) -> Vec<Series> {
    let mut v = Vec::new();
    for variant in r.variants() {
        for o in ["sphere", "cow"] {
            let rows = r.of_variant(variant).filter(|row| row.object == o);
            let points = rows.filter_map(|row| Some((pixels(row), f(row)?)));
            let style = variant_style(variant);
            let name = format!("{variant} {o}");
            v.push(Series::new(name, points.collect(), style, object_color(o)));
        }
    }
    v
}

/// Our curves of the square: per variant and size, the points `f` gives.
fn curves(r: &Ratios, f: impl Fn(&RatioRow) -> Option<(f64, f64)>) -> Vec<Series> {
    let mut v = Vec::new();
    for variant in r.variants() {
        for s in sizes_of(r) {
            let rows = r.of_variant(variant).filter(|row| row.size == s);
            let points: Vec<(f64, f64)> = rows.filter_map(&f).collect();
            let name = format!("{variant} {}", size_text(s));
            v.push(Series::new(
                name,
                points,
                variant_style(variant),
                size_color(s),
            ));
        }
    }
    v
}

/// The published points of the square per size (crosses), from the first variant's rows.
fn published_points(r: &Ratios, f: impl Fn(&RatioRow) -> Option<(f64, f64)>) -> Vec<Series> {
    let first = r.variants().first().copied().unwrap_or("");
    sizes_of(r)
        .into_iter()
        .filter(|&s| pw::size_index(s).is_some())
        .map(|s| {
            let rows = r.of_variant(first).filter(|row| row.size == s);
            let name = format!("Wagner {}", size_text(s));
            Series::new(
                name,
                rows.filter_map(&f).collect(),
                Style::Crosses,
                size_color(s),
            )
        })
        .collect()
}

/// The sizes measured, in order.
fn sizes_of(r: &Ratios) -> Vec<(u32, u32)> {
    let mut v: Vec<(u32, u32)> = Vec::new();
    for row in &r.rows {
        if !v.contains(&row.size) {
            v.push(row.size);
        }
    }
    v
}
