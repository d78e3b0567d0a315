//! The ray tracer's AOVs hold what tools outside read from them (`tools/embree_peer.py` casts
//! the same rays with Intel Embree): `ray_origin`/`ray_direction` are the camera's primary rays
//! of Listing 11 for every pixel in image row order (row 0 = top), `o + hit_t·d` lies on the
//! triangle `triangle_id` of the scene's triangle list (the order of `export-triangles`), and
//! `shadow` is the share of the point lights whose first-hit feeler is unblocked, as the CPU
//! twin computes it. Reflection passes run after the first, so the AOVs must come from it.

mod common;

use common::*;
use glam::{DVec3, Vec3};
use gpgpu_rt::design::Design;
use gpgpu_rt::pipeline::mueller2015::{RenderOptions, ShadowFlags};
use gpgpu_rt::reference::Reference;
use gpgpu_rt::scene::Light;

fn bvh_options(w: u32, h: u32) -> RenderOptions {
    options_with(BVH_FOUR_KERNELS, w, h, 1)
}

/// Barycentric (u, v) of the projection of `p` onto the triangle's plane, and the distance of
/// `p` from that plane, in f64.
fn on_triangle(p: Vec3, tri: &[Vec3; 3]) -> (f64, f64, f64) {
    let [a, b, c] = tri.map(|v| v.as_dvec3());
    let (e1, e2, ep) = (b - a, c - a, p.as_dvec3() - a);
    let n = e1.cross(e2);
    let dist = n.dot(ep).abs() / n.length();
    // ep = u·e1 + v·e2 in the plane: Cramer's rule on the normal equations
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d1p, d2p) = (e1.dot(ep), e2.dot(ep));
    let den = d11 * d22 - d12 * d12;
    let u = (d22 * d1p - d12 * d2p) / den;
    let v = (d11 * d2p - d12 * d1p) / den;
    (u, v, dist)
}

#[test]
fn ray_aovs_hold_the_primary_rays_and_hits_lie_on_their_triangles() {
    let ctx = context();
    let scene = load("teapot1.toml");
    // not square, so that swapped width and height or a wrong row order show
    let (w, h) = (64u32, 40u32);
    let f = render_gpu(&ctx, &scene, bvh_options(w, h));
    let a = f.aovs.as_ref().expect("AOVs");
    let n = (w * h) as usize;
    assert_eq!(
        (a.ray_origin.len(), a.ray_direction.len(), a.hit_t.len()),
        (n, n, n)
    );
    let cam = scene.camera.rays(w, h);
    let c = &scene.camera;
    let forward = (DVec3::from(c.look_at.map(f64::from)) - DVec3::from(c.position.map(f64::from)))
        .normalize();
    let tris = scene.world_triangles();
    let mut hits = 0;
    for row in 0..h {
        for x in 0..w {
            let i = (row * w + x) as usize;
            let (o, d) = (Vec3::from(a.ray_origin[i]), Vec3::from(a.ray_direction[i]));
            // the camera model of Listing 11 on the CPU: GL row h-1-row is image row `row`
            let (eo, ed) = cam.primary_ray(x, h - 1 - row);
            assert!(
                (o - eo).length() < 1e-5,
                "pixel ({x}, {row}): origin {o} != {eo}"
            );
            assert!(
                (d - ed).length() < 1e-5,
                "pixel ({x}, {row}): direction {d} != {ed}"
            );
            assert!((d.length() - 1.0).abs() < 1e-5, "unit direction: {d}");
            // the origin lies on the image plane, on the line from the camera along d
            let from_cam = (o - cam.cam_position).as_dvec3();
            assert!((from_cam.dot(forward) - c.near as f64).abs() < 1e-5);
            assert!(from_cam.normalize().cross(d.as_dvec3()).length() < 1e-5);

            let (id, t) = (a.triangle_id[i], a.hit_t[i]);
            if id < 0 {
                assert_eq!(id, -1);
                assert!(t.is_infinite() && t > 0.0, "miss: hit_t = +inf, not {t}");
                continue;
            }
            hits += 1;
            let (u, v, dist) = on_triangle(o + t * d, &tris[id as usize]);
            assert!(
                dist < 1e-5,
                "pixel ({x}, {row}): o + t·d is {dist} off triangle {id}'s plane"
            );
            let inside = u.min(v).min(1.0 - u - v);
            assert!(
                inside > -1e-3,
                "pixel ({x}, {row}): o + t·d lies outside triangle {id} (u {u}, v {v})"
            );
        }
    }
    assert!(
        hits > n / 2,
        "{hits} of {n} pixels hit the floor or the teapot"
    );
}

