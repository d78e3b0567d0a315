//! The scenes of Wagner 2018, ch. 5: the 720-triangle sphere (Fig. 5.2), the 5804-triangle
//! purple cow (Fig. 5.3) and the subdivided square of Table A.1 (8 … 32768 triangles). Exact
//! triangle counts and geometric invariants: the sphere's vertices lie on it and its mesh is
//! closed and consistently wound; the square covers its square exactly, without cracks or
//! overlaps. CPU only (no GL).

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{load, scene_path};
use glam::Vec3;
use gpgpu_rt::scene::{Overrides, Scene};

/// A vertex by its exact bits: two triangles share a vertex only if it is bit for bit the same.
type Key = [u32; 3];

fn key(p: Vec3) -> Key {
    // +0 and −0 are the same point
    [p.x, p.y, p.z].map(|c| (c + 0.0).to_bits())
}

/// The world-space triangles of the scene's only object.
fn triangles(scene: &Scene) -> Vec<[Vec3; 3]> {
    assert_eq!(scene.objects.len(), 1, "{}", scene.path.display());
    scene.world_triangles()
}

/// How often each directed edge (a → b) occurs.
fn directed_edges(tris: &[[Vec3; 3]]) -> HashMap<(Key, Key), u32> {
    let mut edges = HashMap::new();
    for t in tris {
        for k in 0..3 {
            *edges.entry((key(t[k]), key(t[(k + 1) % 3]))).or_insert(0) += 1;
        }
    }
    edges
}

/// A scene file in `dir` with the sphere or square object `body` under a camera and a light.
fn scene_file(dir: &Path, body: &str) -> std::path::PathBuf {
    let text = format!(
        "[camera]\nposition = [0, 1, 4]\nlook_at = [0, 0, 0]\n\n[[light]]\nposition = [0, 5, 0]\n\n[[object]]\n{body}"
    );
    let path = dir.join("s.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Closed and consistently wound: every directed edge occurs once and its reverse once, so every
/// edge is shared by exactly two triangles that traverse it in opposite directions; and the
/// Euler characteristic is 2 (a sphere).
fn assert_closed(tris: &[[Vec3; 3]], what: &str) {
    let edges = directed_edges(tris);
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "{what}: directed edge {a:?} → {b:?} occurs {n} times");
        assert_eq!(
            edges.get(&(b, a)),
            Some(&1),
            "{what}: edge {a:?} – {b:?} has no neighbour across it (a crack or an open border)"
        );
    }
    let vertices: std::collections::HashSet<Key> = tris.iter().flat_map(|t| t.map(key)).collect();
    let (v, e, f) = (
        vertices.len() as i64,
        edges.len() as i64 / 2,
        tris.len() as i64,
    );
    assert_eq!(v - e + f, 2, "{what}: V − E + F = {v} − {e} + {f}");
}

/// Every vertex at `radius` from the centre, every vertex normal the unit radius vector, every
/// triangle wound counter-clockwise seen from outside (its normal points away from the centre).
fn assert_on_sphere(scene: &Scene, radius: f32, what: &str) {
    let mesh = &scene.objects[0].mesh;
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        assert!(
            (p.length() - radius).abs() <= 2e-6 * radius,
            "{what}: vertex {p} at {} from the centre, not {radius}",
            p.length()
        );
        assert!(
            (*n - *p / radius).length() < 1e-5,
            "{what}: normal {n} at {p}"
        );
    }
    for t in triangles(scene) {
        let normal = (t[1] - t[0]).cross(t[2] - t[0]);
        let centroid = (t[0] + t[1] + t[2]) / 3.0;
        assert!(
            normal.length() > 0.0 && normal.dot(centroid) > 0.0,
            "{what}: triangle {t:?} is degenerate or faces inwards"
        );
    }
}

#[test]
fn the_sphere_has_720_triangles_on_a_closed_surface() {
    let scene = load("sphere.toml");
    assert_eq!(scene.triangle_count(), 720);
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.settings.refl_depth, 0, "no reflection (ch. 5)");
    let (lo, hi) = scene.bounds();
    assert!(
        (0.5 * (lo + hi)).length() < 1e-6,
        "the object is in the centre"
    );
    assert!(scene.lights[0].position.y > hi.y, "the light is above");
    let blue = scene.objects[0].mesh.colors[0];
    assert!(
        blue.z > 2.0 * blue.x && blue.z > 2.0 * blue.y,
        "blue: {blue}"
    );
    assert_on_sphere(&scene, 1.0, "sphere.toml");
    assert_closed(&triangles(&scene), "sphere.toml");
}

