//! The turning pose against an independent computation: `render --rotate objects --turn θ`
//! must show every world-space point p of the still scene at R(θ)·(p − c) + c, with R the turn
//! about the vertical axis and c the centre of the scene's bounding box, and `--rotate camera`
//! must put the eye at R(−θ)·(e − c) + c. The expected hits are ray cast here, in f64, against
//! the still scene's triangles (`export-triangles`) turned by the formula written out below —
//! not by the program's turning code — so a turn composed in the wrong order (each object spun
//! about its own origin, or the angle's sign flipped) fails. The scene's objects stand away
//! from the centre and from their own origins, so those mistakes move them visibly.

mod common;

use std::path::Path;

use common::*;

/// Two teapots and a sphere, off-centre, each translated away from the origin.
const SCENE: &str = r#"
[camera]
position = [0.5, 3.0, 6.0]
look_at = [0.5, 0.3, 0.0]
up = [0.0, 1.0, 0.0]
fov_y = 50.0

[[light]]
position = [2.0, 6.0, 4.0]

[[object]]
type = "teapot"
path = "MODELS/teapot.bpt"
tessellation = 4
scale = 0.5
translate = [2.0, 0.0, -0.5]

[[object]]
type = "teapot"
path = "MODELS/teapot.bpt"
tessellation = 4
scale = 0.3
rotate = [0.0, 40.0, 0.0]
translate = [-1.0, 0.0, 1.2]

[[object]]
type = "sphere"
radius = 0.4
translate = [0.3, 0.4, -1.5]
"#;

const SIZE: usize = 40;

fn read_f32(path: &Path) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap();
    npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
}

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// p turned by `degrees` about the vertical axis through `c` (right-handed, +y up: +90° takes
/// +x to −z).
fn turned(p: V, c: V, degrees: f64) -> V {
    let (s, k) = degrees.to_radians().sin_cos();
    let (x, z) = (p[0] - c[0], p[2] - c[2]);
    [c[0] + k * x + s * z, p[1], c[2] - s * x + k * z]
}

/// The nearest hit distance of the ray (o, d) among `tris` (Möller–Trumbore, f64), if any.
fn nearest(o: V, d: V, tris: &[[V; 3]]) -> Option<f64> {
    let mut best: Option<f64> = None;
    for t in tris {
        let (e1, e2) = (sub(t[1], t[0]), sub(t[2], t[0]));
        let p = cross(d, e2);
        let det = dot(e1, p);
        if det.abs() < 1e-14 {
            continue;
        }
        let s = sub(o, t[0]);
        let u = dot(s, p) / det;
        let q = cross(s, e1);
        let v = dot(d, q) / det;
        let dist = dot(e2, q) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 1e-6 && best.is_none_or(|b| dist < b) {
            best = Some(dist);
        }
    }
    best
}

