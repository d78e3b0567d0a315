//! The streaming tracer (`--tracer stream`) against its CPU twin
//! (`reference::stream_grid`) and brute force: first hits, distances and counts, proximity
//! clouds on and off, the distance field, the occlusion-query halting with bounded work per
//! call, non-cubic grids.

mod common;

use glam::{IVec3, UVec3, Vec3};
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::GlContext;
use gpgpu_rt::pipeline::stream::grid::StreamGrid;
use gpgpu_rt::pipeline::stream::StreamOptions;
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::reference::brute_force::BruteForce;
use gpgpu_rt::reference::stream_grid::{Rule, StreamRay, WalkCounts};
use gpgpu_rt::reference::stream_shading::StreamShading;
use gpgpu_rt::reference::CpuAccelerator;
use gpgpu_rt::scene::Scene;

use common::{context, load, stream_options, stream_renderer};

/// Render one frame and keep the CPU twin's grid.
fn render(ctx: &GlContext, scene: &Scene, o: StreamOptions) -> (Frame, StreamGrid) {
    let mut r = stream_renderer(ctx, scene, o);
    let f = r.render(&scene.camera).expect("frame");
    let g = r.grid();
    let grid = StreamGrid {
        bx: g.bx,
        cells: g.cells.clone(),
        refs: g.refs.clone(),
        proximity: g.proximity.clone(),
        triangles: g.triangles.clone(),
    };
    (f, grid)
}

/// The GPU's primary rays (from the AOVs), so the CPU casts exactly the rays the GPU cast.
fn primary_rays(f: &Frame) -> Vec<StreamRay> {
    let a = f.aovs.as_ref().expect("aovs");
    a.ray_origin
        .iter()
        .zip(&a.ray_direction)
        .map(|(o, d)| StreamRay {
            o: Vec3::from(*o),
            d: Vec3::from(*d),
            skip: -1,
            limit: f32::INFINITY,
        })
        .collect()
}

/// The scene without its point lights (only primary rays are traced, so the counters hold
/// theirs alone).
fn unlit(mut scene: Scene) -> Scene {
    scene.lights.clear();
    scene
}

fn add(a: &mut WalkCounts, b: WalkCounts) {
    a.tests += b.tests;
    a.cells += b.cells;
    a.jumps += b.jumps;
    a.skipped += b.skipped;
}

/// Largest relative difference of GPU and CPU hit distances allowed, as tests/accel.rs: the
/// kernels' Möller–Trumbore rounds differently from the CPU's in the last bits on llvmpipe
/// (measured at most 5.3e-7 here, e.g. 2.7124343 vs 2.7124357); the ids are exact.
const T_REL: f32 = 1e-5;

/// Relative difference allowed between the GPU's counts and the CPU twin's: a hit distance a
/// few ulps off (above) can fall on the other side of a cell's exit and end a walk one cell
/// later or earlier (measured: one ray of 4096 on the cow on a 54³ grid, 4 of 10673 triangle
/// tests and 1 of 80898 cells; every other configuration here exact).
const COUNT_REL: f64 = 1e-3;

