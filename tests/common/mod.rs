//! Shared helpers of the integration tests: a headless context, rendering on the GPU and on
//! the CPU reference, and pixel-by-pixel comparison with stated tolerances.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use glam::Vec3;
use gpgpu_rt::accel::{Accel, BvhLevels, BvhOptions, BvhPasses, ExactGridOptions};
use gpgpu_rt::frame::Frame;
use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::pipeline::mueller2015::{RayTracer, RenderOptions};
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::reference::{Reference, ReferenceFrame};
use gpgpu_rt::scene::{Light, Scene};

/// A shipped scene's path: below `GPGPU_RT_TEST_ROOT` where it is set (a test executable
/// carried to another machine, `scripts/gpu-check.sh --tests`), else below the checkout the
/// tests were built in.
pub fn scene_path(name: &str) -> PathBuf {
    let root = std::env::var_os("GPGPU_RT_TEST_ROOT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")));
    root.join("scenes").join(name)
}

pub fn load(name: &str) -> Scene {
    Scene::load(&scene_path(name)).expect("shipped scene loads")
}

/// A test's context. On zink its test holds the process' turn on the GL for as long as it
/// lives (below); elsewhere the tests of a file render in parallel.
pub struct TestContext {
    ctx: GlContext,
    turn: Option<std::sync::MutexGuard<'static, ()>>,
}

impl std::ops::Deref for TestContext {
    type Target = GlContext;
    fn deref(&self) -> &GlContext {
        &self.ctx
    }
}

