//! The uniform grid (Müller 2015, ch. 3.2, 4.2): Algorithms 2/3 against a brute-force voxel
//! walk, the triangle/box test against dense sampling, the GPU's voxel lists against the CPU
//! reference, the exact grid's image against the base tracer's, the thesis variant's
//! documented losses, and a moving object with the per-frame rebuild.

mod common;

use common::*;
use glam::{IVec3, Mat4, Vec3};
use gpgpu_rt::accel::exact_grid::ExactGrid;
use gpgpu_rt::accel::thesis_grid::ThesisGrid;
use gpgpu_rt::accel::tribox::tri_box_overlap;
use gpgpu_rt::accel::{Accel, GridVariant, ThesisGridOptions};
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::ShaderSource;
use gpgpu_rt::pipeline::mueller2015::{RayTracer, RenderOptions};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::reference::grid::GridSpace;
use gpgpu_rt::scene::Scene;

/// A small deterministic generator (no dependency needed for test data).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    fn point(&mut self) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next()) * 1.98 - 0.99
    }
}

/// Does the segment a -> b pass through the box lo..hi, with positive length inside the open
/// box (interior = true) or touching the closed box grown by `eps` (interior = false)?
fn segment_meets_box(a: Vec3, b: Vec3, lo: Vec3, hi: Vec3, interior: bool, eps: f32) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for k in 0..3 {
        let (l, h) = if interior {
            (lo[k], hi[k])
        } else {
            (lo[k] - eps, hi[k] + eps)
        };
        if d[k].abs() < 1e-12 {
            let inside = if interior {
                a[k] > l && a[k] < h
            } else {
                a[k] >= l && a[k] <= h
            };
            if !inside {
                return false;
            }
        } else {
            let (mut u, mut v) = ((l - a[k]) / d[k], (h - a[k]) / d[k]);
            if u > v {
                std::mem::swap(&mut u, &mut v);
            }
            t0 = t0.max(u);
            t1 = t1.min(v);
        }
    }
    if interior {
        t1 - t0 > 1e-4
    } else {
        t1 >= t0
    }
}

fn check_walk(g: &GridSpace, a: Vec3, b: Vec3) {
    let (vmin, vmax) = (g.clamp(g.get_voxel(a)), g.clamp(g.get_voxel(b)));
    let walk = g.traverse_connection(a, b, vmin, vmax);
    assert_eq!(walk[0], vmin);
    assert_eq!(
        *walk.last().unwrap(),
        vmax,
        "walk {a} -> {b} does not end in the end voxel"
    );
    let e = g.vx_edge();
    for w in walk.windows(2) {
        let step = w[1] - w[0];
        assert!(
            step != IVec3::ZERO && step.abs().max_element() == 1,
            "not a unit move: {step}"
        );
    }
    let boxes = |v: IVec3| {
        let lo = v.as_vec3() * e - 1.0;
        (lo, lo + e)
    };
    // every visited voxel touches the segment
    for v in &walk {
        let (lo, hi) = boxes(*v);
        assert!(
            segment_meets_box(a, b, lo, hi, false, 1e-4),
            "{a} -> {b} visits {v} it does not touch"
        );
    }
    // every voxel whose interior the segment crosses is visited (brute force over all voxels)
    let n = g.n as i32;
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let v = IVec3::new(x, y, z);
                let (lo, hi) = boxes(v);
                if segment_meets_box(a, b, lo, hi, true, 0.0) {
                    assert!(walk.contains(&v), "{a} -> {b} misses voxel {v}");
                }
            }
        }
    }
}

