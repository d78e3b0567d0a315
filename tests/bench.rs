//! `gpgpu-rt bench`: tiny protocol runs (16×16 pixels, two angles) on Mesa llvmpipe whose CSVs,
//! plots and report must be written and agree with each other and with what the tracers must
//! count.

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

mod common;
use common::stderr;

const BIN: &str = env!("CARGO_BIN_EXE_gpgpu-rt");

fn bench(args: &[&str]) -> Output {
    Command::new(BIN)
        .arg("bench")
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run gpgpu-rt")
}

/// `gpgpu-rt bench ARGS --quiet --out OUT`.
fn bench_into(out: &Path, args: &[&str]) -> Output {
    bench(&[args, &["--quiet", "--out", out.to_str().unwrap()]].concat())
}

/// The smallest frame run: 8×8 pixels, one angle, no warm-up.
const TINY: [&str; 8] = [
    "--width", "8", "--height", "8", "--angles", "1", "--warmup", "0",
];

fn has_grid() -> bool {
    gpgpu_rt::design::row("grid-exact").is_ok()
}

/// A CSV as rows of column → value.
fn read_csv(path: &Path) -> Vec<HashMap<String, String>> {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            header
                .iter()
                .cloned()
                .zip(rec.iter().map(String::from))
                .collect()
        })
        .collect()
}

fn f(row: &HashMap<String, String>, col: &str) -> f64 {
    row.get(col)
        .unwrap_or_else(|| panic!("no column {col}"))
        .parse()
        .unwrap_or_else(|_| panic!("{col} = {:?} is not a number", row[col]))
}

