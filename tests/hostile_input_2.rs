//! Hostile input, second round (issue 33): inputs that are not regular files, structures an
//! option makes large, models far from unit size under `fit`, interrupts while outputs are
//! written, output paths that cannot work, messages that name the wrong cause, and inputs a
//! design would ignore. Each is refused (exit 1, a message naming the file or option and the
//! limit, within seconds) or handled, never a hang, an abort or an OOM kill.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_gpgpu-rt");
const HEAD: &str =
    "[camera]\nposition = [0.4, 0.5, 3.0]\nlook_at = [0.3, 0.3, 0.0]\n[[light]]\nposition = [0, 3, 3]\n";

/// Run the binary in `dir` with `GPGPU_RT_MEMORY_LIMIT` = `limit` (if any), killed after
/// `secs` (then the test fails: it hung).
fn run_in(dir: &Path, args: &[&str], limit: Option<&str>, secs: u64) -> Output {
    let mut c = Command::new(BIN);
    c.args(args).current_dir(dir);
    match limit {
        Some(l) => c.env("GPGPU_RT_MEMORY_LIMIT", l),
        None => c.env_remove("GPGPU_RT_MEMORY_LIMIT"),
    };
    c.stdout(Stdio::piped()).stderr(Stdio::piped());
    let mut child = c.spawn().expect("the binary runs");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            panic!("{args:?} still running after {secs} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn refused(o: &Output, needles: &[&str]) -> String {
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "exit 1 expected: {e}");
    for n in needles {
        assert!(e.contains(n), "message lacks `{n}`: {e}");
    }
    assert!(
        !e.contains("panicked") && !e.contains("memory allocation"),
        "{e}"
    );
    e
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// `t.obj` (one triangle) in `dir` and its scene `s.toml`, with `extra` on its object.
fn triangle_scene(dir: &Path, extra: &str) -> PathBuf {
    write(dir, "t.obj", TRIANGLE);
    obj_scene(dir, "t.obj", extra)
}

/// A shipped scene's path, as text.
fn shipped(name: &str) -> String {
    common::scene_path(name).to_str().unwrap().to_string()
}

/// A frame too small to cost time, written to `o.png`.
const SMALL: [&str; 6] = ["--width", "8", "--height", "8", "-o", "o.png"];

fn obj_scene(dir: &Path, model: &str, extra: &str) -> PathBuf {
    named_scene(dir, "s.toml", model, extra)
}

fn named_scene(dir: &Path, name: &str, model: &str, extra: &str) -> PathBuf {
    let body = format!("[[object]]\ntype = \"obj\"\npath = \"{model}\"\n{extra}");
    write(dir, name, &format!("{HEAD}{body}"))
}

// ---- class 1: every input through one bounded reader ----

#[test]
fn inputs_that_are_not_regular_files_are_refused_without_blocking() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    mkfifo(&dir.join("fifo.obj"));
    mkfifo(&dir.join("fifo.mtl"));
    mkfifo(&dir.join("fifo.png"));
    mkfifo(&dir.join("fifo.toml"));
    write(dir, "m.obj", &format!("mtllib fifo.mtl\n{TRIANGLE}"));
    let cases: [(&str, PathBuf, &str); 5] = [
        (
            "a FIFO",
            named_scene(dir, "1.toml", "fifo.obj", ""),
            "fifo.obj",
        ),
        (
            "a character device",
            named_scene(dir, "2.toml", "/dev/zero", ""),
            "/dev/zero",
        ),
        (
            "a FIFO",
            named_scene(dir, "3.toml", "m.obj", ""),
            "fifo.mtl",
        ),
        (
            "a FIFO",
            named_scene(dir, "4.toml", "t.obj", "texture = \"fifo.png\"\n"),
            "fifo.png",
        ),
        ("a FIFO", dir.join("fifo.toml"), "fifo.toml"),
    ];
    write(dir, "t.obj", TRIANGLE);
    for (kind, scene, file) in cases {
        let o = run_in(dir, &["info", scene.to_str().unwrap()], None, 20);
        refused(&o, &[file, kind, "regular files"]);
    }
}

// ---- class 2: memory estimated before it is taken ----

