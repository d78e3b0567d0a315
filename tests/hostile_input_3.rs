//! Hostile input, third round: numbers that are no finite numbers are refused with the option
//! named before anything renders, and a turning scene's pose stays finite for any step and
//! count of frames. (Each case was accepted before: `--turn NaN`, `inf` and `1e39` rendered a
//! background-only image or NaN rays, exit 0; `--tolerance 2` was taken.)

mod common;

use common::*;

#[test]
fn numbers_that_are_not_finite_are_refused_with_the_option() {
    let scene = scene_path("teapot1.toml");
    let scene = scene.to_str().unwrap();
    for value in ["NaN", "inf", "-inf", "1e39", "-1e39"] {
        let turn = format!("--turn={value}");
        let o = run(&["render", scene, "--width", "8", "--height", "8"]
            .into_iter()
            .chain(["--rotate", "objects", &turn, "-o", "/dev/null"])
            .collect::<Vec<_>>());
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{value}: {err}");
        assert!(
            err.contains("--turn") && err.contains("not a finite number"),
            "{err}"
        );
    }
    for (option, value) in [
        ("--tolerance", "NaN"),
        ("--tolerance", "2"),
        ("--count-tolerance", "-0.5"),
    ] {
        let given = format!("{option}={value}");
        let o = run(&["parity", "--list", &given]);
        assert_eq!(o.status.code(), Some(2), "{option} {value}: {}", stderr(&o));
        assert!(stderr(&o).contains(option), "{}", stderr(&o));
    }
}

/// A step so large that its product with the frame count passes what an f32 holds still gives
/// a finite pose: the rays of the last frame are finite and hit the scene.
#[test]
fn a_turning_pose_stays_finite_for_any_step() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_path("teapot1.toml");
    let aovs = dir.path().join("aovs");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
        "--rotate",
        "camera",
        "--turn",
        "3e38",
        "--frames",
        "3",
        "--aov-dir",
        aovs.to_str().unwrap(),
        "-o",
        dir.path().join("x.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(aovs.join("ray_origin.npy")).unwrap();
    let origins: Vec<f32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
    assert!(origins.iter().all(|v| v.is_finite()), "finite ray origins");
    let bytes = std::fs::read(aovs.join("triangle_id.npy")).unwrap();
    let ids: Vec<i32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
    assert!(ids.iter().any(|&id| id >= 0), "the turned scene is hit");
}

// ---- output errors are errors, not panics ----

/// A reader that closed the pipe ends the program quietly, killed by SIGPIPE as other Unix
/// tools are; a full disk under standard output or standard error is exit status 1, never a
/// panic (101). (Before: `info --json | true` and `> /dev/full` panicked with exit 101.)
#[test]
fn a_closed_pipe_or_a_full_disk_is_no_panic() {
    use std::os::unix::process::ExitStatusExt as _;
    use std::process::{Command, Stdio};
    let bin = env!("CARGO_BIN_EXE_gpgpu-rt");
    let mut child = Command::new(bin)
        .args(["info", "--json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take()); // closed before the GL context exists, so before any write
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.signal(), Some(libc::SIGPIPE), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));

    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    let scene = scene_path("teapot1.toml");
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("r.png");
    let render = [
        "render",
        scene.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "-o",
        png.to_str().unwrap(),
    ];
    let cases: [(&[&str], bool); 5] = [
        (&["info", "--json"], true),
        (&["info"], true),
        (&["--help"], true),
        (&["parity", "--list"], true),
        (&render, false),
    ];
    for (args, to_stdout) in cases {
        let mut c = Command::new(bin);
        c.args(args);
        match to_stdout {
            true => c.stdout(full()).stderr(Stdio::piped()),
            false => c.stdout(Stdio::null()).stderr(full()),
        };
        let o = c.output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        if to_stdout {
            let e = stderr(&o);
            assert!(
                e.contains("writing to standard output") && e.contains("No space left"),
                "{args:?}: {e}"
            );
        }
    }
    // the image was written before the summary line failed: only the terminal was full
    assert!(png.exists());
}

// ---- a long run keeps what it finished ----