fn u(row: &HashMap<String, String>, col: &str) -> u64 {
    row.get(col)
        .unwrap_or_else(|| panic!("no column {col}"))
        .parse()
        .unwrap_or_else(|_| panic!("{col} = {:?} is not an integer", row[col]))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Every summary row's statistics agree with its frames: min ≤ median ≤ max, and the median,
/// min and max of the per-frame CSV's columns.
fn check_summary_against_frames(
    frames: &[HashMap<String, String>],
    summary: &[HashMap<String, String>],
) {
    let key = |r: &HashMap<String, String>| {
        [
            "scene",
            "level",
            "tracer",
            "variant",
            "grid_resolution",
            "width",
            "height",
        ]
        .map(|k| r[k].clone())
        .join("/")
    };
    for s in summary.iter().filter(|s| s["error"].is_empty()) {
        let mine: Vec<_> = frames.iter().filter(|r| key(r) == key(s)).collect();
        assert_eq!(mine.len() as u64, u(s, "frames"), "{}", key(s));
        for (frame_col, stat) in [
            ("fps", "fps"),
            ("wall_ms", "wall_ms"),
            ("triangle_tests", "triangle_tests"),
        ] {
            let (lo, med, hi) = (
                f(s, &format!("{stat}_min")),
                f(s, &format!("{stat}_median")),
                f(s, &format!("{stat}_max")),
            );
            assert!(
                lo <= med && med <= hi,
                "{}: {stat} min {lo} median {med} max {hi}",
                key(s)
            );
            let v: Vec<f64> = mine.iter().map(|r| f(r, frame_col)).collect();
            let tol = |x: f64| 1e-3 * x.abs().max(1.0);
            assert!(
                (median(v.clone()) - med).abs() <= tol(med),
                "{}: {stat} median",
                key(s)
            );
            let vmin = v.iter().cloned().fold(f64::INFINITY, f64::min);
            let vmax = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            assert!(
                (vmin - lo).abs() <= tol(lo) && (vmax - hi).abs() <= tol(hi),
                "{}: {stat} min/max",
                key(s)
            );
        }
    }
}

/// Every file the report links exists; every PNG decodes and is not a blank image.
fn check_report_links(out: &Path, report: &str) {
    let mut links = 0;
    for part in report.split("](").skip(1) {
        let target = &part[..part.find(')').expect("closed link")];
        let p = out.join(target);
        assert!(p.is_file(), "report links {target}, which is missing");
        if target.ends_with(".png") {
            let img = image::open(&p)
                .unwrap_or_else(|e| panic!("{target}: {e}"))
                .to_rgb8();
            let first = *img.get_pixel(0, 0);
            assert!(img.pixels().any(|p| *p != first), "{target} is one colour");
        }
        links += 1;
    }
    assert!(links >= 4, "only {links} links in the report");
}

#[test]
fn thesis_5_1_tiny_writes_consistent_csv_plots_and_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b51");
    let o = bench_into(
        &out,
        &[
            "thesis-5.1",
            "--width",
            "16",
            "--height",
            "16",
            "--angles",
            "2",
            "--warmup",
            "1",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));

    let all = read_csv(&out.join("thesis-5.1.csv"));
    assert_eq!(
        all.len(),
        3 * 3 * 2,
        "base and the BVH's two structures, three scenes, two angles each"
    );
    let (frames, bvh): (Vec<_>, Vec<_>) = all.iter().cloned().partition(|r| r["tracer"] == "base");
    let triangles: HashMap<&str, u64> =
        [("teapot1", 14592), ("teapot3", 27392), ("teapot6", 46592)].into();
    // the SAH BVH beside the base tracer (issue 34), one tree and instances: the same scenes
    // and frames, fewer tests; with the objects turned on the second angle the one tree is
    // refitted, the instances' table rewritten, neither rebuilt
    assert_eq!(bvh.len(), 2 * 3 * 2);
    for r in &bvh {
        assert_eq!(r["tracer"], "bvh");
        assert_eq!(u(r, "triangles"), triangles[r["scene"].as_str()]);
        assert!(u(r, "triangle_tests") < 16 * 16 * u(r, "triangles"));
        let turned = r["angle_deg"] == "180";
        match r["variant"].as_str() {
            "sah" => {
                assert_eq!(r["fact_bvh_instances"], "", "{r:?}");
                assert_eq!(
                    r["fact_bvh_refits"],
                    if turned { "1" } else { "0" },
                    "{r:?}"
                );
            }
            "sah-instances" => {
                // a teapot scene's objects: the teapots and the floor
                let objects: HashMap<&str, u64> =
                    [("teapot1", 2), ("teapot3", 4), ("teapot6", 7)].into();
                let n = objects[r["scene"].as_str()];
                assert_eq!(u(r, "fact_bvh_instances"), n, "{r:?}");
                assert_eq!(f(r, "fact_bvh_instances_ms") > 0.0, turned, "{r:?}");
                assert_eq!(r["fact_bvh_refits"], "0", "{r:?}");
            }
            v => panic!("variant {v}"),
        }
        // built in the warm-up frame
        assert_eq!(r["fact_bvh_rebuilt"], "false", "{r:?}");
    }
    for r in &frames {
        let t = triangles[r["scene"].as_str()];
        assert_eq!(u(r, "triangles"), t);
        assert_eq!(r["tracer"], "base");
        assert_eq!(
            (u(r, "width"), u(r, "height"), u(r, "refl_depth")),
            (16, 16, 1)
        );
        assert!(
            ["0", "180"].contains(&r["angle_deg"].as_str()),
            "{}",
            r["angle_deg"]
        );
        // the total is the sum over the kernels
        let (i1, i2) = (u(r, "tests_intersect1"), u(r, "tests_intersect2"));
        assert_eq!(u(r, "triangle_tests"), i1 + i2);
        // the primary pass tests every triangle for every pixel; the one reflection pass at
        // most as many again; a pass has at most one shadow feeler per pixel
        let pass = 16 * 16 * t;
        assert!(
            i1 >= pass && i1 <= 2 * pass,
            "{}: intersect1 {i1} vs W·H·T {pass}",
            r["scene"]
        );
        assert!(i2 <= 2 * pass);
        let (wall, fps) = (f(r, "wall_ms"), f(r, "fps"));
        assert!(
            wall > 0.0 && (fps * wall / 1e3 - 1.0).abs() < 1e-3,
            "fps {fps} wall {wall}"
        );
        assert!(f(r, "gpu_ms_total") > 0.0);
    }
    // more triangles, more tests: the brute-force tracer's work grows with the scene
    let tests_of = |s: &str| {
        frames
            .iter()
            .filter(|r| r["scene"] == s)
            .map(|r| u(r, "triangle_tests"))
            .max()
            .unwrap()
    };
    assert!(tests_of("teapot1") < tests_of("teapot3") && tests_of("teapot3") < tests_of("teapot6"));

    let summary = read_csv(&out.join("thesis-5.1_summary.csv"));
    assert_eq!(summary.len(), 3 * 3);
    check_summary_against_frames(&all, &summary);

    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for needle in [
        "## Machine",
        "GL renderer",
        "CPU",
        "GTX 780",
        "Fig. 19",
        "Fig. 20",
        "14,592 / 14,592",
        "The SAH BVH beside them",
        "refit ms, GPU",
        "instance table ms, CPU",
        "| teapot6 | instances |",
        "16×16",
        "512×512",
    ] {
        assert!(report.contains(needle), "report.md lacks {needle:?}");
    }
    check_report_links(&out, &report);
    for png in ["fig19_fps.png", "fig20_tests.png"] {
        let img = image::open(out.join(png)).unwrap();
        assert_eq!((img.width(), img.height()), (900, 480), "{png}");
    }
}

