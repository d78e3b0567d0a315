//! The work of each kind of rays apart (`accel-compare`): Müller 2015's pipeline (and the streaming
//! tracer) counts primary rays, the feelers towards the first light and towards the others, and the
//! reflection rays into banks of its counter buffer, and times them apart. Checked for every
//! accelerator of the pipeline on the stadium (4 lights, a reflective teapot): the rays of each
//! kind equal those of the CPU reference with the accelerator's twin, the kinds add up to the
//! frame's totals, each kind counts only its own kernel's tests, and each has GPU time.

mod common;

use common::*;
use gpgpu_rt::frame::{Frame, RAY_KINDS};
use gpgpu_rt::pipeline::mueller2015::RenderOptions;
use gpgpu_rt::reference::Reference;

const SIZE: u32 = 24;

/// The pipeline's accelerators: (label, options).
fn accelerators() -> Vec<(&'static str, RenderOptions)> {
    pipeline_accelerators(SIZE, SIZE, 1, 16)
}

/// A counter of a kind of `f`, 0 where the kind or the counter is absent.
fn count(f: &Frame, kind: &str, name: &str) -> u64 {
    f.stats.ray_kinds.get(kind).map_or(0, |k| k.count(name))
}

#[test]
fn every_kind_of_ray_is_counted_and_timed_apart() {
    let ctx = context();
    let scene = load("stadium.toml");
    assert_eq!(scene.lights.len(), 4, "the stadium's floodlights");
    let base = render_cpu(&scene, &options(SIZE, SIZE, 1));
    assert_eq!(
        base.rays[0],
        (SIZE * SIZE) as u64,
        "a primary ray per pixel"
    );
    assert!(
        base.rays.iter().all(|&r| r > 0),
        "every kind traced: {:?}",
        base.rays
    );
    for (label, opts) in accelerators() {
        let twin = gpgpu_rt::design::twin(&scene, &opts.accel).expect("its CPU twin");
        let cpu = Reference::with_accelerator(&scene, twin).render(&scene.camera, SIZE, SIZE, 1);
        let f = render_gpu(&ctx, &scene, opts);
        let s = &f.stats;
        // the thesis grid's fixed voxel lists overflow here (the whole teapot in a few voxels):
        // its twin's lists are complete, so only its primary rays are comparable
        let lossy = s.events.get("dropped_triangle_refs").copied().unwrap_or(0) > 0;
        assert_eq!(lossy, label == "grid thesis", "{label}: dropped references");
        for (kind, &rays) in RAY_KINDS.iter().zip(&cpu.rays) {
            if !lossy || *kind == "primary" {
                assert_eq!(count(&f, kind, "rays"), rays, "{label}: {kind} rays");
            }
            let k = &s.ray_kinds[*kind];
            assert!(k.gpu_ms > 0.0, "{label}: {kind} has GPU time");
            // a kind counts its own kernel's tests only
            let other = if *kind == "primary" || *kind == "reflection" {
                "intersect2"
            } else {
                "intersect1"
            };
            assert_eq!(k.count(other), 0, "{label}: {kind} counted {other}");
        }
        // the kinds add up to the frame's totals
        for name in ["intersect1", "intersect2"] {
            let kinds: u64 = RAY_KINDS.iter().map(|k| count(&f, k, name)).sum();
            assert_eq!(
                kinds, s.triangle_tests[name],
                "{label}: {name} over the kinds"
            );
        }
        for name in ["rays", "voxels_visited", "nodes_visited"] {
            let kinds: u64 = RAY_KINDS.iter().map(|k| count(&f, k, name)).sum();
            assert_eq!(kinds, s.events[name], "{label}: {name} over the kinds");
        }
        let kinds_ms: f64 = s.ray_kinds.values().map(|k| k.gpu_ms).sum();
        assert!(
            kinds_ms <= s.total_gpu_ms() + 1e-6,
            "{label}: kinds' time within the frame's"
        );
        for (kind, k) in &s.ray_kinds {
            assert_eq!(
                k.triangle_tests,
                k.count("intersect1") + k.count("intersect2"),
                "{kind}"
            );
        }
        if label.starts_with("base") {
            let tests = |kinds: &[&str], name| kinds.iter().map(|k| count(&f, k, name)).sum();
            let i1: u64 = tests(&["primary", "reflection"], "intersect1");
            let i2: u64 = tests(&["shadow_first_light", "shadow_other_lights"], "intersect2");
            assert_eq!(
                (i1, i2),
                (cpu.intersect1_tests, cpu.intersect2_tests),
                "base tests"
            );
        }
    }
}

