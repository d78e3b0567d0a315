//! No output loses data: every output path is checked before rendering (format, folder, not an
//! input, not another output), files are written beside their targets and renamed, a render
//! replaces all its outputs or none, and errors name the file. 32×32 renders.

mod common;

use common::{run, stderr};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_gpgpu-rt");

/// `o` failed, its message holds every one of `needles`.
fn assert_fails(o: &Output, needles: &[&str]) -> String {
    let e = stderr(o);
    assert!(!o.status.success(), "should fail: {e}");
    for n in needles {
        assert!(e.contains(n), "message lacks `{n}`: {e}");
    }
    e
}

/// `render SCENE --width 32 --height 32` and `extra`.
fn render(scene: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "32",
    ];
    args.extend_from_slice(extra);
    run(&args)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Every file and folder under `dir`, relative, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if p.is_dir() {
            out.extend(listing(&p).into_iter().map(|n| format!("{name}/{n}")));
        }
        out.push(name);
    }
    out.sort();
    out
}

/// Files with known old content: `out.png`, `stats.json` and every AOV in `aov/`.
fn old_outputs(d: &Path) -> Vec<(PathBuf, String)> {
    let mut files = vec![d.join("out.png"), d.join("stats.json")];
    for name in gpgpu_rt::output::AOV_FILES {
        files.push(d.join("aov").join(name));
    }
    std::fs::create_dir_all(d.join("aov")).unwrap();
    let old: Vec<(PathBuf, String)> = files
        .into_iter()
        .map(|f| (f.clone(), format!("old {}", f.display())))
        .collect();
    for (f, text) in &old {
        std::fs::write(f, text).unwrap();
    }
    old
}

fn assert_unchanged(old: &[(PathBuf, String)]) {
    for (f, text) in old {
        let now = std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert_eq!(&now, text, "{} was replaced", f.display());
    }
}

fn teapot() -> PathBuf {
    common::scene_path("teapot1.toml")
}

#[test]
fn an_unsupported_format_leaves_the_file_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let keep = dir.path().join("keep.bmp");
    std::fs::write(&keep, "precious").unwrap();
    let o = render(&teapot(), &["-o", s(&keep)]);
    assert_fails(&o, &["-o", "keep.bmp", ".png, .jpg, .jpeg or .exr"]);
    assert_eq!(std::fs::read_to_string(&keep).unwrap(), "precious");
    // the same formats for the viewer's screenshot, refused before a window is opened
    let o = run(&["view", s(&teapot()), "--screenshot", s(&keep)]);
    assert_fails(&o, &["--screenshot", "keep.bmp", ".png, .jpg or .jpeg"]);
    let tris = dir.path().join("tris.txt");
    std::fs::write(&tris, "precious").unwrap();
    let o = run(&["export-triangles", s(&teapot()), "-o", s(&tris)]);
    assert_fails(&o, &["tris.txt", ".npy"]);
    assert_eq!(std::fs::read_to_string(&tris).unwrap(), "precious");
    assert_eq!(listing(dir.path()), ["keep.bmp", "tris.txt"]);
    // JPEG is written where its name asks for it
    let jpg = dir.path().join("x.jpg");
    let o = render(&teapot(), &["-o", s(&jpg)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        image::ImageFormat::from_path(&jpg).unwrap(),
        image::ImageFormat::Jpeg
    );
    assert_eq!(
        std::fs::read(&jpg).unwrap()[..2],
        [0xFF, 0xD8],
        "a JPEG file"
    );
}

/// A scene with an OBJ model, its material library and a texture, in `d`.
fn textured_scene(d: &Path) -> PathBuf {
    let img =
        image::RgbImage::from_fn(4, 4, |x, y| image::Rgb([(x * 60) as u8, (y * 60) as u8, 9]));
    img.save(d.join("tex.png")).unwrap();
    std::fs::write(d.join("quad.mtl"), "newmtl tex\nKd 1 1 1\nmap_Kd tex.png\n").unwrap();
    std::fs::write(
        d.join("quad.obj"),
        "mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         vn 0 1 0\nusemtl tex\nf 1/1/1 4/4/1 3/3/1\nf 1/1/1 3/3/1 2/2/1\n",
    )
    .unwrap();
    let scene = d.join("scene.toml");
    std::fs::write(
        &scene,
        "[camera]\nposition = [0.0, 2.0, 1.5]\nlook_at = [0.0, 0.0, 0.0]\n[[light]]\n\
         position = [0.0, 3.0, 0.0]\n[[object]]\ntype = \"obj\"\npath = \"quad.obj\"\n",
    )
    .unwrap();
    scene
}