#[test]
fn thesis_5_3_tiny_base_tests_every_triangle_per_pixel_and_grid_cuts_tests() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b53");
    let o = bench_into(
        &out,
        &[
            "thesis-5.3",
            "--width",
            "16",
            "--height",
            "12",
            "--angles",
            "2",
            "--warmup",
            "0",
            "--grid-res",
            "8,24",
        ],
    );
    let err = stderr(&o);
    let frames = read_csv(&out.join("thesis-5.3.csv"));
    let summary = read_csv(&out.join("thesis-5.3_summary.csv"));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    // bunny base + 2 variants × 2 resolutions; dragon 2 variants × 28³; the BVH's two
    // structures on both
    assert_eq!(summary.len(), 1 + 4 + 2 + 2 * 2, "{err}");

    // no reflection on the bunny: intersect1 is exactly W·H·T, intersect2 at most that
    let base: Vec<_> = frames
        .iter()
        .filter(|r| r["scene"] == "bunny" && r["tracer"] == "base")
        .collect();
    assert_eq!(base.len(), 2, "{err}");
    for r in &base {
        assert_eq!(u(r, "triangles"), 69451);
        assert_eq!(u(r, "refl_depth"), 0);
        assert_eq!(u(r, "tests_intersect1"), 16 * 12 * 69451);
        assert!(u(r, "tests_intersect2") <= 16 * 12 * 69451);
    }
    check_summary_against_frames(&frames, &summary);
    for needle in [
        "0.8804",
        "4.8339",
        "1,137,720,816",
        "287,728,727.1",
        "1.396",
        "204,088",
        "Fig. 23",
        "Fig. 24",
        "16×12",
    ] {
        assert!(report.contains(needle), "report.md lacks {needle:?}");
    }
    check_report_links(&out, &report);

    if has_grid() {
        assert!(o.status.success(), "{err}");
        let base_tests = base.iter().map(|r| u(r, "triangle_tests")).sum::<u64>();
        for res in ["8", "24"] {
            for variant in ["thesis", "exact"] {
                let g: Vec<_> = frames
                    .iter()
                    .filter(|r| {
                        r["scene"] == "bunny"
                            && r["variant"] == variant
                            && r["grid_resolution"] == res
                    })
                    .collect();
                assert_eq!(g.len(), 2, "bunny grid {variant} {res}");
                let tests = g.iter().map(|r| u(r, "triangle_tests")).sum::<u64>();
                assert!(
                    tests < base_tests,
                    "grid {variant} {res}³: {tests} tests vs base {base_tests}"
                );
                assert!(
                    g.iter().all(|r| !r["voxels_visited"].is_empty()),
                    "voxels_visited missing"
                );
            }
        }
        let dragon: Vec<_> = frames
            .iter()
            .filter(|r| r["scene"] == "dragon" && r["tracer"] == "grid")
            .collect();
        assert_eq!(dragon.len(), 2 * 2);
        assert!(dragon
            .iter()
            .all(|r| u(r, "triangles") == 202520 + 2 * 64 * 64 && r["grid_resolution"] == "28"));
        assert!(
            report.contains("202,520 (1,568 fewer; 210,712 with the floor)"),
            "dragon triangle difference"
        );
    } else {
        // without the grid tracer the grid configurations fail, visibly, and so does the run
        assert!(!o.status.success());
        assert!(err.contains("configuration(s) failed"), "{err}");
        assert!(
            report.contains("no grid tracer"),
            "the report names the failures"
        );
        assert_eq!(summary.iter().filter(|s| !s["error"].is_empty()).count(), 6);
    }
}

#[test]
fn bad_bench_options_fail_with_a_message() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let below_file = file.join("out");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![], "PROTOCOL"),
        // checked before the GPU is opened: --out is made when missing, below a folder only
        (
            vec!["thesis-5.1", "--out", below_file.to_str().unwrap()],
            "a-file is not a folder",
        ),
        (vec!["thesis-9"], "thesis-5.1"),
        (vec!["thesis-5.1", "--scale", "huge"], "quick"),
        (
            vec!["thesis-5.1", "--out", file.to_str().unwrap()],
            "not a folder",
        ),
        (vec!["thesis-5.1", "--angles", "0"], "--angles"),
        (vec!["thesis-5.1", "--width", "0"], "--width"),
        (vec!["thesis-5.2", "--grid-res", "8,0"], "--grid-res"),
        (vec!["thesis-5.2", "--grid-res", "8,x"], "invalid value"),
        (vec!["thesis-5.1", "--tile", "12"], "multiple of 8"),
        (vec!["wagner-a1", "--levels", "0"], "--levels"),
        (vec!["wagner-a1", "--levels", "13"], "1 to 12"),
        (vec!["wagner-a1", "--sizes", "640"], "not an image size"),
        (vec!["wagner-a1", "--sizes", "0x480"], "not an image size"),
        (vec!["wagner-a1", "--bvh-variants", "kd"], "sah"),
        (
            vec!["thesis-5.1", "--scenes", "/nonexistent-scenes"],
            "not a folder",
        ),
    ];
    for (args, needle) in cases {
        let o = bench(&args);
        let err = stderr(&o);
        assert!(!o.status.success(), "bench {args:?} succeeded");
        assert!(
            err.contains(needle),
            "bench {args:?}: {err:?} lacks {needle:?}"
        );
        assert!(!err.contains("panicked"), "bench {args:?} panicked: {err}");
    }
}

