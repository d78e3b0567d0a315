//! `--fused-passes` (ours, `glsl/bvh/fused_pass.comp`): each pass of Fig. 8 in one kernel
//! must give what the SAH BVH's four kernels give — the same image, the same first hits,
//! normals and shadow flags, the same counts of every ray kind — and the CPU reference's image,
//! with reflections, several point lights in either flag layout, area lights and tiles.

mod common;

use common::*;
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::GlInfo;
use gpgpu_rt::pipeline::mueller2015::{RenderOptions, ShadowFlags};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::Scene;

/// The SAH BVH in Müller 2015's four kernels, the frame the fused pass is held against.
fn bvh(w: u32, h: u32, refl_depth: u32) -> RenderOptions {
    options_with(BVH_FOUR_KERNELS, w, h, refl_depth)
}

/// The frame of the four kernels and of the fused pass with otherwise the same options.
fn both(scene: &Scene, opts: &RenderOptions) -> (Frame, Frame) {
    let ctx = context();
    let four = render_gpu(&ctx, scene, opts.clone());
    let mut tracer = ray_tracer(&ctx, scene, fused_if(opts, true));
    assert_eq!(
        tracer.settings()["bvh_passes"],
        "fused",
        "the fused pass was not selected"
    );
    let fused = tracer.render(&scene.camera).expect("frame");
    // one tree: the pass runs over the block lists, the blocks without a hit in a kernel of
    // their own (glsl/bvh/block_lists.glsl)
    let ms = &fused.stats.gpu_ms;
    assert!(
        ms.contains_key("fused_pass") && !ms.contains_key("shading"),
        "{ms:?}"
    );
    assert_eq!(
        ms.contains_key("fused_miss"),
        !opts.accel.instances(),
        "{ms:?}"
    );
    (four, fused)
}

