//! OpenEXR outputs read back by the reference implementation (PyPI `openexr`, through
//! `tools/exr_check.py`): `--aov-format exr`'s `aovs.exr` holds, channel by channel, exactly the
//! values of the npy files of the same frame (`triangle_id` as their i32 bits in a UINT
//! channel), and `-o image.exr` the linear colour whose clamped 8-bit rounding is the PNG.
//! Where Python's OpenEXR or NumPy is missing the test says so and passes, except under CI
//! (`.ci/run` installs them), where it fails.

mod common;

use std::path::Path;
use std::process::Command;

use common::*;

fn have_openexr() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import OpenEXR, numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var_os("CI").is_none(),
            "python3 with OpenEXR and NumPy is missing (pip install openexr numpy)"
        );
        eprintln!("skipped: python3 with OpenEXR and NumPy is missing (pip install openexr numpy)");
    }
    ok
}

fn render(scene: &str, out: &Path, aovs: &Path, extra: &[&str]) {
    let scene = scene_path(scene);
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "48",
        "-o",
        out.to_str().unwrap(),
        "--aov-dir",
        aovs.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn exr_outputs_hold_the_npy_values_and_the_png_colour() {
    if !have_openexr() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    // a point-light frame with reflection and shadows, and Klee's soft shadows
    for scene in ["teapot1.toml", "bunny_area.toml"] {
        let (png, npy) = (dir.join("c.png"), dir.join("npy"));
        let (exr, exr_dir) = (dir.join("c.exr"), dir.join("exr"));
        render(scene, &png, &npy, &[]);
        render(scene, &exr, &exr_dir, &["--aov-format", "exr"]);
        let names: Vec<String> = std::fs::read_dir(&exr_dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["aovs.exr"], "{scene}");
        let rgb = dir.join("rgb.npy");
        let tool = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/exr_check.py");
        let o = Command::new("python3")
            .arg(&tool)
            .args([
                exr_dir.join("aovs.exr"),
                npy.clone(),
                exr.clone(),
                rgb.clone(),
            ])
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&o.stdout).into_owned() + &stderr(&o);
        assert!(o.status.success(), "{scene}: {said}");
        let bytes = std::fs::read(&rgb).unwrap();
        let linear: Vec<f32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
        let png = image::open(&png).unwrap().to_rgb8();
        assert_eq!(linear.len(), png.as_raw().len(), "{scene}");
        for (k, (&l, &p)) in linear.iter().zip(png.as_raw()).enumerate() {
            let want = (l.clamp(0.0, 1.0) * 255.0).round() as u8;
            assert_eq!(want, p, "{scene}: value {k}: EXR {l}, PNG {p}");
        }
        assert!(linear.iter().any(|&v| v > 0.05), "{scene}: a lit image");
    }
}

#[test]
fn aov_format_needs_an_aov_dir() {
    let scene = scene_path("teapot1.toml");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--aov-format",
        "exr",
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--aov-dir"), "{}", stderr(&o));
}