#[test]
fn missing_scene_fails_the_protocol_and_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = dir.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    let out = dir.path().join("out");
    let o = bench_into(&out, &["thesis-5.1", "--scenes", scenes.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(err.contains("teapot1.toml"), "{err}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("The protocol failed") && report.contains("teapot1.toml"),
        "{report}"
    );
}

/// A CSV's rows whose `col` is `value`.
fn rows_with<'a>(
    rows: &'a [HashMap<String, String>],
    col: &str,
    value: &str,
) -> Vec<&'a HashMap<String, String>> {
    rows.iter().filter(|r| r[col] == value).collect()
}

/// The ratio CSV of a Wagner protocol agrees with its summary: the same FPS (run) per
/// configuration, and the ratio column is that FPS over the reference configuration's, which
/// `reference` picks among the rows.
fn check_ratios(
    ratios: &[HashMap<String, String>],
    summary: &[HashMap<String, String>],
    reference: impl Fn(&HashMap<String, String>, &HashMap<String, String>) -> bool,
) {
    let at = |r: &HashMap<String, String>| {
        ["scene", "variant", "level", "width", "height"].map(|k| r[k].clone())
    };
    for r in ratios {
        let s: Vec<_> = summary.iter().filter(|s| at(s) == at(r)).collect();
        assert_eq!(s.len(), 1, "{:?}", at(r));
        let fps = f(r, "fps_run");
        assert!(
            (fps - f(s[0], "fps_run")).abs() <= 1e-4 * fps,
            "{:?}: fps_run",
            at(r)
        );
        let refs: Vec<_> = ratios.iter().filter(|q| reference(r, q)).collect();
        assert_eq!(refs.len(), 1, "{:?}: one reference", at(r));
        let want = fps / f(refs[0], "fps_run");
        let got = f(r, "fps_ratio");
        assert!(
            (got - want).abs() <= 1e-5 * want,
            "{:?}: ratio {got} vs {want}",
            at(r)
        );
        // the published ratio is the published FPS over the published reference's
        if let (Ok(p), Ok(p_ref)) = (
            r["published_fps"].parse::<f64>(),
            refs[0]["published_fps"].parse::<f64>(),
        ) {
            let pr = f(r, "published_ratio");
            assert!(
                (pr - p / p_ref).abs() < 1e-5,
                "{:?}: published ratio",
                at(r)
            );
        }
    }
}

/// The published FPS of the ratio row at `scene`, `level`, `width`×`height` ("" if none).
fn published(
    ratios: &[HashMap<String, String>],
    scene: &str,
    level: &str,
    w: u32,
    h: u32,
) -> String {
    let row = ratios.iter().find(|r| {
        r["scene"] == scene
            && r["level"] == level
            && u(r, "width") == w as u64
            && u(r, "height") == h as u64
    });
    row.unwrap_or_else(|| panic!("no row {scene} {level} {w}x{h}"))["published_fps"].clone()
}