/// Every count of the two frames: triangle tests, events, and per ray kind.
fn assert_same_counts(four: &Frame, fused: &Frame, what: &str) {
    let (a, b) = (&four.stats, &fused.stats);
    assert_eq!(a.triangle_tests, b.triangle_tests, "{what}: triangle tests");
    assert_eq!(a.events, b.events, "{what}: events");
    assert_eq!(a.truncated_rays, b.truncated_rays, "{what}");
    let kinds = |s: &gpgpu_rt::frame::FrameStats| {
        s.ray_kinds
            .iter()
            .map(|(k, v)| (k.clone(), v.triangle_tests, v.counts.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(kinds(a), kinds(b), "{what}: ray kinds");
}

/// The same image, first hits, normals and shadow shares.
fn assert_same_frame(four: &Frame, fused: &Frame, what: &str) {
    assert_same_image(four, fused, what);
    let (a, b) = (four.aovs.as_ref().unwrap(), fused.aovs.as_ref().unwrap());
    assert_eq!(a.normal, b.normal, "{what}: normals");
    assert_eq!(a.shadow, b.shadow, "{what}: shadow shares");
    let alpha = |f: &Frame| f.color.iter().map(|c| c[3]).collect::<Vec<_>>();
    assert_eq!(alpha(four), alpha(fused), "{what}: accumulated weights");
}

fn check(scene: &Scene, opts: &RenderOptions, what: &str) -> (Frame, Frame) {
    let (four, fused) = both(scene, opts);
    assert_same_frame(&four, &fused, what);
    assert_same_counts(&four, &fused, what);
    (four, fused)
}

#[test]
fn reflections_equal_the_four_kernels_and_the_reference() {
    // the low-poly bunny mirrors itself: rays live on through two reflection passes
    let scene = load("bunny_low.toml");
    let opts = bvh(64, 48, 2);
    let (_, fused) = check(&scene, &opts, "bunny_low, 2 reflections");
    // the colour of a reflection pass goes through Listing 16's weights twice more and pow()
    // on the GPU and on the CPU: the four kernels (which the fused pass equals, above) are
    // 1.5e-5 from the reference here at worst (llvmpipe, 2026-12-03)
    let tol = Tolerance {
        max_color: 5e-5,
        ..SAME_ARITHMETIC
    };
    assert_close_within(&fused, &render_cpu(&scene, &opts), "bunny_low fused", tol);
    let reflected = fused.stats.ray_kinds["reflection"].count("rays");
    assert!(reflected > 100, "too few reflected rays: {reflected}");
}

#[test]
fn several_lights_in_both_flag_layouts_and_tiles() {
    let mut scene = load("teapot1.toml");
    ring_of_lights(&mut scene, 3);
    for flags in [ShadowFlags::Rgba, ShadowFlags::Bits] {
        let opts = RenderOptions {
            shadow_flags: flags,
            tile: 16,
            ..bvh(56, 40, 1)
        };
        let what = format!("teapot1, 3 lights, {flags:?}, tiles of 16");
        let (_, fused) = check(&scene, &opts, &what);
        let others = fused.stats.ray_kinds["shadow_other_lights"].count("rays");
        let first = fused.stats.ray_kinds["shadow_first_light"].count("rays");
        assert!(first > 100 && others > first, "{what}: {first}, {others}");
        assert_close(&fused, &render_cpu(&scene, &opts), &what);
    }
}

#[test]
fn area_light_samples_equal_the_four_kernels() {
    // an area light beside a point light, a reflective floor and cow: U·V feelers a hit
    let scene = load("cow_area.toml");
    let opts = RenderOptions {
        light_samples: (3, 2),
        ..bvh(64, 48, 1)
    };
    let (_, fused) = check(&scene, &opts, "cow_area, 3x2 samples");
    let others = fused.stats.ray_kinds["shadow_other_lights"].count("rays");
    assert!(
        others > 1000,
        "the area light's samples were not traced: {others}"
    );
    let shadow = fused.aovs.as_ref().unwrap().shadow.as_ref().unwrap();
    let penumbra = shadow.iter().filter(|&&s| s > 0.0 && s < 1.0).count();
    assert!(penumbra > 0, "no partly lit pixel");
    // the area light alone: its samples are the first light's feelers
    let mut alone = scene.clone();
    alone.lights.clear();
    let (_, fused) = check(&alone, &opts, "cow_area without its point light");
    let first = fused.stats.ray_kinds["shadow_first_light"].count("rays");
    assert!(first > 1000, "the samples of light 0: {first}");
}

#[test]
fn no_lights_and_a_single_light() {
    let mut scene = load("cow.toml");
    check(&scene, &bvh(40, 40, 0), "cow, 1 light");
    scene.lights.clear();
    check(&scene, &bvh(40, 40, 0), "cow, no light");
}

#[test]
fn the_fused_pass_is_refused_beside_other_accelerators() {
    // no other accelerator's options can hold it; on the command line it is refused by name
    let row = gpgpu_rt::design::row("grid-exact").unwrap();
    let given = ["four-kernels".to_string()];
    let err = gpgpu_rt::design::refuse_foreign(row, &given, "from --tracer grid").unwrap_err();
    assert!(
        format!("{err:#}").contains("--four-kernels applies to bvh ("),
        "{err:#}"
    );
    let o = run(&[
        "render",
        scene_path("cow.toml").to_str().unwrap(),
        "--bvh-variant",
        "wagner",
        "--four-kernels",
        "--width",
        "16",
        "--height",
        "16",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("--four-kernels applies to bvh"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn eye_rays_in_place_without_aovs() {
    // without AOVs the first pass computes its eye rays in place (no eye-ray kernel; the
    // entry pass too): the same colours and counts as the four kernels
    let scene = load("bunny_low.toml");
    let opts = RenderOptions {
        aovs: false,
        ..bvh(64, 48, 2)
    };
    let (four, fused) = both(&scene, &opts);
    assert!(
        !fused.stats.gpu_ms.contains_key("eye_ray_generation"),
        "{:?}",
        fused.stats.gpu_ms
    );
    assert_eq!(four.color, fused.color, "bunny_low without AOVs: colours");
    assert_same_counts(&four, &fused, "bunny_low without AOVs");
}

/// Two frames of `opts` on `scene` — the second with object 0 turned (a refit and the moved
/// objects' transform) — on a GL whose facts `gl` changes.
fn two_frames(scene: &Scene, opts: &RenderOptions, gl: impl Fn(&mut GlInfo)) -> (Frame, Frame) {
    let ctx = context();
    let mut info = ctx.info.clone();
    gl(&mut info);
    let shaders = gpgpu_rt::gl::ShaderSource::default();
    let mut t = gpgpu_rt::pipeline::mueller2015::RayTracer::new(
        ctx.gl.clone(),
        &info,
        scene,
        &shaders,
        opts.clone(),
    )
    .expect("tracer");
    let still = t.render(&scene.camera).expect("frame");
    let turned = scene.objects[0].model * glam::Mat4::from_rotation_y(0.4);
    t.set_model(0, turned).unwrap();
    (still, t.render(&scene.camera).expect("frame"))
}

#[test]
fn the_storage_buffer_reads_where_the_gl_has_only_8_image_units() {
    // GL 4.5 guarantees 8 image units: there the kernels read the scene, the pixel records,
    // the refit's topology and boxes and the transform's VBOs as storage buffers, not through
    // the image-buffer views of units 8–17 — the same frames, still and after a turn
    let mut scene = load("teapot1.toml");
    ring_of_lights(&mut scene, 2);
    for fused_passes in [false, true] {
        let opts = fused_if(&bvh(48, 40, 1), fused_passes);
        let (a, b) = (
            two_frames(&scene, &opts, |gl| gl.max_image_units = 192),
            two_frames(&scene, &opts, |gl| gl.max_image_units = 8),
        );
        for (x, y, frame) in [(&a.0, &b.0, "still"), (&a.1, &b.1, "turned")] {
            let what = format!("fused {fused_passes}, {frame}, 8 image units");
            assert_same_frame(x, y, &what);
            assert_same_counts(x, y, &what);
        }
        assert_ne!(a.0.color, a.1.color, "the turn changed nothing");
    }
}

#[test]
fn the_work_lists_take_rows_where_the_gl_allows_few_work_groups() {
    // GL guarantees 65535 work groups a dimension (MAX_COMPUTE_WORK_GROUP_COUNT); a list whose
    // dispatch needs more — the fused pass' block lists, the four kernels' hit list — is
    // dispatched in rows of equal length (glsl/common/work_lists.glsl). A GL that allows 2, 3
    // or 5 a row: every list takes rows, some with work groups too many — the same frames and
    // counts
    let mut scene = load("teapot1.toml");
    ring_of_lights(&mut scene, 2);
    for (fused_passes, row) in [false, true]
        .into_iter()
        .flat_map(|f| [(f, 2), (f, 3), (f, 5)])
    {
        let opts = fused_if(&bvh(48, 40, 1), fused_passes);
        let (a, b) = (
            two_frames(&scene, &opts, |_| {}),
            two_frames(&scene, &opts, |gl| {
                gl.compute.max_compute_work_group_count[0] = row
            }),
        );
        for (x, y, frame) in [(&a.0, &b.0, "still"), (&a.1, &b.1, "turned")] {
            let what = format!("fused {fused_passes}, {frame}, {row} work groups a row");
            assert_same_frame(x, y, &what);
            assert_same_counts(x, y, &what);
            let listed = |f: &Frame| f.stats.facts.get("hit_list_pixels").cloned();
            assert_eq!(listed(x), listed(y), "{what}");
            assert_eq!(listed(x).is_some(), !fused_passes, "{what}");
            // the hit lists of the two passes: each several rows of 64 entries a work group
            if let Some(n) = listed(x) {
                assert!(n.as_u64().unwrap() > 2 * 5 * 64, "{what}: {n} listed");
            }
        }
    }
}

#[test]
fn the_first_pass_leaves_its_miss_blocks_to_clears() {
    // without AOVs the first pass does not dispatch the blocks whose eye rays all miss: their
    // output colour is filled with the background and pixel_counts counts each pixel a ray
    // traced that visited nothing (RayTracer::fused_pass), and the frame clears only the ray origins, where a
    // reflection pass reads them (RayTracer::clear_images) — the same colours and counts in
    // every record layout: one point light (packed beside the closest hit), three (the other
    // lights' record), an area light as the first light (a record of its own), with and
    // without reflections, in two frames, the second with object 0 turned (blocks that hit
    // in the first miss in the second: their ray state of the first frame must not live on)
    let mut teapot = load("teapot1.toml");
    ring_of_lights(&mut teapot, 3);
    let mut area = load("cow_area.toml");
    area.lights.clear();
    // (61 × 45: blocks at the right and bottom edges only partly inside the image)
    let cases = [
        (load("bunny.toml"), 0, (64, 48), "bunny"),
        (load("bunny.toml"), 0, (61, 45), "bunny, 61 × 45"),
        (
            load("bunny_low.toml"),
            2,
            (64, 48),
            "bunny_low, 2 reflections",
        ),
        (teapot, 1, (61, 45), "teapot1, 3 lights, 61 × 45"),
        (area, 1, (64, 48), "cow_area, its area light alone"),
    ];
    let ctx = context();
    for (scene, refl_depth, (w, h), what) in cases {
        let opts = RenderOptions {
            aovs: false,
            light_samples: (2, 2),
            ..bvh(w, h, refl_depth)
        };
        let fused_opts = fused_if(&opts, true);
        let mut four = ray_tracer(&ctx, &scene, opts);
        let mut fused = ray_tracer(&ctx, &scene, fused_opts);
        for frame in 0..2 {
            if frame == 1 {
                let turned = scene.objects[0].model * glam::Mat4::from_rotation_y(1.2);
                four.set_model(0, turned).unwrap();
                fused.set_model(0, turned).unwrap();
            }
            let a = four.render(&scene.camera).expect("frame");
            let b = fused.render(&scene.camera).expect("frame");
            let what = format!("{what}, frame {frame}");
            assert_eq!(a.color, b.color, "{what}: colours");
            assert_same_counts(&a, &b, &what);
        }
    }
}