/// GPU triangle ids equal the CPU twin's exactly (it walks the same cells in the same order
/// with the same arithmetic), distances within [`T_REL`], and the counts of triangle tests,
/// cells entered and proximity-cloud jumps exactly; the ids equal brute force's (the grid
/// loses no triangle).
fn check_against_twin(ctx: &GlContext, scene: &Scene, o: StreamOptions) -> Frame {
    let (f, grid) = render(ctx, scene, o);
    let a = f.aovs.as_ref().unwrap();
    let brute = BruteForce::new(scene.world_triangles());
    let mut counts = WalkCounts::default();
    let (mut hits, mut max_rel) = (0, 0.0f32);
    for (i, r) in primary_rays(&f).iter().enumerate() {
        let (hit, n) = grid.trace(r, Rule::Closest, o.proximity_clouds);
        add(&mut counts, n);
        let (id, t) = hit.map_or((-1, f32::INFINITY), |h| (h.id as i32, h.t));
        assert_eq!(a.triangle_id[i], id, "pixel {i}: GPU vs CPU twin");
        let rel = if id < 0 {
            0.0
        } else {
            (a.hit_t[i] - t).abs() / t
        };
        assert!(
            rel <= T_REL,
            "pixel {i}: hit distance {} vs {t}",
            a.hit_t[i]
        );
        max_rel = max_rel.max(rel);
        let bf = brute
            .closest_hit(r.o, r.d, -1)
            .0
            .map_or(-1, |h| h.id as i32);
        assert_eq!(id, bf, "pixel {i}: the grid vs brute force");
        hits += (id >= 0) as usize;
    }
    assert!(
        hits > a.triangle_id.len() / 10,
        "the scene fills the image: {hits} hits"
    );
    eprintln!("{hits} hits, hit distances within {max_rel:e} (relative) of the CPU twin's");
    let s = &f.stats;
    let gpu = [
        s.triangle_tests["closest"],
        s.events["voxels_visited"],
        s.events["cloud_jumps"],
        s.events["empty_cells_skipped"],
    ];
    let cpu = [counts.tests, counts.cells, counts.jumps, counts.skipped];
    eprintln!(
        "{:?} pc {}: GPU {gpu:?} CPU {cpu:?}",
        o.dims, o.proximity_clouds
    );
    for ((g, c), what) in
        gpu.iter()
            .zip(cpu)
            .zip(["triangle tests", "cells", "jumps", "cells skipped"])
    {
        assert!(
            g.abs_diff(c) as f64 <= COUNT_REL * c as f64,
            "{what}: GPU {g}, CPU {c}"
        );
    }
    f
}

#[test]
fn first_hits_and_counts_equal_the_cpu_twin_on_cubic_and_non_cubic_grids() {
    let ctx = context();
    let cow = unlit(load("cow.toml"));
    // the paper's auto grid (∛5804 ≈ 17.97: 18 per axis) and a non-cubic one
    let auto = gpgpu_rt::pipeline::stream::grid::auto_dims(cow.triangle_count());
    assert_eq!(auto, UVec3::splat(18));
    for dims in [auto.to_array(), [7, 13, 4]] {
        for pc in [false, true] {
            check_against_twin(&ctx, &cow, stream_options(64, dims, pc));
        }
    }
    let sphere = unlit(load("sphere.toml"));
    check_against_twin(&ctx, &sphere, stream_options(64, [9, 9, 9], true));
}

/// A floor of 8×8 quads at y = 0 under a light at y = 1; a blocker at y = 0.6 over one part,
/// a roof at y = 1.3 beyond the light over another (it must not shadow: "any intersection
/// closer than the light"). On a 3×3×3 grid the roof shares its cells with the light.
fn light_scene(dir: &std::path::Path) -> Scene {
    let quad = |y: f32, x0: f32, z0: f32, x1: f32, z1: f32, n: usize| {
        let mut s = String::new();
        for j in 0..=n {
            for i in 0..=n {
                let x = x0 + (x1 - x0) * i as f32 / n as f32;
                let z = z0 + (z1 - z0) * j as f32 / n as f32;
                s += &format!("v {x:?} {y:?} {z:?}\n");
            }
        }
        for j in 0..n {
            for i in 0..n {
                let k = j * (n + 1) + i + 1;
                s += &format!(
                    "f {k} {} {}\nf {k} {} {}\n",
                    k + n + 1,
                    k + n + 2,
                    k + n + 2,
                    k + 1
                );
            }
        }
        s
    };
    let objects = [
        quad(0.0, -2.0, -2.0, 2.0, 2.0, 8),
        quad(0.6, -1.0, 0.3, 0.0, 1.0, 1),
        quad(1.3, 0.2, -1.5, 1.5, 1.5, 2),
    ];
    let mut toml = "[camera]\nposition = [0.0, 3.0, 4.0]\nlook_at = [0.0, 0.0, 0.0]\n\
                    [render]\nambient = [0.2, 0.2, 0.2]\nshadow_offset = 0.01\n\
                    [[light]]\nposition = [0.0, 1.0, 0.0]\n"
        .to_string();
    for (k, obj) in objects.iter().enumerate() {
        std::fs::write(dir.join(format!("o{k}.obj")), obj).unwrap();
        toml +=
            &format!("[[object]]\ntype = \"obj\"\npath = \"o{k}.obj\"\ncolor = [0.8, 0.7, 0.6]\n");
    }
    std::fs::write(dir.join("scene.toml"), toml).unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap()
}