#[test]
fn algorithms_2_and_3_match_a_brute_force_walk() {
    let g = GridSpace { n: 8 };
    let mut rng = Lcg(7);
    let e = g.vx_edge();
    for _ in 0..300 {
        check_walk(&g, rng.point(), rng.point());
    }
    // axis-aligned segments, segments along voxel faces and edges, through voxel corners
    let corner = |i: i32, j: i32, k: i32| Vec3::new(i as f32, j as f32, k as f32) * e - 1.0;
    let cases = [
        (Vec3::new(-0.9, 0.1, 0.1), Vec3::new(0.9, 0.1, 0.1)),
        (Vec3::new(0.3, 0.9, -0.3), Vec3::new(0.3, -0.9, -0.3)),
        (corner(1, 1, 1), corner(6, 6, 6)), // through corners (Fig. 13b)
        (corner(1, 1, 1) + 0.01, corner(6, 6, 6) + 0.01), // diagonal, off the corners
        (
            corner(1, 2, 0) + Vec3::new(0.01, 0.0, 0.1),
            corner(5, 6, 0) + Vec3::new(0.01, 0.0, 0.1),
        ), // through edges (Fig. 13a)
        (corner(6, 1, 3), corner(1, 6, 3) + Vec3::new(0.0, 0.0, 0.05)), // mixed directions at edges
        (corner(7, 2, 2) + 0.05, corner(2, 7, 7) + 0.05), // -x, +y, +z through corners
        (Vec3::new(0.0, 0.0, -0.95), Vec3::new(0.0, 0.0, 0.95)), // on voxel edges all along
        (
            corner(2, 3, 4),
            corner(2, 3, 4) + Vec3::new(0.0, 0.0, 3.0 * e),
        ),
    ];
    for (a, b) in cases {
        check_walk(&g, a, b);
        check_walk(&g, b, a);
    }
}

#[test]
fn triangle_box_overlap_matches_dense_sampling() {
    let mut rng = Lcg(11);
    let half = Vec3::splat(0.25);
    for _ in 0..400 {
        let c = rng.point() * 0.5;
        let tri = [rng.point(), rng.point(), rng.point()].map(|p| c + p * 0.6);
        let overlap = tri_box_overlap(Vec3::ZERO, half, tri);
        // dense barycentric samples
        let steps = 120;
        let mut inside = false;
        let mut near = false;
        let spacing = (tri[1] - tri[0]).length().max((tri[2] - tri[0]).length()) / steps as f32;
        for i in 0..=steps {
            for j in 0..=(steps - i) {
                let (u, v) = (i as f32 / steps as f32, j as f32 / steps as f32);
                let p = tri[0] + u * (tri[1] - tri[0]) + v * (tri[2] - tri[0]);
                inside |= p.abs().cmple(half).all();
                near |= p.abs().cmple(half + spacing * 2.0).all();
            }
        }
        if inside {
            assert!(
                overlap,
                "a sample of {tri:?} lies in the box, the test says no overlap"
            );
        }
        if overlap {
            assert!(
                near,
                "the test says {tri:?} overlaps, no sample comes near the box"
            );
        }
    }
}

/// The grid `variant` of `n`³ voxels (the thesis grid with Listing 17's list lengths).
fn grid_accel(variant: GridVariant, n: u32) -> Accel {
    match variant {
        GridVariant::Thesis => thesis_grid(n),
        GridVariant::Exact => exact_grid(n, false),
    }
}

fn grid_options(w: u32, h: u32, variant: GridVariant, n: u32) -> RenderOptions {
    options_with(grid_accel(variant, n), w, h, 1)
}

/// The grid's voxel lists of the last frame and its scene-to-grid mapping (centre, scale).
fn read_lists(t: &RayTracer) -> (Vec<Vec<i32>>, Vec3, f32) {
    let a = t.accelerator().as_any();
    let (lists, m) = match (
        a.downcast_ref::<ThesisGrid>(),
        a.downcast_ref::<ExactGrid>(),
    ) {
        (Some(g), _) => g.read_lists(t.gl()),
        (_, Some(g)) => g.read_lists(t.gl()),
        _ => panic!("not a grid: {}", t.entry().label),
    };
    (lists, m.center, m.scale)
}

/// The voxels whose GPU list differs from the CPU reference's (as multisets: the thesis grid
/// fills a list in atomic order and may store a triangle twice, as its CPU twin does), with
/// both lists; and the number of references the reference holds.
type ListDiff = Vec<(usize, Vec<i32>, Vec<i32>)>;

