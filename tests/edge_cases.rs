//! The cases real scenes almost never exercise, for every point-light design of `design::REGISTRY`, GPU and CPU alike, against expectations computed here in f64:
//! - ties: at exactly equal distance the lower triangle id wins (the same triangle twice,
//!   and coplanar overlapping triangles whose hit distances are bit for bit equal);
//! - shadow feelers end at the light: an occluder beyond a point light does not shadow, one
//!   just before it does; and they start at the scene's `shadow_offset`: an occluder nearer
//!   than the offset does not shadow, one just beyond it does.

mod common;

use std::path::Path;

use common::*;
use glam::{DVec3, Vec3};
use gpgpu_rt::design::{Design, Pipeline, Row, REGISTRY};
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::GlContext;
use gpgpu_rt::pipeline::wagner2018::bvh::WagnerBvh;
use gpgpu_rt::reference::wagner2018::Ray;
use gpgpu_rt::reference::Reference;
use gpgpu_rt::scene::Scene;

/// Every point-light design of the registry, the grids at `grid_resolution` cells per axis,
/// its AOVs kept.
fn every_tracer(grid_resolution: u32) -> Vec<(&'static Row, Design)> {
    let rows = REGISTRY.iter().filter(|r| r.pipeline != Pipeline::Klee2016);
    rows.map(|row| {
        let mut d = Design::plain(row, 64, 64, 0);
        d.keep_aovs();
        match &mut d {
            Design::Mueller2015(o) => o.accel = o.accel.with_grid_resolution(grid_resolution),
            Design::Stream(o) => o.dims = Some([grid_resolution; 3]),
            _ => {}
        }
        (row, d)
    })
    .collect()
}

fn render(ctx: &GlContext, scene: &Scene, design: &Design) -> Frame {
    renderer(ctx, scene, design).render(&scene.camera).unwrap()
}

/// (t, u, v) of the line o + t·d through the triangle's plane, in f64 (None: parallel).
fn line_hit(o: DVec3, d: DVec3, tri: &[Vec3; 3]) -> Option<(f64, f64, f64)> {
    let [a, b, c] = tri.map(|v| v.as_dvec3());
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = o - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    Some((e2.dot(q) / det, u, v))
}

// ---------------------------------------------------------------------------------------------
// ties

/// Three groups of triangles in the plane y = 0, each inside one voxel of a 4³ grid over the
/// scene (so that even the thesis grid, which registers triangles along their edges, lists
/// them), over a floor at y = -0.5:
/// - ids 0, 1: a big triangle and, sharing its corner v0, the same triangle with half its edges
///   (e1/2, e2/2 are exact, so Möller–Trumbore gives bit for bit the same t on both);
/// - ids 2, 3: the same pair, the small one first;
/// - ids 4, 5: one triangle twice.
///
/// Every triangle has its own colour.
fn tie_scene(dir: &Path) -> (Scene, Vec<[Vec3; 3]>) {
    let leg = 1.75;
    let tri = |v0: Vec3, s: f32| {
        [
            v0,
            v0 + Vec3::new(0.0, 0.0, leg * s),
            v0 + Vec3::new(leg * s, 0.0, 0.0),
        ]
    };
    let (a, b, c) = (
        Vec3::new(-1.875, 0.0, -1.875),
        Vec3::new(0.125, 0.0, -1.875),
        Vec3::new(-1.875, 0.0, 0.125),
    );
    let ties = vec![
        tri(a, 1.0),
        tri(a, 0.5),
        tri(b, 0.5),
        tri(b, 1.0),
        tri(c, 1.0),
        tri(c, 1.0),
    ];
    let colours = [
        [0.9, 0.1, 0.1],
        [0.1, 0.9, 0.1],
        [0.1, 0.1, 0.9],
        [0.9, 0.9, 0.1],
        [0.1, 0.9, 0.9],
        [0.9, 0.1, 0.9],
    ];
    let mut objects: Vec<(String, [f32; 3])> = ties
        .iter()
        .zip(colours)
        .map(|(t, c)| (tri_obj(*t), c))
        .collect();
    objects.push((
        "v -4 -0.5 -4\nv -4 -0.5 4\nv 4 -0.5 4\nv 4 -0.5 -4\nf 1 2 3\nf 1 3 4\n".into(),
        [0.5, 0.5, 0.5],
    ));
    let head = "[camera]\nposition = [0.0, 6.0, 0.01]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 45.0\n\
                [render]\nambient = [0.2, 0.2, 0.2]\n[[light]]\nposition = [0.5, 5.0, 1.0]\n";
    let scene = scene_of(dir, head, &objects);
    assert_eq!(
        &scene.world_triangles()[..6],
        &ties[..],
        "ids in object order"
    );
    (scene, ties)
}