/// Shadow rays: every primary hit's feeler towards the light (where the light lies in front
/// of the surface) walked by the CPU twin from the GPU's hit, with the GPU's arithmetic. Every
/// pixel is lit on the GPU exactly where the twin's feeler is unblocked (lit: brighter than
/// the ambient term alone, checked where the light's cosine exceeds 0.01), and the shadow-ray
/// test count and the cells entered by both kinds of rays agree within [`COUNT_REL`]; the
/// shadow AOV is 1 where lit or missed, 0 where blocked or the light is behind. With
/// `naive`, the shadow rays are the naive closest-hit search (`--stream-naive-shadows`); with
/// `no_mask`, the masking is off (`--stream-no-mask`): the twin then also traces the shadow
/// rays of surfaces facing away from the light, as the GPU does, and counts their tests.
fn check_shadows(
    ctx: &GlContext,
    scene: &Scene,
    dims: [u32; 3],
    naive: bool,
    no_mask: bool,
) -> Frame {
    let mut o = stream_options(64, dims, false);
    o.naive_shadows = naive;
    o.no_mask = no_mask;
    let (f, grid) = render(ctx, scene, o);
    let offset = scene.settings.shadow_offset;
    let rule = match naive {
        true => Rule::NaiveShadow(offset),
        false => Rule::AnyHit(offset),
    };
    let a = f.aovs.as_ref().unwrap();
    let attr = scene.world_attributes();
    let ambient = Vec3::from(scene.settings.ambient);
    let light = scene.lights[0].position;
    let mut counts = WalkCounts::default();
    let (mut shadow_tests, mut lit, mut dark) = (0, 0, 0);
    let shares = a.shadow.as_ref().expect("the shadow AOV");
    assert_eq!(scene.lights.len(), 1);
    for (i, r) in primary_rays(&f).iter().enumerate() {
        add(&mut counts, grid.trace(r, Rule::Closest, false).1);
        let id = a.triangle_id[i];
        if id < 0 {
            assert_eq!(shares[i], 1.0, "pixel {i}: a miss has no shadow ray");
            continue;
        }
        let p = r.o + a.hit_t[i] * r.d;
        let n = Vec3::from(a.normal[i]);
        let to_light = light - p;
        let distance = to_light.length();
        let l = to_light / distance;
        let feeler = StreamRay {
            o: p,
            d: l,
            skip: id,
            limit: distance,
        };
        if n.dot(l) <= 0.0 {
            if n.dot(l) < -0.01 {
                assert_eq!(
                    shares[i], 0.0,
                    "pixel {i}: a light behind counts as blocked"
                );
            }
            if no_mask {
                // traced without the masking, its verdict unused
                let c = grid.trace(&feeler, rule, false).1;
                shadow_tests += c.tests;
                add(&mut counts, c);
            }
            continue;
        }
        let (blocker, c) = grid.trace(&feeler, rule, false);
        shadow_tests += c.tests;
        add(&mut counts, c);
        let ambient_only = ambient * attr.colors[3 * id as usize];
        let gpu_lit = (Vec3::from_slice(&f.color[i][..3]) - ambient_only).max_element() > 1e-4;
        if n.dot(l) > 0.01 {
            assert_eq!(gpu_lit, blocker.is_none(), "pixel {i}: lit");
            assert_eq!(
                shares[i], gpu_lit as u32 as f32,
                "pixel {i}: the shadow AOV"
            );
            (lit, dark) = if gpu_lit {
                (lit + 1, dark)
            } else {
                (lit, dark + 1)
            };
        }
    }
    eprintln!("{lit} lit, {dark} in shadow");
    assert!(lit > 100 && dark > 20, "{lit} lit, {dark} in shadow");
    let (gs, gc) = (
        f.stats.triangle_tests["shadow"],
        f.stats.events["voxels_visited"],
    );
    eprintln!(
        "shadow tests GPU {gs} CPU {shadow_tests}, cells GPU {gc} CPU {}",
        counts.cells
    );
    assert!(gs.abs_diff(shadow_tests) as f64 <= COUNT_REL * shadow_tests as f64);
    assert!(gc.abs_diff(counts.cells) as f64 <= COUNT_REL * counts.cells as f64);
    f
}

