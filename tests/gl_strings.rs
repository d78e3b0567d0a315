//! GL strings are whole when many threads query them at once (`gl::context::gl_string`): on
//! zink (Mesa 22.3) GL_RENDERER is formatted into one static buffer at every query, and
//! unserialised queries from four threads read "" or "\0ink (…" thousands of times in 800,000
//! — the cause of contexts refused as "not zink" now and then. The only test of its file: it
//! chooses the driver for the whole process (zink where lavapipe is installed).

use gpgpu_rt::gl::context::gl_string;
use gpgpu_rt::gl::GlContext;

#[test]
fn gl_strings_queried_from_many_threads_are_whole() {
    let zink = std::fs::read_dir("/usr/share/vulkan/icd.d").is_ok_and(|d| {
        d.flatten()
            .any(|e| e.file_name().to_string_lossy().starts_with("lvp_icd"))
    });
    if zink && std::env::var_os("GPGPU_RT_DRIVER").is_none() {
        // SAFETY (of the process' environment): set before any thread of this test starts and
        // before any context is made; the only test of its file.
        std::env::set_var("GPGPU_RT_DRIVER", "zink");
    }
    let start = std::sync::Arc::new(std::sync::Barrier::new(4));
    let threads: Vec<_> = (0..4)
        .map(|_| {
            let start = start.clone();
            std::thread::spawn(move || {
                let ctx = GlContext::headless(None).expect("a context");
                let want = ctx.info.renderer.clone();
                assert!(!want.is_empty() && !want.starts_with('\0'), "{want:?}");
                start.wait();
                let torn = (0..50_000)
                    .map(|_| gl_string(&ctx.gl, glow::RENDERER))
                    .filter(|r| *r != want)
                    .count();
                (want, torn)
            })
        })
        .collect();
    for t in threads {
        let (renderer, torn) = t.join().expect("a thread");
        eprintln!("{renderer}: {torn} torn");
        assert_eq!(torn, 0, "{renderer}: torn GL_RENDERER strings");
    }
}
