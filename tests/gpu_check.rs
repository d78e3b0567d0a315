//! `scripts/gpu-check.sh` keeps to its budget: every command is bounded by what is left of it,
//! and a step that finds none left is skipped and named in `summary.md` (never run without a
//! limit). The whole dry run — every step on this machine's driver — is measured in
//! `docs/drivers.md`; here a budget of 30 s cuts it short.

use std::process::Command;
use std::time::Instant;

#[test]
fn gpu_check_stops_when_its_budget_is_spent_and_names_what_it_skipped() {
    let out = tempfile::tempdir().unwrap();
    let t0 = Instant::now();
    let o = Command::new("bash")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "scripts/gpu-check.sh",
            "--dry-run",
            "--budget",
            "30",
            "--bin",
        ])
        .arg(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .arg("--out")
        .arg(out.path())
        .output()
        .expect("bash runs the script");
    let took = t0.elapsed().as_secs_f64();
    let log = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "a cut run fails: {log}");
    assert!(
        took < 30.0 + 15.0,
        "{took:.0} s for a budget of 30 s: {log}"
    );
    let summary = std::fs::read_to_string(out.path().join("summary.md")).expect("summary.md");
    assert!(summary.contains("| test accel | ok |"), "{summary}");
    assert!(summary.contains("skipped: no time left"), "{summary}");
    assert!(
        summary.contains("(commit "),
        "the version with its commit: {summary}"
    );
    let info = std::fs::read_to_string(out.path().join("info.txt")).expect("info.txt");
    assert!(info.contains("profile: "), "{info}");
}

/// Every argument is checked before anything runs (before: `--reference /nonexistent` ran the
/// whole dry run and then pointed at a report that did not exist).
#[test]
fn gpu_check_refuses_bad_arguments_before_it_runs() {
    let cases: [(&[&str], &str); 7] = [
        (&["--budget", "soon"], "--budget soon"),
        (&["--budget", "3"], "at least 20 seconds"),
        (
            &["--reference", "/nonexistent"],
            "--reference /nonexistent: no such folder",
        ),
        (&["--reference", "/nonexistent.tar.gz"], "no such file"),
        (&["--out", "/dev/null"], "is not a folder"),
        (&["--bin", "/nonexistent"], "not an executable"),
        (&["--out"], "--out needs a value"),
    ];
    for (args, says) in cases {
        let t0 = Instant::now();
        let o = Command::new("bash")
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(["scripts/gpu-check.sh", "--dry-run"])
            .args(args)
            .output()
            .expect("bash runs the script");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(
            t0.elapsed().as_secs_f64() < 5.0,
            "{args:?}: ran before refusing"
        );
    }
}