#[test]
fn shadow_aov_is_the_share_of_unblocked_lights() {
    let ctx = context();
    let mut scene = load("teapot1.toml");
    // the scene's light throws the teapot's shadow on the floor; the second one is below the
    // floor (light behind the surface: blocked without a test), the third one low at the side
    scene.lights.push(Light {
        position: Vec3::new(0.0, -2.0, 0.0),
        color: Vec3::splat(0.3),
    });
    scene.lights.push(Light {
        position: Vec3::new(-3.0, 1.0, -1.0),
        color: Vec3::splat(0.3),
    });
    let (w, h) = (48, 40);
    let twin = gpgpu_rt::design::twin(&scene, &BVH_FOUR_KERNELS).expect("CPU twin");
    let cpu = Reference::with_accelerator(&scene, twin).render(&scene.camera, w, h, 1);
    let want = cpu
        .aovs
        .shadow
        .as_ref()
        .expect("the reference's shadow shares");
    for flags in [ShadowFlags::Bits, ShadowFlags::Rgba] {
        let opts = RenderOptions {
            shadow_flags: flags,
            ..bvh_options(w, h)
        };
        let f = render_gpu(&ctx, &scene, opts);
        let a = f.aovs.as_ref().unwrap();
        let got = a.shadow.as_ref().expect("the ray tracer's shadow AOV");
        let differ = (0..got.len()).filter(|&i| got[i] != want[i]).count();
        assert_eq!(
            differ, 0,
            "{flags:?}: {differ} pixels' shadow shares differ"
        );
        for (i, &s) in got.iter().enumerate() {
            if a.triangle_id[i] < 0 {
                assert_eq!(s, 1.0, "{flags:?}: a miss has no feelers");
            }
        }
        // the shares vary: the floor in the open is lit by 2 of the 3 lights, in the teapot's
        // shadow by 1, and parts of the teapot by none
        for share in [0.0, 1.0 / 3.0, 2.0 / 3.0] {
            let k = got.iter().filter(|&&s| (s - share).abs() < 1e-6).count();
            assert!(k > 0, "{flags:?}: no pixel is lit by a share of {share}");
        }
    }
}

/// Four tilted triangles of different sizes, each its own OBJ (so its vertex normals are its
/// face normal), none mirrored by another: top left big, bottom right small, and two between.
/// Their normals have three different components, so swapped channels show.
fn tilted_scene(dir: &std::path::Path) -> gpgpu_rt::scene::Scene {
    let tris: [[[f32; 3]; 3]; 4] = [
        [[-2.0, 0.2, 0.0], [-0.4, 1.8, -0.6], [-1.8, 1.9, 0.5]],
        [[0.6, -1.0, 0.3], [1.5, -0.6, 0.4], [1.6, -1.9, -0.2]],
        [[-0.9, -1.6, -0.8], [-1.2, -0.2, 0.6], [0.3, -0.4, 0.1]],
        [[0.2, 0.3, 0.9], [1.9, 0.5, -0.7], [0.8, 1.7, 0.2]],
    ];
    let mut toml =
        "[camera]\nposition = [0.3, 0.4, 6.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 40.0\n\
                    [[light]]\nposition = [2.0, 3.0, 4.0]\n"
            .to_string();
    for (k, t) in tris.iter().enumerate() {
        let obj: String = t
            .iter()
            .map(|v| format!("v {:?} {:?} {:?}\n", v[0], v[1], v[2]))
            .collect();
        std::fs::write(dir.join(format!("t{k}.obj")), obj + "f 1 2 3\n").unwrap();
        toml += &format!("[[object]]\ntype = \"obj\"\npath = \"t{k}.obj\"\n");
    }
    std::fs::write(dir.join("scene.toml"), toml).unwrap();
    gpgpu_rt::scene::Scene::load(&dir.join("scene.toml")).unwrap()
}

