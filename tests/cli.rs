//! The command line as other tools use it: render with AOVs and statistics, export-triangles,
//! info --json, and clear errors with a non-zero exit on bad input.

mod common;

use common::{copy_dir, run, stderr};

use std::path::Path;
use std::process::Output;

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .display()
        .to_string()
}

fn read_npy_f32(p: &Path) -> (Vec<u64>, Vec<f32>) {
    let bytes = std::fs::read(p).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    (npy.shape().to_vec(), npy.into_vec::<f32>().unwrap())
}

fn read_npy_i32(p: &Path) -> (Vec<u64>, Vec<i32>) {
    let bytes = std::fs::read(p).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    (npy.shape().to_vec(), npy.into_vec::<i32>().unwrap())
}

#[test]
fn render_writes_png_aovs_and_stats() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let png = d.join("out.png");
    let stats = d.join("s.json");
    let aov = d.join("aov");
    let (w, h) = (40u64, 24u64);
    let o = run(&[
        "render",
        &scene("cow.toml"),
        "--tracer",
        "base",
        "-o",
        png.to_str().unwrap(),
        "--width",
        "40",
        "--height",
        "24",
        "--aov-dir",
        aov.to_str().unwrap(),
        "--stats",
        stats.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (40, 24));

    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    for key in [
        "renderer",
        "width",
        "height",
        "triangles",
        "lights",
        "tracer",
        "triangle_tests",
        "gpu_ms",
    ] {
        assert!(s.get(key).is_some(), "stats lack {key}: {s}");
    }
    assert_eq!(s["triangles"], 5804);
    assert_eq!(s["tracer"], "base");
    // one light, no reflection on the cow: every primary ray tests every triangle once
    assert_eq!(
        s["triangle_tests"]["intersect1"].as_u64().unwrap(),
        w * h * 5804
    );
    assert!(s["triangle_tests"]["intersect2"].as_u64().unwrap() > 0);
    assert!(s["gpu_ms"]["intersect1"].as_f64().unwrap() > 0.0);

    let (shape, t) = read_npy_f32(&aov.join("hit_t.npy"));
    assert_eq!(shape, vec![h, w]);
    let (shape, ids) = read_npy_i32(&aov.join("triangle_id.npy"));
    assert_eq!(shape, vec![h, w]);
    let (shape, dirs) = read_npy_f32(&aov.join("ray_direction.npy"));
    assert_eq!(shape, vec![h, w, 3]);
    let (_, origins) = read_npy_f32(&aov.join("ray_origin.npy"));
    let (shape, normals) = read_npy_f32(&aov.join("normal.npy"));
    assert_eq!(shape, vec![h, w, 3]);
    let hits = ids.iter().filter(|&&i| i >= 0).count();
    assert!(
        hits > 0 && hits < ids.len(),
        "the cow covers part of the image"
    );
    // misses: +inf and -1; hits: finite t and an id below the triangle count
    for (k, (&id, &tk)) in ids.iter().zip(&t).enumerate() {
        if id < 0 {
            assert_eq!(id, -1);
            assert!(tk.is_infinite() && tk > 0.0);
        } else {
            assert!(id < 5804 && tk.is_finite() && tk > 0.0);
            let n = &normals[3 * k..3 * k + 3];
            assert!(((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-3);
        }
        let dv = &dirs[3 * k..3 * k + 3];
        assert!(((dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]).sqrt() - 1.0).abs() < 1e-5);
    }
    // row 0 is the top row: the camera looks down a little, so ray directions in row 0 point
    // higher than in the last row
    assert!(dirs[1] > dirs[3 * ((h - 1) * w) as usize + 1]);
    // the hit point o + t·d lies on the reported triangle (export-triangles gives the vertices)
    let tris = d.join("tris.npy");
    let o2 = run(&[
        "export-triangles",
        &scene("cow.toml"),
        "-o",
        tris.to_str().unwrap(),
    ]);
    assert!(o2.status.success(), "{}", stderr(&o2));
    let (shape, v) = read_npy_f32(&tris);
    assert_eq!(shape, vec![5804, 3, 3]);
    let k = ids.iter().position(|&i| i >= 0).unwrap();
    let id = ids[k] as usize;
    let p: Vec<f32> = (0..3)
        .map(|c| origins[3 * k + c] + t[k] * dirs[3 * k + c])
        .collect();
    let tri: Vec<&[f32]> = (0..3)
        .map(|j| &v[9 * id + 3 * j..9 * id + 3 * j + 3])
        .collect();
    let sub = |a: &[f32], b: &[f32]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let (e1, e2, ep) = (sub(tri[1], tri[0]), sub(tri[2], tri[0]), sub(&p, tri[0]));
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let dist = (n[0] * ep[0] + n[1] * ep[1] + n[2] * ep[2]).abs() / len;
    assert!(dist < 1e-4, "hit point is {dist} off its triangle's plane");
}

#[test]
fn info_json_reports_gl_and_scene_counts() {
    let o = run(&["info", &scene("teapot3.toml"), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["triangles"], 27392, "thesis ch. 5.1: 8192 + 3 × 6400");
    assert_eq!(v["lights"], 1);
    // where the shadow feelers go (tools/embree_peer.py casts them with Embree)
    assert_eq!(v["light_positions"], serde_json::json!([[3.0, 5.0, 3.0]]));
    assert_eq!(v["shadow_offset"].as_f64(), Some(0.02f32 as f64));
    assert!(v["version"].as_str().unwrap().starts_with("4."), "{v}");
    assert!(!v["renderer"].as_str().unwrap().is_empty());
    let o = run(&["info", &scene("teapot6.toml"), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["triangles"], 46592, "thesis ch. 5.1: 8192 + 6 × 6400");
    let o = run(&["info", &scene("bunny_area.toml"), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        v["triangles"],
        69451 + 2 * 16 * 16,
        "the bunny and a 16×16-quad floor"
    );
    assert_eq!(
        (v["lights"].as_u64(), v["area_lights"].as_u64()),
        (Some(0), Some(1))
    );
}

fn assert_fails(o: &Output, needles: &[&str]) {
    assert!(!o.status.success(), "should fail");
    let e = stderr(o);
    for n in needles {
        assert!(e.contains(n), "message lacks `{n}`: {e}");
    }
    assert!(!e.contains("panicked"), "panic: {e}");
}

/// `gpgpu-rt render SCENE -o /dev/null --width 8 --height 8 EXTRA`.
fn render_8x8(scene: &str, extra: &[&str]) -> Output {
    let tiny = [
        "render",
        scene,
        "-o",
        "/dev/null",
        "--width",
        "8",
        "--height",
        "8",
    ];
    run(&[&tiny[..], extra].concat())
}

#[test]
fn bad_input_fails_with_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // missing scene file
    let missing = d.join("nope.toml");
    assert_fails(
        &run(&["render", missing.to_str().unwrap(), "-o", "/dev/null"]),
        &["nope.toml"],
    );
    // TOML syntax error on line 3
    let bad = d.join("bad.toml");
    std::fs::write(
        &bad,
        "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, oops]\n\n[[object]]\ntype = \"floor\"\n",
    )
    .unwrap();
    assert_fails(&run(&["info", bad.to_str().unwrap()]), &["bad.toml:3"]);
    // unknown key, reported at its line
    std::fs::write(&bad, "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\nfocal = 3\n[[object]]\ntype = \"floor\"\n").unwrap();
    assert_fails(
        &run(&["info", bad.to_str().unwrap()]),
        &["bad.toml:4", "focal"],
    );
    // malformed OBJ: the bad line is named
    std::fs::write(d.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n").unwrap();
    std::fs::write(&bad, "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n[[object]]\ntype = \"obj\"\npath = \"m.obj\"\n").unwrap();
    assert_fails(&run(&["info", bad.to_str().unwrap()]), &["m.obj:3"]);
    // OBJ face index out of range
    std::fs::write(
        d.join("m.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
    )
    .unwrap();
    assert_fails(&run(&["info", bad.to_str().unwrap()]), &["m.obj:5"]);
    // non-finite numbers (TOML has nan and inf) and absurd procedural sizes name their line
    let head = "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n";
    for (body, line, needle) in [
        (
            "[[light]]\nposition = [nan, 1, 1]\n[[object]]\ntype = \"floor\"\n",
            4,
            "finite",
        ),
        (
            "[[object]]\ntype = \"floor\"\ntranslate = [inf, 0, 0]\n",
            5,
            "finite",
        ),
        (
            "[[object]]\ntype = \"floor\"\nquads = 100000\n",
            5,
            "at most",
        ),
        (
            "[render]\nambient = [nan, 0, 0]\n[[object]]\ntype = \"floor\"\n",
            5,
            "finite",
        ),
    ] {
        std::fs::write(&bad, format!("{head}{body}")).unwrap();
        let at = format!("bad.toml:{line}");
        assert_fails(&run(&["info", bad.to_str().unwrap()]), &[&at, needle]);
    }
    std::fs::write(
        &bad,
        "[camera]\nposition = [0, nan, 3]\nlook_at = [0, 0, 0]\n[[object]]\ntype = \"floor\"\n",
    )
    .unwrap();
    assert_fails(
        &run(&["info", bad.to_str().unwrap()]),
        &["bad.toml:2", "finite"],
    );
    // a vertex with nan
    std::fs::write(d.join("m.obj"), "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(&bad, "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n[[object]]\ntype = \"obj\"\npath = \"m.obj\"\n").unwrap();
    assert_fails(
        &run(&["info", bad.to_str().unwrap()]),
        &["m.obj:2", "non-finite"],
    );
    // missing OBJ
    std::fs::write(&bad, "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n[[object]]\ntype = \"obj\"\npath = \"gone.obj\"\n").unwrap();
    assert_fails(&run(&["info", bad.to_str().unwrap()]), &["gone.obj"]);
    // unknown option
    assert_fails(
        &run(&["render", &scene("cow.toml"), "--frobnicate"]),
        &["--frobnicate"],
    );
    // bad tile size
    assert_fails(
        &render_8x8(&scene("cow.toml"), &["--tile", "12"]),
        &["--tile"],
    );
    // more lights than the thesis' RGBA shadow flags hold
    let mut text = std::fs::read_to_string(scene("cow.toml")).unwrap();
    text = text.replace("models/cow.obj", &scene("models/cow.obj"));
    for i in 0..5 {
        text.push_str(&format!("\n[[light]]\nposition = [{i}.0, 3.0, 1.0]\n"));
    }
    std::fs::write(&bad, text).unwrap();
    assert_fails(
        &render_8x8(bad.to_str().unwrap(), &["--shadow-flags", "rgba"]),
        &["6 lights", "at most 4"],
    );
    // buffers beyond the GL limits: named, with the limit
    assert_fails(
        &render_8x8(
            &scene("cow.toml"),
            &[
                "--tracer",
                "grid",
                "--grid-variant",
                "thesis",
                "--grid",
                "64",
                "--voxel-array-length",
                "4096",
            ],
        ),
        &["voxelslist", "GL_MAX_SHADER_STORAGE_BLOCK_SIZE"],
    );
    assert_fails(
        &run(&[
            "render",
            &scene("cow.toml"),
            "--tracer",
            "grid",
            "--grid",
            "abc",
        ]),
        &["abc"],
    );
    assert_fails(
        &run(&[
            "render",
            &scene("cow.toml"),
            "-o",
            "/dev/null",
            "--tracer",
            "grid",
            "--grid-variant",
            "thesis",
            "--grid",
            "65",
        ]),
        &["--grid 65", "1..=64"],
    );
    // a GLSL error in an edited kernel names the file and line
    let glsl = d.join("glsl");
    copy_dir(&Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl"), &glsl);
    let shading = glsl.join("mueller2015/shading.comp");
    let src = std::fs::read_to_string(&shading).unwrap();
    let line = src.lines().position(|l| l.contains("void main()")).unwrap() + 1;
    std::fs::write(
        &shading,
        src.replacen(
            "void main()",
            "void main() { undefined_thing = 1; }\nvoid main2()",
            1,
        ),
    )
    .unwrap();
    assert_fails(
        &render_8x8(&scene("cow.toml"), &["--glsl-dir", glsl.to_str().unwrap()]),
        &[&format!("shading.comp:{line}")],
    );
}

#[test]
fn every_shipped_scene_renders() {
    let dir = tempfile::tempdir().unwrap();
    for s in std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")).unwrap() {
        let p = s.unwrap().path();
        if p.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let out = dir.path().join("x.png");
        let o = run(&[
            "render",
            p.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--width",
            "16",
            "--height",
            "16",
        ]);
        assert!(o.status.success(), "{}: {}", p.display(), stderr(&o));
        assert!(out.exists());
    }
}

/// Options of the pipeline a render does not use are refused, not silently ignored: the ray
/// tracer's options with soft shadows (from `--shadows` or the scene's `render.shadows`), the
/// soft shadows' options without them.
#[test]
fn options_of_the_other_pipeline_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let png = png.to_str().unwrap();
    let area = scene("bunny_area.toml");
    let small = ["--width", "16", "--height", "16", "-o", png];
    let with = |extra: &[&str]| {
        let mut a = vec!["render", area.as_str()];
        a.extend_from_slice(&small);
        a.extend_from_slice(extra);
        run(&a)
    };
    // an explicit --tracer wins over the scene's render.shadows, and says so
    let o = with(&["--tracer", "grid"]);
    assert!(o.status.success(), "{}", stderr(&o));
    for needle in [
        "note: --tracer grid renders the point lights",
        "bunny_area.toml",
    ] {
        assert!(stderr(&o).contains(needle), "{needle}: {}", stderr(&o));
    }
    assert!(stderr(&o).contains("grid-exact tracer"), "{}", stderr(&o));
    assert!(stderr(&o).contains("no [[light]]"), "{}", stderr(&o));
    assert_fails(
        &with(&["--shadows", "exact", "--grid", "8", "--refl-depth", "1"]),
        &["--grid, --refl-depth do not apply", "from --shadows"],
    );
    let cow = scene("cow.toml");
    // the light samples belong to Müller 2015's pipeline and Klee 2016's, not the stream's
    let mut a = vec![
        "render",
        cow.as_str(),
        "--light-samples",
        "3x3",
        "--tracer",
        "stream",
    ];
    a.extend_from_slice(&small);
    assert_fails(&run(&a), &["--light-samples does not apply", "--shadows"]);
    // the streaming tracer's switches, with another tracer
    for flag in [
        "--stream-no-mask",
        "--stream-naive-shadows",
        "--stream-single-sided",
    ] {
        let mut a = vec!["render", cow.as_str(), "--tracer", "grid", flag];
        a.extend_from_slice(&small);
        assert_fails(
            &run(&a),
            &[flag, "applies to stream (--tracer stream) only"],
        );
    }
    // the defaults of both pipelines' options are not "given": these render
    let o = with(&["--tile", "64", "--frames", "2", "--light-samples", "2x2"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A PNG whose header claims `w`×`h` pixels, with a few bytes of image data: a decoder that
/// believed it would allocate w·h·3 bytes.
fn png_claiming(w: u32, h: u32) -> Vec<u8> {
    fn chunk(kind: &[u8], data: &[u8]) -> Vec<u8> {
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        let mut out = (data.len() as u32).to_be_bytes().to_vec();
        out.extend_from_slice(&body);
        out.extend_from_slice(&crc32(&body).to_be_bytes());
        out
    }
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    ));
    png.extend(chunk(b"IEND", &[]));
    png
}

#[test]
fn counts_beyond_their_bounds_are_refused_with_the_bound() {
    let scene = format!("{}/scenes/cow.toml", env!("CARGO_MANIFEST_DIR"));
    for (args, needles) in [
        (
            vec!["--refl-depth", "4294967295"],
            ["--refl-depth", "0..=16"],
        ),
        (vec!["--frames", "100001"], ["--frames", "1..=100000"]),
        (vec!["--width", "16385"], ["--width", "1..=16384"]),
        (vec!["--grid", "1025"], ["--grid", "1 to 1024"]),
        (
            vec!["--voxel-array-length", "65537"],
            ["--voxel-array-length", "1..=65536"],
        ),
    ] {
        let mut all = vec!["render", scene.as_str(), "-o", "/dev/null"];
        all.extend(args);
        assert_fails(&run(&all), &needles);
    }
    assert_fails(
        &run(&["bench", "thesis-5.1", "--angles", "3601"]),
        &["--angles", "1..=3600"],
    );
    // the bounds are said in --help
    let help = String::from_utf8_lossy(&run(&["render", "--help"]).stdout).into_owned();
    for said in [
        "0 to 16",
        "1 to 16384",
        "1 to 100000",
        "1 to 1024",
        "1 to 65536",
    ] {
        assert!(help.contains(said), "render --help lacks {said:?}");
    }

    // a scene file: the limit with file and line
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let head = "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n";
    let bad = d.join("deep.toml");
    std::fs::write(
        &bad,
        format!("{head}[render]\nrefl_depth = 17\n[[object]]\ntype = \"floor\"\n"),
    )
    .unwrap();
    assert_fails(
        &run(&["info", bad.to_str().unwrap()]),
        &["deep.toml:5", "refl_depth", "0 to 16"],
    );

    // a small file that claims a 20000×20000 texture is refused before it is decoded
    std::fs::write(d.join("big.png"), png_claiming(20000, 20000)).unwrap();
    let tex = d.join("tex.toml");
    std::fs::write(
        &tex,
        format!("{head}[[object]]\ntype = \"floor\"\ntexture = \"big.png\"\n"),
    )
    .unwrap();
    let start = std::time::Instant::now();
    assert_fails(
        &run(&["info", tex.to_str().unwrap()]),
        &["tex.toml:5", "big.png", "16384x16384"],
    );
    assert!(start.elapsed().as_secs() < 10, "refused without decoding");
}