/// `bench thesis-5.1 thesis-5.2`, interrupted while thesis-5.2 measures: thesis-5.1's CSVs,
/// frames and a report that names thesis-5.2 as unfinished stay; nothing of thesis-5.2 and no
/// staged file is left. (Before: "14 unfinished output(s) removed" and an empty folder.)
#[test]
fn an_interrupted_bench_keeps_the_protocols_it_finished() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b");
    interrupt_bench_in_5_2(&[], &out, "thesis-5.1_summary.csv");
    let mut names: Vec<String> = walk(&out);
    names.sort();
    assert!(
        names
            .iter()
            .all(|n| !n.contains("5.2") && !n.ends_with(".tmp")),
        "{names:?}"
    );
    for kept in ["thesis-5.1.csv", "thesis-5.1_summary.csv", "report.md"] {
        assert!(names.iter().any(|n| n == kept), "{kept} missing: {names:?}");
    }
    assert!(
        names.iter().any(|n| n.starts_with("frames/thesis-5.1/")),
        "{names:?}"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("Unfinished run") && report.contains("thesis-5.2"),
        "{report}"
    );
    let csv = std::fs::read_to_string(out.join("thesis-5.1_summary.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        10,
        "nine configurations and the header: {csv}"
    );
}

/// `bench thesis-5.1 thesis-5.2` (8×8, one angle) with `extra` into `out`, sent SIGINT once
/// `kept` exists there (thesis-5.1 kept) while thesis-5.2 still runs: it exits with 130.
fn interrupt_bench_in_5_2(
    extra: &[&str],
    out: &std::path::Path,
    kept: &str,
) -> std::process::Output {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let mut child = Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .args(["bench", "thesis-5.1", "thesis-5.2", "--quiet"])
        .args(extra)
        .args(["--width", "8", "--height", "8", "--angles", "1"])
        .args(["--warmup", "0", "--out", out.to_str().unwrap()])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !out.join(kept).exists() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "ended before 5.1 was kept"
        );
        assert!(start.elapsed() < Duration::from_secs(300), "5.1 never kept");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(
        child.try_wait().unwrap().is_none(),
        "thesis-5.2 finished before the interrupt: the test needs a slower protocol"
    );
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    o
}

/// Every file below `root`, as a path relative to it.
fn walk(root: &std::path::Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut dirs = vec![root.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            match p.is_dir() {
                true => dirs.push(p),
                false => out.push(p.strip_prefix(root).unwrap().display().to_string()),
            }
        }
    }
    out
}

// ---- every limit before the memory ----

/// The `gpgpu-rt` binary run with `args` in `dir` (and `env`): its exit code, standard error
/// and peak resident memory in MB (from wait4, the child's own).
fn run_measured(dir: &std::path::Path, args: &[&str], env: &[(&str, &str)]) -> (i32, String, u64) {
    let err_path = dir.join("stderr.txt");
    #[allow(clippy::zombie_processes)] // reaped by wait4 below, which also gives its rusage
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .unwrap();
    let (mut status, mut usage) = (0, unsafe { std::mem::zeroed::<libc::rusage>() });
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as i32);
    let code = if libc::WIFEXITED(status) {
        libc::WEXITSTATUS(status)
    } else {
        -1
    };
    let err = std::fs::read_to_string(&err_path).unwrap();
    (code, err, usage.ru_maxrss as u64 / 1024)
}

const HEAD: &str = "[camera]\nposition = [0.0, 1.2, 4.0]\nlook_at = [0.0, 0.7, 0.0]\n\
                    up = [0.0, 1.0, 0.0]\nfov_y = 45.0\n[[light]]\nposition = [2.0, 4.0, 3.0]\n";