#[test]
fn spheres_of_other_tessellations_are_closed_too() {
    let dir = tempfile::tempdir().unwrap();
    for (stacks, slices, radius) in [(2, 3, 1.0), (3, 4, 0.5), (7, 5, 2.5), (40, 64, 3.0)] {
        let body =
            format!("type = \"sphere\"\nstacks = {stacks}\nslices = {slices}\nradius = {radius}\n");
        let scene = Scene::load(&scene_file(dir.path(), &body)).unwrap();
        let what = format!("{stacks}×{slices}");
        assert_eq!(
            scene.triangle_count() as u32,
            2 * slices * (stacks - 1),
            "{what}"
        );
        assert_on_sphere(&scene, radius, &what);
        assert_closed(&triangles(&scene), &what);
    }
    // the defaults are the thesis' 720
    let scene = Scene::load(&scene_file(dir.path(), "type = \"sphere\"\n")).unwrap();
    assert_eq!(scene.triangle_count(), 720);
}

/// Covers the square [−s/2, s/2]² of the xz plane exactly: every triangle in the plane, inside,
/// facing up, their areas summing to s²; inner edges shared by two triangles in opposite
/// directions (no cracks, no T-junctions), the others on the border, 4·s long together; and
/// sample points strictly inside lie in exactly one triangle.
fn assert_covers_square(tris: &[[Vec3; 3]], s: f32, what: &str) {
    let h = s / 2.0;
    let mut area = 0.0f64;
    for t in tris {
        for p in t {
            assert!(
                p.y == 0.0 && p.x.abs() <= h && p.z.abs() <= h,
                "{what}: vertex {p} off the square"
            );
        }
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        assert!(n.y > 0.0, "{what}: triangle {t:?} does not face up");
        area += 0.5 * n.y as f64;
    }
    let want = (s * s) as f64;
    assert!(
        (area - want).abs() <= 1e-5 * want,
        "{what}: areas sum to {area}, not {want}"
    );
    let edges = directed_edges(tris);
    let on_border = |p: Key| {
        let [x, _, z] = p.map(f32::from_bits);
        x.abs() == h || z.abs() == h
    };
    let mut border = 0.0f64;
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "{what}: directed edge {a:?} → {b:?} occurs {n} times");
        if !edges.contains_key(&(b, a)) {
            let [pa, pb] = [a, b].map(|k| Vec3::from(k.map(f32::from_bits)));
            assert!(
                on_border(a) && on_border(b) && (pa.x == pb.x || pa.z == pb.z),
                "{what}: edge {pa} – {pb} inside the square has no neighbour (a crack)"
            );
            border += (pb - pa).length() as f64;
        }
    }
    assert!(
        (border - 4.0 * s as f64).abs() <= 1e-5 * s as f64,
        "{what}: the open edges are {border} long, not the border's {}",
        4.0 * s
    );
    // u = (3a + 1)/3072 and v = (3b + 2)/3072 are never multiples of 1/1024 (the grid lines of
    // levels ≤ 10), nor is u − v (the quads' diagonals): no sample lies on an edge
    for k in 0..500u32 {
        let (a, b) = ((k * 389) % 1024, (k * 677 + 13) % 1024);
        let (u, v) = ((3 * a + 1) as f32 / 3072.0, (3 * b + 2) as f32 / 3072.0);
        let q = Vec3::new(s * (u - 0.5), 0.0, s * (v - 0.5));
        let inside = tris.iter().filter(|t| contains(t, q)).count();
        assert_eq!(inside, 1, "{what}: point {q} lies in {inside} triangles");
    }
}

/// Whether the triangle (in the xz plane, facing up) contains `q`.
fn contains(t: &[Vec3; 3], q: Vec3) -> bool {
    (0..3).all(|k| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        (b - a).cross(q - a).y >= 0.0
    })
}