/// The still scene's world triangles (`export-triangles`) and the centre of their box.
fn still_triangles(dir: &Path, scene: &Path) -> (Vec<[V; 3]>, V) {
    let npy = dir.join("tris.npy");
    let o = run(&[
        "export-triangles",
        scene.to_str().unwrap(),
        "-o",
        npy.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let f = read_f32(&npy);
    let tris: Vec<[V; 3]> = f
        .chunks(9)
        .map(|t| std::array::from_fn(|v| std::array::from_fn(|a| t[3 * v + a] as f64)))
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in tris.iter().flatten() {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (tris, std::array::from_fn(|a| 0.5 * (lo[a] + hi[a])))
}

/// The primary rays and first-hit distances of a `--rotate how --turn degrees` render.
struct Rendered {
    origins: Vec<V>,
    dirs: Vec<V>,
    hit_t: Vec<f32>,
}

fn render_turned(dir: &Path, scene: &Path, how: &str, degrees: f64) -> Rendered {
    let aovs = dir.join(format!("aovs-{how}-{degrees}"));
    let turn = degrees.to_string();
    let size = SIZE.to_string();
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--tracer",
        "bvh",
        "--width",
        &size,
        "--height",
        &size,
        "--rotate",
        how,
        "--turn",
        &turn,
        "--aov-dir",
        aovs.to_str().unwrap(),
        "-o",
        dir.join("x.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let vecs = |name: &str| -> Vec<V> {
        let f = read_f32(&aovs.join(name));
        f.chunks(3)
            .map(|c| [c[0] as f64, c[1] as f64, c[2] as f64])
            .collect()
    };
    Rendered {
        origins: vecs("ray_origin.npy"),
        dirs: vecs("ray_direction.npy"),
        hit_t: read_f32(&aovs.join("hit_t.npy")),
    }
}

/// Every pixel's first hit equals the ray cast against `tris`: the same hit or miss, the same
/// distance (a few grazing rays on an edge may differ).
fn assert_hits(r: &Rendered, tris: &[[V; 3]], what: &str) {
    let (mut hits, mut differ) = (0, Vec::new());
    for (i, (&o, &d)) in r.origins.iter().zip(&r.dirs).enumerate() {
        let want = nearest(o, d, tris);
        // a miss is +inf in hit_t.npy
        let got = r.hit_t[i].is_finite().then_some(r.hit_t[i] as f64);
        hits += want.is_some() as usize;
        let same = match (want, got) {
            (Some(w), Some(g)) => (w - g).abs() <= 1e-3 * w.max(1.0),
            (None, None) => true,
            _ => false,
        };
        if !same {
            differ.push((i, want, got));
        }
    }
    assert!(
        hits > SIZE * SIZE / 16,
        "{what}: the objects are in view ({hits} hits)"
    );
    assert!(
        differ.len() <= SIZE * SIZE / 200,
        "{what}: {} of {} pixels differ from the independent turn, e.g. {:?}",
        differ.len(),
        SIZE * SIZE,
        &differ[..differ.len().min(5)]
    );
}

fn scene_file(dir: &Path) -> std::path::PathBuf {
    let models = scene_path("models");
    let text = SCENE.replace("MODELS", models.to_str().unwrap());
    let path = dir.join("turning.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn turned_objects_stand_where_the_turn_about_the_scene_centre_puts_them() {
    let d = tempfile::tempdir().unwrap();
    let scene = scene_file(d.path());
    let (still, c) = still_triangles(d.path(), &scene);
    for degrees in [30.0, 135.0, -70.0] {
        let r = render_turned(d.path(), &scene, "objects", degrees);
        let moved: Vec<[V; 3]> = still
            .iter()
            .map(|t| t.map(|p| turned(p, c, degrees)))
            .collect();
        assert_hits(&r, &moved, &format!("--rotate objects --turn {degrees}"));
    }
}

#[test]
fn an_orbiting_camera_stands_where_the_opposite_turn_puts_it() {
    let d = tempfile::tempdir().unwrap();
    let scene = scene_file(d.path());
    let (still, c) = still_triangles(d.path(), &scene);
    for degrees in [30.0, 135.0, -70.0] {
        let r = render_turned(d.path(), &scene, "camera", degrees);
        let eye = turned([0.5, 3.0, 6.0], c, -degrees);
        let look = turned([0.5, 0.3, 0.0], c, -degrees);
        // every primary ray (it starts on the near plane) comes from the turned eye
        for (o, d) in r.origins.iter().zip(&r.dirs) {
            let off = cross(sub(eye, *o), *d);
            let miss = dot(off, off).sqrt() / dot(*d, *d).sqrt();
            assert!(
                miss < 1e-4,
                "--turn {degrees}: a ray from {o:?} passes the eye {eye:?} at {miss}"
            );
        }
        // the centre of the image looks at the turned look-at point (an even size: the mean
        // of the four middle pixels' directions)
        let m = SIZE / 2;
        let mid = [
            (m - 1) * SIZE + m - 1,
            (m - 1) * SIZE + m,
            m * SIZE + m - 1,
            m * SIZE + m,
        ];
        let mean: V = std::array::from_fn(|a| mid.iter().map(|&i| r.dirs[i][a]).sum::<f64>());
        let want = sub(look, eye);
        let cos = dot(mean, want) / (dot(mean, mean) * dot(want, want)).sqrt();
        assert!(
            cos > 0.9999,
            "--turn {degrees}: the view turned wrongly (cos {cos})"
        );
        // and the scene itself did not move
        assert_hits(&r, &still, &format!("--rotate camera --turn {degrees}"));
    }
}