/// Scenes whose size shows in the file are refused from their counts, a texture from its
/// header: in well under 300 MB and a second each (before: 2.7 GB after 10 s for 3,000 teapots,
/// 2.2 GB after 12.5 s for 200 bunnies, a 1.7 GB peak for a 16000² texture under a 300 MB
/// limit, and `info` decoded the texture).
#[test]
fn limits_are_checked_before_the_memory_is_taken() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let models = scene_path("models");
    let objects = |n: usize, def: &str| -> String {
        let each = |i: usize| {
            format!(
                "[[object]]\n{def}\ntranslate = [{}.0, 0.0, {}.0]\n",
                i % 50,
                i / 50
            )
        };
        HEAD.to_string() + &(0..n).map(each).collect::<String>()
    };
    let teapot = format!(
        "type = \"teapot\"\npath = \"{}/teapot.bpt\"\ntessellation = 10",
        models.display()
    );
    let bunny = format!(
        "type = \"obj\"\npath = \"{}/stanford-bunny.obj\"",
        models.display()
    );
    std::fs::write(dir.join("teapots.toml"), objects(3000, &teapot)).unwrap();
    std::fs::write(dir.join("bunnies.toml"), objects(200, &bunny)).unwrap();
    std::fs::write(
        dir.join("tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    std::fs::write(dir.join("huge.png"), png_header_only(16000, 16000)).unwrap();
    std::fs::write(
        dir.join("tex.toml"),
        format!("{HEAD}[[object]]\ntype = \"obj\"\npath = \"tri.obj\"\ntexture = \"huge.png\"\n"),
    )
    .unwrap();
    let render = |scene: &str| {
        [
            "render", scene, "--width", "16", "--height", "16", "-o", "o.png",
        ]
        .map(String::from)
    };
    let max_ssbo = {
        let o = run(&["info", "--json"]);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["max_ssbo_block_size"].as_u64().unwrap()
    };
    let limited = [("GPGPU_RT_MEMORY_LIMIT", "300M")];
    let bunny_bytes = 200 * 69_451 * 48;
    type Case<'a> = (Vec<String>, &'a [(&'a str, &'a str)], &'a str);
    let cases: Vec<Case> = vec![
        (
            render("teapots.toml").into(),
            &[],
            "more than the 16777216 a scene may have",
        ),
        (
            render("bunnies.toml").into(),
            &limited,
            "GPGPU_RT_MEMORY_LIMIT",
        ),
        (
            render("tex.toml").into(),
            &limited,
            "16000x16000 texels (from the header)",
        ),
        (
            render("tex.toml").into(),
            &[],
            "cannot load texture huge.png",
        ),
    ];
    let gl_case = (
        render("bunnies.toml").to_vec(),
        &[][..],
        "GL_MAX_SHADER_STORAGE_BLOCK_SIZE",
    );
    let gl_applies = bunny_bytes > max_ssbo;
    for (args, env, says) in cases.into_iter().chain(gl_applies.then_some(gl_case)) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, err, mb) = run_measured(dir, &args, env);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(mb < 300, "{args:?}: {mb} MB before the refusal");
    }
    assert!(!dir.join("o.png").exists());
    // info reads the texture's header only: the image data (none here) is never decoded
    let (code, err, mb) = run_measured(dir, &["info", "tex.toml"], &[]);
    assert_eq!(code, 0, "{err}");
    assert!(mb < 300, "info: {mb} MB");
}

/// A PNG of `w`×`h` RGBA texels by its header; its image data is a few zero bytes, not the
/// image (a decoder fails on it, a header reader does not).
fn png_header_only(w: u32, h: u32) -> Vec<u8> {
    fn chunk(kind: &[u8], data: &[u8]) -> Vec<u8> {
        let mut crc = flate2::Crc::new();
        crc.update(kind);
        crc.update(data);
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend_from_slice(kind);
        c.extend_from_slice(data);
        c.extend_from_slice(&crc.sum().to_be_bytes());
        c
    }
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]);
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut z, &[0; 64]).unwrap();
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", &z.finish().unwrap()));
    png.extend(chunk(b"IEND", &[]));
    png
}

// ---- inputs against every output ----

