//! What every AOV file means, read back from what `render --aov-dir` wrote (issue 33, class 9:
//! a writer that swapped `normal.npy`'s y and z passed every test that looked at the arrays in
//! memory). For each design that writes AOVs, on a floor (normal +y) under a tilted triangle
//! (a normal with three different components) lit from above, checked against geometry in
//! f64 and the GUIDE's definitions, not against the renderer's own arrays:
//!
//! - `ray_direction` is unit length and points through the centre of the pixel of that image
//!   row (row 0 = top) and column; `ray_origin` lies on that ray's line through the camera;
//! - `triangle_id` is the first triangle along the ray (−1 on a miss), `hit_t` the distance
//!   along the unit direction from the origin to it (+inf on a miss);
//! - `normal` is that triangle's normal turned towards the ray: (0, 1, 0) on the floor;
//! - `shadow` is 0 where the tilted triangle hides the light and 1 where nothing does.

mod common;

use std::path::Path;

use glam::{DVec3, Vec3};

/// The tilted triangle above the floor (its own OBJ: its vertex normals are its face normal).
const BLOCKER: [[f64; 3]; 3] = [[-0.6, 0.9, -0.5], [0.7, 1.2, -0.3], [-0.1, 1.0, 0.7]];
const LIGHT: [f64; 3] = [0.3, 3.0, 0.2];
const CAMERA: [f64; 3] = [0.4, 2.6, 3.4];
/// The floor's triangles come first (2 at `quads = 1`), the blocker is triangle 2.
const FLOOR_TRIANGLES: i32 = 2;

fn write_scene(dir: &Path, area_light: bool) -> std::path::PathBuf {
    let v = |p: [f64; 3]| format!("v {} {} {}\n", p[0], p[1], p[2]);
    let obj: String = BLOCKER.iter().map(|&p| v(p)).collect::<String>() + "f 1 2 3\n";
    std::fs::write(dir.join("blocker.obj"), obj).unwrap();
    let light = if area_light {
        // a small light: pixels in its umbra see none of it
        format!(
            "[render]\nshadows = \"exact\"\nlight_samples = \"2x2\"\n[[area_light]]\n\
             corner = [{}, {}, {}]\nedge_u = [0.1, 0.0, 0.0]\nedge_v = [0.0, 0.0, 0.1]\n",
            LIGHT[0] - 0.05,
            LIGHT[1],
            LIGHT[2] - 0.05
        )
    } else {
        format!(
            "[[light]]\nposition = [{}, {}, {}]\n",
            LIGHT[0], LIGHT[1], LIGHT[2]
        )
    };
    let toml = format!(
        "[camera]\nposition = [{}, {}, {}]\nlook_at = [0.0, 0.3, 0.0]\nfov_y = 50.0\n{light}\
         [[object]]\ntype = \"floor\"\nsize = 4.0\nquads = 1\n\
         [[object]]\ntype = \"obj\"\npath = \"blocker.obj\"\n",
        CAMERA[0], CAMERA[1], CAMERA[2]
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    path
}

fn npy<T: npyz::Deserialize>(dir: &Path, name: &str) -> (Vec<u64>, Vec<T>) {
    let bytes = std::fs::read(dir.join(name)).unwrap();
    let f = npyz::NpyFile::new(&bytes[..]).unwrap();
    let shape = f.shape().to_vec();
    (shape, f.into_vec().unwrap())
}

/// Where the ray o + t·d meets the triangle `tri` (t > 0), with its smallest barycentric
/// coordinate (negative: outside), in f64.
fn meet(o: DVec3, d: DVec3, tri: [DVec3; 3]) -> Option<(f64, f64)> {
    let (e1, e2) = (tri[1] - tri[0], tri[2] - tri[0]);
    let n = e1.cross(e2);
    let t = n.dot(tri[0] - o) / n.dot(d);
    if t.is_nan() || t <= 1e-9 {
        return None;
    }
    let p = o + t * d - tri[0];
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d1p, d2p) = (e1.dot(p), e2.dot(p));
    let den = d11 * d22 - d12 * d12;
    let u = (d22 * d1p - d12 * d2p) / den;
    let v = (d11 * d2p - d12 * d1p) / den;
    Some((t, u.min(v).min(1.0 - u - v)))
}

fn floor() -> [[DVec3; 3]; 2] {
    let c = |x: f64, z: f64| DVec3::new(x, 0.0, z);
    [
        [c(-2.0, -2.0), c(2.0, -2.0), c(2.0, 2.0)],
        [c(-2.0, -2.0), c(2.0, 2.0), c(-2.0, 2.0)],
    ]
}

