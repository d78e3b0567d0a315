//! `gpgpu-rt view` under Xvfb (Mesa llvmpipe through GLX): the window's screenshot equals
//! `render`'s PNG (the ray tracer, and the soft shadows of Klee 2016), and an edited kernel in a
//! `--glsl-dir` is reloaded live — a compile error is reported with file and line while the
//! last good program keeps running, and the fixed kernel's effect reaches the window (also a
//! soft-shadow kernel).
//!
//! The tests start the binary through `xvfb-run -a`. Without `xvfb-run` they are skipped with
//! a message, except in CI (`CI` set), where they fail: `.ci/run` installs `xvfb`.

mod common;

use common::copy_dir;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use image::RgbImage;

const BIN: &str = env!("CARGO_BIN_EXE_gpgpu-rt");
/// Upper bound for one viewer run on 2 shared llvmpipe cores (normally a few seconds).
const TIMEOUT: Duration = Duration::from_secs(300);
/// Largest per-channel difference (8-bit units) between the window's screenshot and the PNG of
/// `render`: both come from the same RGBA32F output texture, clamped to [0, 1]; the window
/// converts to 8 bits in the GL pipeline, the PNG writer with round(), so a value exactly
/// between two steps may land on either side. In practice the images are identical.
const MAX_CHANNEL_DIFF: u8 = 1;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn in_ci() -> bool {
    std::env::var("CI")
        .map(|v| !v.is_empty() && v != "0" && v != "false")
        .unwrap_or(false)
}

/// `xvfb-run`, or `None` (test skipped) when it is missing outside CI.
fn xvfb_run() -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    if let Some(p) = std::env::split_paths(&path)
        .map(|d| d.join("xvfb-run"))
        .find(|p| p.is_file())
    {
        return Some(p);
    }
    if in_ci() {
        panic!("xvfb-run is missing, but CI is set: the viewer tests must run (.ci/run installs the Debian package xvfb)");
    }
    eprintln!("SKIPPED: xvfb-run not found (Debian: apt-get install xvfb); the viewer tests need an X server");
    None
}

/// The viewer command under its own X server.
fn view(xvfb: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(xvfb);
    c.args(["-a", "-s", "-screen 0 1024x768x24", BIN, "view"])
        .args(args)
        .current_dir(root());
    // its own process group, so a hung run can be ended with everything it started
    std::os::unix::process::CommandExt::process_group(&mut c, 0);
    c
}

/// A child process that is ended (with its process group) if the test gives up on it.
struct Running {
    child: Child,
}

