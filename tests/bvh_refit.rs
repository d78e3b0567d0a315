//! The SAH BVH with moving objects (`accel::bvh::refit`, `glsl/bvh/refit_*.comp`): a turned
//! object is refitted on the GPU, not rebuilt, and gives the first hits of the base tracer, of a
//! fresh build over the turned scene and of the CPU reference, frame after frame; the refitted
//! words are those of the refit's CPU twin, and their records hold the CPU boxes of the turned
//! triangles on their grid; a refit that grew the SAH cost past the threshold makes the next
//! moving frame rebuild.

mod common;

use common::*;
use glam::{Mat4, Vec3};
use gpgpu_rt::accel::bvh::{
    Bvh, BvhTree, Grid, NodeRecord, NODE_WORDS, OCTANTS,
    REBUILD_GROWTH,
};
use gpgpu_rt::accel::TracerKind;
use gpgpu_rt::pipeline::mueller2015::{RayTracer, RenderOptions};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::{transform_triangles, Scene};
use serde_json::json;

fn bvh_options(w: u32, h: u32) -> RenderOptions {
    RenderOptions {
        tracer: TracerKind::Bvh,
        ..options(w, h, 1)
    }
}

fn bvh(t: &RayTracer) -> &Bvh {
    t.accelerator().as_any().downcast_ref::<Bvh>().expect("a BVH tracer")
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
    let growth = bvh(&tracer).sah_growth();
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
        subtree_triangles(&twin, k, &mut |id| tris[id].iter().for_each(|&p| b.grow_point(p)));
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
            assert!(b.sah_growth() > REBUILD_GROWTH, "{}", b.sah_growth());
        } else {
            assert_eq!(v.stats.facts["bvh_rebuilt"], json!(true));
            assert_eq!((b.builds(), b.refits()), (2, 0));
            assert_eq!(b.sah_growth(), 1.0);
        }
    }
}
