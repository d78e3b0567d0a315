//! The SAH BVH with moving objects (`accel::bvh::refit`, `glsl/bvh/refit_*.comp`): a turned
//! object is refitted on the GPU, not rebuilt, and gives the first hits of the base tracer, of a
//! fresh build over the turned scene and of the CPU reference, frame after frame; the refitted
//! words are those of the refit's CPU twin, and their records hold the CPU boxes of the turned
//! triangles on their grid; a refit that grew the SAH cost past the threshold makes the next
//! moving frame rebuild.

mod common;

use common::*;
use glam::{Mat4, Vec3};
use gpgpu_rt::accel::bvh::{Bvh, BvhTree, Grid, NodeRecord, NODE_WORDS, OCTANTS, REBUILD_GROWTH};
use gpgpu_rt::pipeline::mueller2015::{RayTracer, RenderOptions};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::{transform_triangles, Scene};
use serde_json::json;

fn bvh_options(w: u32, h: u32) -> RenderOptions {
    options_with(BVH_FOUR_KERNELS, w, h, 1)
}

fn bvh(t: &RayTracer) -> &Bvh {
    t.accelerator()
        .as_any()
        .downcast_ref::<Bvh>()
        .expect("a BVH tracer")
}

/// Object `object` of `scene` turned by `degrees` about its vertical axis.
fn turned(scene: &Scene, object: usize, degrees: f32) -> Mat4 {
    scene.objects[object].model * Mat4::from_axis_angle(Vec3::Y, degrees.to_radians())
}

fn world_triangles(scene: &Scene) -> Vec<[Vec3; 3]> {
    transform_triangles(
        scene
            .objects
            .iter()
            .map(|o| (o.mesh.positions.as_slice(), o.model)),
    )
}

/// The teapot of `teapot1.toml` turns 20° a frame for three frames: each frame refits (no
/// build after the first), and its first hits (triangle ids, distances) and colours are the
/// base tracer's and those of a BVH built afresh over the turned scene, and its image the CPU
/// reference's.
#[test]
fn a_turning_object_is_refitted_and_hits_what_a_fresh_build_hits() {
    let ctx = context();
    let scene = load("teapot1.toml");
    let mut tracer = ray_tracer(&ctx, &scene, bvh_options(40, 40));
    let mut base = ray_tracer(&ctx, &scene, options(40, 40, 1));
    tracer.render(&scene.camera).unwrap();
    for frame in 1..=3 {
        let model = turned(&scene, 1, 20.0 * frame as f32);
        tracer.set_model(1, model).unwrap();
        base.set_model(1, model).unwrap();
        let v = tracer.render(&scene.camera).unwrap();
        let f = &v.stats.facts;
        assert_eq!(f["bvh_rebuilt"], json!(false), "frame {frame}");
        assert_eq!(f["bvh_refits"], json!(frame), "frame {frame}");
        assert!(f["bvh_refit_ms"].as_f64().unwrap() > 0.0);
        assert_eq!((bvh(&tracer).builds(), bvh(&tracer).refits()), (1, frame));
        assert_same_image(&base.render(&scene.camera).unwrap(), &v, "refit vs base");
        let mut moved = scene.clone();
        moved.objects[1].model = model;
        let fresh = render_gpu(&ctx, &moved, bvh_options(40, 40));
        assert_same_image(&fresh, &v, "refit vs a fresh build");
        if frame == 3 {
            assert_close(&v, &render_cpu(&moved, &bvh_options(40, 40)), "refit, CPU");
        }
    }
    // the refitted tree is worse than a fresh one, not broken
    let growth = bvh(&tracer).sah_growth().unwrap();
    assert!(growth > 1.0 && growth <= REBUILD_GROWTH, "growth {growth}");
}

