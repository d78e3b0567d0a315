//! glTF 2.0 against files this project did not write: shipped OBJ models converted by Cesium's
//! `obj2gltf` (npm; a GLB, and a .gltf with an external .bin) and by `trimesh` (PyPI), and a
//! scene authored with `pygltflib` (PyPI: a node hierarchy, a data-URI buffer and an external
//! one, an external texture, a camera as a matrix, a KHR_lights_punctual point light) — each
//! valid for Khronos' glTF validator (npm) — render the same first hits as the OBJ/TOML scene
//! they came from: hit or miss in every pixel, the distance within 1e-5 relative, the hit
//! triangle's face normal within 1e-4 (triangle order may differ, so each render's own
//! triangles are exported); the authored scene's camera, light and texture are honoured (the
//! same shadows, colours within 2/255).
//!
//! The tools come from `tools/node` (`npm ci --prefix tools/node`) and PyPI (`trimesh
//! pygltflib numpy`); where they are missing the tests say so and pass, except under CI
//! (`.ci/run` installs them), where they fail.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::*;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Are the outside tools here? Under CI they must be.
fn have_tools() -> bool {
    let node = root().join("tools/node/node_modules");
    let npm = node.join("obj2gltf").is_dir() && node.join("gltf-validator").is_dir();
    let py = Command::new("python3")
        .args(["-c", "import trimesh, pygltflib, numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !(npm && py) {
        let what = "obj2gltf and gltf-validator (npm ci --prefix tools/node) or trimesh, \
                    pygltflib and numpy (pip install trimesh pygltflib numpy)";
        assert!(std::env::var_os("CI").is_none(), "missing: {what}");
        eprintln!("skipped: missing {what}");
    }
    npm && py
}

fn tool(cmd: &mut Command, what: &str) {
    let o = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    let said = String::from_utf8_lossy(&o.stdout).into_owned() + &stderr(&o);
    assert!(o.status.success(), "{what}: {said}");
}

fn obj2gltf(from: &Path, to: &Path, separate: bool) {
    let bin = root().join("tools/node/node_modules/.bin/obj2gltf");
    let mut c = Command::new(bin);
    c.arg("-i").arg(from).arg("-o").arg(to);
    if separate {
        c.arg("--separate");
    }
    tool(&mut c, "obj2gltf");
}

fn validate(files: &[PathBuf]) {
    let mut c = Command::new("node");
    c.arg(root().join("tools/node/validate.js")).args(files);
    tool(&mut c, "the glTF validator");
}

/// A render's first hits: the distance, the hit triangle's face normal (None: a miss), the
/// shadow and the colour of every pixel.
struct Hits {
    t: Vec<f32>,
    face: Vec<Option<[f64; 3]>>,
    shadow: Vec<f32>,
    rgb: Vec<u8>,
}

fn npy<T: npyz::Deserialize>(path: &Path) -> Vec<T> {
    let bytes = std::fs::read(path).unwrap();
    npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
}

fn render(scene: &Path, dir: &Path, name: &str) -> Hits {
    let (png, aovs, tris) = (
        dir.join(format!("{name}.png")),
        dir.join(format!("{name}-aovs")),
        dir.join(format!("{name}-tris.npy")),
    );
    let s = scene.to_str().unwrap();
    let o = run(&[
        "render",
        s,
        "--width",
        "64",
        "--height",
        "64",
        "-o",
        png.to_str().unwrap(),
        "--aov-dir",
        aovs.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let o = run(&["export-triangles", s, "-o", tris.to_str().unwrap()]);
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let tri: Vec<f32> = npy(&tris);
    let ids: Vec<i32> = npy(&aovs.join("triangle_id.npy"));
    let face = ids
        .iter()
        .map(|&id| {
            let id = usize::try_from(id).ok()?;
            let v =
                |k: usize| -> [f64; 3] { std::array::from_fn(|a| tri[9 * id + 3 * k + a] as f64) };
            let (a, b, c) = (v(0), v(1), v(2));
            let (e1, e2) = (
                [0, 1, 2].map(|i| b[i] - a[i]),
                [0, 1, 2].map(|i| c[i] - a[i]),
            );
            let n = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            Some(n.map(|x| x / len))
        })
        .collect();
    Hits {
        t: npy(&aovs.join("hit_t.npy")),
        face,
        shadow: npy(&aovs.join("shadow.npy")),
        rgb: image::open(&png).unwrap().to_rgb8().into_raw(),
    }
}

/// The same first hits in every pixel (module documentation); with `colours`, the same shadows
/// and colours too.
fn assert_same(a: &Hits, b: &Hits, what: &str, colours: bool) {
    let mut hits = 0;
    for i in 0..a.t.len() {
        match (a.face[i], b.face[i]) {
            (None, None) => continue,
            (Some(na), Some(nb)) => {
                hits += 1;
                let (ta, tb) = (a.t[i] as f64, b.t[i] as f64);
                assert!(
                    (ta - tb).abs() <= 1e-5 * ta.max(tb),
                    "{what}: pixel {i}: t {ta} vs {tb}"
                );
                let d = (0..3).map(|k| (na[k] - nb[k]).abs()).fold(0.0, f64::max);
                assert!(d <= 1e-4, "{what}: pixel {i}: face normal {na:?} vs {nb:?}");
            }
            (x, y) => panic!("{what}: pixel {i}: hit {} vs {}", x.is_some(), y.is_some()),
        }
    }
    assert!(hits > a.t.len() / 10, "{what}: only {hits} hits");
    if colours {
        assert_eq!(a.shadow, b.shadow, "{what}: shadows");
        let worst = a
            .rgb
            .iter()
            .zip(&b.rgb)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap();
        assert!(worst <= 2, "{what}: colours differ by {worst}/255");
    }
}

/// A TOML scene with one `kind` object at `path`, fitted to 1.6 units, seen by a fixed camera.
fn toml_scene(dir: &Path, name: &str, kind: &str, path: &Path) -> PathBuf {
    let text = format!(
        "[camera]\nposition = [0.0, 0.8, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 40.0\n\
         [[light]]\nposition = [2.0, 4.0, 3.0]\n\
         [[object]]\ntype = \"{kind}\"\npath = \"{}\"\nrotate = [0.0, 25.0, 0.0]\n\
         translate = [0.0, -0.6, 0.0]\nfit = 1.6\n",
        path.display()
    );
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn converted_models_give_the_obj_scenes_first_hits() {
    if !have_tools() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let models = root().join("scenes/models");
    tool(
        Command::new("python3")
            .arg(root().join("tools/gltf_fixtures.py"))
            .arg(dir)
            .arg(&models),
        "tools/gltf_fixtures.py",
    );
    let (cow, bunny) = (dir.join("cow.glb"), dir.join("bunny_low.gltf"));
    obj2gltf(&models.join("cow.obj"), &cow, false);
    obj2gltf(&models.join("bunny_low.obj"), &bunny, true);
    let knot = dir.join("torus_knot.glb");
    validate(&[
        cow.clone(),
        bunny.clone(),
        knot.clone(),
        dir.join("authored.gltf"),
    ]);
    // each model fitted to the same size (`fit`), so that it fills the view
    for (obj, gltf) in [
        ("cow.obj", &cow),
        ("bunny_low.obj", &bunny),
        ("torus_knot.obj", &knot),
    ] {
        let a = toml_scene(dir, &format!("{obj}-gltf"), "gltf", gltf);
        let b = toml_scene(dir, &format!("{obj}-obj"), "obj", &models.join(obj));
        let (a, b) = (
            render(&a, dir, &format!("{obj}-gltf")),
            render(&b, dir, &format!("{obj}-obj")),
        );
        assert_same(&a, &b, obj, false);
    }
    // the authored scene, rendered directly, against its TOML twin
    let a = render(&dir.join("authored.gltf"), dir, "authored-gltf");
    let b = render(&dir.join("authored.toml"), dir, "authored-toml");
    assert_same(&a, &b, "the authored scene", true);
}

/// A glTF file of one triangle whose JSON is `edit`ed: three f32 positions in a data URI.
fn triangle_gltf(edit: impl Fn(&mut serde_json::Value)) -> String {
    use base64::Engine as _;
    let pos: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&pos)
    );
    let mut doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": uri}]
    });
    edit(&mut doc);
    doc.to_string()
}