/// The shadow rays, optimised (any hit before the light) and naive (the closest hit anywhere),
/// masked and not, against the twin; all give the same image, the naive ones and the unmasked
/// ones (on the cow, where surfaces face away from the light) more triangle tests.
#[test]
fn shadows_equal_the_cpu_twin() {
    let ctx = context();
    let dir = tempfile::tempdir().unwrap();
    let scenes = [
        (load("cow.toml"), [20, 20, 20]),
        (light_scene(dir.path()), [3, 3, 3]),
    ];
    for (scene, dims) in &scenes {
        let fast = check_shadows(&ctx, scene, *dims, false, false);
        let naive = check_shadows(&ctx, scene, *dims, true, false);
        assert_eq!(fast.color, naive.color, "the naive shadow rays' image");
        let tests = |f: &Frame| f.stats.triangle_tests["shadow"];
        for naive_too in [false, true] {
            let unmasked = check_shadows(&ctx, scene, *dims, naive_too, true);
            assert_eq!(
                fast.color, unmasked.color,
                "the unmasked shadow rays' image"
            );
            assert_eq!(
                fast.aovs.as_ref().unwrap().shadow,
                unmasked.aovs.as_ref().unwrap().shadow,
                "the unmasked shadow AOV"
            );
            let masked = if naive_too { &naive } else { &fast };
            eprintln!(
                "shadow tests: masked {}, unmasked {}",
                tests(masked),
                tests(&unmasked)
            );
            assert!(tests(&unmasked) >= tests(masked));
            if scene.triangle_count() > 100 {
                assert!(
                    tests(&unmasked) > tests(masked),
                    "the cow has back faces lit"
                );
            }
        }
        eprintln!(
            "shadow tests: any hit {}, naive {}",
            tests(&fast),
            tests(&naive)
        );
        assert!(
            tests(&naive) > tests(&fast),
            "the naive search does more work"
        );
    }
}

