//! `--bvh-instances` (ours, `accel::bvh::instances`): the SAH BVH as a tree per object under
//! the objects' instances. It must hit what the CPU reference hits, in a still scene and with
//! objects that turn and move frame after frame — which update the instances only: no refit,
//! no rebuild, no transform of the scene's vertices — in the four kernels and the fused pass.

mod common;

use common::*;
use glam::{Mat4, Vec3};
use gpgpu_rt::accel::bvh::Bvh;
use gpgpu_rt::accel::{BvhLevels, BvhPasses};
use gpgpu_rt::frame::Frame;
use gpgpu_rt::pipeline::mueller2015::{RayTracer, RenderOptions};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::Scene;
use serde_json::json;

/// The two-level BVH in Müller 2015's four kernels.
fn instances(w: u32, h: u32, refl_depth: u32) -> RenderOptions {
    let accel = common::bvh(BvhPasses::FourKernels, BvhLevels::Two);
    options_with(accel, w, h, refl_depth)
}

fn bvh(t: &RayTracer) -> &Bvh {
    t.accelerator()
        .as_any()
        .downcast_ref::<Bvh>()
        .expect("a BVH tracer")
}

/// Every object of `scene` stretched unevenly (its normals then turn otherwise than its
/// surface), turned by `degrees` about its vertical axis and lifted by `lift`.
fn moved(scene: &Scene, degrees: f32, lift: f32) -> Vec<Mat4> {
    let stretch = Mat4::from_scale(Vec3::new(1.6, 0.5, 1.0));
    let turn = Mat4::from_axis_angle(Vec3::Y, degrees.to_radians());
    let up = Mat4::from_translation(Vec3::Y * lift);
    scene
        .objects
        .iter()
        .map(|o| up * o.model * turn * stretch)
        .collect()
}

/// The walk meets the triangles in object space, and the rounding of the ray's transform moves
/// a hit distance by some ulps and may flip a ray that grazes an edge shared by two triangles:
/// the tolerances of `common::SAME_ARITHMETIC` widened by those roundings.
fn assert_hits_reference(gpu: &Frame, scene: &Scene, opts: &RenderOptions, what: &str) {
    let c = compare(gpu, &render_cpu(scene, opts));
    eprintln!("{what}: {c:?}");
    assert!(c.hits > c.pixels / 16, "{what}: too little geometry: {c:?}");
    // measured on llvmpipe (teapot1, 3 and 6, 40×40, still and moved): no id differs, hit
    // distances within 4.0e-6 relative, colours within 1.2e-4 at worst and 2.3e-7 on average;
    // an edge ray or two may flip where a GL implementation rounds the transform otherwise
    assert!(c.id_mismatches <= 2, "{what}: triangle ids differ: {c:?}");
    assert!(c.max_t_rel <= 1e-5, "{what}: hit distances differ: {c:?}");
    assert!(c.max_color_diff <= 1e-3, "{what}: colours differ: {c:?}");
    assert!(c.mean_color_diff <= 1e-5, "{what}: colours differ: {c:?}");
}

/// Still scenes of 1 (the walk without the instance loop), 2, 4 and 7 objects: the CPU
/// reference's first hits, distances and colours, as one tree gives them.
#[test]
fn instances_hit_what_the_reference_hits() {
    let ctx = context();
    for name in ["cow.toml", "teapot1.toml", "teapot3.toml", "teapot6.toml"] {
        let scene = load(name);
        let opts = instances(40, 40, 1);
        let mut t = ray_tracer(&ctx, &scene, opts.clone());
        let v = t.render(&scene.camera).unwrap();
        assert_eq!(
            v.stats.facts["bvh_instances"],
            json!(scene.objects.len()),
            "{name}"
        );
        assert_hits_reference(&v, &scene, &opts, name);
    }
}

