//! Hostile input (issue 14, classes 1, 2 and 6): sizes a file claims are checked against its
//! length, input-controlled allocations against the host's memory and the GL limits before they
//! are made; NaN and inf never reach an uploaded array; messages name the right file, line and
//! thing. CPU-side through the library where possible (fast); the binary where the environment
//! or GL is involved.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use gpgpu_rt::scene::{Scene, SceneError};

const BIN: &str = env!("CARGO_BIN_EXE_gpgpu-rt");
const HEAD: &str = "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n";

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models")
}

/// Write `files` (name, text) and a scene `HEAD + body` into `dir`; load the scene.
fn load(dir: &Path, body: &str, files: &[(&str, &str)]) -> Result<Scene, SceneError> {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let path = dir.join("s.toml");
    std::fs::write(&path, format!("{HEAD}{body}")).unwrap();
    Scene::load(&path)
}

/// The error of loading, which must name `at` (`file:line` or a file) and every needle.
fn refused(dir: &Path, body: &str, files: &[(&str, &str)], at: &str, needles: &[&str]) {
    let e = load(dir, body, files).expect_err("should be refused");
    let text = e.to_string();
    assert!(text.contains(at), "`{at}` not named: {text}");
    for n in needles {
        assert!(text.contains(n), "message lacks `{n}`: {text}");
    }
}

fn obj_body(name: &str) -> String {
    format!("[[object]]\ntype = \"obj\"\npath = \"{name}\"\n")
}

/// Run the binary with `GPGPU_RT_MEMORY_LIMIT` = `limit` (if any); it must exit within `secs`.
fn run(args: &[&str], limit: Option<&str>, secs: u64) -> Output {
    let mut c = Command::new(BIN);
    c.args(args);
    match limit {
        Some(l) => c.env("GPGPU_RT_MEMORY_LIMIT", l),
        None => c.env_remove("GPGPU_RT_MEMORY_LIMIT"),
    };
    let t = Instant::now();
    let o = c.output().expect("the binary runs");
    assert!(
        t.elapsed() < Duration::from_secs(secs),
        "{args:?} took {:?}",
        t.elapsed()
    );
    o
}

fn assert_fails(o: &Output, needles: &[&str]) {
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "should fail: {e}");
    for n in needles {
        assert!(e.contains(n), "message lacks `{n}`: {e}");
    }
    assert!(
        !e.contains("panicked") && !e.contains("memory allocation"),
        "{e}"
    );
}

// ---- class 1: sizes from files, allocations estimated first ----

#[test]
fn bpt_patch_count_is_checked_against_the_file() {
    let d = tempfile::tempdir().unwrap();
    let teapot = std::fs::read_to_string(models().join("teapot.bpt")).unwrap();
    let body = "[[object]]\ntype = \"teapot\"\npath = \"t.bpt\"\n";
    let rest = teapot.split_once('\n').unwrap().1;
    for claim in ["4000000000", "18446744073709551615", "33"] {
        let bpt = format!("{claim}\n{rest}");
        let needle = format!("claims {claim} patches");
        refused(
            d.path(),
            body,
            &[("t.bpt", &bpt)],
            "t.bpt:1",
            &[&needle, "at most 32"],
        );
    }
    // the shipped file's 32 patches load
    assert!(load(d.path(), body, &[("t.bpt", &teapot)]).is_ok());
}

#[test]
fn bpt_triangles_are_checked_with_the_files_patch_count() {
    // 64 patches (the 32 twice) at tessellation 800: 81,920,000 triangles, beyond the cap,
    // although 32 patches would be within it
    let d = tempfile::tempdir().unwrap();
    let teapot = std::fs::read_to_string(models().join("teapot.bpt")).unwrap();
    let rest = teapot.split_once('\n').unwrap().1;
    let bpt = format!("64\n{rest}{rest}");
    let body = "[[object]]\ntype = \"teapot\"\npath = \"t.bpt\"\ntessellation = 800\n";
    let t = Instant::now();
    refused(
        d.path(),
        body,
        &[("t.bpt", &bpt)],
        "t.bpt",
        &[
            "64 patches at tessellation 800",
            "81920000 triangles",
            "at most 67108864",
        ],
    );
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
}