#[test]
fn the_square_has_8_to_32768_triangles_and_covers_the_square_exactly() {
    let path = scene_path("square.toml");
    let shipped = Scene::load(&path).unwrap();
    assert_eq!(shipped.triangle_count(), 8, "level 1: four quads");
    assert_eq!(shipped.settings.refl_depth, 0);
    assert!(shipped.lights[0].position.y > 0.0, "the light is above");
    for level in 1..=7u32 {
        let scene = Scene::load_with(&path, &Overrides { level: Some(level) }).unwrap();
        let want = 8 * 4usize.pow(level - 1);
        assert_eq!(scene.triangle_count(), want, "level {level}");
        assert_covers_square(&triangles(&scene), 2.0, &format!("level {level}"));
    }
    assert_eq!(
        8 * 4usize.pow(6),
        32768,
        "Table A.1's largest square is level 7"
    );
    // the unit square by default
    let dir = tempfile::tempdir().unwrap();
    let unit = Scene::load(&scene_file(dir.path(), "type = \"square\"\nlevel = 2\n")).unwrap();
    assert_covers_square(&triangles(&unit), 1.0, "unit square, level 2");
}

#[test]
fn the_cow_is_purple_centred_and_lit_from_above() {
    let scene = load("cow.toml");
    assert_eq!(scene.triangle_count(), 5804);
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.settings.refl_depth, 0);
    let (lo, hi) = scene.bounds();
    let c = 0.5 * (lo + hi);
    assert!(c.x.abs() < 0.15 && c.z.abs() < 0.15, "centred: {c}");
    assert!(scene.lights[0].position.y > hi.y, "the light is above");
    let purple = scene.objects[0].mesh.colors[0];
    assert!(
        purple.x > purple.y && purple.z > purple.y,
        "purple: {purple}"
    );
}

/// Loading `body` fails with an error naming the file, the object's line and `needles`.
fn assert_refused(dir: &Path, body: &str, needles: &[&str]) {
    let path = scene_file(dir, body);
    let e = Scene::load(&path).expect_err(body).to_string();
    // the object starts on line 9; its `type` is the line the error names
    assert!(e.contains("s.toml:9"), "{body:?}: {e}");
    for n in needles {
        assert!(e.contains(n), "{body:?}: {e:?} lacks {n:?}");
    }
}

#[test]
fn bad_procedural_parameters_are_refused_with_file_key_and_limit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert_refused(
        d,
        "type = \"square\"\nlevel = 0\n",
        &["level = 0", "positive"],
    );
    assert_refused(
        d,
        "type = \"square\"\nlevel = 13\n",
        &["level = 13", "134217728 triangles", "at most 67108864"],
    );
    assert_refused(d, "type = \"square\"\nlevel = 4000000000\n", &["at most"]);
    assert_refused(
        d,
        "type = \"sphere\"\nstacks = 1\n",
        &["stacks = 1", "at least 2"],
    );
    assert_refused(
        d,
        "type = \"sphere\"\nslices = 2\n",
        &["slices = 2", "at least 3"],
    );
    assert_refused(
        d,
        "type = \"sphere\"\nstacks = 100000\nslices = 100000\n",
        &["stacks = 100000 with slices = 100000", "at most"],
    );
    assert_refused(
        d,
        "type = \"sphere\"\nradius = -1.0\n",
        &["radius", "positive"],
    );
    assert_refused(
        d,
        "type = \"sphere\"\nradius = nan\n",
        &["radius", "finite"],
    );
    assert_refused(d, "type = \"square\"\nsize = 0.0\n", &["size", "positive"]);
    // a key of another type is refused, not ignored
    assert_refused(
        d,
        "type = \"sphere\"\nlevel = 3\n",
        &["level", "\"square\""],
    );
    assert_refused(
        d,
        "type = \"square\"\nstacks = 3\n",
        &["stacks", "\"sphere\""],
    );
    assert_refused(
        d,
        "type = \"floor\"\nradius = 3.0\n",
        &["radius", "\"sphere\""],
    );
    // an unknown key names its own line
    let e = Scene::load(&scene_file(d, "type = \"sphere\"\nfoo = 3\n"))
        .expect_err("foo")
        .to_string();
    assert!(
        e.contains("s.toml:10") && e.contains("unknown field `foo`"),
        "{e}"
    );
    // an override no object takes
    let e = Scene::load_with(&scene_path("sphere.toml"), &Overrides { level: Some(2) })
        .expect_err("the sphere has no square")
        .to_string();
    assert!(e.contains("sphere.toml") && e.contains("\"square\""), "{e}");
    // and an override beyond the limit names it
    let e = Scene::load_with(&scene_path("square.toml"), &Overrides { level: Some(20) })
        .expect_err("level 20")
        .to_string();
    assert!(
        e.contains("square.toml:") && e.contains("level = 20"),
        "{e}"
    );
}