/// The lowest id among the tie triangles that contain the point where the ray (o, d) meets
/// y = 0, clearly inside (1e-3 from every edge); `Some(None)`: clearly in none; `None`: too
/// near an edge to say.
fn lowest_containing(o: Vec3, d: Vec3, ties: &[[Vec3; 3]]) -> Option<Option<i32>> {
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let mut best = None;
    for (id, t) in ties.iter().enumerate() {
        let (_, u, v) = line_hit(o, d, t)?;
        let inside = u.min(v).min(1.0 - u - v);
        if inside.abs() < 1e-3 {
            return None;
        }
        if inside > 0.0 && best.is_none() {
            best = Some(id as i32);
        }
    }
    Some(best)
}

#[test]
fn equal_distances_go_to_the_lower_triangle_id_on_every_tracer() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, ties) = tie_scene(dir.path());
    let ctx = context();
    let wagner_cpu = WagnerBvh::build(scene.world_triangles()).unwrap();
    for (row, design) in every_tracer(4) {
        let name = row.name;
        let gpu = render(&ctx, &scene, &design);
        let a = gpu.aovs.as_ref().unwrap();
        // the CPU side: the accelerator's twin, Wagner's BVH on the CPU; the stream's twin is
        // held against its GPU side in tests/stream.rs, here only the GPU's ids are checked
        let cpu_ids: Vec<i32> = match (&design, row.accel) {
            (Design::Mueller2015(o), Some(_)) => {
                let twin = gpgpu_rt::design::twin(&scene, &o.accel).unwrap();
                let cpu = Reference::with_accelerator(&scene, twin).render(
                    &scene.camera,
                    o.width,
                    o.height,
                    0,
                );
                // same ids, same colours, pixel by pixel
                let c = compare(&gpu, &cpu);
                assert_eq!(c.id_mismatches, 0, "{name}: GPU vs CPU twin: {c:?}");
                assert_eq!(c.color_outliers, 0.0, "{name}: GPU vs CPU twin: {c:?}");
                cpu.aovs.triangle_id
            }
            (Design::Stream(_), _) => a.triangle_id.clone(),
            _ => (0..a.triangle_id.len())
                .map(|i| {
                    let ray = Ray {
                        origin: Vec3::from(a.ray_origin[i]),
                        direction: Vec3::from(a.ray_direction[i]),
                    };
                    wagner_cpu.closest_hit(&ray).hit.map_or(-1, |h| h.id as i32)
                })
                .collect(),
        };
        // every pixel clearly inside a group: the lowest id there, on the GPU and the CPU
        let mut tied = [0usize; 3];
        for (i, &cpu_id) in cpu_ids.iter().enumerate() {
            let (o, d) = (Vec3::from(a.ray_origin[i]), Vec3::from(a.ray_direction[i]));
            let Some(Some(want)) = lowest_containing(o, d, &ties) else {
                continue;
            };
            for (side, got) in [("GPU", a.triangle_id[i]), ("CPU", cpu_id)] {
                assert_eq!(got, want, "{name}: {side}: pixel {i}");
            }
            // a pixel inside two triangles of the group
            let other = if want == 4 { 5 } else { want ^ 1 };
            let (_, u, v) = line_hit(o.as_dvec3(), d.as_dvec3(), &ties[other as usize]).unwrap();
            if u.min(v).min(1.0 - u - v) > 0.0 {
                tied[want as usize / 2] += 1;
            }
        }
        eprintln!("{name}: tied pixels per group {tied:?}");
        assert!(tied.iter().all(|&k| k > 40), "{name}: {tied:?} tied pixels");
    }
}

// ---------------------------------------------------------------------------------------------
// shadow feelers: from the offset to the light

/// A floor of 32×32 quads at y = 0, a point light at (0, 1, 0), `shadow_offset = 0.5`, and
/// four occluders (all small triangles, so that the thesis grid's edge-only lists hold them):
/// - beyond the light: a 6×6-quad roof at y = 1.5 that every visible floor point's feeler would
///   meet past the light (the camera looks past it);
/// - just before the light: a triangle at y = 0.85 (its shadow lands near (1, 0, 1)), and
///   just beyond it a small cap at y = 1.1 that all feelers would meet: a BVH puts the two in
///   one leaf whose box holds the light, so the bound on t is what keeps the cap out (a walk
///   that skips boxes beyond the light never sees the roof);
/// - nearer than the offset: a triangle at y = 0.25 that the feelers from the floor beyond it
///   meet at t ≈ 0.4 < 0.5;
/// - just beyond the offset: a triangle at y = 0.35 met at t ≈ 0.6 > 0.5.
fn light_scene(dir: &Path) -> Scene {
    let grid = |y: f32, x0: f32, z0: f32, x1: f32, z1: f32, n: usize| {
        let mut s = String::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, z) = (
                    x0 + (x1 - x0) * i as f32 / n as f32,
                    z0 + (z1 - z0) * j as f32 / n as f32,
                );
                s += &format!("v {x:?} {y:?} {z:?}\n");
            }
        }
        for j in 0..n {
            for i in 0..n {
                let k = j * (n + 1) + i + 1;
                let (a, b, c, d) = (k, k + 1, k + n + 2, k + n + 1);
                s += &format!("f {a} {d} {c}\nf {a} {c} {b}\n");
            }
        }
        s
    };
    let floor = grid(0.0, -3.0, -3.0, 3.0, 3.0, 32);
    let roof = grid(1.5, -1.5, -1.5, 1.5, 0.9, 6);
    let small = |c: Vec3, r: f32| {
        tri_obj([
            c + Vec3::new(-r, 0.0, -r),
            c + Vec3::new(-r, 0.0, r),
            c + Vec3::new(r, 0.0, 0.0),
        ])
    };
    let objects = vec![
        (floor, [0.8, 0.8, 0.8]),
        (roof, [0.8, 0.2, 0.2]),
        (small(Vec3::new(0.15, 0.85, 0.15), 0.04), [0.2, 0.8, 0.2]),
        (small(Vec3::new(0.0, 1.1, 0.0), 0.2), [0.8, 0.2, 0.8]),
        (small(Vec3::new(0.0, 0.25, 1.0), 0.35), [0.2, 0.2, 0.8]),
        (small(Vec3::new(0.75, 0.35, 0.5), 0.25), [0.8, 0.8, 0.2]),
    ];
    let head = "[camera]\nposition = [0.0, 3.0, 4.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 50.0\n\
                [render]\nambient = [0.2, 0.2, 0.2]\nshadow_offset = 0.5\n\
                [[light]]\nposition = [0.0, 1.0, 0.0]\n";
    scene_of(dir, head, &objects)
}

