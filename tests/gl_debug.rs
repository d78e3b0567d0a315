//! `GPGPU_RT_GL_DEBUG=1`: a debug context whose messages reach the log. Its own test binary,
//! since the switch is an environment variable of the process.

use glow::HasContext;
use gpgpu_rt::gl::context::gl_debug_errors;
use gpgpu_rt::gl::GlContext;

#[test]
fn gl_debug_output_reports_errors() {
    std::env::set_var("GPGPU_RT_GL_DEBUG", "1");
    let ctx = GlContext::headless(None).expect("a GL 4.5 context");
    assert_eq!(
        gl_debug_errors(),
        0,
        "a fresh context has reported no error"
    );
    // SAFETY: a deliberately invalid call (GL_INVALID_ENUM), nothing is bound or changed.
    unsafe { ctx.gl.bind_buffer(0x1234, None) };
    // synchronous output: the message arrives during the call
    assert!(gl_debug_errors() >= 1, "the invalid enum was not reported");
    // and glGetError still sees it: the debug output does not swallow errors
    // SAFETY: a plain query on the current context.
    assert_eq!(unsafe { ctx.gl.get_error() }, glow::INVALID_ENUM);
}