fn list_differences(
    ctx: &gpgpu_rt::gl::GlContext,
    scene: &Scene,
    grid: Accel,
) -> (ListDiff, usize) {
    let opts = options_with(grid, 16, 16, 1);
    let mut t = ray_tracer(ctx, scene, opts);
    let f = t.render(&scene.camera).unwrap();
    for lost in ["dropped_triangle_refs", "truncated_rays"] {
        assert_eq!(f.stats.events.get(lost).copied().unwrap_or(0), 0, "{lost}");
    }
    let (lists, center, scale) = read_lists(&t);
    // the exact grid's count and fill passes agree on every overlap (precise arithmetic in
    // both programs): every list slot count reserved is written, none past it
    if let Some(g) = t.accelerator().as_any().downcast_ref::<ExactGrid>() {
        assert_eq!(
            g.count_fill_mismatches(t.gl()),
            0,
            "voxels count and fill disagree on"
        );
    }
    let n = grid.grid_resolution().unwrap();
    let g = GridSpace { n };
    let mut expected = vec![Vec::new(); (n * n * n) as usize];
    for (id, tri) in scene.world_triangles().iter().enumerate() {
        let tg = tri.map(|p| (p - center) * scale);
        let voxels = match grid {
            Accel::ThesisGrid(_) => g.thesis_voxels(tg),
            _ => g.exact_voxels(tg),
        };
        for v in voxels {
            expected[v].push(id as i32);
        }
    }
    let mut differing = Vec::new();
    for (v, (got, want)) in lists.iter().zip(&expected).enumerate() {
        let mut got = got.clone();
        got.sort();
        if &got != want {
            differing.push((v, got, want.clone()));
        }
    }
    let refs = expected.iter().map(|l| l.len()).sum();
    (differing, refs)
}

/// The GPU's voxel lists equal the CPU reference's exactly (same f32 operations in the same
/// order on both sides: grid.glsl, voxelwalk.glsl and tribox.glsl against reference/grid.rs).
fn check_lists(ctx: &gpgpu_rt::gl::GlContext, scene: &Scene, variant: GridVariant, n: u32) {
    let grid = match grid_accel(variant, n) {
        Accel::ThesisGrid(o) => Accel::ThesisGrid(ThesisGridOptions {
            voxel_array_length: 4096,
            ..o
        }),
        other => other,
    };
    let (differing, refs) = list_differences(ctx, scene, grid);
    assert!(
        refs > scene.triangle_count(),
        "{variant:?}: {refs} references"
    );
    assert!(
        differing.is_empty(),
        "{variant:?} N={n}: {} voxel lists differ, e.g. (voxel, GPU, CPU) {:?}",
        differing.len(),
        &differing[..differing.len().min(3)]
    );
}

#[test]
fn gpu_voxel_lists_match_the_reference() {
    let ctx = context();
    let scene = load("cow.toml");
    check_lists(&ctx, &scene, GridVariant::Thesis, 12);
    check_lists(&ctx, &scene, GridVariant::Exact, 12);
}

/// The object-space f32 that the grid mapping (p − 0) · scale takes closest to the grid-space
/// value g (exactly onto it where some f32 lands there).
fn preimage(g: f32, scale: f32) -> f32 {
    let mut near = vec![g / scale];
    for _ in 0..8 {
        let (lo, hi) = (near[0].next_down(), near[near.len() - 1].next_up());
        near.insert(0, lo);
        near.push(hi);
    }
    let off = |p: &f32| (p * scale - g).abs();
    near.into_iter()
        .min_by(|a, b| off(a).total_cmp(&off(b)))
        .unwrap()
}