/// Proximity clouds skip empty cells but change no pixel: colours (with shadows and two
/// reflection bounces) and first hits are identical with and without them, and they jump.
#[test]
fn proximity_clouds_change_no_pixel() {
    let ctx = context();
    for (name, dims) in [("teapot1.toml", [24, 16, 24]), ("cow.toml", [40, 40, 40])] {
        let scene = load(name);
        let mut o = stream_options(64, dims, false);
        o.refl_depth = 2;
        let (plain, _) = render(&ctx, &scene, o);
        o.proximity_clouds = true;
        let (pc, _) = render(&ctx, &scene, o);
        let ev = |f: &Frame, k: &str| f.stats.events[k];
        assert!(ev(&pc, "cloud_jumps") > 0, "{name}: no jump");
        assert!(
            ev(&pc, "voxels_visited") < ev(&plain, "voxels_visited"),
            "{name}: skipping should enter fewer cells"
        );
        // every cell a jump skips is one the plain walk enters (a last jump out of the grid
        // skips cells it does not count)
        let (visited, skipped) = (ev(&pc, "voxels_visited"), ev(&pc, "empty_cells_skipped"));
        assert!(
            skipped >= ev(&pc, "cloud_jumps"),
            "{name}: {skipped} skipped"
        );
        assert!(
            visited + skipped <= ev(&plain, "voxels_visited"),
            "{name}: {visited} entered + {skipped} skipped > {} entered without clouds",
            ev(&plain, "voxels_visited")
        );
        assert_eq!(plain.color, pc.color, "{name}: colours");
        let ids = |f: &Frame| f.aovs.as_ref().unwrap().triangle_id.clone();
        assert_eq!(ids(&plain), ids(&pc), "{name}: first hits");
    }
}

/// The proximity distances of a real grid (non-cubic) against their definition: the
/// Chebyshev distance to the nearest non-empty cell, by brute force over all cell pairs.
#[test]
fn distance_field_equals_brute_force() {
    let scene = load("cow.toml");
    let dims = UVec3::new(9, 6, 11);
    let grid = StreamGrid::build(scene.world_triangles(), scene.bounds(), dims).unwrap();
    let d = dims.as_ivec3();
    let pos = |i: usize| {
        let i = i as i32;
        IVec3::new(i % d.x, (i / d.x) % d.y, i / (d.x * d.y))
    };
    let filled: Vec<usize> = (0..grid.cells.len())
        .filter(|&i| grid.cells[i].1 > 0)
        .collect();
    assert!(filled.len() > 20 && filled.len() < grid.cells.len() / 2);
    for (i, &got) in grid.proximity.iter().enumerate() {
        let want = filled
            .iter()
            .map(|&j| (pos(i) - pos(j)).abs().max_element() as u32)
            .min()
            .unwrap();
        assert_eq!(got, want, "cell {:?}", pos(i));
    }
    assert!(
        grid.proximity.iter().any(|&p| p >= 3),
        "some far empty cells"
    );
}

/// The halting condition: with a few steps per call, a traversal takes many calls, ended by the
/// occlusion query; the image equals one with many steps per call. With too few calls allowed,
/// the frame is refused rather than shown unfinished.
#[test]
fn the_occlusion_query_halts_after_many_bounded_calls() {
    let ctx = context();
    let scene = load("cow.toml");
    let mut o = stream_options(48, [30, 30, 30], false);
    o.steps_per_call = 4096;
    let (big, _) = render(&ctx, &scene, o);
    o.steps_per_call = 3;
    let (small, _) = render(&ctx, &scene, o);
    let calls = |f: &Frame| f.stats.events["max_calls_per_traversal"];
    // with 4096 steps every ray finishes in the first call; the query finds the second idle
    assert_eq!(calls(&big), 2);
    assert!(calls(&small) > 10, "{} calls", calls(&small));
    assert_eq!(big.color, small.color);
    assert_eq!(big.stats.triangle_tests, small.stats.triangle_tests);
    o.max_calls = 3;
    let mut r = stream_renderer(&ctx, &scene, o);
    let e = r.render(&scene.camera).expect_err("a capped frame fails");
    assert!(e.to_string().contains("still walking"), "{e}");
}