impl Running {
    fn wait(mut self, deadline: Instant) -> std::process::ExitStatus {
        loop {
            if let Some(status) = self.child.try_wait().expect("wait for the viewer") {
                return status;
            }
            assert!(
                Instant::now() < deadline,
                "the viewer did not finish within {TIMEOUT:?}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = Command::new("kill")
                .args(["-TERM", "--", &format!("-{}", self.child.id())])
                .status();
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// Run to completion with the timeout; returns the output.
fn run_bounded(mut cmd: Command) -> Output {
    let child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start the viewer");
    let mut running = Running { child };
    let out = running.child.stdout.take().unwrap();
    let err = running.child.stderr.take().unwrap();
    let out = std::thread::spawn(move || std::io::read_to_string(out).unwrap_or_default());
    let err = std::thread::spawn(move || std::io::read_to_string(err).unwrap_or_default());
    let status = running.wait(Instant::now() + TIMEOUT);
    Output {
        status,
        stdout: out.join().unwrap().into_bytes(),
        stderr: err.join().unwrap().into_bytes(),
    }
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// `render ARGS` and `view ARGS --frames N --log-frames --screenshot` at 96×96: both images
/// and the viewer's stdout, after checking that it logged N frames and read the window back.
fn render_and_view(xvfb: &Path, args: &[&str], frames: u32) -> (RgbImage, RgbImage, String) {
    let dir = tempfile::tempdir().unwrap();
    let rendered = dir.path().join("render.png");
    let shot = dir.path().join("view.png");
    let size = ["--width", "96", "--height", "96"];

    let out = Command::new(BIN)
        .current_dir(root())
        .arg("render")
        .args(args)
        .arg("-o")
        .arg(&rendered)
        .args(size)
        .output()
        .unwrap();
    assert!(out.status.success(), "render failed: {}", text(&out.stderr));

    let frames = frames.to_string();
    let mut cmd = view(xvfb, args);
    cmd.args(["--frames", &frames, "--log-frames", "--screenshot"])
        .arg(&shot)
        .args(size);
    let out = run_bounded(cmd);
    let stdout = text(&out.stdout);
    assert!(
        out.status.success(),
        "view failed ({}):\nstdout:\n{stdout}\nstderr:\n{}",
        out.status,
        text(&out.stderr)
    );
    assert_eq!(
        stdout
            .lines()
            .filter(|l| l.starts_with("frame "))
            .count()
            .to_string(),
        frames,
        "{stdout}"
    );
    // the screenshot is the window's own framebuffer, not an offscreen copy
    assert!(
        stdout.contains(&format!("frame {frames}, window framebuffer")),
        "{stdout}"
    );
    let a = image::open(&rendered).unwrap().to_rgb8();
    let b = image::open(&shot).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), (96, 96));
    assert_eq!(b.dimensions(), a.dimensions());
    (a, b, stdout)
}

/// Every channel of `b` within MAX_CHANNEL_DIFF of `a`; `a` has more than `min_colours`
/// distinct colours (not a trivially equal pair of blank images), and `b`'s top and bottom
/// rows differ (a flipped image would not match).
fn assert_same_image(a: &RgbImage, b: &RgbImage, min_colours: usize) {
    let mut max = 0u8;
    let mut differing = 0;
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let d = (0..3).map(|k| pa[k].abs_diff(pb[k])).max().unwrap();
        max = max.max(d);
        differing += (d > 0) as usize;
    }
    assert!(
        max <= MAX_CHANNEL_DIFF,
        "screenshot differs from render by up to {max} (8-bit) in {differing} pixels"
    );
    let mut colours: Vec<[u8; 3]> = a.pixels().map(|p| p.0).collect();
    colours.sort();
    colours.dedup();
    assert!(
        colours.len() > min_colours,
        "only {} distinct colours in the render",
        colours.len()
    );
    // the top row is background, the bottom row floor
    assert_ne!(b.get_pixel(48, 0), b.get_pixel(48, 95));
}

#[test]
fn screenshot_equals_render() {
    let Some(xvfb) = xvfb_run() else { return };
    let (a, b, _) = render_and_view(&xvfb, &["scenes/teapot1.toml"], 3);
    // the teapot and the checker floor are there
    assert_same_image(&a, &b, 200);
}

/// The soft shadows of Klee 2016 in the window (G-buffer, shadow pass, quad into the
/// renderer's output texture, shown by the viewer's screen-filling quad) equal `render`'s.
#[test]
fn soft_shadow_screenshot_equals_render() {
    let Some(xvfb) = xvfb_run() else { return };
    let args = [
        "scenes/bunny_area.toml",
        "--shadows",
        "linespace",
        "--light-samples",
        "3x3",
    ];
    let (a, b, stdout) = render_and_view(&xvfb, &args, 2);
    // the title's figures per frame: the shadow kernels' GPU times, tests and lookups
    let frame = stdout
        .lines()
        .find(|l| l.starts_with("frame 2: soft shadows linespace 3x3,"))
        .unwrap_or_else(|| panic!("no soft-shadow frame line: {stdout}"));
    for part in [
        "gbuffer=",
        "shadow_linespace=",
        "present=",
        "line-space lookups ",
    ] {
        assert!(frame.contains(part), "{part} missing: {frame}");
    }
    let lookups: u64 = frame
        .rsplit("line-space lookups ")
        .next()
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or_else(|| panic!("no lookup count: {frame}"));
    assert!(lookups > 0, "{frame}");
    // the bunny, the checker floor and a penumbra: many grey levels
    assert_same_image(&a, &b, 100);
}

/// Lines of the viewer's stdout, with a deadline.
struct Lines {
    rx: Receiver<String>,
    seen: Vec<String>,
    deadline: Instant,
}

impl Lines {
    /// Wait for a line starting with `prefix`; returns it.
    fn expect(&mut self, prefix: &str) -> String {
        loop {
            let left = self.deadline.saturating_duration_since(Instant::now());
            match self.rx.recv_timeout(left) {
                Ok(line) => {
                    self.seen.push(line.clone());
                    if line.starts_with(prefix) {
                        return line;
                    }
                }
                Err(RecvTimeoutError::Timeout) => {
                    panic!(
                        "no `{prefix}` line within {TIMEOUT:?}; stdout so far:\n{}",
                        self.seen.join("\n")
                    )
                }
                Err(RecvTimeoutError::Disconnected) => {
                    panic!(
                        "the viewer ended before a `{prefix}` line; stdout:\n{}",
                        self.seen.join("\n")
                    )
                }
            }
        }
    }
}

/// Start the viewer; its stdout line by line (deadline TIMEOUT from now), its stderr at the end.
fn spawn_lines(mut cmd: Command) -> (Running, Lines, std::thread::JoinHandle<String>) {
    let mut child = Running {
        child: cmd
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start the viewer"),
    };
    let (tx, rx) = mpsc::channel();
    let stdout = child.child.stdout.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let stderr = child.child.stderr.take().unwrap();
    let stderr = std::thread::spawn(move || std::io::read_to_string(stderr).unwrap_or_default());
    let lines = Lines {
        rx,
        seen: Vec::new(),
        deadline: Instant::now() + TIMEOUT,
    };
    (child, lines, stderr)
}

/// Replace a file the way editors save: write a sibling, rename it over the original.
fn save(path: &Path, contents: &str) {
    let tmp = path.with_file_name(".edit.tmp");
    std::fs::write(&tmp, contents).unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

/// A copy of the kernels in `dir`, to edit: its folder.
fn kernels_copy(dir: &Path) -> PathBuf {
    let glsl = dir.join("glsl");
    copy_dir(&root().join("glsl"), &glsl);
    glsl
}

/// Start the viewer `cmd` on the kernels in `glsl` (reloaded when they change), its screenshot
/// to `shot`.
fn spawn_live(
    mut cmd: Command,
    glsl: &Path,
    shot: &Path,
) -> (Running, Lines, std::thread::JoinHandle<String>) {
    cmd.arg("--glsl-dir")
        .arg(glsl)
        .arg("--screenshot")
        .arg(shot);
    spawn_lines(cmd)
}

/// The viewer ended well (`status`, its `stderr` shown if not) and its screenshot `shot` is all
/// magenta, the edited kernels' constant colour: the screenshot.
fn assert_ends_magenta(
    status: std::process::ExitStatus,
    stderr: std::thread::JoinHandle<String>,
    shot: &Path,
) -> RgbImage {
    assert!(
        status.success(),
        "viewer failed ({status}): {}",
        stderr.join().unwrap()
    );
    let img = image::open(shot).unwrap().to_rgb8();
    let off = img.pixels().filter(|p| p.0 != [255, 0, 255]).count();
    assert_eq!(
        off, 0,
        "{off} pixels are not the edited kernel's constant colour"
    );
    img
}

#[test]
fn kernel_edit_reloads_live() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let glsl = kernels_copy(dir.path());
    let shading = glsl.join("mueller2015/shading.comp");
    let original = std::fs::read_to_string(&shading).unwrap();

    // a compile error on a known line: a line of garbage before `void main()`
    let main_line = original
        .lines()
        .position(|l| l.starts_with("void main()"))
        .expect("shading.comp has main")
        + 1;
    let mut broken: Vec<&str> = original.lines().collect();
    broken.insert(main_line - 1, "this is not GLSL;");
    let broken = broken.join("\n") + "\n";
    // the fix: Listing 16's store replaced by a constant colour
    let store =
        "imageStore(finalTexture, storePos, addToFinal(final_color, temp_color, pColor.w));";
    assert_eq!(
        original.matches(store).count(),
        1,
        "shading.comp changed; update this test"
    );
    let magenta = original.replace(
        store,
        "imageStore(finalTexture, storePos, vec4(1.0, 0.0, 1.0, 1.0));",
    );

    let shot = dir.path().join("after.png");
    let cmd = view(
        &xvfb,
        &[
            "scenes/teapot1.toml",
            // the four kernels: the edited kernel is their shading (the fused pass has its own)
            "--four-kernels",
            "--width",
            "64",
            "--height",
            "64",
            "--refl-depth",
            "0",
            "--log-frames",
            "--wait-reload",
            "--frames",
            "2",
        ],
    );
    let (child, mut lines, stderr) = spawn_live(cmd, &glsl, &shot);
    let deadline = lines.deadline;

    lines.expect("watching ");
    // the original kernels render
    lines.expect("frame ");

    save(&shading, &broken);
    let failed = lines.expect("reload failed: ");
    let located = format!("shading.comp:{main_line}");
    assert!(
        failed.contains(&located),
        "the error does not name {located}: {failed}"
    );
    // the last good program keeps running
    lines.expect("frame ");

    save(&shading, &magenta);
    lines.expect("reload ok: mueller2015/shading.comp");
    let shot_line = lines.expect("screenshot: ");
    assert!(shot_line.contains("window framebuffer"), "{shot_line}");
    let img = assert_ends_magenta(child.wait(deadline), stderr, &shot);
    assert_eq!(img.dimensions(), (64, 64));
}

/// With soft shadows shown, an edit of their quad kernel (`linespace_quad.frag`) is reloaded
/// live and reaches the window.
#[test]
fn soft_shadow_kernel_edit_reloads_live() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let glsl = kernels_copy(dir.path());
    let quad = glsl.join("klee2016/linespace_quad.frag");
    let original = std::fs::read_to_string(&quad).unwrap();
    let store = "fragColor = vec4(texture(colorTexture, texCoord).rgb, 1.0);";
    assert_eq!(
        original.matches(store).count(),
        1,
        "linespace_quad.frag changed; update this test"
    );
    let magenta = original.replace(store, "fragColor = vec4(1.0, 0.0, 1.0, 1.0);");

    let shot = dir.path().join("after.png");
    let cmd = view(
        &xvfb,
        &[
            "scenes/bunny_area.toml",
            "--shadows",
            "linespace",
            "--light-samples",
            "2x2",
            "--width",
            "32",
            "--height",
            "32",
            "--log-frames",
            "--wait-reload",
            "--frames",
            "1",
        ],
    );
    let (child, mut lines, stderr) = spawn_live(cmd, &glsl, &shot);
    let deadline = lines.deadline;
    lines.expect("watching ");
    lines.expect("frame 1: soft shadows linespace 2x2");
    save(&quad, &magenta);
    let ok = lines.expect("reload ok: klee2016/linespace_quad.frag");
    assert!(ok.contains("soft shadows linespace 2x2"), "{ok}");
    lines.expect("screenshot: ");
    assert_ends_magenta(child.wait(deadline), stderr, &shot);
}

#[test]
fn bad_view_input_fails_cleanly() {
    // no display needed: these fail before a window is opened
    // exit status 1 for bad input, 2 for a command line clap refuses (a value out of its range)
    let run_status = |args: &[&str], status: i32| {
        let out = Command::new(BIN)
            .current_dir(root())
            .arg("view")
            .args(args)
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(status),
            "{args:?}: {}",
            text(&out.stderr)
        );
        text(&out.stderr)
    };
    let run = |args: &[&str]| run_status(args, 1);
    assert!(run(&["scenes/missing.toml"]).contains("missing.toml"));
    let e = run_status(&["scenes/teapot1.toml", "--frames", "0"], 2);
    assert!(e.contains("--frames") && e.contains("1..=100000"), "{e}");
    assert!(run(&["scenes/teapot1.toml", "--wait-reload", "--frames", "1"]).contains("--glsl-dir"));
    // the formats of `render -o`: PNG or JPEG, said in the message
    let e = run(&["scenes/teapot1.toml", "--screenshot", "x.bmp"]);
    assert!(
        e.contains("x.bmp") && e.contains(".png, .jpg or .jpeg"),
        "{e}"
    );
    assert!(run(&["scenes/teapot1.toml", "--glsl-dir", "no/such/dir"]).contains("no/such/dir"));
    // soft shadows need an area light: render's message, before a window is opened
    let e = run(&["scenes/teapot1.toml", "--shadows", "linespace"]);
    assert!(
        e.contains("teapot1.toml: --shadows needs an [[area_light]] in the scene file"),
        "{e}"
    );
    // no window system: a message that says what to do, not a panic
    let out = Command::new(BIN)
        .current_dir(root())
        .args([
            "view",
            "scenes/teapot1.toml",
            "--width",
            "8",
            "--height",
            "8",
        ])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("xvfb-run"),
        "{}",
        text(&out.stderr)
    );
}
