//! Soft shadows with the Cascaded Line Space (Klee 2016): line-space bits against a brute-force
//! shaft test, the Listing 3 texture layout, GPU against CPU, line space against exact.

mod common;

use common::Rng;
use glam::Vec3;
use gpgpu_rt::frame::{Aovs, FrameStats};
use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::pipeline::klee2016::ntree::{
    self, build_linespace, build_linespace_brute_force, entry_index, face_rect, get_bit,
    pack_linespaces, shaft_hits_box, Aabb, NTree,
};
use gpgpu_rt::pipeline::klee2016::{KleeShading, SoftShadowOptions, SoftShadowRenderer};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::reference::linespace::ShadowCounts;
use gpgpu_rt::scene::Scene;
use gpgpu_rt::scene::{Camera, ShadowMode};

/// A soft-shadow frame as the tests read it: the renderer's frame, its shadow values and the
/// G-buffer it was shaded from (row 0 = the top image row everywhere).
struct SoftFrame {
    color: Vec<[f32; 4]>,
    shadow: Vec<f32>,
    gbuffer_position: Vec<[f32; 4]>,
    gbuffer_normal: Vec<[f32; 4]>,
    aovs: Aovs,
    stats: FrameStats,
    /// per pixel the first rays of the batches the GPU traced its shadow rays in (bit r)
    batch_starts: Vec<[u32; 4]>,
}

fn render(r: &mut SoftShadowRenderer, camera: &Camera) -> anyhow::Result<SoftFrame> {
    let f = r.render(camera)?;
    let (gbuffer_position, gbuffer_normal) = r.read_gbuffer();
    let mut aovs = f.aovs.expect("the soft-shadow renderer keeps its AOVs");
    Ok(SoftFrame {
        color: f.color,
        shadow: aovs.shadow.take().expect("shadow values"),
        gbuffer_position,
        gbuffer_normal,
        aovs,
        stats: f.stats,
        batch_starts: r.read_batch_starts(),
    })
}

/// The first rays of the batches pixel `i`'s shadow rays were traced in on the GPU (ascending;
/// the first is ray 0): a pixel whose batch hit llvmpipe's loop limit went on in smaller ones.
fn batch_starts(f: &SoftFrame, i: usize) -> Vec<usize> {
    let mask = f.batch_starts[i];
    let starts: Vec<usize> = (0..128)
        .filter(|r| mask[r / 32] & (1 << (r % 32)) != 0)
        .collect();
    assert_eq!(starts.first(), Some(&0), "pixel {i}: batches {mask:?}");
    starts
}

#[test]
fn linespace_bits_equal_brute_force_shaft_test() {
    let mut rng = Rng(0x9E3779B97F4A7C15);
    for (n, density) in [
        (3u32, 0.2),
        (4, 0.1),
        (5, 0.04),
        (4, 0.0),
        (3, 1.0),
        (6, 0.01),
    ] {
        let filled: Vec<bool> = (0..n.pow(3)).map(|_| rng.unit() < density).collect();
        let fast = build_linespace(n, &filled);
        let brute = build_linespace_brute_force(n, &filled);
        assert_eq!(fast.len(), ntree::linespace_words(n));
        assert_eq!(fast, brute, "N = {n}, density {density}");
        if density == 0.0 {
            assert!(fast.iter().all(|w| *w == 0));
        }
    }
    // a real node: the bunny's N-tree at N = 6, its root and its fullest inner node
    let scene = common::load("bunny_area.toml");
    let tree = NTree::build(&scene.world_triangles(), 6, 3).unwrap();
    let groups = tree.inner_groups();
    let fullest = (1..groups.len())
        .max_by_key(|&i| tree.group_filled(groups[i]).iter().filter(|f| **f).count())
        .unwrap();
    for i in [0, fullest] {
        let filled = tree.group_filled(groups[i]);
        assert!(filled.iter().any(|f| *f));
        assert_eq!(
            tree.linespace(i),
            &build_linespace_brute_force(6, &filled)[..],
            "line space {i}"
        );
    }
}