/// Bad glTF files are refused with the file and what is wrong, exit status 1, nothing
/// written; a good one-triangle file renders (its framing camera and default light).
#[test]
fn bad_gltf_files_are_refused_with_what_is_wrong() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let good = dir.join("good.gltf");
    std::fs::write(&good, triangle_gltf(|_| {})).unwrap();
    let png = dir.join("x.png");
    let render16 = |scene: &Path| {
        let (s, p) = (scene.to_str().unwrap(), png.to_str().unwrap());
        run(&["render", s, "--width", "16", "--height", "16", "-o", p])
    };
    let o = render16(&good);
    assert!(o.status.success(), "{}", stderr(&o));
    // a cycle of children (the specification forbids it; nothing may loop on it): each node
    // once, or refused as malformed
    let cycle = dir.join("cycle.gltf");
    std::fs::write(
        &cycle,
        triangle_gltf(|d| {
            d["nodes"] = serde_json::json!([{"mesh": 0, "children": [1]}, {"children": [0]}])
        }),
    )
    .unwrap();
    let o = render16(&cycle);
    assert!(o.status.code().is_some_and(|c| c <= 1), "{}", stderr(&o));
    std::fs::remove_file(&png).unwrap();
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "lines",
            Box::new(|d| d["meshes"][0]["primitives"][0]["mode"] = 1.into()),
            "only TRIANGLES",
        ),
        (
            "short",
            Box::new(|d| d["accessors"][0]["count"] = 4.into()),
            "whole triangles",
        ),
        (
            "past",
            Box::new(|d| d["accessors"][0]["byteOffset"] = 12.into()),
            "more than its buffer view",
        ),
        (
            "long view",
            Box::new(|d| d["bufferViews"][0]["byteLength"] = 48.into()),
            "past its buffer",
        ),
        (
            "missing bin",
            Box::new(|d| d["buffers"][0]["uri"] = "gone.bin".into()),
            "cannot read",
        ),
        (
            "absolute",
            Box::new(|d| d["buffers"][0]["uri"] = "file:///etc/passwd".into()),
            "not a relative path",
        ),
        (
            "no scene",
            Box::new(|d| {
                d["scenes"] = serde_json::json!([]);
                d.as_object_mut().unwrap().remove("scene");
            }),
            "no scene",
        ),
        (
            "bad index",
            Box::new(|d| d["nodes"][0]["mesh"] = 7.into()),
            "malformed glTF",
        ),
    ];
    for (name, edit, says) in cases {
        let f = dir.join(format!("{name}.gltf"));
        std::fs::write(&f, triangle_gltf(edit)).unwrap();
        let o = render16(&f);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{name}: {e}");
        assert!(
            e.contains(says) && e.contains(&format!("{name}.gltf")),
            "{name}: {e}"
        );
        assert!(!png.exists(), "{name}: wrote the image");
    }
    let o = run(&["render", "/dev/null/x.glb", "-o", png.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
}