#[test]
fn an_input_is_refused_as_an_output_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = textured_scene(d);
    let inputs = ["scene.toml", "quad.obj", "quad.mtl", "tex.png"];
    let before: Vec<Vec<u8>> = inputs
        .iter()
        .map(|f| std::fs::read(d.join(f)).unwrap())
        .collect();
    // the scene file as --stats: refused, and nothing rendered
    let o = render(&scene, &["-o", s(&d.join("out.png")), "--stats", s(&scene)]);
    assert_fails(&o, &["--stats", "scene.toml"]);
    // the texture the scene reads, named directly and through `..`
    let o = render(&scene, &["-o", s(&d.join("tex.png"))]);
    assert_fails(
        &o,
        &[
            "-o",
            "tex.png",
            "a texture of the scene",
            "refusing to overwrite",
        ],
    );
    let through = d.join("sub/../tex.png");
    std::fs::create_dir(d.join("sub")).unwrap();
    let o = render(&scene, &["-o", s(&through)]);
    assert_fails(&o, &["tex.png", "a texture of the scene"]);
    // a link named like an output at the scene file
    std::os::unix::fs::symlink(&scene, d.join("link.json")).unwrap();
    let o = render(
        &scene,
        &[
            "-o",
            s(&d.join("out.png")),
            "--stats",
            s(&d.join("link.json")),
        ],
    );
    assert_fails(&o, &["link.json", "the scene file"]);
    let o = run(&["export-triangles", s(&scene), "-o", s(&d.join("quad.obj"))]);
    assert_fails(&o, &["quad.obj", ".npy"]);
    for (f, old) in inputs.iter().zip(&before) {
        assert_eq!(&std::fs::read(d.join(f)).unwrap(), old, "{f} changed");
    }
    assert!(!d.join("out.png").exists(), "refused before rendering");
    let mut expected = vec![
        "link.json",
        "quad.mtl",
        "quad.obj",
        "scene.toml",
        "sub",
        "tex.png",
    ];
    expected.sort();
    assert_eq!(listing(d), expected);
}

#[test]
fn two_outputs_at_one_file_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let old = old_outputs(d);
    // a PNG name that is a link to the statistics, and one that is a hard link to them
    std::os::unix::fs::symlink(d.join("stats.json"), d.join("soft.png")).unwrap();
    std::fs::hard_link(d.join("stats.json"), d.join("hard.png")).unwrap();
    for png in ["soft.png", "hard.png"] {
        let o = render(
            &teapot(),
            &["-o", s(&d.join(png)), "--stats", s(&d.join("stats.json"))],
        );
        assert_fails(&o, &[png, "stats.json", "are the same file"]);
    }
    assert_unchanged(&old);
}

#[test]
fn a_failing_aov_dir_leaves_the_old_png_and_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let old = old_outputs(d);
    let before = listing(d);
    let png = d.join("out.png");
    // --aov-dir is a file; a folder below a file
    for aov in [d.join("stats.json"), d.join("stats.json/aov")] {
        let o = render(&teapot(), &["-o", s(&png), "--aov-dir", s(&aov)]);
        assert_fails(&o, &["--aov-dir", "stats.json", "is not a folder"]);
    }
    // a folder that takes no new files, even for root (Linux' /proc)
    let o = render(
        &teapot(),
        &["-o", s(&png), "--aov-dir", "/proc/gpgpu-rt-aov"],
    );
    assert_fails(
        &o,
        &[
            "--aov-dir /proc/gpgpu-rt-aov",
            "cannot create files in /proc",
        ],
    );
    // --stats in a folder that does not exist, or that is a folder
    let o = render(
        &teapot(),
        &["-o", s(&png), "--stats", s(&d.join("none/s.json"))],
    );
    assert_fails(&o, &["--stats", "none", "does not exist"]);
    let o = render(&teapot(), &["-o", s(&png), "--stats", s(&d.join("aov"))]);
    assert_fails(&o, &["--stats", "is a folder"]);
    // a read-only file is not replaced (the rename would succeed)
    let stats = d.join("stats.json");
    let mut ro = std::fs::metadata(&stats).unwrap().permissions();
    ro.set_readonly(true);
    std::fs::set_permissions(&stats, ro).unwrap();
    let o = render(&teapot(), &["-o", s(&png), "--stats", s(&stats)]);
    assert_fails(&o, &["--stats", "stats.json", "is read-only"]);
    assert_unchanged(&old);
    assert_eq!(listing(d), before);
}