#[test]
fn shaft_test_is_exact_on_simple_cases_and_conservative_against_sampled_lines() {
    let n = 4;
    // one filled child in the middle of a 4³ node
    let c = Aabb::cell(1, 1, 1);
    // x = 0 side to x = N side straight through it: set; a parallel shaft beside it: not set
    assert!(shaft_hits_box(
        &face_rect(n, 0, 1, 2, 1, 2),
        &face_rect(n, 1, 1, 2, 1, 2),
        &c
    ));
    assert!(!shaft_hits_box(
        &face_rect(n, 0, 2, 3, 1, 2),
        &face_rect(n, 1, 2, 3, 1, 2),
        &c
    ));
    // touching the child's boundary only does not count
    assert!(!shaft_hits_box(
        &face_rect(n, 0, 0, 1, 1, 2),
        &face_rect(n, 1, 0, 1, 1, 2),
        &c
    ));
    // a diagonal shaft from cell (0,0) of side y=0 to cell (3,3) of side y=N passes (1,1,1)
    assert!(shaft_hits_box(
        &face_rect(n, 2, 0, 1, 0, 1),
        &face_rect(n, 3, 3, 4, 3, 4),
        &c
    ));
    // symmetric entries are one
    assert_eq!(
        entry_index(n, 0, 1, 2, 3, 2, 1),
        entry_index(n, 3, 2, 1, 0, 1, 2)
    );
    assert_eq!(entry_index(n, 2, 0, 0, 2, 1, 1), None);
    // every sampled line between two cells that passes through a child's interior must find
    // the shaft's bit set
    let mut rng = Rng(12345);
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let mut hits = 0;
    for _ in 0..4000 {
        let s = (rng.next() % 6) as usize;
        let e = (rng.next() % 6) as usize;
        if s == e {
            continue;
        }
        let cell = |rng: &mut Rng| {
            (
                (rng.next() % n as u64) as u32,
                (rng.next() % n as u64) as u32,
            )
        };
        let (su, sv) = cell(&mut rng);
        let (eu, ev) = cell(&mut rng);
        let a = face_rect(n, s, su, su + 1, sv, sv + 1);
        let b = face_rect(n, e, eu, eu + 1, ev, ev + 1);
        let child = Aabb::cell(
            (rng.next() % 4) as u32,
            (rng.next() % 4) as u32,
            (rng.next() % 4) as u32,
        );
        let pa: [f64; 3] = std::array::from_fn(|i| lerp(a.lo[i], a.hi[i], rng.unit()));
        let pb: [f64; 3] = std::array::from_fn(|i| lerp(b.lo[i], b.hi[i], rng.unit()));
        let through = (1..200).any(|k| {
            let t = k as f64 / 200.0;
            (0..3).all(|i| {
                let x = lerp(pa[i], pb[i], t);
                x > child.lo[i] + 1e-9 && x < child.hi[i] - 1e-9
            })
        });
        if through {
            hits += 1;
            assert!(
                shaft_hits_box(&a, &b, &child),
                "sides {s}->{e}, a line passes the child, shaft test says no"
            );
        }
    }
    assert!(
        hits > 100,
        "the sampling found only {hits} lines through children"
    );
}

#[test]
fn packed_texture_layout_round_trips() {
    let mut rng = Rng(777);
    let words_per = ntree::linespace_words(10);
    assert_eq!(words_per, 4688); // 15 · 10⁴ bits
    let count = 7;
    let words: Vec<u32> = (0..words_per * count).map(|_| rng.next() as u32).collect();
    for max_dim in [2048u32, 64, 50] {
        let p = pack_linespaces(&words, words_per, count, max_dim).unwrap();
        assert!(p.tex_x_res <= max_dim && p.tex_y_res <= max_dim && p.tex_z_res <= max_dim);
        assert_eq!(
            p.texels.len(),
            (p.tex_x_res * p.tex_y_res * p.tex_z_res) as usize
        );
        let mut seen = std::collections::HashSet::new();
        for ls in 0..count {
            assert_eq!(
                p.unpack(ls as u32),
                words[ls * words_per..(ls + 1) * words_per],
                "max_dim {max_dim}"
            );
            for w in 0..words_per as u32 {
                assert!(
                    seen.insert(p.texel(ls as u32, w)),
                    "two words share a texel"
                );
            }
            for _ in 0..200 {
                let e = (rng.next() % (words_per as u64 * 32)) as usize;
                assert_eq!(
                    p.get_entry(ls as u32, e),
                    get_bit(&words[ls * words_per..], e)
                );
            }
        }
        if max_dim == 50 {
            assert!(p.tex_z_res > 1, "the layout continues along z");
        }
    }
    assert!(pack_linespaces(&words, words_per, count, 8).is_err());
}

fn opts(mode: ShadowMode, s: u32, w: u32) -> SoftShadowOptions {
    SoftShadowOptions {
        mode,
        samples_u: s,
        samples_v: s,
        ntree_n: 10,
        ntree_depth: 3,
        shading: Default::default(),
        linespace_build: Default::default(),
        width: w,
        height: w,
        tile: 32,
    }
}