/// What the feeler from `p` (on triangle `skip`) to `light` meets, in f64: `None` if some
/// triangle is met within 1e-3 of one of its edges or within 1e-3 of the offset or the light
/// (too close to call); else the distances of the triangles met, beyond t = 0.05 (the floor's
/// neighbours of `skip` lie at t ≈ 0).
fn feeler(p: Vec3, light: Vec3, skip: usize, tris: &[[Vec3; 3]], offset: f64) -> Option<Vec<f64>> {
    let (o, to) = (p.as_dvec3(), light.as_dvec3() - p.as_dvec3());
    let (d, dist) = (to.normalize(), to.length());
    let mut met = Vec::new();
    for (j, t) in tris.iter().enumerate() {
        let Some((tj, u, v)) = line_hit(o, d, t) else {
            continue;
        };
        if j == skip || tj < 0.05 {
            continue;
        }
        let inside = u.min(v).min(1.0 - u - v);
        if inside.abs() < 1e-3 {
            return None;
        }
        if inside > 0.0 {
            if (tj - offset).abs() < 1e-3 || (tj - dist).abs() < 1e-3 {
                return None;
            }
            met.push(tj / dist);
        }
    }
    Some(met)
}

#[test]
fn shadow_feelers_run_from_the_offset_to_the_light_on_every_tracer() {
    let dir = tempfile::tempdir().unwrap();
    let scene = light_scene(dir.path());
    let tris = scene.world_triangles();
    let floor = 2 * 32 * 32;
    let light = scene.lights[0].position;
    let offset = scene.settings.shadow_offset as f64;
    let ctx = context();
    for (row, design) in every_tracer(8) {
        let name = row.name;
        let gpu = render(&ctx, &scene, &design);
        let a = gpu.aovs.as_ref().unwrap();
        let shadow = a.shadow.as_ref().unwrap();
        // pixels on the floor whose feeler meets: only the roof beyond the light, the occluder
        // just before the light, only the one nearer than the offset, the one beyond it
        let (mut beyond, mut before, mut under, mut over) = (0, 0, 0, 0);
        for (i, &share) in shadow.iter().enumerate() {
            let id = a.triangle_id[i];
            if id < 0 || id as usize >= floor {
                continue;
            }
            let p = Vec3::from(a.ray_origin[i]) + a.hit_t[i] * Vec3::from(a.ray_direction[i]);
            let Some(met) = feeler(p, light, id as usize, &tris, offset) else {
                continue;
            };
            let dist = (light - p).length() as f64;
            let blocked = met.iter().any(|&s| s * dist > offset && s < 1.0);
            assert_eq!(
                share == 0.0,
                blocked,
                "{name}: pixel {i} at {p}: feeler meets {met:?} (fractions of the way to the light), \
                 shadow share {}",
                share
            );
            beyond += (met.iter().all(|&s| s > 1.0) && !met.is_empty()) as usize;
            before += met.iter().any(|&s| s > 0.8 && s < 1.0) as usize;
            under += (!blocked && met.iter().any(|&s| s * dist < offset)) as usize;
            over += met.iter().any(|&s| s * dist > offset && s < 0.5) as usize;
        }
        eprintln!("{name}: beyond {beyond}, before the light {before}, under the offset {under}, over it {over}");
        assert!(beyond > 1000, "{name}: {beyond} feelers meet the roof");
        for (k, what) in [
            (before, "before the light"),
            (under, "under"),
            (over, "over"),
        ] {
            assert!(k > 10, "{name}: {k} pixels with an occluder {what}");
        }
    }
}