#[test]
fn the_stream_grid_is_estimated_before_it_is_allocated() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let scene = triangle_scene(dir, "");
    let s = scene.to_str().unwrap();
    let args = |g| {
        [
            &["render", s, "--tracer", "stream", "--grid", g][..],
            &SMALL,
        ]
        .concat()
    };
    // 1024³ cells: tens of GB, whatever the host has
    let o = run_in(dir, &args("1024"), None, 20);
    refused(&o, &["1024x1024x1024 cells", "--grid decides its size"]);
    // 128³ within the host, but not within a limit of 8 MiB
    let o = run_in(dir, &args("128"), Some("8M"), 20);
    refused(
        &o,
        &[
            "128x128x128 cells",
            "8.0 MiB of GPGPU_RT_MEMORY_LIMIT",
            "--grid",
        ],
    );
    assert!(!dir.join("o.png").exists());
}

#[test]
fn the_stream_grid_refuses_2_to_the_24_references_as_it_counts_them() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    // 30,000 copies of a triangle across the grid's bottom layer (the grid's box reaches to
    // a small triangle at (1, 1, 1)): each copy in about 2^15 of its cells
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nv 0.99 1 1\nv 1 0.99 1\n");
    obj += &"f 1 2 3\n".repeat(30_000);
    obj += "f 4 5 6\n";
    write(dir, "many.obj", &obj);
    let scene = obj_scene(dir, "many.obj", "");
    let s = scene.to_str().unwrap();
    let args = [
        "render", s, "--tracer", "stream", "--grid", "256", "-o", "o.png",
    ];
    let t = Instant::now();
    let o = run_in(dir, &args, None, 60);
    refused(&o, &["2^24 or more references", "--grid"]);
    assert!(t.elapsed() < Duration::from_secs(30), "{:?}", t.elapsed());
}

#[test]
fn the_ntree_is_estimated_as_it_grows() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let scene = write(
        dir,
        "floor.toml",
        "[camera]\nposition = [0, 2, 4]\nlook_at = [0, 0, 0]\n[render]\nshadows = \"linespace\"\n\
         [[area_light]]\ncorner = [0.3, 3.0, 0.2]\nedge_u = [1, 0, 0]\nedge_v = [0, 0, 1]\n\
         [[object]]\ntype = \"floor\"\nsize = 4.0\n",
    );
    let s = scene.to_str().unwrap();
    let ntree = ["render", s, "--ntree-depth", "4", "--ntree-n", "16"];
    let args = [&ntree[..], &SMALL].concat();
    let o = run_in(dir, &args, Some("256M"), 30);
    refused(
        &o,
        &[
            "N-tree of N = 16, depth 4",
            "--ntree-n with --ntree-depth",
            "256.0 MiB",
        ],
    );
}

#[test]
fn each_design_is_estimated_before_it_is_built() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    // 131,072 triangles: the load's own estimate (544 bytes each, 68 MiB) passes 100 MiB, the
    // build of Wagner's BVH and textures (about 1 KB each) does not
    let scene = write(
        dir,
        "sq.toml",
        &format!("{HEAD}[[object]]\ntype = \"square\"\nlevel = 8\n"),
    );
    let s = scene.to_str().unwrap();
    let wagner = ["render", s, "--tracer", "bvh", "--bvh-variant", "wagner"];
    let wagner = [&wagner[..], &SMALL].concat();
    let o = run_in(dir, &wagner, Some("100M"), 60);
    refused(
        &o,
        &[
            "131072 triangles",
            "100.0 MiB of GPGPU_RT_MEMORY_LIMIT",
            "--tracer",
        ],
    );
}

#[test]
fn a_frame_is_estimated_before_it_is_rendered() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let scene = triangle_scene(dir, "");
    let s = scene.to_str().unwrap();
    let size = ["--width", "4096", "--height", "4096"];
    for design in [&["--tracer", "base"][..], &["--tracer", "stream"]] {
        let args = [
            &["render", s, "-o", "o.png", "--aov-dir", "a"][..],
            &size,
            design,
        ]
        .concat();
        let o = run_in(dir, &args, Some("1G"), 30);
        refused(
            &o,
            &[
                "4096x4096 frame with its AOVs",
                "--width with --height",
                "1.0 GiB",
            ],
        );
    }
}