#[test]
fn gpu_agrees_with_cpu_and_linespace_differs_from_exact_only_by_conservative_shafts() {
    let ctx = common::context();
    let shaders = ShaderSource::default();
    let (scene, mut r) = bunny_renderer(&ctx, &shaders);
    // the 3D texture holds exactly the packed layout
    assert_eq!(r.read_linespace_texture(), r.scene.packed.texels);
    let mut shadows = Vec::new();
    for mode in MODES {
        r.reconfigure(&shaders, mode, 3, 3).unwrap();
        let f = render(&mut r, &scene.camera).unwrap();
        let cpu = r.cpu();
        let (mut hits, mut off, mut cpu_tests) = (0usize, 0usize, 0u64);
        for (i, p) in f.gbuffer_position.iter().enumerate() {
            if p[3] <= 0.0 {
                assert_eq!(f.shadow[i], 1.0);
                assert_eq!(f.aovs.triangle_id[i], -1);
                continue;
            }
            hits += 1;
            let nrm = f.gbuffer_normal[i];
            let (s, c) = cpu.shadow_in_ranges(
                mode,
                Vec3::new(p[0], p[1], p[2]),
                Vec3::new(nrm[0], nrm[1], nrm[2]).normalize(),
                &batch_starts(&f, i),
            );
            cpu_tests += c.triangle_tests;
            if (s - f.shadow[i]).abs() > 1e-6 {
                off += 1;
            }
        }
        assert!(hits > 1500, "{hits} pixels hit geometry");
        // the CPU twin reads the same G-buffer and runs the kernel's arithmetic: measured
        // (llvmpipe, 2026-11-23) no pixel differs and the triangle tests are equal in all
        // three modes (398,484 / 283,991 / 292,060); was: 1 % of the pixels, tests within 2 %
        assert_eq!(
            off, 0,
            "{mode:?}: {off} of {hits} pixels differ between GPU and CPU"
        );
        let gpu_tests = f.stats.total_triangle_tests();
        assert_eq!(gpu_tests, cpu_tests, "{mode:?}: triangle tests GPU vs CPU");
        assert!(f.stats.events["linespace_lookups"] > 0);
        shadows.push((
            f.shadow.clone(),
            f.gbuffer_position.clone(),
            f.gbuffer_normal.clone(),
        ));
    }
    // the CPU's primary rays (Table 1: ray traced on the CPU) find what the G-buffer rasterised
    let f = render(&mut r, &scene.camera).unwrap();
    let cpu = r.cpu();
    let rays = scene.camera.rays(64, 64);
    let (mut same, mut hit_px) = (0, 0);
    for row in 0..64u32 {
        for x in 0..64u32 {
            let (o, d) = rays.primary_ray(x, 63 - row);
            let i = (row * 64 + x) as usize;
            let mut c = Default::default();
            let hit = cpu.closest_hit(o, d, &mut c);
            if f.aovs.triangle_id[i] >= 0 {
                hit_px += 1;
                if let Some((t, id)) = hit {
                    if id as i32 == f.aovs.triangle_id[i] || (t - f.aovs.hit_t[i]).abs() < 1e-3 * t
                    {
                        same += 1;
                    }
                }
            }
        }
    }
    // measured (llvmpipe, 2026-11-23): all 2,294 pixels agree (was: 97 % required)
    assert_eq!(
        same, hit_px,
        "CPU primary hits agree with the G-buffer at {same} of {hit_px} pixels"
    );
    let (exact, pos, nrm) = &shadows[0];
    let (ls, _, _) = &shadows[1];
    let (dda, _, _) = &shadows[2];
    let hit: Vec<usize> = (0..pos.len()).filter(|&i| pos[i][3] > 0.0).collect();
    // the exact mode is exact: every sample against every triangle on the CPU, every 9th pixel
    let cpu = r.cpu();
    let mut wrong = 0;
    let checked: Vec<usize> = hit.iter().copied().step_by(9).collect();
    for &i in &checked {
        let b = cpu.brute_force(
            Vec3::new(pos[i][0], pos[i][1], pos[i][2]),
            Vec3::new(nrm[i][0], nrm[i][1], nrm[i][2]).normalize(),
        );
        if (b - exact[i]).abs() > 1e-6 {
            wrong += 1;
        }
    }
    // measured: 0 of 255 (was: 1 % allowed)
    assert_eq!(
        wrong,
        0,
        "exact vs brute force: {wrong} of {} pixels differ",
        checked.len()
    );
    // the line space only adds occluders (a set bit may be an empty part of the shaft), never
    // removes them: linespace <= exact, and the packet and the DDA decide alike
    // (measured: none lighter, none differing; was: 0.5 % and 1 % allowed)
    let brighter = hit.iter().filter(|&&i| ls[i] > exact[i] + 1e-6).count();
    assert_eq!(
        brighter, 0,
        "{brighter} pixels lighter with the line space than exact"
    );
    let dda_off = hit
        .iter()
        .filter(|&&i| (dda[i] - ls[i]).abs() > 1e-6)
        .count();
    assert_eq!(dda_off, 0, "{dda_off} pixels differ between packet and DDA");
    let mean = hit.iter().map(|&i| (ls[i] - exact[i]).abs()).sum::<f32>() / hit.len() as f32;
    // the conservative shafts' darkening: measured 0.038 on average (was: 0.1 allowed)
    assert!(mean <= 0.05, "mean |linespace - exact| = {mean}");
    let penumbra = hit
        .iter()
        .filter(|&&i| exact[i] > 0.0 && exact[i] < 1.0)
        .count();
    assert!(
        penumbra * 50 > hit.len(),
        "no visible penumbra: {penumbra} pixels"
    );
    // 100 rays per pixel (the thesis' largest packet): GPU and CPU still agree
    r.reconfigure(&shaders, ShadowMode::Linespace, 10, 10)
        .unwrap();
    let ls10 = render(&mut r, &scene.camera).unwrap();
    let off = cpu_mismatches(&r, &ls10, ShadowMode::Linespace, &hit);
    // measured: 0 (was: 1 % allowed)
    assert_eq!(off, 0, "10x10: {off} pixels differ between GPU and CPU");
    // llvmpipe ends loops after 65535 iterations per SIMD vector: `exact` with 100 rays on the
    // bunny reaches that there (8-lane vectors); the frame is then rendered again with the rays
    // in batches — whatever the GL implementation, the frame comes out right
    r.reconfigure(&shaders, ShadowMode::Exact, 10, 10).unwrap();
    let f = render(&mut r, &scene.camera).expect("exact 10x10 renders, in ray batches if need be");
    assert_eq!(f.stats.truncated_rays, 0);
    let batches = f.stats.facts["ray_batches"].as_u64().unwrap();
    eprintln!(
        "exact 10x10: {batches} ray batches per pixel on {}",
        ctx.info.renderer
    );
    let off = cpu_mismatches(&r, &f, ShadowMode::Exact, &hit);
    assert!(
        off * 100 <= hit.len(),
        "exact 10x10 in {batches} batches: {off} pixels differ between GPU and CPU"
    );
    // batches are only a way of dispatching: forced on a frame that needs none, the image is
    // the same as the whole packet's frame above (linespace, 10x10, each pixel's 100 rays in
    // 4 dispatches)
    r.reconfigure(&shaders, ShadowMode::Linespace, 10, 10)
        .unwrap();
    r.set_ray_batches(4);
    let split = render(&mut r, &scene.camera).unwrap();
    assert_eq!(split.stats.facts["ray_batches"], 4);
    assert_eq!(ls10.shadow, split.shadow, "ray batches changed the shadows");
    assert_eq!(ls10.color, split.color, "ray batches changed the image");
}