#[test]
fn a_full_disk_leaves_every_old_file_and_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let old = old_outputs(d);
    let before = listing(d);
    let (png, aov) = (d.join("out.png"), d.join("aov"));
    // /dev/full answers every write with ENOSPC: the statistics fail after the render
    let o = render(
        &teapot(),
        &["-o", s(&png), "--aov-dir", s(&aov), "--stats", "/dev/full"],
    );
    let e = assert_fails(&o, &["/dev/full", "No space left on device"]);
    assert!(e.contains("cannot write /dev/full"), "{e}");
    assert_unchanged(&old);
    assert_eq!(listing(d), before);
    // regular files beyond a size limit fail as on a full disk (EFBIG): 8 KiB takes the PNG but
    // not the first AOV (12 KiB); the new AOV folder is removed again
    let new_aov = d.join("new/aov");
    let limited = format!(
        "trap '' XFSZ; ulimit -f 16; exec '{BIN}' render '{}' --width 32 --height 32 -o '{}' \
         --aov-dir '{}'",
        teapot().display(),
        png.display(),
        new_aov.display()
    );
    let o = Command::new("sh").args(["-c", &limited]).output().unwrap();
    assert_fails(&o, &["cannot write", "ray_origin.npy", "File too large"]);
    assert_unchanged(&old);
    assert_eq!(listing(d), before);
}

#[test]
fn a_render_replaces_all_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let old = old_outputs(d);
    std::fs::remove_file(d.join("out.png")).unwrap(); // a new file
    use std::os::unix::fs::PermissionsExt;
    let mode = |f: &str| std::fs::metadata(d.join(f)).unwrap().permissions().mode() & 0o777;
    let group_only = std::fs::Permissions::from_mode(0o640);
    std::fs::set_permissions(d.join("stats.json"), group_only).unwrap();
    let args = ["-o", "out.png", "--aov-dir", "aov", "--stats", "stats.json"];
    let o = Command::new(BIN)
        .current_dir(d)
        .args(["render", s(&teapot()), "--width", "32", "--height", "32"])
        .args(args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    for (f, text) in &old {
        assert_ne!(
            &std::fs::read_to_string(f).unwrap_or_default(),
            text,
            "{}",
            f.display()
        );
    }
    assert_eq!(listing(d), listing_of_outputs());
    // a new file gets the usual permissions (not the 0600 of a temporary file), a replaced file
    // keeps its own
    assert_eq!(mode("out.png") & 0o044, 0o044, "readable by others");
    assert_eq!(mode("stats.json"), 0o640);
}

#[test]
fn stats_to_dev_stdout_are_written_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let png = d.join("out.png");
    let args = ["-o", s(&png), "--stats", "/dev/stdout"];
    // a pipe
    let o = render(&teapot(), &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(doc["width"], 32);
    // a file the shell redirected stdout to
    let captured = d.join("captured.json");
    let o = Command::new(BIN)
        .args(["render", s(&teapot()), "--width", "32", "--height", "32"])
        .args(args)
        .stdout(std::fs::File::create(&captured).unwrap())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&captured).unwrap()).unwrap();
    assert_eq!(doc["height"], 32);
    assert_eq!(listing(d), ["captured.json", "out.png"]);
}

fn listing_of_outputs() -> Vec<String> {
    let mut v = vec!["aov".to_string(), "out.png".into(), "stats.json".into()];
    v.extend(
        gpgpu_rt::output::AOV_FILES
            .iter()
            .map(|f| format!("aov/{f}")),
    );
    v.sort();
    v
}