#[test]
fn wagner_a1_and_a2_tiny_rows_published_values_and_ratios() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bw");
    // 64×48 and the reference 320×240 (always measured); levels 1 (always) and 2
    let o = bench_into(
        &out,
        &[
            "wagner-a1",
            "wagner-a2",
            "--sizes",
            "64x48",
            "--levels",
            "2",
            "--angles",
            "1",
            "--warmup",
            "1",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));

    // Table A.1: the square at levels 1 and 2 × two sizes × both BVH variants, nothing moving
    let frames = read_csv(&out.join("wagner-a1.csv"));
    assert_eq!(frames.len(), 2 * 2 * 2, "{frames:?}");
    assert_eq!(rows_with(&frames, "variant", "wagner").len(), 2 * 2);
    for r in &frames {
        assert_eq!(
            (r["scene"].as_str(), r["tracer"].as_str()),
            ("square", "bvh")
        );
        assert!(["sah", "wagner"].contains(&r["variant"].as_str()), "{r:?}");
        let level = u(r, "level") as u32;
        assert_eq!(u(r, "triangles"), 8 * 4u64.pow(level - 1));
        assert_eq!((u(r, "refl_depth"), u(r, "lights")), (0, 1));
        assert_eq!(r["angle_deg"], "0");
        assert_eq!(
            r["fact_bvh_rebuilt"], "false",
            "camera and objects fixed: no rebuild"
        );
        assert!(f(r, "fact_bvh_build_ms") > 0.0 && u(r, "fact_bvh_nodes") >= 1);
    }
    let summary = read_csv(&out.join("wagner-a1_summary.csv"));
    check_summary_against_frames(&frames, &summary);
    let ratios = read_csv(&out.join("wagner-a1_ratios.csv"));
    assert_eq!(ratios.len(), 8);
    check_ratios(&ratios, &summary, |r, q| {
        q["level"] == "1"
            && q["variant"] == r["variant"]
            && (&q["width"], &q["height"]) == (&r["width"], &r["height"])
    });
    // typed in from Table A.1: 8 and 32 triangles at 320×240; 64×48 is not in the table
    assert_eq!(published(&ratios, "square", "1", 320, 240), "162.990000");
    assert_eq!(published(&ratios, "square", "2", 320, 240), "113.790000");
    assert_eq!(published(&ratios, "square", "2", 64, 48), "");

    // Table A.2: sphere and cow × two sizes, and the dragon's build
    let frames = read_csv(&out.join("wagner-a2.csv"));
    let triangles: HashMap<&str, u64> = [("sphere", 720), ("cow", 5804), ("dragon", 210712)].into();
    for r in &frames {
        assert_eq!(u(r, "triangles"), triangles[r["scene"].as_str()]);
        assert_eq!(r["fact_bvh_rebuilt"], "false");
    }
    assert_eq!(rows_with(&frames, "scene", "sphere").len(), 2 * 2);
    assert_eq!(rows_with(&frames, "scene", "cow").len(), 2 * 2);
    let dragon = rows_with(&frames, "scene", "dragon");
    assert_eq!(
        dragon.len(),
        1,
        "the faithful build of the dragon at full scale only"
    );
    assert!(f(dragon[0], "fact_bvh_build_ms") > 0.0);
    let summary = read_csv(&out.join("wagner-a2_summary.csv"));
    check_summary_against_frames(&frames, &summary);
    let ratios = read_csv(&out.join("wagner-a2_ratios.csv"));
    assert_eq!(ratios.len(), 8, "sphere and cow; the dragon has no ratio");
    check_ratios(&ratios, &summary, |r, q| {
        q["scene"] == r["scene"]
            && q["variant"] == r["variant"]
            && (u(q, "width"), u(q, "height")) == (320, 240)
    });
    assert_eq!(published(&ratios, "sphere", "", 320, 240), "20.120000");
    assert_eq!(published(&ratios, "cow", "", 320, 240), "11.910000");
    assert_eq!(published(&ratios, "cow", "", 64, 48), "");

    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for needle in [
        "Wagner 2018",
        "GTX 1060",
        "Table A.1",
        "Fig. 5.1",
        "162.99 (×1.00)",
        "45.07 (×0.28)",
        "9.41 (×1.00)",
        "Fig. 5.4",
        "20.12 (×1.00)",
        "1.33 (×0.11)",
        "18 (3) / 12 (3)",
        "five minutes",
        "210,712",
        "kernel per pixel",
    ] {
        assert!(report.contains(needle), "report.md lacks {needle:?}");
    }
    check_report_links(&out, &report);
    for png in ["fig5_1_triangles_fps.png", "fig5_4_resolution_fps.png"] {
        assert!(out.join(png).is_file(), "{png}");
    }
    // frames that differ only in size get the size in their names
    for variant in ["sah", "wagner"] {
        let png = format!("frames/wagner-a2/sphere_bvh-{variant}_64x48.png");
        assert!(out.join(&png).is_file(), "{png}");
    }
    assert!(out
        .join("frames/wagner-a1/square-level-2_bvh-sah_320x240.png")
        .is_file());
}

/// The published milliseconds of `proximity-clouds-table<n>`'s paper CSV row of `scene` in `column`.
fn paper_ms(rows: &[HashMap<String, String>], scene: &str, column: &str) -> String {
    let row = rows
        .iter()
        .find(|r| r["scene"] == scene && r["column"] == column);
    row.unwrap_or_else(|| panic!("no row {scene} {column}"))["paper_ms"].clone()
}