/// Hit pixels (indices into the frame) whose GPU shadow value differs from the CPU
/// implementation's for the same G-buffer point.
fn cpu_mismatches(r: &SoftShadowRenderer, f: &SoftFrame, mode: ShadowMode, hit: &[usize]) -> usize {
    differing(f, hit, &cpu_frame(r, f, mode, hit).0)
}

/// How many of the `hit` pixels' GPU shadow values differ from `cpu` (in `hit`'s order).
fn differing(f: &SoftFrame, hit: &[usize], cpu: &[f32]) -> usize {
    let off = hit.iter().zip(cpu);
    off.filter(|(&i, s)| (f.shadow[i] - **s).abs() > 1e-6)
        .count()
}

/// The pixels whose G-buffer holds geometry.
fn hit_pixels(f: &SoftFrame) -> Vec<usize> {
    (0..f.shadow.len())
        .filter(|&i| f.gbuffer_position[i][3] > 0.0)
        .collect()
}

/// A soft-shadow renderer on `scene` with its N-tree of N = `n` and `levels` levels, built once
/// for several modes.
fn tree_renderer(
    ctx: &GlContext,
    scene: &Scene,
    shaders: &ShaderSource,
    o: SoftShadowOptions,
    (n, levels): (u32, u32),
) -> SoftShadowRenderer {
    let tree = NTree::build(&scene.world_triangles(), n, levels).unwrap();
    SoftShadowRenderer::with_tree(ctx.gl.clone(), &ctx.info, scene, shaders, o, tree).unwrap()
}

/// Klee 2016's shadow modes: exact, and the line space traversed with CGT and with DDA.
const MODES: [ShadowMode; 3] = [
    ShadowMode::Exact,
    ShadowMode::Linespace,
    ShadowMode::LinespaceDda,
];

/// The bunny under its area light with an N-tree of N = 10 and 3 levels, at 64², exact at 3×3
/// rays.
fn bunny_renderer(ctx: &GlContext, shaders: &ShaderSource) -> (Scene, SoftShadowRenderer) {
    let scene = common::load("bunny_area.toml");
    let o = opts(ShadowMode::Exact, 3, 64);
    let r = tree_renderer(ctx, &scene, shaders, o, (10, 3));
    (scene, r)
}