fn blocker() -> [DVec3; 3] {
    BLOCKER.map(DVec3::from)
}

/// The first of floor and blocker along the ray: (t, is the blocker), unless the ray passes
/// near an edge (then `None` and the pixel is skipped), `Some(None)` for a miss.
#[allow(clippy::option_option)]
fn first_hit(o: DVec3, d: DVec3) -> Option<Option<(f64, bool)>> {
    let mut best: Option<(f64, bool)> = None;
    let floor_hit =
        floor()
            .iter()
            .filter_map(|t| meet(o, d, *t))
            .fold(None::<(f64, f64)>, |a, (t, inside)| match a {
                Some((_, i)) if i >= inside => a,
                _ => Some((t, inside)),
            });
    // the floor's diagonal is no edge of the floor: only its outline counts
    if let Some((t, _)) = floor_hit {
        let p = o + t * d;
        let margin = 2.0 - p.x.abs().max(p.z.abs());
        if margin.abs() < 1e-3 {
            return None;
        }
        if margin > 0.0 {
            best = Some((t, false));
        }
    }
    if let Some((t, inside)) = meet(o, d, blocker()) {
        if inside.abs() < 1e-3 {
            return None;
        }
        if inside > 0.0 && best.is_none_or(|(bt, _)| t < bt) {
            best = Some((t, true));
        }
    }
    Some(best)
}

/// Is the segment from `p` to `light` blocked by the blocker? `None` near its edge.
fn shadowed(p: DVec3, light: DVec3) -> Option<bool> {
    match meet(p, light - p, blocker()) {
        Some((t, inside)) if t < 1.0 => {
            if inside.abs() < 2e-2 {
                None
            } else {
                Some(inside > 0.0)
            }
        }
        _ => Some(false),
    }
}

struct Counts {
    floor: usize,
    blocker: usize,
    miss: usize,
    dark: usize,
    lit: usize,
}

/// Check the AOV files in `dir` of a `w`×`h` render; `area` when the light is the small area
/// light (shadow 0 only where all four corners are hidden).
fn check_aovs(design: &str, dir: &Path, w: u32, h: u32, area: bool) -> Counts {
    let (s, origin) = npy::<f32>(dir, "ray_origin.npy");
    assert_eq!(s, [h as u64, w as u64, 3], "{design}: ray_origin shape");
    let (_, direction) = npy::<f32>(dir, "ray_direction.npy");
    let (s, hit_t) = npy::<f32>(dir, "hit_t.npy");
    assert_eq!(s, [h as u64, w as u64], "{design}: hit_t shape");
    let (_, ids) = npy::<i32>(dir, "triangle_id.npy");
    let (_, normal) = npy::<f32>(dir, "normal.npy");
    let shadow = dir
        .join("shadow.npy")
        .exists()
        .then(|| npy::<f32>(dir, "shadow.npy").1);
    let scene = gpgpu_rt::scene::Scene::load(&dir.join("../scene.toml")).unwrap();
    let rays = scene.camera.rays(w, h);
    let cam = DVec3::from(CAMERA);
    let v3 = |a: &[f32], i: usize| Vec3::new(a[3 * i], a[3 * i + 1], a[3 * i + 2]).as_dvec3();
    let mut n = Counts {
        floor: 0,
        blocker: 0,
        miss: 0,
        dark: 0,
        lit: 0,
    };
    for row in 0..h {
        for x in 0..w {
            let i = (row * w + x) as usize;
            let at = format!("{design}: pixel ({x}, {row})");
            let (o, d) = (v3(&origin, i), v3(&direction, i));
            assert!(
                (d.length() - 1.0).abs() < 1e-5,
                "{at}: |direction| = {}",
                d.length()
            );
            // through the centre of this pixel: the CPU camera's ray of GL row h - 1 - row
            let (_, want_d) = rays.primary_ray(x, h - 1 - row);
            let off = (d - want_d.as_dvec3()).length();
            assert!(off < 1e-5, "{at}: direction {d} vs the pixel's {want_d}");
            // the origin is on the ray's line through the camera, not behind it
            let oc = o - cam;
            assert!(
                oc.cross(d).length() < 1e-4,
                "{at}: origin {o} is off the ray"
            );
            assert!(oc.dot(d) > -1e-4, "{at}: origin {o} behind the camera");
            let Some(hit) = first_hit(o, d) else { continue };
            let (t, id, nrm) = (hit_t[i] as f64, ids[i], v3(&normal, i));
            let Some((want_t, on_blocker)) = hit else {
                assert_eq!(id, -1, "{at}: a miss");
                assert!(t.is_infinite() && t > 0.0, "{at}: hit_t {t} on a miss");
                n.miss += 1;
                continue;
            };
            assert!(
                (t - want_t).abs() < 1e-4 * want_t,
                "{at}: hit_t {t} vs {want_t}"
            );
            let want_n = if on_blocker {
                n.blocker += 1;
                assert_eq!(id, FLOOR_TRIANGLES, "{at}: the blocker");
                let b = blocker();
                let f = (b[1] - b[0]).cross(b[2] - b[0]).normalize();
                if f.dot(d) > 0.0 {
                    -f
                } else {
                    f
                }
            } else {
                n.floor += 1;
                assert!((0..FLOOR_TRIANGLES).contains(&id), "{at}: floor, not {id}");
                DVec3::Y
            };
            assert!(
                (nrm - want_n).length() < 1e-4,
                "{at}: normal {nrm} vs {want_n}"
            );
            let (Some(shadow), false) = (&shadow, on_blocker) else {
                continue;
            };
            let p = o + want_t * d;
            let light = DVec3::from(LIGHT);
            let corners: Vec<DVec3> = if area {
                [(-0.05, -0.05), (0.05, -0.05), (-0.05, 0.05), (0.05, 0.05)]
                    .map(|(a, b)| light + DVec3::new(a, 0.0, b))
                    .to_vec()
            } else {
                vec![light]
            };
            let hidden: Option<Vec<bool>> = corners.iter().map(|&l| shadowed(p, l)).collect();
            match hidden.as_deref() {
                Some(v) if v.iter().all(|&b| b) => {
                    assert!(shadow[i] < 1e-6, "{at}: shadow {} in the umbra", shadow[i]);
                    n.dark += 1;
                }
                Some(v) if v.iter().all(|&b| !b) => {
                    assert!(shadow[i] > 1.0 - 1e-6, "{at}: shadow {} lit", shadow[i]);
                    n.lit += 1;
                }
                _ => {}
            }
        }
    }
    n
}