/// Colours with shadows and two reflection bounces against the CPU twin of the shading (the
/// GPU's primary rays, the twin's walks): every channel of every pixel within 10⁻⁴ (float sums
/// in another order: the GPU adds the terms by blending; measured at most 6·10⁻⁶).
#[test]
fn colours_with_shadows_and_reflections_equal_the_cpu_twin() {
    let ctx = context();
    let scene = load("teapot1.toml");
    for pc in [false, true] {
        let mut o = stream_options(64, [24, 16, 24], pc);
        o.refl_depth = 2;
        let (f, grid) = render(&ctx, &scene, o);
        let twin = StreamShading::new(&scene, &grid, pc);
        let mut off = 0;
        let mut max = 0.0f32;
        for (i, r) in primary_rays(&f).iter().enumerate() {
            let want = twin.pixel(*r, o.refl_depth).to_array();
            let d = (0..4)
                .map(|c| (f.color[i][c] - want[c]).abs())
                .fold(0.0, f32::max);
            max = max.max(d);
            off += (d > 1e-4) as usize;
        }
        eprintln!(
            "pc {pc}: {off} of {} pixels off by more than 1e-4, max {max}",
            f.color.len()
        );
        assert_eq!(off, 0, "{off} pixels off, by up to {max}");
    }
}