/// The words the refit leaves on the GPU are its CPU twin's (`BvhTree::refit` of the first
/// build's tree over the turned triangles), bit for bit; and, checked apart from the twin, every
/// record of every octant holds, on the header's grid, the CPU box of the turned triangles of
/// its subtree.
#[test]
fn the_refitted_records_hold_the_turned_triangles() {
    let ctx = context();
    let mut scene = load("teapot1.toml");
    let mut tracer = ray_tracer(&ctx, &scene, bvh_options(24, 24));
    tracer.render(&scene.camera).unwrap();
    let mut twin = BvhTree::new(world_triangles(&scene));
    assert_words(&bvh(&tracer).words(), &twin.gpu_words(), "the upload");
    let model = turned(&scene, 1, 35.0) * Mat4::from_rotation_x(0.4);
    tracer.set_model(1, model).unwrap();
    tracer.render(&scene.camera).unwrap();
    scene.objects[1].model = model;
    let tris = world_triangles(&scene);
    twin.refit(tris.clone());
    let want = twin.gpu_words();
    let words = bvh(&tracer).words();
    assert_words(&words, &want, "the refit's words are its twin's");
    let f = |w: &[u32]| Vec3::from_array([0, 1, 2].map(|k| f32::from_bits(w[k])));
    let grid = Grid {
        origin: f(&words[1..4]),
        step: f(&words[4..7]),
    };
    for (k, node) in twin.nodes.iter().enumerate() {
        let mut b = gpgpu_rt::accel::bvh::Aabb::EMPTY;
        subtree_triangles(&twin, k, &mut |id| {
            tris[id].iter().for_each(|&p| b.grow_point(p))
        });
        for o in 0..OCTANTS {
            let texel = twin.record_texels(o)[k] as usize;
            let r: NodeRecord = bytemuck::pod_read_unaligned(bytemuck::cast_slice(
                &words[4 * texel..4 * texel + NODE_WORDS],
            ));
            for a in 0..3 {
                let down = (o >> a) & 1 == 1;
                let (lo, hi) = match down {
                    true => (r.far[a], r.near[a]),
                    false => (r.near[a], r.far[a]),
                };
                assert!(
                    grid.plane(a, lo) <= b.lo[a] as f64 && b.hi[a] as f64 <= grid.plane(a, hi),
                    "node {k} ({}), octant {o}, axis {a}",
                    if node.is_leaf() { "leaf" } else { "inner" }
                );
            }
        }
    }
}

/// A refit cut short (its boxes pass over half the leaves, then nothing) leaves no trace in the
/// next: the arrival counts are cleared at every refit, so the refit after it leaves its twin's
/// words, bit for bit, and two refits later still do (counts that relied on their parity
/// across refits were wrong from the abandoned one on).
#[test]
fn a_refit_after_an_abandoned_one_is_whole() {
    let ctx = context();
    let mut scene = load("teapot1.toml");
    let mut tracer = ray_tracer(&ctx, &scene, bvh_options(24, 24));
    tracer.render(&scene.camera).unwrap();
    let mut twin = BvhTree::new(world_triangles(&scene));
    for (frame, degrees) in [(1, 25.0), (2, 50.0)] {
        let model = turned(&scene, 1, degrees);
        if frame == 1 {
            bvh(&tracer).abandon_next_refit_halfway();
        }
        tracer.set_model(1, model).unwrap();
        tracer.render(&scene.camera).unwrap();
        assert_eq!(
            bvh(&tracer).refits(),
            frame,
            "frame {frame}: a refit, no rebuild"
        );
        scene.objects[1].model = model;
        twin.refit(world_triangles(&scene));
        let what = format!("frame {frame}: the refit after an abandoned one");
        assert_words(&bvh(&tracer).words(), &twin.gpu_words(), &what);
    }
}

/// The first `want.len()` words of `words` are `want` (the block entries follow them).
fn assert_words(words: &[u32], want: &[u32], what: &str) {
    assert!(words.len() >= want.len(), "{what}: {} words", words.len());
    let differ = (0..want.len()).filter(|&i| words[i] != want[i]);
    let differ: Vec<_> = differ.take(5).map(|i| (i, words[i], want[i])).collect();
    assert!(differ.is_empty(), "{what}: (word, GPU, twin) {differ:?}");
}

/// Every triangle id under node `k`.
fn subtree_triangles(tree: &BvhTree, k: usize, each: &mut impl FnMut(usize)) {
    let n = &tree.nodes[k];
    if n.is_leaf() {
        let entries = n.first as usize..(n.first + n.count()) as usize;
        tree.tris[entries].iter().for_each(|&id| each(id as usize));
    } else {
        subtree_triangles(tree, n.first as usize, each);
        subtree_triangles(tree, n.first as usize + 1, each);
    }
}

/// The teapot lifted far above its floor: the refit must stretch the boxes that held floor and
/// teapot together, its SAH cost grows past the threshold, and the next frame that moves an
/// object rebuilds (a fresh tree, no refits), the image the base tracer's throughout.
#[test]
fn a_refit_past_the_threshold_makes_the_next_move_rebuild() {
    let ctx = context();
    let scene = load("teapot1.toml");
    let mut tracer = ray_tracer(&ctx, &scene, bvh_options(32, 32));
    let mut base = ray_tracer(&ctx, &scene, options(32, 32, 1));
    tracer.render(&scene.camera).unwrap();
    let lifted = Mat4::from_translation(Vec3::new(3.0, 2.0, 0.0)) * scene.objects[1].model;
    for (frame, model) in [lifted, turned(&scene, 1, 10.0)].into_iter().enumerate() {
        tracer.set_model(1, model).unwrap();
        base.set_model(1, model).unwrap();
        let v = tracer.render(&scene.camera).unwrap();
        assert_same_image(&base.render(&scene.camera).unwrap(), &v, "lifted teapot");
        let b = bvh(&tracer);
        if frame == 0 {
            assert_eq!(v.stats.facts["bvh_rebuilt"], json!(false));
            let growth = b.sah_growth().unwrap();
            assert!(growth > REBUILD_GROWTH, "{growth}");
        } else {
            assert_eq!(v.stats.facts["bvh_rebuilt"], json!(true));
            assert_eq!((b.builds(), b.refits()), (2, 0));
            assert_eq!(b.sah_growth().unwrap(), 1.0);
        }
    }
}