fn render(dir: &Path, scene: &Path, w: u32, h: u32, design: &[&str]) {
    let (aovs, png) = (dir.join("aovs"), dir.join("c.png"));
    let (ws, hs) = (w.to_string(), h.to_string());
    let args = [
        &[
            "render",
            scene.to_str().unwrap(),
            "--width",
            &ws,
            "--height",
            &hs,
            "-o",
            png.to_str().unwrap(),
            "--aov-dir",
            aovs.to_str().unwrap(),
        ][..],
        design,
    ]
    .concat();
    let o = common::run(&args);
    assert!(o.status.success(), "{design:?}: {}", common::stderr(&o));
}

#[test]
fn every_designs_aov_files_mean_what_the_guide_says() {
    let (w, h) = (40u32, 32u32);
    let designs: [(&str, &[&str]); 6] = [
        ("base", &["--tracer", "base"]),
        (
            "thesis grid",
            &["--tracer", "grid", "--grid-variant", "thesis"],
        ),
        (
            "exact grid",
            &["--tracer", "grid", "--grid-variant", "exact"],
        ),
        ("bvh", &["--tracer", "bvh"]),
        ("wagner", &["--tracer", "bvh", "--bvh-variant", "wagner"]),
        ("stream", &["--tracer", "stream"]),
    ];
    for (name, args) in designs {
        let d = tempfile::tempdir().unwrap();
        let scene = write_scene(d.path(), false);
        render(d.path(), &scene, w, h, args);
        let n = check_aovs(name, &d.path().join("aovs"), w, h, false);
        let counts = [n.floor, n.blocker, n.miss, n.dark, n.lit];
        eprintln!("{name}: floor, blocker, miss, dark, lit pixels {counts:?}");
        assert!(counts.iter().all(|&c| c >= 20), "{name}: {counts:?}");
    }
}

#[test]
fn the_soft_shadow_aov_files_mean_what_the_guide_says() {
    let (w, h) = (40u32, 32u32);
    let d = tempfile::tempdir().unwrap();
    let scene = write_scene(d.path(), true);
    render(d.path(), &scene, w, h, &[]);
    let n = check_aovs("soft shadows", &d.path().join("aovs"), w, h, true);
    let counts = [n.floor, n.blocker, n.miss, n.dark, n.lit];
    eprintln!("soft shadows: floor, blocker, miss, dark, lit pixels {counts:?}");
    assert!(counts.iter().all(|&c| c >= 20), "{counts:?}");
}