/// Adversarial triangles in grid space ([-1, 1)³, N voxels per axis, edge e): vertices on the
/// voxel lattice and its midpoints (edges along voxel faces, through voxel edges and corners:
/// the cases of Fig. 13), their mirror images through the grid centre, triangles lying in a
/// voxel face, and copies shifted off a face by 1e-6 … 1e-4 and by the exact grid's margin.
fn adversarial_triangles(n: u32) -> Vec<[Vec3; 3]> {
    let e = 2.0 / n as f32;
    let mut rng = Lcg(5 + n as u64);
    let half_lattice = |r: &mut Lcg| {
        let k = |r: &mut Lcg| ((r.next() * (2 * n + 1) as f32) as i32).min(2 * n as i32);
        Vec3::new(k(r) as f32, k(r) as f32, k(r) as f32) * (0.5 * e) - 1.0
    };
    let mut tris = Vec::new();
    for _ in 0..60 {
        let t = [0; 3].map(|_| half_lattice(&mut rng));
        tris.push(t);
        tris.push(t.map(|p| -p)); // symmetric about the grid centre
    }
    // in a voxel face: all three vertices on the plane z = 2e - 1 (and x = -e... , centre planes)
    for _ in 0..20 {
        let mut t = [0; 3].map(|_| half_lattice(&mut rng));
        let axis = (rng.next() * 3.0) as usize % 3;
        let plane = ((rng.next() * n as f32) as i32) as f32 * e - 1.0;
        for p in &mut t {
            p[axis] = plane;
        }
        tris.push(t);
    }
    let margin = e * 1e-4;
    let shifts = [1e-6, 1e-5, 1e-4, margin, margin * 0.999, margin * 1.001];
    for (k, base) in tris.clone().iter().take(40).enumerate() {
        let d = shifts[k % shifts.len()] * if k % 2 == 0 { 1.0 } else { -1.0 };
        let mut offset = Vec3::ZERO;
        offset[k % 3] = d;
        tris.push(base.map(|p| p + offset));
    }
    tris
}

/// The grid mapping of the adversarial scenes: centre 0, scale 2 / (2 · 1.001) (their bounds
/// are ±1, enlarged as `GridMapping::of_objects` does).
const SCALE: f32 = 2.0 / (2.0 * 1.001);

/// The object-space point written for the grid-space point p.
fn object_point(p: Vec3) -> [f32; 3] {
    p.to_array()
        .map(|c| preimage(c.clamp(-0.998, 0.998), SCALE))
}

/// Where the grids see the grid-space point p after the round trip through the scene file.
fn seen(p: Vec3) -> Vec3 {
    Vec3::from(object_point(p)) * SCALE
}

/// Does Algorithm 2's clamp to t_max = 1 change the thesis walk of p0 -> p1 (grid space, as
/// `voxelwalk.glsl` computes it)? It does where the end point lies on two voxel planes and the
/// last crossing of one of them rounds to just above 1: clamped, the crossings are equal and
/// the walk moves diagonally (Fig. 13); unclamped, it moves twice, through one more voxel.
fn clamp_matters(g: &GridSpace, p0: Vec3, p1: Vec3) -> bool {
    let (v0, v1) = (g.clamp(g.get_voxel(p0)), g.clamp(g.get_voxel(p1)));
    let rd = p1 - p0;
    let (mut at_end, mut over) = (0, 0);
    for d in 0..3 {
        if rd[d] == 0.0 || v0[d] == v1[d] {
            continue;
        }
        let last = if rd[d] > 0.0 { v1[d] } else { v1[d] + 1 };
        let t = (last as f32 * g.vx_edge() - 1.0 - p0[d]) / rd[d];
        at_end += (t >= 1.0) as u32;
        over += (t > 1.0) as u32;
    }
    at_end >= 2 && over >= 1
}

/// Triangles with an edge whose walk the clamp changes: edges that end a few ulps around a
/// voxel corner, kept where [`clamp_matters`] (at least `want` of them).
fn clamp_cases(n: u32, want: usize) -> Vec<[Vec3; 3]> {
    let g = GridSpace { n };
    let e = g.vx_edge();
    let mut rng = Lcg(99 + n as u64);
    let mut out = Vec::new();
    for _ in 0..20_000 {
        let lattice = |r: &mut Lcg| ((r.next() * (n - 1) as f32) as i32 + 1) as f32 * e - 1.0;
        let mut corner = Vec3::new(lattice(&mut rng), lattice(&mut rng), lattice(&mut rng));
        for k in 0..3 {
            for _ in 0..(rng.next() * 4.0) as u32 {
                corner[k] = if rng.next() < 0.5 {
                    corner[k].next_up()
                } else {
                    corner[k].next_down()
                };
            }
        }
        let (p0, p2) = (rng.point() * 0.95, rng.point() * 0.95);
        if clamp_matters(&g, seen(p0), seen(corner)) {
            out.push([p0, corner, p2]);
            if out.len() == want {
                break;
            }
        }
    }
    assert_eq!(
        out.len(),
        want,
        "N={n}: too few edges where the clamp matters"
    );
    out
}