/// The command line: the statistics of a stream render (the paper's M beside the bytes
/// uploaded, the calls, the per-kernel times), and bad options refused with their names.
#[test]
fn the_command_line_reports_and_refuses() {
    let bin = env!("CARGO_BIN_EXE_gpgpu-rt");
    let dir = tempfile::tempdir().unwrap();
    let scene = common::scene_path("cow.toml");
    let run = |extra: &[&str]| {
        let mut c = std::process::Command::new(bin);
        c.arg("render")
            .arg(&scene)
            .args(["--width", "16", "--height", "16", "-o"]);
        c.arg(dir.path().join("x.png")).args(extra);
        c.output().unwrap()
    };
    let stats = dir.path().join("s.json");
    let out = run(&[
        "--tracer",
        "stream",
        "--grid",
        "5x7x3",
        "--stats",
        stats.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(doc["grid_dims"], serde_json::json!([5, 7, 3]));
    assert_eq!(
        doc["grid_paper_bytes"],
        serde_json::json!(96 * 5804 + 16 * 5 * 7 * 3)
    );
    assert!(doc["grid_bytes"].as_u64().unwrap() > 96 * 5804);
    assert!(doc["kernel_calls"].as_u64().unwrap() >= 2);
    assert!(doc["gpu_ms"]["traverse_intersect"].as_f64().unwrap() > 0.0);
    for (args, says) in [
        (&["--tracer", "stream", "--grid", "14x16"][..], "GXxGYxGZ"),
        (
            &[
                "--tracer",
                "grid",
                "--grid-variant",
                "thesis",
                "--proximity-clouds",
            ],
            "--proximity-clouds applies to grid-exact (--tracer grid --grid-variant exact), stream",
        ),
        (
            &["--tracer", "base", "--stream-steps", "8"],
            "--stream-steps",
        ),
        (&["--tracer", "stream", "--tile", "64"], "--tile"),
        (
            &["--tracer", "stream", "--stream-steps", "5000"],
            "1..=4096",
        ),
        (
            &[
                "--tracer",
                "stream",
                "--stream-steps",
                "1",
                "--stream-max-calls",
                "2",
            ],
            "still walking",
        ),
    ] {
        let out = run(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(says),
            "{args:?}: {err}"
        );
    }
}

/// Rays straight at a lone small triangle across empty cells: the proximity-cloud jumps must
/// stop short of the one cell that holds it (the triangle lies inside a cell, not on a cell
/// boundary, where two cells would hold it and a jump one cell too far would still find it in
/// the second: that is how the mutant `stream-cloud-cube-too-large` escaped the dense scenes).
#[test]
fn a_jump_never_passes_the_nearest_non_empty_cell() {
    let ctx = context();
    let dir = tempfile::tempdir().unwrap();
    let tri = |c: [f32; 3]| {
        let [x, y, z] = c;
        format!(
            "v {x} {} {}\nv {x} {} {}\nv {x} {y} {}\nf 1 2 3\n",
            y - 0.05,
            z - 0.05,
            y + 0.05,
            z - 0.05,
            z + 0.05
        )
    };
    let mut toml = "[camera]\nposition = [-3.0, 0.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]\n\
                    fov_y = 6.0\n[[light]]\nposition = [-3.0, 0.5, 0.0]\n"
        .to_string();
    // the target in the middle of the grid (so a jump can pass it) and inside one cell along x
    // (16 cells over [-1, 1]: 0.06 lies in cell 8, 0 would be on the boundary of 7 and 8);
    // two more far off the axis
    let centres = [[0.06, 0.0, 0.0], [-1.0, 1.5, 1.5], [1.0, -1.5, -1.5]];
    for (k, c) in centres.into_iter().enumerate() {
        std::fs::write(dir.path().join(format!("t{k}.obj")), tri(c)).unwrap();
        toml += &format!("[[object]]\ntype = \"obj\"\npath = \"t{k}.obj\"\n");
    }
    std::fs::write(dir.path().join("scene.toml"), toml).unwrap();
    let scene = Scene::load(&dir.path().join("scene.toml")).unwrap();
    let (plain, _) = render(&ctx, &scene, stream_options(32, [16, 16, 16], false));
    let (pc, _) = render(&ctx, &scene, stream_options(32, [16, 16, 16], true));
    let ids = |f: &Frame| f.aovs.as_ref().unwrap().triangle_id.clone();
    let hits = ids(&plain).iter().filter(|&&t| t == 0).count();
    assert!(hits > 10, "the target covers {hits} pixels");
    assert!(pc.stats.events["cloud_jumps"] > 0, "no jump");
    let (a, b) = (ids(&plain), ids(&pc));
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert_eq!(
        differ, 0,
        "{differ} first hits differ with proximity clouds"
    );
}

/// The paper's single-sided test (`--stream-single-sided`) drops back faces and nothing else:
/// on the streaming tracer's scenes (no eye ray meets a back face first) the first hits and the eye
/// rays' triangle tests are those of the two-sided test; on the teapot (patches not consistently
/// wound) the pixels that change are exactly those whose two-sided first hit is a back face,
/// and where the single-sided test hits, it hits a front face.
#[test]
fn single_sided_test_drops_back_faces_only() {
    let ctx = context();
    let back = |tri: &[Vec3; 3], d: Vec3| (tri[1] - tri[0]).cross(tri[2] - tri[0]).dot(d) > 0.0;
    for (file, dims) in [
        ("knight.toml", [14, 16, 14]),
        ("torus_knot.toml", [16, 16, 16]),
        ("teapot1.toml", [24, 24, 24]),
    ] {
        let scene = unlit(load(file));
        let tris = scene.world_triangles();
        let two = render(&ctx, &scene, stream_options(64, dims, false)).0;
        let mut o = stream_options(64, dims, false);
        o.single_sided = true;
        let one = render(&ctx, &scene, o).0;
        let (a2, a1) = (two.aovs.as_ref().unwrap(), one.aovs.as_ref().unwrap());
        let mut changed = 0;
        for (i, d) in a2.ray_direction.iter().enumerate() {
            let d = Vec3::from(*d);
            let (id2, id1) = (a2.triangle_id[i], a1.triangle_id[i]);
            if id1 >= 0 {
                assert!(
                    !back(&tris[id1 as usize], d),
                    "{file} pixel {i}: a back face"
                );
            }
            if id2 != id1 {
                changed += 1;
                assert!(id2 >= 0 && back(&tris[id2 as usize], d), "{file} pixel {i}");
            }
        }
        let tests = |f: &Frame| f.stats.triangle_tests["closest"];
        eprintln!(
            "{file}: {changed} pixels changed; tests two-sided {}, single-sided {}",
            tests(&two),
            tests(&one)
        );
        if file == "teapot1.toml" {
            assert!(changed > 100, "{file}: {changed} back-face first hits");
        } else {
            assert_eq!(changed, 0, "{file}");
            assert_eq!(tests(&two), tests(&one), "{file}: the same walks");
        }
    }
}