#[test]
fn ply_element_counts_are_checked_against_the_file() {
    let d = tempfile::tempdir().unwrap();
    let ascii = "ply\nformat ascii 1.0\nelement vertex VC\nproperty float x\nproperty float y\n\
                 property float z\nelement face FC\nproperty list uchar int vertex_indices\n\
                 end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let body = "[[object]]\ntype = \"ply\"\npath = \"m.ply\"\n";
    let ok = ascii.replace("VC", "3").replace("FC", "1");
    assert_eq!(
        load(d.path(), body, &[("m.ply", &ok)])
            .unwrap()
            .triangle_count(),
        1
    );
    for (vc, fc, element) in [("4000000000", "1", "vertex"), ("3", "4294967295", "face")] {
        let ply = ascii.replace("VC", vc).replace("FC", fc);
        let needle = format!(
            "claims {} elements `{element}`",
            if element == "vertex" { vc } else { fc }
        );
        refused(
            d.path(),
            body,
            &[("m.ply", &ply)],
            "m.ply",
            &[&needle, "after the header"],
        );
    }
    // binary: 12 bytes a vertex
    let mut bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n\
                    property float x\nproperty float y\nproperty float z\nend_header\n"
        .to_vec();
    bin.extend_from_slice(&[0u8; 36]);
    std::fs::write(d.path().join("b.ply"), &bin).unwrap();
    let body = "[[object]]\ntype = \"ply\"\npath = \"b.ply\"\n";
    refused(
        d.path(),
        body,
        &[],
        "b.ply",
        &["12000000000 bytes of binary data", "36 bytes"],
    );
}

#[test]
fn procedural_objects_are_estimated_against_host_memory_first() {
    let d = tempfile::tempdir().unwrap();
    let s = d.path().join("s.toml");
    // 2·4096² = 33,554,432 triangles: about 17 GiB with the copies for the GPU
    std::fs::write(
        &s,
        format!("{HEAD}[[object]]\ntype = \"floor\"\nquads = 4096\n"),
    )
    .unwrap();
    let o = run(&["info", s.to_str().unwrap()], Some("1G"), 10);
    assert_fails(
        &o,
        &[
            "s.toml:5",
            "quads = 4096",
            "33554432 triangles",
            "1.0 GiB of GPGPU_RT_MEMORY_LIMIT",
        ],
    );
    // the same for a sphere and a square
    for (body, needle) in [
        (
            "type = \"sphere\"\nstacks = 2000\nslices = 2000\n",
            "stacks = 2000 with slices = 2000",
        ),
        ("type = \"square\"\nlevel = 11\n", "level = 11"),
    ] {
        std::fs::write(&s, format!("{HEAD}[[object]]\n{body}")).unwrap();
        let o = run(&["info", s.to_str().unwrap()], Some("100M"), 10);
        assert_fails(&o, &["s.toml:5", needle, "GPGPU_RT_MEMORY_LIMIT"]);
    }
}

#[test]
fn model_files_are_estimated_against_host_memory_before_reading() {
    let d = tempfile::tempdir().unwrap();
    let s = d.path().join("s.toml");
    // (a teapot of tessellation 1 is within the limit, its file's 7.5 KB read are not)
    for (kind, file, extra) in [
        ("obj", "stanford-bunny.obj", ""),
        ("ply", "dragon_vrip_res2.ply.gz", ""),
        ("teapot", "teapot.bpt", "tessellation = 1\n"),
    ] {
        let path = models().join(file);
        let body = format!(
            "[[object]]\ntype = \"{kind}\"\npath = \"{}\"\n{extra}",
            path.display()
        );
        std::fs::write(&s, format!("{HEAD}{body}")).unwrap();
        let o = run(&["info", s.to_str().unwrap()], Some("64K"), 10);
        assert_fails(
            &o,
            &[file, "reading this", "64.0 KiB of GPGPU_RT_MEMORY_LIMIT"],
        );
    }
}

#[test]
fn scene_buffers_beyond_the_gl_limit_are_refused_before_upload() {
    // 2·1200² = 2,880,000 triangles: 138 MB in the vertex SSBO, beyond llvmpipe's 128 MiB
    let d = tempfile::tempdir().unwrap();
    let s = d.path().join("s.toml");
    let light = "[[light]]\nposition = [0, 3, 0]\n";
    std::fs::write(
        &s,
        format!("{HEAD}{light}[[object]]\ntype = \"floor\"\nquads = 1200\n"),
    )
    .unwrap();
    let o = run(
        &[
            "render",
            s.to_str().unwrap(),
            "-o",
            d.path().join("o.png").to_str().unwrap(),
            "--width",
            "8",
            "--height",
            "8",
            "--tracer",
            "base",
        ],
        None,
        60,
    );
    assert_fails(
        &o,
        &[
            "2880000 triangles",
            "`vertex`",
            "GL_MAX_SHADER_STORAGE_BLOCK_SIZE",
        ],
    );
}