/// Every output option given an input of the command as its target — the scene file, a model,
/// its material library, a texture — is refused, and the input is left byte for byte as it
/// was: `-o`, `--stats`, each file `--aov-dir` writes (the input inside the folder under that
/// file's name), `export-triangles -o`, `bench --out` and `parity --out`.
#[test]
fn no_output_option_writes_over_an_input() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let png = {
        let img = image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]));
        let mut c = std::io::Cursor::new(Vec::new());
        img.write_to(&mut c, image::ImageFormat::Png).unwrap();
        c.into_inner()
    };
    // each input kind under a name: in the folder itself, and inside an --aov-dir under the
    // name of a file it writes
    let aovs = dir.join("aovs");
    std::fs::create_dir(&aovs).unwrap();
    let inputs = |model: &str, mtl: &str, texture: &str| {
        let obj = format!(
            "mtllib {mtl}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n"
        );
        let scene = format!("{HEAD}[[object]]\ntype = \"obj\"\npath = \"{model}\"\n");
        (
            scene,
            obj,
            format!("newmtl m\nKd 1 1 1\nmap_Kd {texture}\n"),
        )
    };
    let (scene, obj, mtl) = inputs("m.obj", "m.mtl", "t.png");
    let files: Vec<(std::path::PathBuf, Vec<u8>)> = vec![
        (dir.join("s.toml"), scene.into_bytes()),
        (dir.join("m.obj"), obj.into_bytes()),
        (dir.join("m.mtl"), mtl.into_bytes()),
        (dir.join("t.png"), png.clone()),
    ];
    let (scene, obj, mtl) = inputs("normal.npy", "ray_origin.npy", "hit_t.npy");
    let in_aovs: Vec<(std::path::PathBuf, Vec<u8>)> = vec![
        (aovs.join("triangle_id.npy"), scene.into_bytes()),
        (aovs.join("normal.npy"), obj.into_bytes()),
        (aovs.join("ray_origin.npy"), mtl.into_bytes()),
        (aovs.join("hit_t.npy"), png),
    ];
    for (p, bytes) in files.iter().chain(&in_aovs) {
        std::fs::write(p, bytes).unwrap();
    }
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let small = ["--width", "8", "--height", "8"].map(String::from);
    let mut commands: Vec<(String, Vec<String>)> = Vec::new();
    for (input, _) in &files {
        let scene = s(&files[0].0);
        let render = |extra: &[String]| {
            let mut a = vec!["render".to_string(), scene.clone()];
            a.extend(small.iter().cloned());
            a.extend(extra.iter().cloned());
            a
        };
        let name = input.file_name().unwrap().to_string_lossy().into_owned();
        let png_out = s(&dir.join("out.png"));
        commands.push((format!("-o {name}"), render(&["-o".into(), s(input)])));
        let stats = ["-o".into(), png_out, "--stats".into(), s(input)];
        commands.push((format!("--stats {name}"), render(&stats)));
        let export = vec![
            "export-triangles".into(),
            scene.clone(),
            "-o".into(),
            s(input),
        ];
        commands.push((format!("export-triangles -o {name}"), export));
        let bench = [
            "bench",
            "thesis-5.1",
            "--angles",
            "1",
            "--warmup",
            "0",
            "--out",
        ];
        let mut bench: Vec<String> = bench.map(String::from).to_vec();
        bench.splice(2..2, small.iter().cloned());
        bench.push(s(input));
        commands.push((format!("bench --out {name}"), bench));
        let parity = vec![
            "parity".into(),
            "--only".into(),
            "base.teapot1".into(),
            "--out".into(),
            s(input),
        ];
        commands.push((format!("parity --out {name}"), parity));
    }
    let aov_scene = s(&in_aovs[0].0);
    let mut aov = vec!["render".to_string(), aov_scene];
    aov.extend(small.iter().cloned());
    aov.extend([
        "-o".into(),
        s(&dir.join("out2.png")),
        "--aov-dir".into(),
        s(&aovs),
    ]);
    commands.push(("--aov-dir over its inputs".into(), aov));
    for (what, args) in &commands {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run(&args);
        assert!(!o.status.success(), "{what}: accepted");
        for (p, bytes) in files.iter().chain(&in_aovs) {
            assert_eq!(
                &std::fs::read(p).unwrap(),
                bytes,
                "{what}: {} changed",
                p.display()
            );
        }
    }
}

/// A loop-limit refusal names what to change: 20,000 overlapping squares under the two-level
/// BVH pass llvmpipe's loop limit, and the message names --bvh-instances and the one-tree
/// alternative (before: "shader loops stopped early … 65535 iterations" and nothing more).
#[test]
fn a_loop_limit_refusal_names_the_option_that_avoids_it() {
    let d = tempfile::tempdir().unwrap();
    let each = |i: usize| {
        format!(
            "[[object]]\ntype = \"square\"\nsize = 2.0\nrotate = [{}.0, {}.0, 0.0]\n",
            (i * 7) % 90,
            (i * 13) % 360
        )
    };
    let scene = d.path().join("overlap.toml");
    let text = HEAD.to_string() + &(0..20_000).map(each).collect::<String>();
    std::fs::write(&scene, text).unwrap();
    let png = d.path().join("x.png");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--tracer",
        "bvh",
        "--bvh-instances",
        "--width",
        "16",
        "--height",
        "16",
        "-o",
        png.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    if o.status.success() {
        // a driver that keeps no loop limit renders it: only llvmpipe (and zink over
        // lavapipe) must refuse
        assert!(
            !e.contains("llvmpipe"),
            "rendered on llvmpipe past its loop limit: {e}"
        );
        return;
    }
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("loops stopped early") && e.contains("render without --bvh-instances"),
        "{e}"
    );
}

/// A shard keeps its finished protocols too: interrupted in thesis-5.2, its folder holds
/// thesis-5.1's rows and a `shard.json` naming thesis-5.2 as pending, and `bench merge`
/// refuses that shard as cut short rather than report a run with a protocol missing.
#[test]
fn an_interrupted_shard_keeps_its_protocols_and_the_merge_refuses_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s1");
    interrupt_bench_in_5_2(&["--shard", "1/1"], &out, "shard.json");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("shard.json")).unwrap()).unwrap();
    assert_eq!(
        manifest["pending"],
        serde_json::json!(["thesis-5.2"]),
        "{manifest}"
    );
    assert_eq!(
        manifest["configs"].as_object().unwrap().len(),
        9,
        "thesis-5.1's nine"
    );
    assert!(out.join("thesis-5.1.csv").exists());
    let merged = dir.path().join("m");
    let o = run(&[
        "bench",
        "merge",
        out.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("cut short before thesis-5.2"),
        "{}",
        stderr(&o)
    );
}
