//! Every kernel of every design compiles without a compiler warning on Mesa (a warning such as
//! "`x` used uninitialized" can hide a real bug). Its own test binary: the driver's shader
//! cache is switched off for the process, so that every stage is really compiled and its log
//! is seen.

mod common;

use gpgpu_rt::gl::program::compiler_messages;
use gpgpu_rt::gl::{compile_program, Defines, ShaderSource};
use gpgpu_rt::tracer::linespace::{ShadowMode, SoftShadowOptions, SoftShadowRenderer};
use gpgpu_rt::tracer::{self, GridOptions, GridVariant, ShadowFlags, TracerKind};

#[test]
fn every_kernel_compiles_without_warnings() {
    std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true");
    let ctx = common::context();
    let shaders = ShaderSource::default();

    // the ray tracers: base (both shadow-flag layouts), grid (both variants)
    let scene = common::load("teapot1.toml");
    let mut configs = Vec::new();
    for flags in [ShadowFlags::Bits, ShadowFlags::Rgba] {
        configs.push((TracerKind::Base, GridOptions::default(), flags));
    }
    for variant in [GridVariant::Thesis, GridVariant::Exact] {
        let grid = GridOptions {
            variant,
            resolution: Some(8),
            ..GridOptions::default()
        };
        configs.push((TracerKind::Grid, grid, ShadowFlags::Bits));
    }
    for (kind, grid, shadow_flags) in configs {
        let opts = gpgpu_rt::tracer::RenderOptions {
            grid,
            shadow_flags,
            ..common::options(8, 8, 1)
        };
        let mut t = tracer::create(kind, ctx.gl.clone(), &ctx.info, &scene, &shaders, opts)
            .expect("tracer");
        t.render(&scene.camera).expect("frame");
    }

    // the soft shadows: G-buffer, the three shadow modes, the quad
    let area = common::load("bunny_area.toml");
    for mode in [
        ShadowMode::Exact,
        ShadowMode::Linespace,
        ShadowMode::LinespaceDda,
    ] {
        let opts = SoftShadowOptions {
            mode,
            samples_u: 2,
            samples_v: 2,
            ntree_n: 10,
            ntree_depth: 3,
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
            (glow::VERTEX_SHADER, "screen_quad.vert"),
            (glow::FRAGMENT_SHADER, "screen_quad.frag"),
        ],
        &Defines::new(),
    )
    .expect("screen quad");

    assert_eq!(
        compiler_messages(),
        0,
        "kernels compiled with warnings (run with RUST_LOG=warn to see them)"
    );
}
