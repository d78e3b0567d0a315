//! The barrier bookkeeping of `gl::sync`: a pass that ran shaders leaves every bit pending; an
//! access issues the bits of its kind that are pending, once — a second access of the same kind
//! issues none; the bits of other kinds stay pending for their accesses. (Whether a bit is
//! missing where it is needed no run here can show: llvmpipe's and lavapipe's barriers finish
//! all work. `scripts/gpu-check.sh` compares every bit against these on a GPU.)

mod common;

use common::*;
use gpgpu_rt::gl::sync;
use gpgpu_rt::pipeline::Renderer;

#[test]
fn a_pass_leaves_every_bit_pending_and_an_access_takes_only_its_own() {
    let ctx = context();
    let scene = load("cow.toml");
    let mut opts = options(16, 16, 0);
    opts.accel = BVH_FOUR_KERNELS;
    let mut t = ray_tracer(&ctx, &scene, opts);
    // a frame ends with its counters and images read back: those bits were issued for them
    t.render(&scene.camera).expect("frame");
    let after_frame = sync::pending(&ctx.gl);
    assert_eq!(
        after_frame & glow::BUFFER_UPDATE_BARRIER_BIT,
        0,
        "{after_frame:#x}"
    );
    assert_eq!(
        after_frame & glow::TEXTURE_UPDATE_BARRIER_BIT,
        0,
        "{after_frame:#x}"
    );
    // the next pass needs the shader bits: still pending after the read-backs
    assert_eq!(after_frame & sync::SHADER, sync::SHADER, "{after_frame:#x}");
    sync::after_pass(&ctx.gl);
    assert_eq!(sync::pending(&ctx.gl), sync::ALL);
    sync::before(&ctx.gl, glow::BUFFER_UPDATE_BARRIER_BIT);
    assert_eq!(
        sync::pending(&ctx.gl),
        sync::ALL & !glow::BUFFER_UPDATE_BARRIER_BIT
    );
    sync::before(&ctx.gl, sync::SHADER);
    let left = sync::ALL & !glow::BUFFER_UPDATE_BARRIER_BIT & !sync::SHADER;
    assert_eq!(sync::pending(&ctx.gl), left);
}