/// The streaming tracer's Tables 1–3 at 16×16 (one frame each): every scene with the paper's grid
/// in the stream tracer's g and pc columns (the Stanford bunny g only) and the compute grid; eye
/// rays only in Table 1 (no lights, no shadow tests), shadows in 2 and 3, two reflection bounces in
/// 3; the published milliseconds beside ours; the best GPU time the frames' sum.
#[test]
fn proximity_clouds_tables_tiny_rows_grids_and_published_milliseconds() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bp");
    let o = bench_into(
        &out,
        &[
            // the old name stays an alias
            "purcell-table1",
            "proximity-clouds-table2",
            "proximity-clouds-table3",
            "--sizes",
            "16x16",
            "--angles",
            "1",
            "--warmup",
            "0",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let triangles: HashMap<&str, u64> = [
        ("knight", 636),
        ("torus_knot", 1024),
        ("bunny_low", 1764),
        ("bunny", 69451),
        ("sparse_room", 1776),
    ]
    .into();
    let grids: HashMap<&str, &str> = [
        ("knight", "14x16x14"),
        ("torus_knot", "16"),
        ("bunny_low", "20"),
        ("bunny", "128"),
        ("sparse_room", "32"),
    ]
    .into();
    // the published values of Tables 1–3 at 256² (16² stands for the smallest side), g and pc
    let published = [
        [
            ("knight", "45", "47"),
            ("torus_knot", "55", "55"),
            ("bunny_low", "37", "37"),
        ],
        [
            ("knight", "96", "91"),
            ("torus_knot", "169", "164"),
            ("bunny_low", "75", "75"),
        ],
        [
            ("knight", "168", "164"),
            ("torus_knot", "306", "300"),
            ("bunny_low", "129", "130"),
        ],
    ];
    let stanford = ["142", "235", "482"];
    for n in 1..=3u32 {
        let p = format!("proximity-clouds-table{n}");
        let frames = read_csv(&out.join(format!("{p}.csv")));
        // 3 scenes × (g, pc, grid g, grid pc) + the Stanford bunny × (g, grid g) + the sparse
        // room × 4, and in Table 2 the 4 scenes' g with naive shadow rays, without masking,
        // and with neither optimisation
        let configs = if n == 2 { 30 } else { 18 };
        assert_eq!(frames.len(), configs, "{p}");
        for r in &frames {
            let scene = r["scene"].as_str();
            assert_eq!(u(r, "triangles"), triangles[scene], "{p} {scene}");
            assert_eq!(u(r, "lights"), (n > 1) as u64, "{p}: lights");
            assert_eq!(u(r, "refl_depth"), if n == 3 { 2 } else { 0 }, "{p}");
            assert_eq!((u(r, "width"), u(r, "height")), (16, 16));
            let stream = r["tracer"] == "stream";
            assert!(
                stream
                    || (r["tracer"] == "grid"
                        && ["exact", "exact-pc"].contains(&r["variant"].as_str())),
                "{r:?}"
            );
            if stream {
                assert_eq!(r["grid_resolution"], grids[scene], "{p} {scene}");
                let variant = r["variant"].as_str();
                assert!(["g", "pc", "g-naive", "g-nomask", "g-naive-nomask"].contains(&variant));
                assert_eq!(
                    r["fact_naive_shadows"],
                    variant.contains("naive").to_string()
                );
                assert_eq!(r["fact_masking"], (!variant.contains("nomask")).to_string());
                assert_eq!(
                    r["fact_proximity_clouds"],
                    (r["variant"] == "pc").to_string()
                );
            }
            if n == 1 {
                let shadow = r["tests_shadow"].as_str();
                assert!(["", "0"].contains(&shadow), "{p}: eye rays only, {shadow}");
            }
        }
        assert_eq!(
            rows_with(&frames, "variant", "pc").len(),
            4,
            "no pc for bunny"
        );
        for variant in ["g-naive", "g-nomask", "g-naive-nomask"] {
            let rows = rows_with(&frames, "variant", variant);
            assert_eq!(rows.len(), if n == 2 { 4 } else { 0 }, "{p}: {variant}");
            for r in rows {
                // the same shadows, found with an optimisation off: at least as many tests
                let g = frames
                    .iter()
                    .find(|g| g["scene"] == r["scene"] && g["variant"] == "g")
                    .unwrap();
                assert!(u(r, "tests_shadow") >= u(g, "tests_shadow"), "{r:?}");
                assert_eq!(u(r, "tests_closest"), u(g, "tests_closest"), "{r:?}");
            }
        }
        let summary = read_csv(&out.join(format!("{p}_summary.csv")));
        check_summary_against_frames(&frames, &summary);
        let paper = read_csv(&out.join(format!("{p}_paper.csv")));
        assert_eq!(paper.len(), configs);
        for (scene, g, pc) in published[n as usize - 1] {
            assert_eq!(
                paper_ms(&paper, scene, "g"),
                format!("{g}.000000"),
                "{p} {scene}"
            );
            assert_eq!(
                paper_ms(&paper, scene, "pc"),
                format!("{pc}.000000"),
                "{p} {scene}"
            );
            assert_eq!(
                paper_ms(&paper, scene, "grid-g"),
                "",
                "the paper has no compute grid"
            );
        }
        let bunny = paper_ms(&paper, "bunny", "g");
        assert_eq!(bunny, format!("{}.000000", stanford[n as usize - 1]));
        assert_eq!(paper_ms(&paper, "sparse_room", "g"), "", "not in the paper");
        for r in &paper {
            assert_eq!(u(r, "paper_width"), 256);
            // one frame: the best GPU time is that frame's
            let s: Vec<_> = summary
                .iter()
                .filter(|s| {
                    s["scene"] == r["scene"]
                        && s["grid_resolution"] == r["grid"]
                        && (s["variant"] == r["column"]
                            || (s["variant"] == "exact" && r["column"] == "grid-g")
                            || (s["variant"] == "exact-pc" && r["column"] == "grid-pc"))
                })
                .collect();
            assert_eq!(s.len(), 1, "{r:?}");
            let (best, min) = (f(r, "best_gpu_ms"), f(s[0], "gpu_ms_min"));
            assert!((best - min).abs() <= 1e-4 * min, "{r:?}: {best} vs {min}");
        }
        let report = std::fs::read_to_string(out.join("report.md")).unwrap();
        assert!(
            report.contains(&format!("The streaming tracer, Table {n}:")),
            "{report}"
        );
        assert!(out.join(format!("{p}.png")).is_file());
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    check_report_links(&out, &report);
    let title = report.lines().next().unwrap();
    assert!(
        title.starts_with("# The streaming tracer, Tables 1–3"),
        "{title}"
    );
    // the paper's test machine, as its ch. 4 names it
    assert!(report.contains("GeForce 6800GT 400 MHz with 256 MB at 1100 MHz"));
    assert!(report.contains("NVIDIA driver 1.0-9746"));
    assert!(report.contains("almost always worse than not using proximity clouds"));
    // Table 2's shadow-ray savings, each optimisation for every dense scene
    let shadows = report
        .lines()
        .find(|l| l.contains("shadow-ray optimisations each switched off"))
        .expect("Table 2's shadow-ray finding");
    for col in [
        "1 − g / g-naive)",
        "1 − g / g-nomask)",
        "1 − g / g-naive-nomask)",
    ] {
        let part = &shadows[shadows.find(col).expect(col)..];
        for scene in ["Knight", "Torus knot", "Bunny", "Stanford Bunny"] {
            assert!(part.contains(&format!("{scene} ")), "{scene}: {part}");
        }
    }
    assert!(!shadows.contains('–'), "every saving measured: {shadows}");
}

#[test]
fn accel_compare_tiny_every_scene_and_accelerator_kinds_agreement_and_the_stadium() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ac");
    let tiny = [&["accel-compare"][..], &TINY].concat();
    let listed = bench_into(&out, &[&tiny[..], &["--list"]].concat());
    assert!(listed.status.success(), "{}", stderr(&listed));
    let listed = String::from_utf8_lossy(&listed.stdout).lines().count();
    let o = bench_into(&out, &tiny);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = read_csv(&out.join("accel-compare_kinds.csv"));
    let kinds = [
        "primary",
        "shadow, 1st light",
        "shadow, all lights",
        "reflection",
        "frame",
    ];
    // Wagner's megakernel: the frame only; Müller's pipeline and the stream: every kind
    let megakernel = rows
        .iter()
        .filter(|r| r["accelerator"] == "bvh wagner")
        .count();
    assert!(megakernel > 0, "Wagner's configurations");
    let per_kind = rows.len() - megakernel;
    assert_eq!(per_kind % kinds.len(), 0, "a line per kind");
    assert_eq!(
        per_kind / kinds.len() + megakernel,
        listed,
        "every configuration listed"
    );
    let get = |scene: &str, accel: &str, kind: &str| {
        rows.iter()
            .find(|r| r["scene"] == scene && r["accelerator"] == accel && r["kind"] == kind)
            .unwrap_or_else(|| panic!("{scene} {accel} {kind}"))
    };
    // every scene of every source, and the stadium; quick scale: base up to 30k triangles,
    // Wagner's faithful build up to 50k
    let scenes: Vec<&str> = rows.iter().map(|r| r["scene"].as_str()).collect();
    for s in [
        "square",
        "knight",
        "bunny_low",
        "stadium",
        "teapot6",
        "dragon",
        "dragon_area",
    ] {
        assert!(scenes.contains(&s), "{s}");
    }
    for r in rows.iter().filter(|r| r["kind"] == "frame") {
        let t = u(r, "triangles");
        let accel = r["accelerator"].as_str();
        assert!(accel != "base" || t <= 30_000, "{r:?}");
        assert!(accel != "bvh wagner" || t <= 50_000, "{r:?}");
        // every pipeline counts its rays; the judge is the CPU reference
        assert!(f(r, "rays") >= 64.0, "{r:?}");
        let agree = f(r, "first_hit_agreement");
        if accel == "grid thesis" {
            assert!(agree > 0.8, "{r:?}");
        } else {
            assert_eq!(agree, 1.0, "{r:?}: first hits");
        }
        if accel != "bvh wagner" {
            let p = get(&r["scene"], accel, "primary");
            assert_eq!(f(p, "rays"), 64.0, "a primary ray per pixel: {p:?}");
            if accel == "base" {
                assert_eq!(f(p, "tests_per_ray"), t as f64, "base: every triangle");
            }
        }
    }
    // the stadium's four floodlights, and the grid that breaks there
    let one = get("stadium", "bvh sah", "shadow, 1st light");
    let all = get("stadium", "bvh sah", "shadow, all lights");
    assert!(
        f(all, "rays") > 2.0 * f(one, "rays"),
        "4 lights: {one:?} {all:?}"
    );
    let tests = |scene: &str, accel: &str| f(get(scene, accel, "primary"), "tests_per_ray");
    let (grid, bvh) = (tests("stadium", "grid exact"), tests("stadium", "bvh sah"));
    assert!(
        grid > 100.0 * bvh,
        "the grid breaks in the stadium: {grid} vs {bvh}"
    );
    assert!(
        grid > 10.0 * tests("teapot1", "grid exact"),
        "the same teapot on its floor"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for section in [
        "Frame throughput",
        "Each kind of ray apart",
        "Analysis",
        "stadium",
    ] {
        assert!(report.contains(section), "{section}");
    }
    assert!(out.join("accel-compare.png").is_file());
    check_report_links(&out, &report);
}

/// The cells of the markdown table line of `report` that starts with `| first |`.
fn report_line<'a>(report: &'a str, first: &str) -> Vec<&'a str> {
    let line = report
        .lines()
        .find(|l| l.starts_with(&format!("| {first} |")))
        .unwrap_or_else(|| panic!("no line {first}"));
    line.trim_matches('|').split('|').map(str::trim).collect()
}