/// A floor under a 1×1 area light at y = 2, a small occluder at y = 1 between them, and a
/// large roof at y = 2.001, just beyond the light (closer than an N-tree leaf is wide, so the
/// traversals meet it in the leaves they visit): shadow rays run from the surface to the light
/// samples only, so the roof shadows nothing (issue 16, class 2, for the soft shadows). Its files
/// live in a temporary folder for the load only: the scene holds its triangles.
fn roof_scene() -> Scene {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let quad = |y: f32, h: f32| {
        format!(
            "v {} {y} {}\nv {h} {y} {}\nv {h} {y} {h}\nv {} {y} {h}\n",
            -h, -h, -h, -h
        )
    };
    let obj = format!(
        "{}{}f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n",
        quad(2.001, 4.0),
        quad(1.0, 0.3)
    );
    std::fs::write(dir.join("occluders.obj"), obj).unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        "[camera]\nposition = [0.0, 1.6, 2.8]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 45.0\n\
         [render]\nshadow_offset = 0.002\n\
         [[area_light]]\ncorner = [-0.5, 2.0, -0.5]\nedge_u = [1.0, 0.0, 0.0]\nedge_v = [0.0, 0.0, 1.0]\n\
         [[object]]\ntype = \"floor\"\nsize = 4.0\nquads = 4\n\
         [[object]]\ntype = \"obj\"\npath = \"occluders.obj\"\n",
    )
    .unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap()
}

#[test]
fn occluders_beyond_the_area_light_shadow_nothing() {
    let scene = roof_scene();
    let ctx = common::context();
    let shaders = ShaderSource::default();
    let mut r = tree_renderer(
        &ctx,
        &scene,
        &shaders,
        opts(ShadowMode::Exact, 3, 48),
        (10, 3),
    );
    for mode in MODES {
        r.reconfigure(&shaders, mode, 3, 3).unwrap();
        let f = render(&mut r, &scene.camera).unwrap();
        let hit: Vec<usize> = hit_pixels(&f);
        let off = cpu_mismatches(&r, &f, mode, &hit);
        assert_eq!(off, 0, "{mode:?}: GPU vs CPU");
        if mode != ShadowMode::Exact {
            // the line space's conservative shafts count the roof's cells next to the light
            // as blocking (measured: no pixel fully lit): that is the line space, not a bug
            continue;
        }
        let lit = hit.iter().filter(|&&i| f.shadow[i] == 1.0).count();
        let shadowed = hit.iter().filter(|&&i| f.shadow[i] < 1.0).count();
        // most of the floor sees the whole light; the small occluder's shadow is there
        assert!(lit * 2 > hit.len(), "{lit} of {} lit", hit.len());
        assert!(shadowed > 20, "{shadowed} shadowed");
    }
}

/// `gpgpu-rt render` of the bunny under its area light with `args`; it must succeed.
fn render_bunny_ok(args: &[&str]) {
    let bunny = common::scene_path("bunny_area.toml");
    let o = common::run(&[&["render", bunny.to_str().unwrap()][..], args].concat());
    assert!(o.status.success(), "{}", common::stderr(&o));
}

#[test]
fn render_cli_writes_shadow_aov_and_stats() {
    let dir = tempfile::tempdir().unwrap();
    let (png, json) = (dir.path().join("a.png"), dir.path().join("s.json"));
    render_bunny_ok(&[
        "--shadows",
        "linespace",
        "--light-samples",
        "2x2",
        "--width",
        "40",
        "--height",
        "32",
        "-o",
        png.to_str().unwrap(),
        "--aov-dir",
        dir.path().to_str().unwrap(),
        "--stats",
        json.to_str().unwrap(),
    ]);
    let npy = std::fs::read(dir.path().join("shadow.npy")).unwrap();
    assert!(String::from_utf8_lossy(&npy[..128]).contains("(32, 40, )"));
    assert_eq!(npy.len() % 64, (32 * 40 * 4) % 64);
    for f in [
        "ray_origin.npy",
        "ray_direction.npy",
        "hit_t.npy",
        "triangle_id.npy",
        "normal.npy",
        "a.png",
    ] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    for k in [
        "gpu_ms",
        "triangle_tests",
        "linespace_lookups",
        "ntree_bytes",
        "linespace_bytes",
    ] {
        assert!(!s[k].is_null(), "stats lack {k}");
    }
    assert!(s["linespace_bytes"].as_u64().unwrap() > 0);
    // bad samples and a scene without an area light fail with a message
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .args([
            "render",
            common::scene_path("bunny.toml").to_str().unwrap(),
            "--shadows",
            "exact",
            "--width",
            "8",
            "--height",
            "8",
        ])
        .arg("-o")
        .arg(dir.path().join("b.png"))
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("area_light"));
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .args([
            "render",
            "x.toml",
            "--shadows",
            "exact",
            "--light-samples",
            "11x2",
        ])
        .output()
        .unwrap();
    assert!(!bad.status.success());
}

