//! A GL driver that crashes ends the program with a message naming the kernel, exit 1 — not a
//! bare segmentation fault.
//!
//! Compile and link errors are caught where the program is made (`compile_program` checks both
//! statuses). Some drivers compile later: zink builds a Vulkan pipeline at a program's first
//! dispatch or draw, and where that fails (Mesa 22.3's lavapipe refuses some kernels,
//! `docs/drivers.md`) it prints `vkCreateComputePipelines failed` and then dereferences the
//! missing pipeline. No GL query reports that failure, so the last line of defence is the
//! signal: every program put in use records a message naming it ([`note_program`]), and the
//! handler that [`install`] sets for SIGSEGV, SIGBUS, SIGILL and SIGFPE writes that message after
//! the driver's own and exits with status 1. A fault before any program was in use is not the
//! driver's doing as far as we can tell: the handler then restores the default action and lets
//! the signal end the process as it would have.

use std::collections::BTreeMap;
use std::ffi::{c_int, CStr, CString};
use std::sync::atomic::{AtomicPtr, Ordering};
use std::sync::{Mutex, Once};

/// The message of the program in use, NUL-terminated and never freed (null: none yet).
static LAST_PROGRAM: AtomicPtr<u8> = AtomicPtr::new(std::ptr::null_mut());

/// One leaked message per distinct text, so that a bench that makes renderers again and again
/// leaks each message once.
static MESSAGES: Mutex<BTreeMap<String, &'static CStr>> = Mutex::new(BTreeMap::new());

/// The message the handler writes when the driver faults while or after `kernel` (the name its
/// GPU time is kept under), assembled from `files`, was the program in use on `renderer`.
pub fn message(kernel: &str, files: &[&str], renderer: &str) -> String {
    format!(
        "error: the GL driver ({renderer}) crashed; the program in use was kernel `{kernel}` \
         ({}). The driver's own message, if it printed one, is above. The program compiled \
         and linked; a driver that builds its pipelines late (zink) may still refuse it when \
         it first runs. Try another driver (docs/drivers.md) or report it with the \
         command line.\n",
        files.join(" + ")
    )
}

/// `text` (see [`message`]) as the handler writes it: kept for the life of the process.
pub fn keep(text: &str) -> &'static CStr {
    let mut map = MESSAGES.lock().unwrap_or_else(|e| e.into_inner());
    map.entry(text.to_string()).or_insert_with(|| {
        let owned = CString::new(text.replace('\0', " ")).expect("NULs replaced");
        Box::leak(owned.into_boxed_c_str())
    })
}

/// Record `note` (from [`keep`]) as the message of the program in use.
pub fn note_program(note: &'static CStr) {
    LAST_PROGRAM.store(note.as_ptr() as *mut u8, Ordering::Release);
}

const SIGNALS: [c_int; 4] = [libc::SIGSEGV, libc::SIGBUS, libc::SIGILL, libc::SIGFPE];

/// Set the handler for the fatal signals a driver fault raises (once per process; the
/// application calls it at start).
pub fn install() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        for sig in SIGNALS {
            // SAFETY: a sigaction with a handler that calls only async-signal-safe functions
            // (write, signal, raise, _exit); SA_ONSTACK uses the alternate stack Rust's runtime
            // sets up, so a fault on an exhausted stack can still be handled.
            unsafe {
                let mut action: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = on_fatal_signal as *const () as libc::sighandler_t;
                action.sa_flags = libc::SA_ONSTACK;
                libc::sigemptyset(&mut action.sa_mask);
                libc::sigaction(sig, &action, std::ptr::null_mut());
            }
        }
    });
}

extern "C" fn on_fatal_signal(sig: c_int) {
    let text = LAST_PROGRAM.load(Ordering::Acquire);
    // SAFETY: only async-signal-safe calls; `text` is null or a leaked NUL-terminated string.
    unsafe {
        if text.is_null() {
            libc::signal(sig, libc::SIG_DFL);
            libc::raise(sig);
            return;
        }
        let len = libc::strlen(text as *const libc::c_char);
        libc::write(2, b"\n".as_ptr() as *const libc::c_void, 1);
        libc::write(2, text as *const libc::c_void, len);
        libc::_exit(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_kernel_and_are_kept_once() {
        let m = message(
            "shadow_exact",
            &["glsl/klee2016/linespace_shadow.comp"],
            "zink",
        );
        assert!(m.contains("`shadow_exact`") && m.contains("linespace_shadow.comp"));
        assert!(m.contains("(zink)") && m.ends_with('\n'));
        note_program(keep(&m));
        let first = LAST_PROGRAM.load(Ordering::Acquire);
        note_program(keep(&message(
            "intersect1",
            &["glsl/bvh/intersect1.comp"],
            "zink",
        )));
        assert_ne!(LAST_PROGRAM.load(Ordering::Acquire), first);
        note_program(keep(&m));
        assert_eq!(
            LAST_PROGRAM.load(Ordering::Acquire),
            first,
            "kept once, reused"
        );
    }
}
