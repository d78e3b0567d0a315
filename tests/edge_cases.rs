//! The cases real scenes almost never exercise, for every tracer (`accel::REGISTRY` and Wagner
//! 2018's megakernel), GPU and CPU alike, against expectations computed here in f64:
//! - ties: at exactly equal distance the lower triangle id wins (the same triangle twice,
//!   and coplanar overlapping triangles whose hit distances are bit for bit equal);
//! - shadow feelers end at the light: an occluder beyond a point light does not shadow, one
//!   just before it does; and they start at the scene's `shadow_offset`: an occluder nearer
//!   than the offset does not shadow, one just beyond it does.

mod common;

use std::path::Path;

use common::*;
use glam::{DVec3, Vec3};
use gpgpu_rt::accel::{BvhVariant, GridOptions, REGISTRY};
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::pipeline;
use gpgpu_rt::pipeline::raytrace::RenderOptions;
use gpgpu_rt::reference::wagner2018::Ray;
use gpgpu_rt::reference::wagner_bvh::WagnerBvh;
use gpgpu_rt::reference::Reference;
use gpgpu_rt::scene::Scene;

/// A scene file in `dir`: `head` (camera, render, lights) and one object per (OBJ text, colour).
fn scene_of(dir: &Path, head: &str, objects: &[(String, [f32; 3])]) -> Scene {
    let mut toml = head.to_string();
    for (k, (obj, c)) in objects.iter().enumerate() {
        std::fs::write(dir.join(format!("o{k}.obj")), obj).unwrap();
        toml += &format!(
            "[[object]]\ntype = \"obj\"\npath = \"o{k}.obj\"\ncolor = [{:?}, {:?}, {:?}]\nspecular = 0.0\n",
            c[0], c[1], c[2]
        );
    }
    std::fs::write(dir.join("scene.toml"), toml).unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap()
}

/// An OBJ of one triangle.
fn tri_obj(t: [Vec3; 3]) -> String {
    let mut s = String::new();
    for v in t {
        s += &format!("v {:?} {:?} {:?}\n", v.x, v.y, v.z);
    }
    s + "f 1 2 3\n"
}

/// Every tracer: each registry entry (the grids at `grid_resolution`) and Wagner's megakernel,
/// with a name for messages.
fn every_tracer(grid_resolution: u32) -> Vec<(String, RenderOptions)> {
    let mut v: Vec<(String, RenderOptions)> = REGISTRY
        .iter()
        .map(|e| {
            let grid = GridOptions {
                variant: e.grid_variant.unwrap_or_default(),
                resolution: Some(grid_resolution),
                ..GridOptions::default()
            };
            (
                e.label.to_string(),
                RenderOptions {
                    tracer: e.tracer,
                    grid,
                    ..options(64, 64, 0)
                },
            )
        })
        .collect();
    v.push((
        "bvh-wagner".into(),
        RenderOptions {
            tracer: gpgpu_rt::accel::TracerKind::Bvh,
            bvh_variant: BvhVariant::Wagner,
            ..options(64, 64, 0)
        },
    ));
    v
}

fn render(ctx: &GlContext, scene: &Scene, opts: RenderOptions) -> Frame {
    let shaders = ShaderSource::default();
    let mut r = pipeline::ray_tracer(ctx.gl.clone(), &ctx.info, scene, &shaders, opts).unwrap();
    r.render(&scene.camera).unwrap()
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
    for (name, opts) in every_tracer(4) {
        let gpu = render(&ctx, &scene, opts.clone());
        let a = gpu.aovs.as_ref().unwrap();
        // the CPU side: the registry entry's twin, or Wagner's BVH on the CPU
        let cpu_ids: Vec<i32> = match REGISTRY.iter().find(|e| e.label == name) {
            Some(e) => {
                let twin = (e.cpu)(&scene, &opts.grid).unwrap();
                let cpu = Reference::with_accelerator(&scene, twin).render(
                    &scene.camera,
                    opts.width,
                    opts.height,
                    0,
                );
                // same ids, same colours, pixel by pixel
                let c = compare(&gpu, &cpu);
                assert_eq!(c.id_mismatches, 0, "{name}: GPU vs CPU twin: {c:?}");
                assert_eq!(c.color_outliers, 0.0, "{name}: GPU vs CPU twin: {c:?}");
                cpu.aovs.triangle_id
            }
            None => (0..a.triangle_id.len())
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
        for i in 0..a.triangle_id.len() {
            let (o, d) = (Vec3::from(a.ray_origin[i]), Vec3::from(a.ray_direction[i]));
            let Some(Some(want)) = lowest_containing(o, d, &ties) else {
                continue;
            };
            for (side, got) in [("GPU", a.triangle_id[i]), ("CPU", cpu_ids[i])] {
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