#[test]
fn klee_tables_2_3_and_fig12_tiny_report_the_same_error_against_exact() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("klee");
    let o = bench_into(
        &out,
        &[
            &["klee-table2", "klee-table3", "klee-fig12"][..],
            &common::KLEE_TINY,
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    let table3 =
        &report[report.find("## klee-table3").unwrap()..report.find("## klee-fig12").unwrap()];
    let fig12 = &report[report.find("## klee-fig12").unwrap()..];
    // Table 2's `linespace` at 4 rays is Table 3's CGT at 4 rays and Fig. 12's 2×2: the same
    // G-buffer, rays and modes, each against its own `exact`
    let table2 = report_line(&report, "linespace (A)")[5].to_string();
    let error: f64 = table2.parse().unwrap();
    assert!(error > 0.0 && error < 0.2, "{table2}");
    for (rays, k) in [(4, 2), (9, 3), (16, 4), (100, 10)] {
        let t3 = report_line(table3, &format!("{rays} (A)"));
        let f12 = report_line(fig12, &format!("{k}×{k} (A)"));
        // CGT and DDA ask the same line spaces: the same shadows
        assert_eq!(t3[8], t3[9], "{rays} rays: CGT and DDA errors");
        assert_eq!(f12[7], t3[8], "{rays} rays: Fig. 12 and Table 3");
        if rays == 4 {
            assert_eq!(t3[8], table2, "Table 2 and Table 3 at 4 rays");
        }
    }
}

/// A run that measures nothing (every configuration fails: an empty `--glsl-dir`) leaves the
/// previous run's report, CSVs and plots as they were, and no temporary file behind.
#[test]
fn a_run_that_measures_nothing_keeps_the_previous_results() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b");
    let tiny = [&["thesis-5.1"][..], &TINY].concat();
    let o = bench_into(&out, &tiny);
    assert!(o.status.success(), "{}", stderr(&o));
    let snapshot = |d: &Path| {
        let mut files: Vec<(String, Vec<u8>)> = walk(d)
            .into_iter()
            .map(|p| {
                let rel = p.strip_prefix(d).unwrap().display().to_string();
                (rel, std::fs::read(&p).unwrap())
            })
            .collect();
        files.sort();
        files
    };
    let before = snapshot(&out);
    assert!(before.iter().any(|(n, _)| n == "report.md"), "{before:?}");
    let empty = dir.path().join("no-kernels");
    std::fs::create_dir(&empty).unwrap();
    let glsl = ["--glsl-dir", empty.to_str().unwrap()];
    let o = bench_into(&out, &[&tiny[..], &glsl[..]].concat());
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("nothing was measured"),
        "{}",
        stderr(&o)
    );
    let after = snapshot(&out);
    let names = |v: &[(String, Vec<u8>)]| v.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&after), names(&before), "files added or removed");
    assert!(after == before, "a file of the good run was replaced");
}

/// Every file below `d`.
fn walk(d: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(d).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}