// ---- class 2: NaN and inf never reach the GPU ----

#[test]
fn non_finite_bpt_control_points_name_their_line() {
    let d = tempfile::tempdir().unwrap();
    let teapot = std::fs::read_to_string(models().join("teapot.bpt")).unwrap();
    let body = "[[object]]\ntype = \"teapot\"\npath = \"t.bpt\"\n";
    for bad in ["nan", "inf", "-inf", "1e39"] {
        let mut lines: Vec<String> = teapot.lines().map(String::from).collect();
        lines[40] = format!("0.5 {bad} 1.0");
        let bpt = lines.join("\n");
        refused(
            d.path(),
            body,
            &[("t.bpt", &bpt)],
            "t.bpt:41",
            &["non-finite"],
        );
    }
}

#[test]
fn fit_of_an_object_without_extent_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let obj = "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n";
    let body = format!("{}fit = 2\n", obj_body("z.obj"));
    refused(
        d.path(),
        &body,
        &[("z.obj", obj)],
        "s.toml:5",
        &["fit = 2", "extent is 0"],
    );
    // tiny but not zero: the scale overflows, also refused
    let obj = "v 0 0 0\nv 1e-45 0 0\nv 0 0 0\nf 1 2 3\n";
    refused(d.path(), &body, &[("z.obj", obj)], "s.toml:5", &["fit = 2"]);
}

#[test]
fn non_finite_obj_vertex_colours_name_their_line() {
    let d = tempfile::tempdir().unwrap();
    for bad in ["nan", "inf", "1e39"] {
        let obj = format!("v 0 0 0 1 1 1\nv 1 0 0 1 {bad} 1\nv 0 1 0 1 1 1\nf 1 2 3\n");
        refused(
            d.path(),
            &obj_body("c.obj"),
            &[("c.obj", &obj)],
            "c.obj:2",
            &["non-finite"],
        );
    }
}

#[test]
fn non_finite_mtl_numbers_name_the_mtl_file_and_line() {
    let d = tempfile::tempdir().unwrap();
    let obj = "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    for (key, value) in [
        ("Kd", "1 nan 0"),
        ("Ks", "inf 0 0"),
        ("Ka", "0 0 1e39"),
        ("Ns", "nan"),
        ("d", "-inf"),
    ] {
        let mtl = format!("newmtl a\nKd 0.5 0.5 0.5\n{key} {value}\n");
        let files = [("o.obj", obj), ("m.mtl", mtl.as_str())];
        refused(d.path(), &obj_body("o.obj"), &files, "m.mtl:3", &[key]);
    }
}

#[test]
fn transforms_that_overflow_are_refused_naming_the_object() {
    let d = tempfile::tempdir().unwrap();
    let body = "[[object]]\ntype = \"floor\"\nname = \"big\"\nscale = 3e38\n";
    refused(
        d.path(),
        body,
        &[],
        "s.toml:5",
        &["`big`", "world-space position"],
    );
    let body = "[[object]]\ntype = \"floor\"\ntranslate = [3e38, 0, 0]\nscale = [3e38, 1, 1]\n";
    refused(d.path(), body, &[], "s.toml:5", &["world-space position"]);
}

#[test]
fn the_upload_check_catches_scenes_built_by_code() {
    let d = tempfile::tempdir().unwrap();
    let mut scene = load(d.path(), "[[object]]\ntype = \"floor\"\nquads = 2\n", &[]).unwrap();
    assert!(gpgpu_rt::scene::validate::scene(&scene).is_ok());
    let ok = scene.clone();
    for (k, edit) in [
        |s: &mut Scene| s.objects[0].mesh.normals[3].y = f32::NAN,
        |s: &mut Scene| s.objects[0].mesh.colors[0].x = f32::INFINITY,
        |s: &mut Scene| s.objects[0].mesh.texcoords[1].x = f32::NAN,
        |s: &mut Scene| s.objects[0].mesh.triangle_material[0] = 7,
        |s: &mut Scene| s.materials[0].shininess = f32::NAN,
        |s: &mut Scene| s.objects[0].model.w_axis.x = f32::NAN,
    ]
    .into_iter()
    .enumerate()
    {
        scene = ok.clone();
        edit(&mut scene);
        assert!(
            gpgpu_rt::scene::validate::scene(&scene).is_err(),
            "edit {k} passed"
        );
    }
}