#[test]
fn area_light_errors_name_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.toml");
    std::fs::write(
        &p,
        "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n\n[[area_light]]\ncorner = [0, 2, 0]\n\
         edge_u = [1, 0, 0]\nedge_v = [2, 0, 0]\n\n[[object]]\ntype = \"floor\"\n",
    )
    .unwrap();
    let e = Scene::load(&p).unwrap_err();
    assert_eq!(e.line, Some(5), "{e}");
    assert!(e.to_string().contains("area_light"), "{e}");
    std::fs::write(&p, "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n[[area_light]]\ncorner = [0, 2, 0]\nedge_u = [1, 0, 0]\nsize = 3\n").unwrap();
    assert!(Scene::load(&p).is_err());
    let s = common::load("bunny_area.toml");
    assert_eq!(s.area_lights.len(), 1);
}

/// `render.shadows` / `render.light_samples` in a scene file are the defaults of `render`;
/// the command line overrides them; a bad value or a missing area light names the line.
#[test]
fn scene_file_soft_shadow_defaults() {
    let s = common::load("bunny_area.toml");
    assert_eq!(s.settings.shadows, Some(ShadowMode::Linespace));
    assert_eq!(s.settings.light_samples, Some((5, 5)));

    let dir = tempfile::tempdir().unwrap();
    let stats = |extra: &[&str]| -> serde_json::Value {
        let (png, json) = (dir.path().join("a.png"), dir.path().join("s.json"));
        let (png, json_path) = (png.to_str().unwrap(), json.to_str().unwrap());
        let size = ["--width", "24", "--height", "16"];
        let outputs = ["-o", png, "--stats", json_path];
        render_bunny_ok(&[&size[..], &outputs, extra].concat());
        serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap()
    };
    let d = stats(&[]);
    assert_eq!(d["shadows"], "linespace", "{d}");
    assert_eq!(d["light_samples"], "5x5", "{d}");
    let d = stats(&["--shadows", "exact", "--light-samples", "2x3"]);
    assert_eq!(d["shadows"], "exact", "{d}");
    assert_eq!(d["light_samples"], "2x3", "{d}");

    let p = dir.path().join("bad.toml");
    let head = "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n\n[render]\n";
    let floor = "\n[[object]]\ntype = \"floor\"\n";
    std::fs::write(&p, format!("{head}light_samples = \"5y5\"\n{floor}")).unwrap();
    let e = Scene::load(&p).unwrap_err();
    assert_eq!(e.line, Some(6), "{e}");
    assert!(e.to_string().contains("5y5"), "{e}");
    std::fs::write(&p, format!("{head}shadows = \"linespace\"\n{floor}")).unwrap();
    let e = Scene::load(&p).unwrap_err();
    assert_eq!(e.line, Some(5), "{e}");
    assert!(e.to_string().contains("area_light"), "{e}");
}

/// `--klee-shading fig7` is Fig. 7's product: every pixel's colour is its shadow value times
/// the diffuse colour of its surface (one of the scene's three), black in full shadow; the
/// default (`lit`) is not.
#[test]
fn fig7_shading_is_the_shadow_value_times_the_diffuse_colour() {
    let ctx = common::context();
    let scene = common::load("bunny_area.toml");
    let shaders = ShaderSource::default();
    let diffuse = [
        Vec3::splat(0.75),
        Vec3::splat(0.6),
        Vec3::new(0.85, 0.8, 0.7),
    ];
    let mut off = [0usize; 2];
    for (k, shading) in [KleeShading::Fig7, KleeShading::Lit]
        .into_iter()
        .enumerate()
    {
        let o = SoftShadowOptions {
            shading,
            ..opts(ShadowMode::Exact, 2, 48)
        };
        let mut r =
            SoftShadowRenderer::new(ctx.gl.clone(), &ctx.info, &scene, &shaders, o).unwrap();
        let f = render(&mut r, &scene.camera).unwrap();
        let (mut hits, mut dark) = (0, 0);
        for (i, p) in f.gbuffer_position.iter().enumerate() {
            if p[3] <= 0.0 {
                continue;
            }
            hits += 1;
            let (s, c) = (f.shadow[i], Vec3::from_slice(&f.color[i][..3]));
            let fits = diffuse
                .iter()
                .any(|d| (c - s * *d).abs().max_element() < 1e-5);
            off[k] += !fits as usize;
            dark += (s == 0.0) as usize;
        }
        assert!(
            hits > 1000 && dark > 20,
            "{shading:?}: {hits} hits, {dark} in full shadow"
        );
    }
    assert_eq!(off[0], 0, "fig7: pixels not s · diffuse");
    assert!(
        off[1] > 1000,
        "lit: only {} pixels differ from s · diffuse",
        off[1]
    );
}

