//! Every design and accelerator renders alike on Mesa's llvmpipe and on Mesa's zink (OpenGL on
//! Vulkan): `gpgpu-rt parity` on each, the second compared with the first — the same first
//! hit on every pixel (edge ties aside), the same shadows, the counts within the parity's
//! tolerance (docs/drivers.md). zink needs Debian's mesa-vulkan-drivers, which `.ci/run`
//! installs; elsewhere the test is skipped with a message, unless CI is set.
//!
//! Planted: `triangleCount()` from `vertex.length() / 3` again (glsl/common/scene.glsl) —
//! the grids' first hits differ on zink, caught; LOOP_BUDGET back to 60000 in the soft-shadow
//! kernel — not caught here at 3×3 rays (`tests/linespace.rs` renders 10×10 on either driver).

use std::path::Path;
use std::process::Command;

fn parity(driver: &str, out: &Path, against: Option<&Path>) -> std::process::Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("GPGPU_RT_DRIVER", driver)
        .args(["parity", "--size", "32", "--out"])
        .arg(out);
    if let Some(a) = against {
        c.arg("--against").arg(a);
    }
    c.output().expect("the binary runs")
}

fn zink_installed() -> bool {
    let icd = Path::new("/usr/share/vulkan/icd.d");
    std::fs::read_dir(icd).is_ok_and(|d| {
        d.flatten()
            .any(|e| e.file_name().to_string_lossy().starts_with("lvp_icd"))
    })
}