/// Objects that turn and rise every frame: each frame rewrites the instances only — one build
/// (the first frame's), no refit, no rebuild, no transform pass after the first frame — and
/// hits what the CPU reference hits in the moved scene.
#[test]
fn moving_objects_update_the_instances_only() {
    let ctx = context();
    // one object (no instance loop) and four
    for name in ["cow.toml", "teapot3.toml"] {
        let scene = load(name);
        let opts = instances(40, 40, 1);
        let mut t = ray_tracer(&ctx, &scene, opts.clone());
        let first = t.render(&scene.camera).unwrap();
        assert!(first.stats.gpu_ms.contains_key("transform"));
        // the first frame builds the trees; no table was rewritten
        assert_eq!(first.stats.facts["bvh_rebuilt"], json!(true), "{name}");
        assert_eq!(first.stats.facts["bvh_instances_ms"], json!(0.0), "{name}");
        for frame in 1..=3 {
            let models = moved(&scene, 25.0 * frame as f32, 0.3 * frame as f32);
            let mut now = scene.clone();
            for (k, m) in models.iter().enumerate() {
                t.set_model(k, *m).unwrap();
                now.objects[k].model = *m;
            }
            let v = t.render(&scene.camera).unwrap();
            let f = &v.stats.facts;
            let what = format!("{name}, frame {frame}");
            assert_eq!(f["bvh_rebuilt"], json!(false), "{what}");
            assert_eq!(f["bvh_refits"], json!(0), "{what}");
            assert_eq!(bvh(&t).builds(), 1, "{what}");
            // the frame's one update: the instance table's write, timed
            assert!(f["bvh_instances_ms"].as_f64().unwrap() > 0.0, "{what}");
            assert!(
                !v.stats.gpu_ms.contains_key("transform"),
                "{what}: {:?}",
                v.stats.gpu_ms
            );
            assert_hits_reference(&v, &now, &opts, &what);
        }
        // a frame where nothing moved writes nothing
        let still = t.render(&scene.camera).unwrap();
        assert_eq!(still.stats.facts["bvh_instances_ms"], json!(0.0), "{name}");
        assert_eq!(bvh(&t).builds(), 1, "{name}");
    }
}

/// The fused pass walks the same instances: after a turn, the four kernels' image, first hits,
/// shadow flags and counts.
#[test]
fn the_fused_pass_walks_the_instances() {
    let ctx = context();
    let scene = load("teapot3.toml");
    let models = moved(&scene, 40.0, 0.0);
    let mut frames = Vec::new();
    for passes in [BvhPasses::FourKernels, BvhPasses::Fused] {
        let opts = options_with(common::bvh(passes, BvhLevels::Two), 40, 40, 1);
        let mut t = ray_tracer(&ctx, &scene, opts);
        t.render(&scene.camera).unwrap();
        for (k, m) in models.iter().enumerate() {
            t.set_model(k, *m).unwrap();
        }
        frames.push(t.render(&scene.camera).unwrap());
    }
    let (four, fused) = (&frames[0], &frames[1]);
    assert_same_image(four, fused, "fused vs four kernels");
    let (a, b) = (four.aovs.as_ref().unwrap(), fused.aovs.as_ref().unwrap());
    assert_eq!(a.shadow, b.shadow);
    assert_eq!(a.normal, b.normal);
    assert_eq!(four.stats.triangle_tests, fused.stats.triangle_tests);
    assert_eq!(four.stats.events, fused.stats.events);
}

/// Only the SAH BVH has instances (no other accelerator's options can hold them): beside
/// another design the option is refused by name, with the design that takes it.
#[test]
fn instances_are_refused_beside_other_accelerators() {
    let row = gpgpu_rt::design::row("grid-exact").unwrap();
    let given = ["bvh-instances".to_string()];
    let err = gpgpu_rt::design::refuse_foreign(row, &given, "from --tracer grid").unwrap_err();
    let err = format!("{err:#}");
    assert!(err.contains("--bvh-instances applies to bvh ("), "{err}");
}
