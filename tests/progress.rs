//! Progress of a long `render`: on a terminal (a pseudo-terminal made by util-linux's
//! `script`) a render that runs over 2 s shows a line with its stage, the reflection pass and
//! the kernel at work; with `--quiet`, or when standard error is not a terminal, nothing but
//! the summary line.

mod common;

use std::process::Command;

use common::*;

/// The base tracer on the bunny at 48², two frames: about 5 s on llvmpipe.
fn long_render(out: &std::path::Path, quiet: bool) -> Vec<String> {
    let scene = scene_path("bunny.toml");
    let mut args = vec![
        env!("CARGO_BIN_EXE_gpgpu-rt").to_string(),
        "render".into(),
        scene.display().to_string(),
        "--tracer".into(),
        "base".into(),
        "--width".into(),
        "48".into(),
        "--height".into(),
        "48".into(),
        "--frames".into(),
        "2".into(),
        "-o".into(),
        out.join("p.png").display().to_string(),
    ];
    if quiet {
        args.push("--quiet".into());
    }
    args.push("2>&1".into());
    let log = out.join(format!("typescript-{quiet}"));
    let o = Command::new("script")
        .args(["-q", "-e", "-c", &args.join(" ")])
        .arg(&log)
        .output()
        .expect("util-linux's script runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&log).unwrap();
    text.split(['\r', '\n']).map(str::to_string).collect()
}

#[test]
fn a_long_render_shows_its_progress_on_a_terminal_only() {
    let d = tempfile::tempdir().unwrap();
    let lines = long_render(d.path(), false);
    let shown = |needle: &str| lines.iter().any(|l| l.contains(needle));
    // (which frame and kernel the line catches depends on the machine's speed)
    let stage = |l: &String| l.contains("frame ") && l.contains(" of 2, pass ") && l.contains(": ");
    assert!(
        lines.iter().any(stage),
        "a frame, its pass and a kernel: {lines:?}"
    );
    assert!(shown("69451 triangles"), "the summary line: {lines:?}");
    let quiet = long_render(d.path(), true);
    assert!(!quiet.iter().any(|l| l.contains("frame ")), "{quiet:?}");
    assert!(
        quiet.iter().any(|l| l.contains("69451 triangles")),
        "{quiet:?}"
    );
    // not a terminal: the summary alone, no control characters
    let scene = scene_path("bunny.toml");
    let png = d.path().join("q.png");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--tracer",
        "base",
        "--width",
        "48",
        "--height",
        "48",
        "--frames",
        "2",
        "-o",
        png.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        !e.contains('\r') && !e.contains('\x1b') && !e.contains("frame "),
        "{e:?}"
    );
}