// ---- class 6: messages that name the right thing ----

#[test]
fn too_many_lights_suggests_bits_only_where_bits_would_hold_them() {
    use gpgpu_rt::pipeline::mueller2015::{too_many_lights, ShadowFlags};
    let d = tempfile::tempdir().unwrap();
    let mut scene = load(d.path(), "[[object]]\ntype = \"floor\"\nquads = 1\n", &[]).unwrap();
    let light = gpgpu_rt::scene::Light {
        position: glam::Vec3::Y,
        color: glam::Vec3::ONE,
    };
    scene.lights = vec![light.clone(); 6];
    let m = too_many_lights(&scene, ShadowFlags::Rgba);
    assert!(
        m.contains("6 lights") && m.contains("use --shadow-flags bits"),
        "{m}"
    );
    scene.lights = vec![light; 200];
    for flags in [ShadowFlags::Bits, ShadowFlags::Rgba] {
        let m = too_many_lights(&scene, flags);
        assert!(!m.contains("use --shadow-flags bits"), "{m}");
        assert!(
            m.contains("200 lights") && m.contains("fewer lights"),
            "{m}"
        );
    }
    // through the command line: 200 lights with bits
    let lights: String = (0..200)
        .map(|i| format!("[[light]]\nposition = [{i}, 3, 0]\n"))
        .collect();
    let s = d.path().join("l.toml");
    std::fs::write(&s, format!("{HEAD}{lights}[[object]]\ntype = \"floor\"\n")).unwrap();
    let out = d.path().join("o.png");
    let args = ["render", s.to_str().unwrap(), "-o", out.to_str().unwrap()];
    let o = run(
        &[
            &args[..],
            &["--width", "8", "--height", "8", "--shadow-flags", "bits"],
        ]
        .concat(),
        None,
        60,
    );
    assert_fails(
        &o,
        &[
            "200 lights",
            "--shadow-flags bits holds at most 128",
            "fewer lights",
        ],
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("use --shadow-flags bits"));
}

#[test]
fn camera_and_render_errors_cite_the_keys_line() {
    let d = tempfile::tempdir().unwrap();
    let scene = |camera: &str, render: &str| {
        format!(
            "# a comment\n[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n{camera}\n\
             [render]\nwidth = 8\n{render}\n[[object]]\ntype = \"floor\"\n"
        )
    };
    let path = d.path().join("c.toml");
    for (camera, render, line, needle) in [
        ("up = [0, 0, 0]", "", 5, "camera.up is the zero vector"),
        ("up = [0, 2, 6]", "", 5, "parallel"),
        ("fov_y = 180", "", 5, "camera.fov_y"),
        ("near = -1", "", 5, "camera.near"),
        ("near = nan", "", 5, "camera.near must be finite"),
        ("", "ambient = [0, inf, 0]", 8, "render.ambient"),
        ("", "refl_depth = 99", 8, "render.refl_depth"),
        ("", "shadow_offset = -1", 8, "render.shadow_offset"),
    ] {
        std::fs::write(&path, scene(camera, render)).unwrap();
        let e = Scene::load(&path).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "{e}");
        assert!(
            !(needle.contains("zero") && e.message.contains("parallel")),
            "{e}"
        );
    }
    // a key given before others: its own line, not the header's
    std::fs::write(
        &path,
        "[camera]\nposition = [0, nan, 3]\nlook_at = [0, 0, 0]\n[[object]]\ntype = \"floor\"\n",
    )
    .unwrap();
    assert_eq!(Scene::load(&path).unwrap_err().line, Some(2));
    std::fs::write(
        &path,
        "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 1, 3]\n[[object]]\ntype = \"floor\"\n",
    )
    .unwrap();
    assert_eq!(Scene::load(&path).unwrap_err().line, Some(3));
}

