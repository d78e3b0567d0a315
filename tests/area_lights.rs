//! Area lights in Müller 2015's ray tracer (ours, after Klee 2016; issue 35, item 4): intersect2
//! casts one feeler per light sample, the shading kernel weights the light by the share of
//! unblocked samples. Held against the CPU reference with each accelerator's twin on a scene
//! with a point light beside the area light and a reflective floor and cow, so that the
//! reflected hits' soft shadows are compared too: the same image, shadow shares, triangle tests
//! and rays per kind.

mod common;

use common::*;
use gpgpu_rt::frame::{Frame, RAY_KINDS};
use gpgpu_rt::pipeline::mueller2015::{RayTracer, RenderOptions, ShadowFlags};
use gpgpu_rt::reference::{Reference, ReferenceFrame};
use gpgpu_rt::scene::Scene;

const SIZE: (u32, u32) = (48, 36);
/// Unequal U and V, so that a swap of the two shows.
const SAMPLES: (u32, u32) = (3, 2);

/// Every accelerator of the pipeline, with the samples: (label, options).
fn accelerators() -> Vec<(&'static str, RenderOptions)> {
    let mut all = pipeline_accelerators(SIZE.0, SIZE.1, 1, 12);
    for (_, o) in &mut all {
        o.light_samples = SAMPLES;
    }
    all
}

fn reference(scene: &Scene, o: &RenderOptions, samples: (u32, u32)) -> ReferenceFrame {
    let twin = gpgpu_rt::design::twin(scene, &o.accel).expect("CPU twin");
    Reference::with_accelerator(scene, twin)
        .with_light_samples(samples)
        .render(&scene.camera, o.width, o.height, o.refl_depth)
}

/// Pixels whose share of the area light's samples is neither 0 nor 1: with one point light
/// and one area light the lit share is (point + area share) / 2.
fn penumbra(shadow: &[f32]) -> usize {
    shadow
        .iter()
        .filter(|&&s| (2.0 * s - (2.0 * s).round()).abs() > 1e-3)
        .count()
}

fn assert_same_work(gpu: &Frame, cpu: &ReferenceFrame, label: &str) {
    let g2 = gpu.stats.triangle_tests["intersect2"];
    assert_eq!(g2, cpu.intersect2_tests, "{label}: intersect2 tests");
    let g1 = gpu.stats.triangle_tests["intersect1"];
    assert_eq!(g1, cpu.intersect1_tests, "{label}: intersect1 tests");
    for (kind, rays) in RAY_KINDS.iter().zip(cpu.rays) {
        let g = gpu
            .stats
            .ray_kinds
            .get(*kind)
            .map_or(0, |k| k.count("rays"));
        assert_eq!(g, rays, "{label}: {kind} rays");
    }
}

#[test]
fn every_accelerator_casts_the_area_lights_feelers_as_the_reference() {
    let ctx = context();
    let scene = load("cow_area.toml");
    assert_eq!((scene.lights.len(), scene.area_lights.len()), (1, 1));
    for (label, opts) in accelerators() {
        let gpu = render_gpu(&ctx, &scene, opts.clone());
        let cpu = reference(&scene, &opts, SAMPLES);
        let c = assert_close(&gpu, &cpu, label);
        assert!(c.hits > 800, "{label}: {} hits", c.hits);
        assert_same_work(&gpu, &cpu, label);
        // the shadow AOV: the share of the first hit's feelers unblocked, sample by sample
        let (gs, cs) = (gpu.aovs.as_ref().unwrap().shadow.as_ref().unwrap(), {
            cpu.aovs.shadow.as_ref().unwrap()
        });
        let off = gs.iter().zip(cs).filter(|(g, c)| (*g - *c).abs() > 1e-6);
        assert_eq!(off.count(), 0, "{label}: shadow shares differ");
        // a penumbra to compare: the test is not passed by hard shadows
        let soft = penumbra(cs);
        eprintln!("{label}: {c:?}, {soft} penumbra pixels");
        assert!(soft > 60, "{label}: {soft} penumbra pixels");
    }
}

/// The samples matter, in the primary and the reflected hits: the reference with the one
/// sample at the light's centre differs from the one with the samples spread, also in pixels
/// whose first hit has the same shadow share in both (so the difference is the reflected
/// hits') — so the comparison above would catch a GPU that ignores the samples, in either pass.
#[test]
fn the_samples_change_the_primary_and_the_reflected_hits() {
    let scene = load("cow_area.toml");
    let opts = &pipeline_accelerator("bvh four-kernels", &accelerators());
    let spread = reference(&scene, opts, SAMPLES);
    let centre = reference(&scene, opts, (1, 1));
    let share = |f: &ReferenceFrame| f.aovs.shadow.clone().unwrap();
    let (s1, s2) = (share(&spread), share(&centre));
    let differs = |i: usize| (0..3).any(|k| (spread.color[i][k] - centre.color[i][k]).abs() > 1e-3);
    let all = (0..s1.len()).filter(|&i| differs(i)).count();
    let reflected = (0..s1.len())
        .filter(|&i| s1[i] == s2[i] && differs(i))
        .count();
    eprintln!(
        "{all} pixels change with the sample positions, {reflected} of them in the reflection only"
    );
    assert!(all > 100, "{all}");
    assert!(reflected >= 10, "{reflected}");
}

fn tracer(scene: &Scene, opts: RenderOptions) -> anyhow::Result<RayTracer> {
    try_ray_tracer(&context(), scene, opts)
}

/// Area lights need a flag bit per sample: the thesis' RGBA layout, and more samples than the
/// 128 bits hold, are refused with a message that says so.
#[test]
fn layouts_that_cannot_hold_the_samples_are_refused() {
    let mut scene = load("cow_area.toml");
    let mut opts = pipeline_accelerator("bvh four-kernels", &accelerators());
    opts.shadow_flags = ShadowFlags::Rgba;
    let err = tracer(&scene, opts.clone())
        .err()
        .expect("refused")
        .to_string();
    assert!(
        err.contains("--shadow-flags bits") && err.contains("cow_area.toml"),
        "{err}"
    );
    opts.shadow_flags = ShadowFlags::Bits;
    opts.light_samples = (8, 8);
    scene.area_lights.push(scene.area_lights[0]);
    let err = tracer(&scene, opts.clone())
        .err()
        .expect("refused")
        .to_string();
    assert!(
        err.contains("need 129 shadow flag bits") && err.contains("holds 128"),
        "{err}"
    );
    // 1 + 2·63 = 127 bits fit
    opts.light_samples = (9, 7);
    assert!(tracer(&scene, opts).is_ok());
}