/// The measurement behind `REBUILD_GROWTH` (`docs/design/bvh.md`, "Moving objects"): the SAH
/// cost of the refitted tree over the built tree's, as the scene turns about the vertical axis
/// through its centre (the bench's `--rotate objects`) in steps of 15°, refitted by the CPU twin
/// (whose words are the GPU refit's, above) and never rebuilt; and a fresh build's cost at each
/// angle. Run: `cargo test --release --test bvh_refit -- --ignored --nocapture growth`.
#[test]
#[ignore = "a measurement, not a check: prints a table"]
fn sah_growth_over_a_full_turn() {
    for name in ["bunny.toml", "dragon.toml"] {
        let scene = load(name);
        let tris = world_triangles(&scene);
        let mut b = gpgpu_rt::accel::bvh::Aabb::EMPTY;
        tris.iter().flatten().for_each(|&p| b.grow_point(p));
        let c = 0.5 * (b.lo + b.hi);
        let mut tree = BvhTree::new(tris.clone());
        let built = tree.stats.sah_cost;
        eprintln!("{name}: built SAH cost {built:.2}; degrees, refitted/built, fresh/built");
        for step in 1..=24 {
            let deg = 15.0 * step as f32;
            let r = Mat4::from_translation(c)
                * Mat4::from_rotation_y(deg.to_radians())
                * Mat4::from_translation(-c);
            let turned: Vec<_> = tris
                .iter()
                .map(|t| t.map(|p| r.transform_point3(p)))
                .collect();
            tree.refit(turned.clone());
            let fresh = BvhTree::new(turned).stats.sah_cost;
            eprintln!(
                "  {deg:5.0}  {:.3}  {:.3}",
                tree.stats.sah_cost / built,
                fresh / built
            );
        }
    }
}

/// The measurement of a turning frame against a still one (`docs/design/bvh.md`, "Moving
/// objects"): `scene` at 512², no reflections, every object turned about the scene's vertical
/// axis through its centre (the bench's `--rotate objects`) by 3° on every other frame, so that
/// refitted and still frames alternate; their GPU time (every kernel, `gpu_ms_total`) and the
/// refit's. Run: `cargo test --release --test bvh_refit -- --ignored --nocapture turning`.
#[test]
#[ignore = "a measurement, not a check: prints a table"]
fn turning_frames_against_still_ones() {
    let ctx = context();
    for name in ["bunny.toml", "dragon.toml"] {
        let scene = load(name);
        let mut b = gpgpu_rt::accel::bvh::Aabb::EMPTY;
        world_triangles(&scene)
            .iter()
            .flatten()
            .for_each(|&p| b.grow_point(p));
        let c = 0.5 * (b.lo + b.hi);
        let mut tracer = ray_tracer(
            &ctx,
            &scene,
            RenderOptions {
                refl_depth: 0,
                ..bvh_options(512, 512)
            },
        );
        tracer.render(&scene.camera).unwrap();
        let (mut still, mut turning, mut refit) = (Vec::new(), Vec::new(), Vec::new());
        for frame in 1..=10 {
            if frame % 2 == 0 {
                let r = Mat4::from_translation(c)
                    * Mat4::from_rotation_y((3.0 * frame as f32).to_radians())
                    * Mat4::from_translation(-c);
                for (i, o) in scene.objects.iter().enumerate() {
                    tracer.set_model(i, r * o.model).unwrap();
                }
            }
            let s = tracer.render(&scene.camera).unwrap().stats;
            let total: f64 = s.gpu_ms.values().sum();
            match frame % 2 {
                0 => turning.push(total),
                _ => still.push(total),
            }
            refit.push(s.facts["bvh_refit_ms"].as_f64().unwrap());
            assert_eq!(s.facts["bvh_rebuilt"], json!(false));
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let refit: Vec<f64> = refit.into_iter().filter(|&m| m > 0.0).collect();
        eprintln!(
            "{name}: still {:.1} ms, turning {:.1} ms (ratio {:.3}), refit {:.1} ms; still {still:.1?}, turning {turning:.1?}",
            mean(&still),
            mean(&turning),
            mean(&turning) / mean(&still),
            mean(&refit)
        );
    }
}