#[test]
fn one_light_and_no_reflection_leave_their_kinds_out() {
    let ctx = context();
    let scene = load("bunny_low.toml");
    assert_eq!(scene.lights.len(), 1);
    let mut opts = options(SIZE, SIZE, 0);
    opts.accel = BVH_FOUR_KERNELS;
    let f = render_gpu(&ctx, &scene, opts);
    let kinds: Vec<&str> = f.stats.ray_kinds.keys().map(|k| k.as_str()).collect();
    assert_eq!(kinds, ["primary", "shadow_first_light"]);
    assert_eq!(count(&f, "primary", "rays"), (SIZE * SIZE) as u64);
}

/// A frame of `design` (Wagner's megakernel or the stream).
fn pipeline_frame(
    ctx: &gpgpu_rt::gl::GlContext,
    scene: &gpgpu_rt::scene::Scene,
    design: gpgpu_rt::design::Design,
) -> Frame {
    common::renderer(ctx, scene, &design)
        .render(&scene.camera)
        .expect("frame")
}

/// The rays of `f`'s frame: `rays` among its events.
fn rays(f: &Frame) -> u64 {
    f.stats.events["rays"]
}

#[test]
fn the_own_pipelines_count_the_rays_they_trace() {
    let ctx = context();
    let scene = load("teapot1.toml");
    assert_eq!(scene.lights.len(), 1);
    // the stream traces the same rays as Müller's pipeline: eye, feelers, reflection
    let mut opts = options(SIZE, SIZE, 1);
    opts.accel = BVH_FOUR_KERNELS;
    let mueller = render_gpu(&ctx, &scene, opts.clone());
    let reflection = count(&mueller, "reflection", "rays");
    assert!(reflection > 0, "the teapot reflects");
    let stream = pipeline_frame(&ctx, &scene, common::stream(&opts));
    assert_eq!(rays(&stream), rays(&mueller), "stream rays");
    // and counts them per kind, as Müller's pipeline does
    for kind in RAY_KINDS {
        let (s, m) = (count(&stream, kind, "rays"), count(&mueller, kind, "rays"));
        assert_eq!(s, m, "stream: {kind} rays");
    }
    let closest: u64 = ["primary", "reflection"]
        .map(|k| stream.stats.ray_kinds[k].triangle_tests)
        .iter()
        .sum();
    assert_eq!(
        closest, stream.stats.triangle_tests["closest"],
        "stream: closest-hit tests"
    );
    assert_eq!(
        stream.stats.ray_kinds["shadow_first_light"].triangle_tests,
        stream.stats.triangle_tests["shadow"],
        "stream: one light's feelers"
    );
    assert!(stream.stats.ray_kinds.values().all(|k| k.gpu_ms > 0.0));
    // Wagner's kernel: the eye rays and the first light's feelers, no reflection
    opts.refl_depth = 0;
    let wagner = pipeline_frame(&ctx, &scene, common::wagner(&opts));
    let eye_and_feelers = render_gpu(&ctx, &scene, opts);
    assert_eq!(rays(&wagner), rays(&eye_and_feelers), "Wagner's rays");
    assert_eq!(
        rays(&eye_and_feelers),
        count(&eye_and_feelers, "primary", "rays")
            + count(&eye_and_feelers, "shadow_first_light", "rays")
    );
}