/// The twin's shadow values and summed counts for every hit pixel of `f`'s G-buffer.
fn cpu_frame(
    r: &SoftShadowRenderer,
    f: &SoftFrame,
    mode: ShadowMode,
    hit: &[usize],
) -> (Vec<f32>, ShadowCounts) {
    let cpu = r.cpu();
    let mut counts = ShadowCounts::default();
    let values = hit
        .iter()
        .map(|&i| {
            let (p, n) = (f.gbuffer_position[i], f.gbuffer_normal[i]);
            // the rays in the packets the GPU split them into (its loop budget)
            let (s, c) = cpu.shadow_in_ranges(
                mode,
                Vec3::new(p[0], p[1], p[2]),
                Vec3::new(n[0], n[1], n[2]).normalize(),
                &batch_starts(f, i),
            );
            counts += c;
            s
        })
        .collect();
    (values, counts)
}

/// `mode` at `rays`×`rays` rays per area light, rendered on the GPU and by its CPU twin on the
/// GPU's G-buffer: the frame, its hit pixels and the twin's counts, once every hit pixel's shadow
/// and the line-space lookups are checked equal (`what` names the case in the messages).
fn gpu_equals_twin(
    r: &mut SoftShadowRenderer,
    shaders: &ShaderSource,
    camera: &Camera,
    (mode, rays): (ShadowMode, u32),
    what: &str,
) -> (SoftFrame, Vec<usize>, ShadowCounts) {
    r.reconfigure(shaders, mode, rays, rays).unwrap();
    let f = render(r, camera).unwrap();
    let hit: Vec<usize> = hit_pixels(&f);
    let (cpu, counts) = cpu_frame(r, &f, mode, &hit);
    let off = differing(&f, &hit, &cpu);
    assert_eq!(off, 0, "{what}: pixels differ between GPU and twin");
    assert_eq!(
        f.stats.events["linespace_lookups"], counts.linespace_lookups,
        "{what}: line-space lookups GPU vs twin"
    );
    (f, hit, counts)
}

/// Table 2's variants as the thesis defines them, on the bunny (3 levels, 3x3 rays, 64²):
/// GPU = twin; `variant1` (exact without our near-origin rule) gives the exact image;
/// `variant2` (linespace without it) tests no triangle and is never lighter than exact.
/// Planted: BIT_IS_HIT for variant1 (its image then differs from exact: caught) and the
/// near-origin rule for variant2 (triangle tests appear: caught).
#[test]
fn table2_variants_as_defined_gpu_equals_twin() {
    let ctx = common::context();
    let shaders = ShaderSource::default();
    let (scene, mut r) = bunny_renderer(&ctx, &shaders);
    let mut frames = Vec::new();
    for mode in [
        ShadowMode::Exact,
        ShadowMode::Variant1,
        ShadowMode::Variant2,
    ] {
        let camera = &scene.camera;
        let (f, hit, counts) =
            gpu_equals_twin(&mut r, &shaders, camera, (mode, 3), &format!("{mode:?}"));
        assert_eq!(
            f.stats.total_triangle_tests(),
            counts.triangle_tests,
            "{mode:?}"
        );
        frames.push((f, hit, counts));
    }
    let (exact, hit, _) = &frames[0];
    let v1 = &frames[1].0.shadow;
    let differ = v1.iter().zip(&exact.shadow).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "variant1 differs from exact at {differ} pixels");
    let (v2, _, v2_counts) = &frames[2];
    assert_eq!(
        v2_counts.triangle_tests, 0,
        "variant2 visits the deepest level"
    );
    let lighter = hit
        .iter()
        .filter(|&&i| v2.shadow[i] > exact.shadow[i] + 1e-6);
    assert_eq!(lighter.count(), 0, "variant2 lighter than exact");
    // the origin's own shaft holds the surface: surfaces shadow themselves. Measured
    // (llvmpipe, 2026-11-23, 3x3 rays, 3 levels): mean |variant2 − exact| 0.861 over the hit
    // pixels; the bound keeps it (GPU = twin above, so this is the rule, not a kernel slip)
    let mean = hit
        .iter()
        .map(|&i| (v2.shadow[i] - exact.shadow[i]).abs())
        .sum::<f32>()
        / hit.len() as f32;
    eprintln!("mean |variant2 - exact| = {mean}");
    assert!(
        (0.8..=0.9).contains(&mean),
        "mean |variant2 - exact| = {mean}"
    );
}