#[test]
fn gl_allocation_errors_say_what_and_how_large() {
    let m = gpgpu_rt::gl::alloc_error(0x0505, "the shader storage buffer `vertex`", 3 << 30);
    assert!(m.contains("GL_OUT_OF_MEMORY (0x0505)"), "{m}");
    assert!(
        m.contains("`vertex`") && m.contains("3.0 GiB") && m.contains("3221225472 bytes"),
        "{m}"
    );
    let m = gpgpu_rt::gl::alloc_error(0x0501, "x", 16);
    assert!(
        m.contains("GL_INVALID_VALUE (0x0501)") && m.contains("16 bytes"),
        "{m}"
    );
    // a real one: llvmpipe's textures live in the process' memory; with 6 GB of address space
    // a 16384² RGBA32F image (4 GiB) fails (the limit of 1 TiB lets it past the frame's
    // estimate, which would refuse it first)
    if !cfg!(target_os = "linux") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let cow = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cow.toml");
    let cmd = format!(
        "ulimit -v 6000000; GPGPU_RT_MEMORY_LIMIT=1T exec '{BIN}' render '{}' -o '{}' --width 16384 --height 16384 --tracer base",
        cow.display(),
        d.path().join("o.png").display()
    );
    let o = Command::new("bash").args(["-c", &cmd]).output().unwrap();
    assert_fails(&o, &["GL_OUT_OF_MEMORY (0x0505)", "16384x16384", "4.0 GiB"]);
}

#[test]
fn obj_faces_of_fewer_than_three_vertices_and_lines_only_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for (body, line, needle) in [
        (
            "f 1 2 3\nf 1 2\n",
            "o.obj:5",
            "at least 3 vertices, this has 2",
        ),
        ("f 1\n", "o.obj:4", "this has 1"),
        ("f\n", "o.obj:4", "this has 0"),
    ] {
        let obj = format!("{v}{body}");
        refused(
            d.path(),
            &obj_body("o.obj"),
            &[("o.obj", &obj)],
            line,
            &[needle],
        );
    }
    for body in ["l 1 2 3\n", "p 1 2 3\n", "l 1 2\np 3\n", ""] {
        let obj = format!("{v}{body}");
        refused(
            d.path(),
            &obj_body("o.obj"),
            &[("o.obj", &obj)],
            "o.obj",
            &["no faces"],
        );
    }
    // lines beside faces are dropped, not made triangles
    let obj = format!("{v}l 1 2\nf 1 2 3\nl 2 3 1\np 1\n");
    let s = load(d.path(), &obj_body("o.obj"), &[("o.obj", &obj)]).unwrap();
    assert_eq!(s.triangle_count(), 1);
}

#[test]
fn mtl_files_missing_or_broken_are_named_with_their_line() {
    let d = tempfile::tempdir().unwrap();
    let obj = "# model\nmtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    refused(
        d.path(),
        &obj_body("o.obj"),
        &[("o.obj", obj)],
        "o.obj:2",
        &["gone.mtl"],
    );
    let obj = "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    for (mtl, line, needle) in [
        ("newmtl a\nKd 0.5 oops 0.5\n", "m.mtl:2", "Kd"),
        ("newmtl a\nKd 0.5 0.5\n", "m.mtl:2", "Kd"),
        ("newmtl a\nNs\n", "m.mtl:2", "Ns"),
        ("newmtl\n", "m.mtl:1", "newmtl"),
    ] {
        let files = [("o.obj", obj), ("m.mtl", mtl)];
        refused(d.path(), &obj_body("o.obj"), &files, line, &[needle]);
    }
    let files = [("o.obj", obj), ("m.mtl", "newmtl a\nKd 0.2 0.4 0.6\n")];
    let s = load(d.path(), &obj_body("o.obj"), &files).unwrap();
    assert_eq!(s.objects[0].mesh.colors[0], glam::Vec3::new(0.2, 0.4, 0.6));
    // a usemtl of a name the MTL file does not define: tobj would give its faces no material
    let files = [("o.obj", obj), ("m.mtl", "newmtl b\nKd 0.2 0.4 0.6\n")];
    refused(
        d.path(),
        &obj_body("o.obj"),
        &files,
        "o.obj:2",
        &["usemtl a", "b"],
    );
}

#[test]
fn viewer_errors_do_not_print_a_dependencys_source_path() {
    let o = Command::new(BIN)
        .args([
            "view",
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("scenes/cow.toml")
                .display()
                .to_string(),
        ])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    assert_fails(&o, &["cannot connect to a window system", "DISPLAY"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!e.contains(".rs:") && !e.contains(".cargo"), "{e}");
}