#[test]
fn llvmpipe_and_zink_render_every_design_alike() {
    let in_ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && v != "false");
    if !zink_installed() {
        assert!(
            !in_ci,
            "lavapipe (mesa-vulkan-drivers) is missing, but CI is set (.ci/run installs it)"
        );
        eprintln!("SKIPPED: zink needs lavapipe (Debian: apt-get install mesa-vulkan-drivers)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (llvmpipe, zink) = (dir.path().join("llvmpipe"), dir.path().join("zink"));
    let o = parity("llvmpipe", &llvmpipe, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = parity("zink", &zink, Some(&llvmpipe));
    let report = std::fs::read_to_string(zink.join("report.md")).unwrap_or_default();
    assert!(
        o.status.success(),
        "{report}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // the report is the two drivers' own, every case of the matrix in it
    assert!(
        report.contains("`zink (") && report.contains("against `llvmpipe ("),
        "{report}"
    );
    for case in [
        "base.teapot1",
        "grid-exact-pc.stadium",
        "bvh-wagner.bunny",
        "stream.teapot1",
    ] {
        assert!(
            report.contains(&format!("| {case} | 1024 |")),
            "{case}: {report}"
        );
    }
    assert!(
        report.contains("| soft-linespace-dda.bunny-area | 1024 | 0 |"),
        "{report}"
    );
    // the cases that look where a GPU could go wrong: every one compared, the colour too
    for case in [
        "| bvh-four-kernels.teapot1 | 1024 | 0 | 0 | 0 | 0 | 0 |",
        "| bvh-instances.teapot3-turning-in-flight | 1024 | 0 |",
        "| bvh.teapot1-tile64 | 13600 | 0 |",
        "| bvh-wagner.teapot1-61x47 | 2867 | 0 |",
        "| base.teapot1-colour | 1024 | 0 | 0 | 0 | 0 | 0 |",
        "| soft-exact.bunny-area-5x5 | 1024 | 0 |",
        "| bvh.teapot1-512-run5 | 262144 | 0 |",
    ] {
        assert!(report.contains(case), "{case}: {report}");
    }
    assert!(report.contains("Every case agrees."), "{report}");
}

/// `parity --list`: every case, one a line, with the options it is rendered with — the GPU's
/// cases among them (the four kernels, instances, tiles, an odd size, 5×5 soft shadows, frames in
/// flight, the colour image, the repeated 512² case).
#[test]
fn parity_lists_its_cases_with_their_options() {
    let o = Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .args(["parity", "--list"])
        .output()
        .expect("the binary runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let list = String::from_utf8_lossy(&o.stdout);
    for (case, options) in [
        (
            "bvh-four-kernels.teapot1 ",
            "--four-kernels (colour compared)",
        ),
        (
            "bvh-instances.teapot3-turning-in-flight ",
            "--bvh-instances (frames in flight)",
        ),
        (
            "grid-exact.teapot1-tile64 ",
            "136x100 --tracer grid --grid-variant exact --tile 64",
        ),
        ("stream.teapot1-61x47 ", "61x47 --tracer stream"),
        ("soft-linespace.bunny-area-5x5 ", "--light-samples 5x5"),
        ("bvh.teapot1-colour ", "(colour compared)"),
        ("bvh.teapot1-512-run5 ", "512x512 --tracer bvh"),
    ] {
        let line = list.lines().find(|l| l.starts_with(case));
        assert!(line.is_some_and(|l| l.contains(options)), "{case}: {list}");
    }
    assert_eq!(list.lines().filter(|l| l.contains("-512-run")).count(), 5);
}

/// `--driver` and `GPGPU_RT_DRIVER` pick the driver `info` reports; a name that is no driver
/// is refused with the variable named.
#[test]
fn the_driver_is_picked_by_flag_or_environment() {
    let info = |args: &[&str], env: Option<&str>| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"));
        c.args(["info", "--json"]).args(args);
        match env {
            Some(v) => c.env("GPGPU_RT_DRIVER", v),
            None => c.env_remove("GPGPU_RT_DRIVER"),
        };
        c.output().expect("the binary runs")
    };
    let renderer = |o: &std::process::Output| {
        let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("info --json");
        doc["renderer"].as_str().unwrap().to_string()
    };
    let o = info(&["--driver", "llvmpipe"], None);
    assert!(renderer(&o).starts_with("llvmpipe"), "{}", renderer(&o));
    if zink_installed() {
        let o = info(&["--driver", "zink"], None);
        assert!(renderer(&o).starts_with("zink"), "{}", renderer(&o));
        let o = info(&[], Some("zink"));
        assert!(renderer(&o).starts_with("zink"), "{}", renderer(&o));
    }
    let o = info(&[], Some("nouveau"));
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("GPGPU_RT_DRIVER=nouveau") && err.contains("zink"),
        "{err}"
    );
}

/// A comparison never writes what it compares against, and an `--against` record that cannot
/// be compared is refused before anything renders: `--out` the same folder, a folder inside
/// it or a link to it is refused and the record left as it was; a missing folder and a record
/// that lacks cases are refused with every missing case named, no `--out` folder made.
#[test]
fn parity_refuses_to_overwrite_or_to_compare_with_an_incomplete_record() {
    let dir = tempfile::tempdir().unwrap();
    let record = dir.path().join("record");
    let parity = |out: &Path, against: &Path, only: &str| {
        Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(["parity", "--size", "16", "--only", only, "--out"])
            .arg(out)
            .arg("--against")
            .arg(against)
            .output()
            .expect("the binary runs")
    };
    let o = Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["parity", "--size", "16", "--only", "teapot1-61x47", "--out"])
        .arg(&record)
        .output()
        .expect("the binary runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stats = record.join("bvh.teapot1-61x47/stats.json");
    let before = std::fs::read(&stats).unwrap();
    let link = dir.path().join("link");
    std::os::unix::fs::symlink(&record, &link).unwrap();
    for out in [record.clone(), record.join("inside"), link] {
        let o = parity(&out, &record, "teapot1-61x47");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{}: {err}", out.display());
        assert!(err.contains("overwrite the record"), "{err}");
    }
    assert_eq!(
        std::fs::read(&stats).unwrap(),
        before,
        "the record is untouched"
    );
    assert!(!record.join("inside").exists());
    let fresh = dir.path().join("fresh");
    let o = parity(&fresh, &dir.path().join("missing"), "teapot1-61x47");
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no such folder"));
    // the record holds the 61×47 cases only: the plain teapot1 cases are missing
    let o = parity(&fresh, &record, "teapot1");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("bvh.teapot1:") && err.contains("bvh-four-kernels.teapot1:"),
        "{err}"
    );
    assert!(
        !fresh.exists(),
        "refused before anything was rendered or written"
    );
    // a case whose array was cut short is named as truncated
    let hit_t = record.join("bvh.teapot1-61x47/hit_t.npy");
    let bytes = std::fs::read(&hit_t).unwrap();
    std::fs::write(&hit_t, &bytes[..bytes.len() / 2]).unwrap();
    let o = parity(&fresh, &record, "teapot1-61x47");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("hit_t.npy: truncated"), "{err}");
    assert!(!fresh.exists());
}