/// A scene of the triangles (grid space) placed so that the grid's mapping takes them back to
/// (within rounding of) where they were: a bounding pair of tiny triangles at ±1 fixes the
/// bounds, and each coordinate is the f32 that maps onto the wanted grid-space value.
fn adversarial_scene(dir: &std::path::Path, tris: &[[Vec3; 3]]) -> Scene {
    let mut obj = String::from("v -1 -1 -1\nv -0.999 -1 -1\nv -1 -0.999 -1\n");
    obj += "v 1 1 1\nv 0.999 1 1\nv 1 0.999 1\n";
    for t in tris {
        for p in t {
            let q = object_point(*p);
            obj += &format!("v {:?} {:?} {:?}\n", q[0], q[1], q[2]);
        }
    }
    for f in 0..tris.len() + 2 {
        obj += &format!("f {} {} {}\n", 3 * f + 1, 3 * f + 2, 3 * f + 3);
    }
    std::fs::write(dir.join("tris.obj"), obj).unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        "[camera]\nposition = [0.3, 0.4, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 50.0\n[[light]]\nposition = [1.0, 4.0, 1.0]\n[[object]]\ntype = \"obj\"\npath = \"tris.obj\"\n",
    )
    .unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap()
}

/// Issue 16, class 6: the special cases of the grid build, on the GPU against the CPU,
/// exactly, for both grid variants and two resolutions (N = 8: a power-of-two voxel edge,
/// N = 12: an inexact one).
#[test]
fn gpu_voxel_lists_equal_the_reference_on_adversarial_triangles() {
    let ctx = context();
    let dir = tempfile::tempdir().unwrap();
    for n in [8, 12] {
        let mut tris = adversarial_triangles(n);
        tris.extend(clamp_cases(n, 12));
        let scene = adversarial_scene(dir.path(), &tris);
        let m = gpgpu_rt::accel::grid_frame::GridMapping::of_scene(&scene);
        assert_eq!((m.center, m.scale), (Vec3::ZERO, SCALE));
        for variant in [GridVariant::Thesis, GridVariant::Exact] {
            check_lists(&ctx, &scene, variant, n);
        }
    }
}

#[test]
fn exact_grid_gives_the_base_tracers_image() {
    let ctx = context();
    for (name, n, refl) in [
        ("teapot1.toml", 16, 1),
        ("bunny.toml", 24, 1),
        ("teapot3.toml", 20, 2),
    ] {
        let scene = load(name);
        let base = render_gpu(&ctx, &scene, options(48, 40, refl));
        let mut t = ray_tracer(
            &ctx,
            &scene,
            RenderOptions {
                refl_depth: refl,
                ..grid_options(48, 40, GridVariant::Exact, n)
            },
        );
        let grid = t.render(&scene.camera).unwrap();
        assert_same_image(&base, &grid, name);
        // far fewer tests
        let (tb, tg) = (
            base.stats.total_triangle_tests(),
            grid.stats.total_triangle_tests(),
        );
        assert!(tg * 10 < tb, "{name}: grid {tg} vs base {tb} tests");
        assert!(grid.stats.events["voxels_visited"] > 0);
        assert_eq!(grid.stats.events["dropped_triangle_refs"], 0);
        assert_eq!(grid.stats.facts["grid_resolution"], n);
    }
}

/// Two big triangles (a quad of 4×4 units) seen from above, and a small one.
fn big_triangle_scene(dir: &std::path::Path) -> Scene {
    std::fs::write(
        dir.join("quad.obj"),
        "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nv -0.2 0.5 -0.2\nv 0.2 0.5 -0.2\nv 0 0.8 0.2\nf 1 4 3\nf 1 3 2\nf 5 6 7\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        "[camera]\nposition = [0.0, 5.0, 0.01]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 50.0\n[[light]]\nposition = [1.0, 4.0, 1.0]\n[[object]]\ntype = \"obj\"\npath = \"quad.obj\"\n",
    )
    .unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap()
}