#[test]
fn a_memory_limit_that_is_no_size_is_refused() {
    let d = tempfile::tempdir().unwrap();
    for bad in ["abc", "-5", "1.5G", "0"] {
        let o = run_in(d.path(), &["info"], Some(bad), 20);
        refused(&o, &["GPGPU_RT_MEMORY_LIMIT", bad, "not a positive size"]);
    }
    // KB, MiB and the like are sizes
    let o = run_in(d.path(), &["info"], Some("64KB"), 20);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

// ---- class 3: no NaN after the transforms ----

/// A tetrahedron at coordinates of `scale` (1e10, 1e-12) with `fit = 2`: every pixel that hits
/// it has a unit normal on every point-light design, the same (smooth, area-weighted) normal
/// as the tetrahedron at unit size.
#[test]
fn models_far_from_unit_size_fit_without_nan() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let mut unit_size: Vec<Vec<f32>> = Vec::new();
    for scale in [1.0f64, 1e10, 1e-12] {
        let v =
            |x: f64, y: f64, z: f64| format!("v {:e} {:e} {:e}\n", x * scale, y * scale, z * scale);
        let obj = v(1.0, 1.0, 1.0) + &v(3.0, 1.0, 1.0) + &v(1.0, 3.0, 1.0) + &v(1.0, 1.0, 3.0);
        write(
            dir,
            "tet.obj",
            &(obj + "f 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n"),
        );
        let scene = obj_scene(dir, "tet.obj", "fit = 2.0\n");
        for (k, tracer) in [
            &["--tracer", "base"][..],
            &["--tracer", "bvh", "--bvh-variant", "wagner"],
            &["--tracer", "stream"],
        ]
        .into_iter()
        .enumerate()
        {
            let s = scene.to_str().unwrap();
            let args = [
                &[
                    "render",
                    s,
                    "--width",
                    "24",
                    "--height",
                    "24",
                    "-o",
                    "o.png",
                    "--aov-dir",
                    "a",
                ][..],
                tracer,
            ]
            .concat();
            let o = run_in(dir, &args, None, 60);
            let at = format!("scale {scale}, {tracer:?}");
            assert!(
                o.status.success(),
                "{at}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            let bytes = std::fs::read(dir.join("a/normal.npy")).unwrap();
            let n: Vec<f32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
            let bytes = std::fs::read(dir.join("a/triangle_id.npy")).unwrap();
            let ids: Vec<i32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
            let hits = ids.iter().filter(|&&i| i >= 0).count();
            assert!(hits > 50, "{at}: {hits} hits");
            for (i, _) in ids.iter().enumerate().filter(|(_, &id)| id >= 0) {
                let len = (n[3 * i].powi(2) + n[3 * i + 1].powi(2) + n[3 * i + 2].powi(2)).sqrt();
                assert!(
                    (len - 1.0).abs() < 1e-4,
                    "{at}: pixel {i}: normal of length {len}"
                );
            }
            if scale == 1.0 {
                unit_size.push(n);
                continue;
            }
            let far = n.iter().zip(&unit_size[k]).map(|(a, b)| (a - b).abs());
            let worst = far.fold(0.0f32, f32::max);
            assert!(
                worst < 1e-3,
                "{at}: normals {worst} from the unit-size model's"
            );
        }
    }
}

#[test]
fn a_small_uniform_scale_is_no_zero_scale() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let ok = triangle_scene(dir, "scale = 1e-4\n");
    let o = run_in(dir, &["info", ok.to_str().unwrap()], None, 20);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let zero = obj_scene(dir, "t.obj", "scale = [1.0, 0.0, 1.0]\n");
    let o = run_in(dir, &["info", zero.to_str().unwrap()], None, 20);
    refused(&o, &["s.toml:", "has a zero component"]);
}

// ---- class 4: interrupts leave nothing behind ----