/// What each AOV means, on an asymmetric scene, for the four-kernel pipeline and Wagner's:
/// `triangle_id` is the triangle the CPU camera's ray of that image row and column meets first
/// (cast here in f64: so rows and columns are in image order), `hit_t` the distance along the
/// pixel's ray to that triangle's plane, `normal` that triangle's face normal turned towards
/// the ray.
#[test]
fn aovs_mean_the_first_triangle_its_distance_and_its_normal() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tilted_scene(dir.path());
    let tris = scene.world_triangles();
    let ctx = context();
    let (w, h) = (48u32, 40u32);
    let sah = bvh_options(w, h);
    for design in [Design::Mueller2015(sah.clone()), wagner(&sah)] {
        let variant = design.row().name;
        let f = renderer(&ctx, &scene, &design)
            .render(&scene.camera)
            .unwrap();
        let a = f.aovs.as_ref().unwrap();
        let cam = scene.camera.rays(w, h);
        let mut seen = [0usize; 4];
        for row in 0..h {
            for x in 0..w {
                let i = (row * w + x) as usize;
                let (o, d) = cam.primary_ray(x, h - 1 - row);
                let (o, d) = (o.as_dvec3(), d.as_dvec3());
                // the first triangle along the CPU's ray, unless it passes near an edge
                let mut first: Option<(f64, usize)> = None;
                let mut near_edge = false;
                for (k, t) in tris.iter().enumerate() {
                    let [p0, p1, p2] = t.map(|v| v.as_dvec3());
                    let (e1, e2) = (p1 - p0, p2 - p0);
                    let n = e1.cross(e2);
                    let tt = n.dot(p0 - o) / n.dot(d);
                    let (u, v, _) = on_triangle((o + tt * d).as_vec3(), t);
                    let inside = u.min(v).min(1.0 - u - v);
                    near_edge |= inside.abs() < 1e-3;
                    if inside > 0.0 && tt > 0.0 && first.is_none_or(|(ft, _)| tt < ft) {
                        first = Some((tt, k));
                    }
                }
                if near_edge {
                    continue;
                }
                let id = a.triangle_id[i];
                assert_eq!(
                    id,
                    first.map_or(-1, |(_, k)| k as i32),
                    "{variant}: pixel ({x}, {row})"
                );
                let Some((_, k)) = first else { continue };
                seen[k] += 1;
                // hit_t: along the GPU's own ray to the triangle's plane
                let [p0, p1, p2] = tris[k].map(|v| v.as_dvec3());
                let n = (p1 - p0).cross(p2 - p0).normalize();
                let (go, gd) = (
                    Vec3::from(a.ray_origin[i]).as_dvec3(),
                    Vec3::from(a.ray_direction[i]).as_dvec3(),
                );
                let want_t = n.dot(p0 - go) / n.dot(gd);
                let t = a.hit_t[i] as f64;
                assert!(
                    (t - want_t).abs() < 1e-5 * want_t,
                    "{variant}: pixel ({x}, {row}): hit_t {t} vs {want_t}"
                );
                // normal: the face normal turned towards the ray (triangles 1 and 2 are wound
                // away from the camera, so their vertex normals must be turned)
                let got = Vec3::from(a.normal[i]).as_dvec3();
                let want = if n.dot(gd) > 0.0 { -n } else { n };
                let d = (got - want).length();
                assert!(
                    d < 1e-5,
                    "{variant}: pixel ({x}, {row}): normal {got} vs face normal {n} of {k}"
                );
            }
        }
        eprintln!("{variant}: pixels per triangle {seen:?}");
        assert!(seen.iter().all(|&s| s > 20), "{variant}: {seen:?}");
    }
}