/// The N-tree depth's two readings on a small scene (N = 5): with 3 levels counting the root
/// the line spaces are asked at stack depth 0 only (no cascade); with 4 ("Tiefe null ist die
/// Tiefe der Kinder des Wurzelknotens", three depths below the root) at depths 0 and 1 — the
/// cascade — and the GPU's lookups and shadows equal the twin's. `variant2` has no near-origin
/// rule, so its depth-1 lookups come from the cascade alone. Planted: last_linespace_depth
/// fixed at 0 (the 3-level reading at 4 levels): `variant2` asks nothing at depth 1, caught
/// (`linespace` still asks depth 1 below the origin's own node, so it alone would not catch it).
#[test]
fn four_levels_query_the_cascade_gpu_equals_twin() {
    let scene = roof_scene();
    let ctx = common::context();
    let shaders = ShaderSource::default();
    for levels in [3, 4] {
        let mut r = tree_renderer(
            &ctx,
            &scene,
            &shaders,
            opts(ShadowMode::Linespace, 2, 32),
            (5, levels),
        );
        for mode in [
            ShadowMode::Linespace,
            ShadowMode::Exact,
            ShadowMode::Variant2,
            ShadowMode::LinespaceFast,
        ] {
            let what = format!("{levels} levels, {mode:?}");
            let (_, _, counts) = gpu_equals_twin(&mut r, &shaders, &scene.camera, (mode, 2), &what);
            let by_depth = counts.lookups_by_depth;
            eprintln!("{levels} levels, {mode:?}: lookups by depth {by_depth:?}");
            assert!(by_depth[0] > 0, "{levels} levels: {by_depth:?}");
            if levels == 3 {
                assert_eq!(by_depth[1..], [0, 0], "3 levels: {by_depth:?}");
            } else {
                assert!(by_depth[1] > 0, "4 levels: no cascade, {by_depth:?}");
                assert_eq!(by_depth[2], 0, "the leaves have no line space");
            }
        }
    }
}

/// `linespace-fast` (ours) answers as `linespace` for less work, on the bunny (3 levels, 5x5
/// rays, 64²): every pixel's value equal to `linespace`'s, GPU = twin in values, triangle tests,
/// skipped triangles and lookups per depth; a quarter of `linespace`'s triangle tests at most
/// (measured: 0.06), and within 0.05 of `exact` on average. Planted: the pyramid's side planes
/// turned inwards in the kernel (values and tests differ from the twin: caught); the near walk
/// left out (`phase == 1` never walked: pixels lighter than `linespace`: caught).
#[test]
fn linespace_fast_gives_linespace_values_with_fewer_tests_gpu_equals_twin() {
    let ctx = common::context();
    let shaders = ShaderSource::default();
    let (scene, mut r) = bunny_renderer(&ctx, &shaders);
    let camera = &scene.camera;
    let mut frames = Vec::new();
    for mode in [
        ShadowMode::Exact,
        ShadowMode::Linespace,
        ShadowMode::LinespaceFast,
    ] {
        let what = format!("{mode:?}");
        let (f, hit, counts) = gpu_equals_twin(&mut r, &shaders, camera, (mode, 5), &what);
        let ev = &f.stats.events;
        assert_eq!(
            f.stats.total_triangle_tests(),
            counts.triangle_tests,
            "{what}"
        );
        assert_eq!(ev["triangles_culled"], counts.triangles_culled, "{what}");
        let by_depth = [ev["lookups_depth0"], ev["lookups_depth1"]];
        assert_eq!(by_depth, counts.lookups_by_depth[..2], "{what}");
        frames.push((f, hit, counts));
    }
    let (exact, hit, _) = &frames[0];
    let (ls, _, ls_counts) = &frames[1];
    let (fast, _, fast_counts) = &frames[2];
    let differ = hit
        .iter()
        .filter(|&&i| fast.shadow[i] != ls.shadow[i])
        .count();
    assert_eq!(
        differ, 0,
        "linespace-fast differs from linespace at {differ} pixels"
    );
    let ratio = fast_counts.triangle_tests as f64 / ls_counts.triangle_tests as f64;
    eprintln!("triangle tests linespace-fast / linespace = {ratio:.3}");
    assert!(fast_counts.triangles_culled > 0 && ratio < 0.25, "{ratio}");
    let mean = hit
        .iter()
        .map(|&i| (fast.shadow[i] - exact.shadow[i]).abs())
        .sum::<f32>()
        / hit.len() as f32;
    eprintln!("mean |linespace-fast - exact| = {mean}");
    assert!(mean <= 0.05, "mean |linespace-fast - exact| = {mean}");
}