/// Outputs staged, the command blocked opening `--stats` (a FIFO nobody reads) at the commit:
/// SIGINT or SIGTERM removes every temporary file and the new `--aov-dir` folder, and the old
/// image stays as it was.
#[test]
fn an_interrupt_while_outputs_are_written_leaves_nothing_behind() {
    for (signal, name) in [(libc::SIGINT, "SIGINT"), (libc::SIGTERM, "SIGTERM")] {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        let scene = triangle_scene(dir, "");
        write(dir, "old.png", "the old image");
        mkfifo(&dir.join("stats.json"));
        let mut child = Command::new(BIN)
            .args([
                "render",
                scene.to_str().unwrap(),
                "--width",
                "16",
                "--height",
                "16",
            ])
            .args([
                "-o",
                "old.png",
                "--aov-dir",
                "aovs",
                "--stats",
                "stats.json",
            ])
            .current_dir(dir)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let names = || -> Vec<String> {
            let mut v: Vec<String> = std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        };
        let start = Instant::now();
        while !names().iter().any(|n| n.ends_with(".tmp")) || !dir.join("aovs").exists() {
            assert!(
                child.try_wait().unwrap().is_none(),
                "{name}: ended before staging"
            );
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "{name}: nothing staged"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        // every regular output is staged before the stats are written to the pipe
        std::thread::sleep(Duration::from_millis(300));
        unsafe { libc::kill(child.id() as i32, signal) };
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(128 + signal), "{name}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(name) && e.contains("removed"), "{e}");
        assert_eq!(
            names(),
            ["old.png", "s.toml", "stats.json", "t.obj"],
            "{name}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("old.png")).unwrap(),
            "the old image"
        );
    }
}

// ---- class 6: output paths checked before the work ----

#[test]
fn impossible_outputs_are_refused_before_the_render() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let b = &shipped("bunny.toml");
    let cases: [(&[&str], &[&str]); 3] = [
        (
            &["-o", "x.png", "--aov-dir", "x.png"],
            &["-o x.png", "--aov-dir x.png/", "cannot be both"],
        ),
        (&["-o", "y.png/"], &["-o y.png/", "names a folder"]),
        (&["-o", ".png"], &["`.png` has no extension"]),
    ];
    for (outs, needles) in cases {
        let args = [&["render", b, "--tracer", "base"][..], outs].concat();
        let t = Instant::now();
        let o = run_in(dir, &args, None, 60);
        refused(&o, needles);
        // the base render of the bunny takes seconds; a refusal before it, well under one
        assert!(
            t.elapsed() < Duration::from_secs(2),
            "{outs:?}: {:?}",
            t.elapsed()
        );
    }
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        0,
        "something was written"
    );
}

// ---- class 7: messages name what decides ----

#[test]
fn buffer_limits_name_the_options_that_decide_them() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let s = &shipped("bunny_low.toml");
    let grid = ["--tracer", "grid", "--grid-variant", "thesis"];
    let cases: [(&[&str], &str); 2] = [
        (
            &["--grid", "64", "--voxel-array-length", "65536"],
            "--grid with --voxel-array-length decides",
        ),
        (
            &[
                "--grid",
                "8",
                "--ray-array-length",
                "65536",
                "--width",
                "512",
                "--height",
                "512",
            ],
            "the image size with --ray-array-length decides",
        ),
    ];
    for (extra, needle) in cases {
        let args = [&["render", s, "-o", "o.png"][..], &grid, extra].concat();
        let o = run_in(dir, &args, None, 60);
        let e = refused(&o, &[needle, "GL_MAX_SHADER_STORAGE_BLOCK_SIZE"]);
        assert!(!e.contains("smaller scene"), "{e}");
    }
}

// ---- class 8: inputs a design would ignore ----

#[test]
fn inputs_a_design_would_ignore_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let b = &shipped("bunny_low.toml");
    let o = run_in(
        dir,
        &[
            "render",
            b,
            "--tracer",
            "bvh",
            "--bvh-variant",
            "wagner",
            "--proximity-clouds",
            "-o",
            "o.png",
        ],
        None,
        60,
    );
    refused(&o, &["--proximity-clouds applies to"]);
    // a point light beside the area light of a soft-shadow scene, and the reverse
    let area = std::fs::read_to_string(common::scene_path("bunny_area.toml")).unwrap();
    let models = common::scene_path("models");
    let area = area.replace(
        "path = \"models/",
        &format!("path = \"{}/", models.display()),
    );
    let both = write(
        dir,
        "both.toml",
        &format!("{area}\n[[light]]\nposition = [0, 3, 0]\n"),
    );
    let o = run_in(
        dir,
        &["render", both.to_str().unwrap(), "-o", "o.png"],
        None,
        60,
    );
    refused(&o, &["both.toml", "point [[light]]", "ignored"]);
    let point = area.replace("shadows = \"linespace\"", "");
    let point = write(
        dir,
        "point.toml",
        &format!("{point}\n[[light]]\nposition = [0, 3, 0]\n"),
    );
    // Müller 2015's pipeline lights area lights (tests/area_lights.rs); the streaming
    // tracer does not
    let o = run_in(
        dir,
        &[
            "render",
            point.to_str().unwrap(),
            "-o",
            "o.png",
            "--tracer",
            "stream",
        ],
        None,
        60,
    );
    refused(&o, &["point.toml", "[[area_light]]", "ignored"]);
}