/// The turn on the GL of the tests of one process under zink. Mesa 22.3's zink on lavapipe
/// crashed once (SIGSEGV) in four runs of the suite when two test threads rendered through two
/// contexts at once (`tests/edge_cases.rs`; not reproduced in 40 runs of that file alone); the
/// program itself renders through one context a process. So under zink a file's tests take
/// turns; a test that makes a second context keeps its turn.
static ZINK_TURN: std::sync::Mutex<()> = std::sync::Mutex::new(());
thread_local! {
    static HOLDS_TURN: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

pub fn context() -> TestContext {
    let ctx =
        GlContext::headless(None).expect("a headless GL 4.5 context (Mesa llvmpipe or a GPU)");
    let zink = ctx.info.renderer.starts_with("zink");
    let turn = (zink && !HOLDS_TURN.get()).then(|| {
        let held = ZINK_TURN.lock().unwrap_or_else(|e| e.into_inner());
        HOLDS_TURN.set(true);
        held
    });
    TestContext { ctx, turn }
}

impl Drop for TestContext {
    fn drop(&mut self) {
        if self.turn.is_some() {
            HOLDS_TURN.set(false);
        }
    }
}

/// The base tracer at `w`×`h` with `refl_depth` reflection passes, keeping its AOVs.
pub fn options(w: u32, h: u32, refl_depth: u32) -> RenderOptions {
    RenderOptions {
        aovs: true,
        ..RenderOptions::new(Accel::Base, w, h, refl_depth)
    }
}

/// [`options`] with the accelerator `accel`.
pub fn options_with(accel: Accel, w: u32, h: u32, refl_depth: u32) -> RenderOptions {
    RenderOptions {
        accel,
        ..options(w, h, refl_depth)
    }
}

/// The SAH BVH with `passes` over `levels`.
pub fn bvh(passes: BvhPasses, levels: BvhLevels) -> Accel {
    Accel::Bvh(BvhOptions { passes, levels })
}

/// The SAH BVH in Müller 2015's four kernels, one tree.
pub const BVH_FOUR_KERNELS: Accel = Accel::Bvh(BvhOptions {
    passes: BvhPasses::FourKernels,
    levels: BvhLevels::One,
});

/// The SAH BVH's fused pass over one tree (the default).
pub const BVH_FUSED: Accel = Accel::Bvh(BvhOptions {
    passes: BvhPasses::Fused,
    levels: BvhLevels::One,
});

/// `opts` (the SAH BVH) with the fused pass where `fused`, else the four kernels; its levels
/// kept.
pub fn fused_if(opts: &RenderOptions, fused: bool) -> RenderOptions {
    let Accel::Bvh(b) = opts.accel else {
        panic!("not the SAH BVH: {:?}", opts.accel)
    };
    let passes = match fused {
        true => BvhPasses::Fused,
        false => BvhPasses::FourKernels,
    };
    RenderOptions {
        accel: Accel::Bvh(BvhOptions { passes, ..b }),
        ..opts.clone()
    }
}

/// The exact grid of `n`³ voxels.
pub fn exact_grid(n: u32, proximity_clouds: bool) -> Accel {
    Accel::ExactGrid(ExactGridOptions {
        resolution: Some(n),
        proximity_clouds,
    })
}

/// The thesis grid of `n`³ voxels with Listing 17's list lengths.
pub fn thesis_grid(n: u32) -> Accel {
    gpgpu_rt::accel::thesis_grid::ENTRY
        .plain
        .with_grid_resolution(n)
}

/// The ray tracer with the accelerator `opts.tracer` for `scene`, kernels built in.
pub fn ray_tracer(ctx: &GlContext, scene: &Scene, opts: RenderOptions) -> RayTracer {
    try_ray_tracer(ctx, scene, opts).expect("tracer")
}

/// [`ray_tracer`], or why it is refused.
pub fn try_ray_tracer(
    ctx: &GlContext,
    scene: &Scene,
    opts: RenderOptions,
) -> anyhow::Result<RayTracer> {
    RayTracer::new(
        ctx.gl.clone(),
        &ctx.info,
        scene,
        &ShaderSource::default(),
        opts,
    )
}

/// Every accelerator of Müller 2015's pipeline and each of its variants that the registry
/// holds equal to its twin (`accel::Entry::variants`) at `w`×`h` with `refl_depth` reflection
/// passes and grids of `n`³, the base tracer also with its triangles split over dispatches of
/// 2000 (a ray counted once, a found occluder carried in the flag): (label, options).
pub fn pipeline_accelerators(
    w: u32,
    h: u32,
    refl_depth: u32,
    n: u32,
) -> Vec<(&'static str, RenderOptions)> {
    let mut all = Vec::new();
    for entry in gpgpu_rt::design::accelerators() {
        for &(label, accel) in entry.variants {
            all.push((
                label,
                options_with(accel.with_grid_resolution(n), w, h, refl_depth),
            ));
            if accel == Accel::Base {
                let split = RenderOptions {
                    triangles_per_dispatch: Some(2000),
                    ..options(w, h, refl_depth)
                };
                all.push(("base split", split));
            }
        }
    }
    all
}

/// The options of `label` among [`pipeline_accelerators`].
pub fn pipeline_accelerator(label: &str, all: &[(&'static str, RenderOptions)]) -> RenderOptions {
    let found = all.iter().find(|(l, _)| *l == label);
    found
        .unwrap_or_else(|| panic!("no accelerator `{label}`"))
        .1
        .clone()
}

pub fn render_gpu(ctx: &GlContext, scene: &Scene, opts: RenderOptions) -> Frame {
    ray_tracer(ctx, scene, opts)
        .render(&scene.camera)
        .expect("frame")
}

pub fn render_cpu(scene: &Scene, opts: &RenderOptions) -> ReferenceFrame {
    Reference::new(scene).render(&scene.camera, opts.width, opts.height, opts.refl_depth)
}

/// How a GPU frame differs from the CPU reference.
#[derive(Debug)]
pub struct Comparison {
    pub pixels: usize,
    /// pixels whose first-hit triangle id differs
    pub id_mismatches: usize,
    /// largest relative hit-distance difference over pixels with equal ids
    pub max_t_rel: f32,
    /// mean over pixels and channels of |gpu - cpu| colour
    pub mean_color_diff: f32,
    /// largest |gpu - cpu| of any channel of any pixel
    pub max_color_diff: f32,
    /// share of pixels with any channel off by more than 0.02
    pub color_outliers: f32,
    pub hits: usize,
}

pub fn compare(gpu: &Frame, cpu: &ReferenceFrame) -> Comparison {
    let a = gpu.aovs.as_ref().expect("GPU AOVs");
    let n = cpu.color.len();
    assert_eq!(gpu.color.len(), n);
    let mut c = Comparison {
        pixels: n,
        id_mismatches: 0,
        max_t_rel: 0.0,
        mean_color_diff: 0.0,
        max_color_diff: 0.0,
        color_outliers: 0.0,
        hits: 0,
    };
    let mut sum = 0.0f64;
    let mut outliers = 0;
    for i in 0..n {
        let (gi, ci) = (a.triangle_id[i], cpu.aovs.triangle_id[i]);
        if ci >= 0 {
            c.hits += 1;
        }
        if gi != ci {
            c.id_mismatches += 1;
        } else if ci >= 0 {
            let rel = (a.hit_t[i] - cpu.aovs.hit_t[i]).abs() / cpu.aovs.hit_t[i].max(1e-3);
            c.max_t_rel = c.max_t_rel.max(rel);
        } else {
            assert!(
                a.hit_t[i].is_infinite() && a.hit_t[i] > 0.0,
                "miss must have hit_t = +inf"
            );
        }
        let mut worst = 0.0f32;
        for k in 0..3 {
            let d = (gpu.color[i][k] - cpu.color[i][k]).abs();
            sum += d as f64;
            worst = worst.max(d);
        }
        if worst > 0.02 {
            outliers += 1;
        }
        c.max_color_diff = c.max_color_diff.max(worst);
    }
    c.mean_color_diff = (sum / (3 * n) as f64) as f32;
    c.color_outliers = outliers as f32 / n as f32;
    c
}

/// Tolerances of a GPU/CPU image comparison. The first hits must be the same triangles in
/// every pixel; hit distances and colours differ by the rounding of two implementations of the
/// same arithmetic (the GPU compiler may contract a·b + c into one fused multiply-add, the CPU
/// does not), so those bounds sit just above the noise measured on the tests' frames.
#[derive(Debug, Clone, Copy)]
pub struct Tolerance {
    /// largest relative hit-distance difference
    pub t_rel: f32,
    /// largest colour difference of any channel of any pixel
    pub max_color: f32,
    /// largest mean colour difference
    pub mean_color: f32,
}

/// Measured (Mesa llvmpipe, 2026-11-23) over the seven frames of `base_tracer.rs`, `bvh.rs`
/// and `grid.rs` that use it: 0 differing ids, hit distances within 5.7e-7 relative, colours
/// within 2.3e-8 on average and 3.6e-6 at worst (5.2e-6 on the cow of `accel.rs`; formerly
/// allowed: 0.5 % of the ids, 1e-4, 0.005 mean and 1 % of the pixels off by 0.02).
pub const SAME_ARITHMETIC: Tolerance = Tolerance {
    t_rel: 2e-6,
    max_color: 1e-5,
    mean_color: 1e-6,
};

/// Compare with [`SAME_ARITHMETIC`].
pub fn assert_close(gpu: &Frame, cpu: &ReferenceFrame, what: &str) -> Comparison {
    assert_close_within(gpu, cpu, what, SAME_ARITHMETIC)
}

/// The same first triangle in every pixel, distances and colours within `tol`.
pub fn assert_close_within(
    gpu: &Frame,
    cpu: &ReferenceFrame,
    what: &str,
    tol: Tolerance,
) -> Comparison {
    let c = compare(gpu, cpu);
    eprintln!("{what}: {c:?}");
    assert!(c.hits > 0, "{what}: the image shows no geometry");
    assert_eq!(c.id_mismatches, 0, "{what}: triangle ids differ: {c:?}");
    assert!(
        c.max_t_rel <= tol.t_rel,
        "{what}: hit distances differ: {c:?}"
    );
    assert!(
        c.max_color_diff <= tol.max_color,
        "{what}: colours differ: {c:?}"
    );
    assert!(
        c.mean_color_diff <= tol.mean_color,
        "{what}: colours differ: {c:?}"
    );
    c
}

/// Copy a folder tree (e.g. `glsl/` for `--glsl-dir`).
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

/// `other` shows the base tracer's image: the same first triangle ids and hit distances in every
/// pixel, colours within 1e-4.
pub fn assert_same_image(base: &Frame, other: &Frame, what: &str) {
    let (a, b) = (base.aovs.as_ref().unwrap(), other.aovs.as_ref().unwrap());
    let differ = a
        .triangle_id
        .iter()
        .zip(&b.triangle_id)
        .filter(|(x, y)| x != y)
        .count();
    assert_eq!(
        differ, 0,
        "{what}: {differ} triangle ids differ from the base tracer"
    );
    assert_eq!(a.hit_t, b.hit_t, "{what}");
    let colour_diff = base
        .color
        .iter()
        .zip(&other.color)
        .map(|(x, y)| {
            (x[0] - y[0])
                .abs()
                .max((x[1] - y[1]).abs())
                .max((x[2] - y[2]).abs())
        })
        .fold(0.0f32, f32::max);
    assert!(
        colour_diff < 1e-4,
        "{what}: colours differ by {colour_diff}"
    );
}

/// The `gpgpu-rt` binary run with `args`, its exit status and output kept.
pub fn run(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// The smallest Klee 2016 bench run: the N-tree reading A only (3 levels; reading B's tree takes
/// minutes to build), at 16×16.
pub const KLEE_TINY: [&str; 6] = ["--ntree-levels", "3", "--width", "16", "--height", "16"];

/// The standard error of a run, as text.
pub fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A scene file in `dir`: `head` (camera, render, lights) and one object per (OBJ text, colour).
pub fn scene_of(dir: &Path, head: &str, objects: &[(String, [f32; 3])]) -> Scene {
    let mut toml = head.to_string();
    for (k, (obj, c)) in objects.iter().enumerate() {
        std::fs::write(dir.join(format!("o{k}.obj")), obj).unwrap();
        toml += &format!(
            "[[object]]\ntype = \"obj\"\npath = \"o{k}.obj\"\ncolor = [{:?}, {:?}, {:?}]\nspecular = 0.0\n",
            c[0], c[1], c[2]
        );
    }
    std::fs::write(dir.join("scene.toml"), toml).unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap()
}

/// An OBJ of one triangle.
pub fn tri_obj(t: [Vec3; 3]) -> String {
    let mut s = String::new();
    for v in t {
        s += &format!("v {:?} {:?} {:?}\n", v.x, v.y, v.z);
    }
    s + "f 1 2 3\n"
}

/// Wagner 2018's design with the size, tiles and AOVs of `o` (its other options do not apply).
pub fn wagner(o: &RenderOptions) -> gpgpu_rt::design::Design {
    gpgpu_rt::design::Design::Wagner2018(gpgpu_rt::pipeline::wagner2018::WagnerOptions {
        width: o.width,
        height: o.height,
        tile: o.tile,
        aovs: o.aovs,
    })
}

/// The streaming tracer with the size, reflection depth and AOVs of `o`, the command
/// line's defaults otherwise.
pub fn stream(o: &RenderOptions) -> gpgpu_rt::design::Design {
    use gpgpu_rt::pipeline::stream::StreamOptions;
    gpgpu_rt::design::Design::Stream(StreamOptions {
        aovs: o.aovs,
        ..StreamOptions::new(o.width, o.height, o.refl_depth)
    })
}

/// The streaming tracer at `size`² on the grid `dims`, with or without proximity clouds:
/// eye rays only, 64 steps per call, AOVs kept.
pub fn stream_options(
    size: u32,
    dims: [u32; 3],
    proximity_clouds: bool,
) -> gpgpu_rt::pipeline::stream::StreamOptions {
    gpgpu_rt::pipeline::stream::StreamOptions {
        width: size,
        height: size,
        refl_depth: 0,
        dims: Some(dims),
        proximity_clouds,
        steps_per_call: 64,
        max_calls: 10_000,
        naive_shadows: false,
        no_mask: false,
        single_sided: false,
        aovs: true,
    }
}

/// The streaming tracer with the kernels built in, or with `STREAM_TEST_GLSL_DIR=DIR` those of
/// DIR (a copy of `glsl/` with a planted bug: the stream tests were each seen to fail so).
pub fn stream_renderer(
    ctx: &GlContext,
    scene: &Scene,
    o: gpgpu_rt::pipeline::stream::StreamOptions,
) -> gpgpu_rt::pipeline::stream::StreamRenderer {
    let dir = std::env::var_os("STREAM_TEST_GLSL_DIR").map(Into::into);
    let shaders = ShaderSource::from_dir(dir).expect("STREAM_TEST_GLSL_DIR");
    gpgpu_rt::pipeline::stream::StreamRenderer::new(ctx.gl.clone(), &ctx.info, scene, &shaders, o)
        .expect("stream tracer")
}

/// The renderer of `design` for `scene`, kernels built in.
pub fn renderer(
    ctx: &GlContext,
    scene: &Scene,
    design: &gpgpu_rt::design::Design,
) -> Box<dyn gpgpu_rt::pipeline::Renderer> {
    design
        .renderer(ctx.gl.clone(), &ctx.info, scene, &ShaderSource::default())
        .expect("a renderer")
}

/// A small deterministic generator (xorshift): the same random cases every run.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A float in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A lattice box's corners as integers (the N-tree's shaft tests take them so).
pub fn lattice(b: &gpgpu_rt::pipeline::klee2016::ntree::Aabb) -> ([i32; 3], [i32; 3]) {
    (b.lo.map(|v| v as i32), b.hi.map(|v| v as i32))
}

/// `n` point lights in a ring around the scene, of different heights and colours.
pub fn ring_of_lights(scene: &mut Scene, n: usize) {
    scene.lights = (0..n)
        .map(|i| {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            Light {
                position: Vec3::new(3.0 * a.cos(), 3.0 + (i % 3) as f32, 3.0 * a.sin()),
                color: Vec3::splat(0.9 / n as f32 * 2.0)
                    * Vec3::new(1.0, 0.6 + 0.4 * (i % 2) as f32, 0.8),
            }
        })
        .collect();
}
