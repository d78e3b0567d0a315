//! Every kernel of every design compiles without a compiler warning on Mesa (a warning such as
//! "`x` used uninitialized" can hide a real bug), and its assembled source is valid GLSL 4.50
//! for Khronos' reference compiler, glslangValidator (stricter than Mesa in places, so a
//! kernel that passes is more likely to compile on other drivers too). Its own test binary:
//! the driver's shader cache is switched off for the process, so that every stage is really
//! compiled and its log is seen, and the assembled sources are dumped (GPGPU_RT_DUMP_GLSL).

mod common;

use gpgpu_rt::accel::{BvhLevels, BvhPasses};
use gpgpu_rt::design::{accelerators, Design};
use gpgpu_rt::gl::program::compiler_messages;
use gpgpu_rt::gl::{compile_program, Defines, GlContext, ShaderSource};
use gpgpu_rt::pipeline::klee2016::{LinespaceBuild, SoftShadowOptions, SoftShadowRenderer};
use gpgpu_rt::pipeline::mueller2015::{RayTracer, RenderOptions, ShadowFlags};
use gpgpu_rt::pipeline::stream::StreamOptions;
use gpgpu_rt::pipeline::wagner2018::WagnerOptions;
use gpgpu_rt::pipeline::Renderer;
use gpgpu_rt::scene::{Scene, ShadowMode};

#[test]
fn every_kernel_compiles_without_warnings() {
    std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true");
    let dump = tempfile::tempdir().unwrap();
    std::env::set_var("GPGPU_RT_DUMP_GLSL", dump.path());
    let ctx = common::context();
    let shaders = ShaderSource::default();

    // the ray tracer with every accelerator of the registry and each of its variants (the exact
    // grid's distance pass, proximity.comp; the SAH BVH's four kernels beside its fused pass),
    // each accelerator's first in both shadow-flag layouts
    let scene = common::load("teapot1.toml");
    for entry in accelerators() {
        for (i, (_, accel)) in entry.variants.iter().enumerate() {
            let layouts: &[ShadowFlags] = match i {
                0 => &[ShadowFlags::Bits, ShadowFlags::Rgba],
                _ => &[ShadowFlags::Bits],
            };
            for &shadow_flags in layouts {
                let opts = RenderOptions {
                    shadow_flags,
                    ..common::options_with(accel.with_grid_resolution(8), 8, 8, 1)
                };
                let mut t = RayTracer::new(ctx.gl.clone(), &ctx.info, &scene, &shaders, opts)
                    .expect("tracer");
                t.render(&scene.camera).expect("frame");
            }
        }
    }

    // the SAH BVH's two levels (BVH_INSTANCES), in the fused pass and the four kernels: with
    // several objects, and with one (its walk without the instance loop)
    let cow = common::load("cow.toml");
    for passes in [BvhPasses::FourKernels, BvhPasses::Fused] {
        for scene in [&scene, &cow] {
            let opts = common::options_with(common::bvh(passes, BvhLevels::Two), 8, 8, 1);
            let mut t =
                RayTracer::new(ctx.gl.clone(), &ctx.info, scene, &shaders, opts).expect("tracer");
            t.render(&scene.camera).expect("frame");
        }
    }

    // Wagner 2018's kernel
    let opts = WagnerOptions {
        width: 8,
        height: 8,
        tile: 0,
        aovs: true,
    };
    one_frame(&ctx, &scene, Design::Wagner2018(opts));

    // the streaming tracer: its six fragment programs, with a reflection bounce
    let opts = StreamOptions {
        width: 8,
        height: 8,
        refl_depth: 1,
        dims: None,
        proximity_clouds: true,
        steps_per_call: 16,
        max_calls: 10_000,
        naive_shadows: true,
        no_mask: true,
        single_sided: false,
        aovs: true,
    };
    one_frame(&ctx, &scene, Design::Stream(opts));

    // the soft shadows: G-buffer, the six shadow modes, the quad; the line spaces built on the
    // GPU once (glsl/klee2016/linespace_build.comp)
    let area = common::load("bunny_area.toml");
    for mode in [
        ShadowMode::Exact,
        ShadowMode::Linespace,
        ShadowMode::LinespaceFast,
        ShadowMode::LinespaceDda,
        ShadowMode::Variant1,
        ShadowMode::Variant2,
    ] {
        let opts = SoftShadowOptions {
            mode,
            samples_u: 2,
            samples_v: 2,
            ntree_n: 10,
            ntree_depth: 3,
            shading: Default::default(),
            linespace_build: if mode == ShadowMode::Linespace {
                LinespaceBuild::Gpu
            } else {
                LinespaceBuild::Cpu
            },
            width: 8,
            height: 8,
            tile: 0,
        };
        let mut r = SoftShadowRenderer::new(ctx.gl.clone(), &ctx.info, &area, &shaders, opts)
            .expect("soft-shadow renderer");
        r.render(&area.camera).expect("frame");
    }

    // the viewer's screen-filling quad
    compile_program(
        &ctx.gl,
        &shaders,
        &[
            (glow::VERTEX_SHADER, "common/screen_quad.vert"),
            (glow::FRAGMENT_SHADER, "common/screen_quad.frag"),
        ],
        &Defines::new(),
    )
    .expect("screen quad");

    assert_eq!(
        compiler_messages(),
        0,
        "kernels compiled with warnings (run with RUST_LOG=warn to see them)"
    );
    validate_with_glslang(dump.path());
}

/// A frame of `design` on `scene`, kernels built in: every kernel it dispatches compiled.
fn one_frame(ctx: &GlContext, scene: &Scene, design: Design) {
    let mut r = common::renderer(ctx, scene, &design);
    r.render(&scene.camera).expect("frame");
}

/// Every dumped stage through `glslangValidator` (Debian: glslang-tools; `.ci/run` installs
/// it). Skipped with a message where it is missing, unless `CI` is set.
fn validate_with_glslang(dir: &std::path::Path) {
    let in_ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && v != "false");
    if std::process::Command::new("glslangValidator")
        .arg("--version")
        .output()
        .is_err()
    {
        assert!(
            !in_ci,
            "glslangValidator is missing, but CI is set (.ci/run installs glslang-tools)"
        );
        eprintln!("SKIPPED: glslangValidator not found (Debian: apt-get install glslang-tools)");
        return;
    }
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    // every kernel file of glsl/ was compiled at least once (dumped as `folder.file.comp`)
    for (name, _) in gpgpu_rt::gl::program::EMBEDDED {
        if is_kernel(name) {
            assert!(
                dir.join(name.replace('/', ".")).exists(),
                "{name} was not compiled by the test"
            );
        }
    }
    let mut failures = Vec::new();
    for f in &files {
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        let stage = ["comp", "vert", "frag"]
            .into_iter()
            .find(|s| name.contains(&format!(".{s}")))
            .unwrap_or_else(|| panic!("unknown stage of {name}"));
        let out = std::process::Command::new("glslangValidator")
            .args(["-S", stage])
            .arg(f)
            .output()
            .unwrap();
        if !out.status.success() {
            failures.push(format!(
                "{name}:\n{}",
                String::from_utf8_lossy(&out.stdout).trim()
            ));
        }
    }
    assert!(files.len() >= 20, "only {} stages dumped", files.len());
    eprintln!(
        "glslangValidator: {} assembled stages, {} rejected",
        files.len(),
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "glslangValidator:\n{}",
        failures.join("\n")
    );
}

fn is_kernel(n: &str) -> bool {
    n.ends_with(".comp") || n.ends_with(".vert") || n.ends_with(".frag")
}