#[test]
fn thesis_grid_loses_big_triangle_interiors_the_exact_grid_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let scene = big_triangle_scene(dir.path());
    let ctx = context();
    let base = render_gpu(&ctx, &scene, options(48, 48, 0));
    let hits = |f: &Frame| {
        f.aovs
            .as_ref()
            .unwrap()
            .triangle_id
            .iter()
            .filter(|&&i| i >= 0)
            .count()
    };
    let mut thesis = ray_tracer(
        &ctx,
        &scene,
        RenderOptions {
            refl_depth: 0,
            ..grid_options(48, 48, GridVariant::Thesis, 16)
        },
    );
    let mut exact = ray_tracer(
        &ctx,
        &scene,
        RenderOptions {
            refl_depth: 0,
            ..grid_options(48, 48, GridVariant::Exact, 16)
        },
    );
    let (ft, fe) = (
        thesis.render(&scene.camera).unwrap(),
        exact.render(&scene.camera).unwrap(),
    );
    assert!(hits(&base) > 1500, "the quad fills most of the image");
    assert_eq!(hits(&fe), hits(&base), "the exact grid sees the whole quad");
    // edge-only registration: the quad's interior voxels hold no triangle, rays pass through
    assert!(
        hits(&ft) < hits(&base) / 2,
        "thesis grid: {} of {} hits",
        hits(&ft),
        hits(&base)
    );
    assert_eq!(
        ft.stats.events["dropped_triangle_refs"], 0,
        "the holes are not list overflows"
    );
}

#[test]
fn thesis_grid_counts_what_its_fixed_lists_drop() {
    let ctx = context();
    let scene = load("bunny.toml");
    let accel = Accel::ThesisGrid(ThesisGridOptions {
        resolution: Some(8),
        voxel_array_length: 16,
        ray_array_length: Some(2),
    });
    let opts = options_with(accel, 24, 24, 0);
    let mut t = ray_tracer(&ctx, &scene, opts);
    let f = t.render(&scene.camera).unwrap();
    let dropped = f.stats.events["dropped_triangle_refs"];
    let overflows = f.stats.events["ray_list_overflows"];
    // 69451 triangles in 8³ voxels with 16 entries each: most references are dropped
    assert!(dropped > 50_000, "dropped {dropped}");
    assert!(overflows > 0, "ray list overflows {overflows}");
    // the references kept are exactly what the lists hold
    let (lists, _, _) = read_lists(&t);
    assert!(lists.iter().all(|l| l.len() <= 16));
}

#[test]
fn moving_object_is_rebuilt_every_frame() {
    let ctx = context();
    let mut scene = load("teapot1.toml");
    let opts = grid_options(40, 40, GridVariant::Exact, 16);
    let mut grid = ray_tracer(&ctx, &scene, opts.clone());
    let mut base = RayTracer::new(
        ctx.gl.clone(),
        &ctx.info,
        &scene,
        &ShaderSource::default(),
        RenderOptions {
            accel: Accel::Base,
            ..opts
        },
    )
    .unwrap();
    let first = grid.render(&scene.camera).unwrap();
    // lift the teapot far up: the scene's bounds change, the grid follows
    let moved = Mat4::from_translation(Vec3::new(0.5, 1.5, -0.5))
        * Mat4::from_rotation_y(1.0)
        * scene.objects[1].model;
    grid.set_model(1, moved).unwrap();
    base.set_model(1, moved).unwrap();
    let (g, b) = (
        grid.render(&scene.camera).unwrap(),
        base.render(&scene.camera).unwrap(),
    );
    assert_ne!(first.color, g.color);
    assert_eq!(
        g.aovs.as_ref().unwrap().triangle_id,
        b.aovs.as_ref().unwrap().triangle_id
    );
    scene.objects[1].model = moved;
    assert_close(
        &g,
        &render_cpu(&scene, &options(40, 40, 1)),
        "moved teapot, grid",
    );
}
