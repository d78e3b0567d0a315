//! Interrupts leave nothing behind (issue 33, class 4): every temporary file and folder a
//! [`super::Staging`] makes is registered here while it exists, and SIGINT, SIGTERM or SIGHUP
//! remove them before the process ends (exit status 128 + the signal's number, as a shell
//! reports a killed command). The old outputs stay as they were: they are replaced only by
//! renames, and a commit in progress holds the registry, so a signal lands before its first
//! rename or after its last.
//!
//! The signal is received by a thread of its own (signal-hook's iterator), not in a handler:
//! removing files takes locks and allocations, which a handler may not.

use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard, Once};

/// What a staging made and has not yet committed or removed.
pub struct Registry {
    next: u64,
    entries: Vec<(u64, PathBuf, bool)>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    next: 0,
    entries: Vec::new(),
});

/// The registry, held: a staging makes and registers a file under it, and commits under it.
pub fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
}

impl Registry {
    /// Register `path` (a folder when `dir`); the id forgets it again.
    pub fn add(&mut self, path: PathBuf, dir: bool) -> u64 {
        self.next += 1;
        self.entries.push((self.next, path, dir));
        self.next
    }

    pub fn forget(&mut self, ids: &[u64]) {
        self.entries.retain(|(id, _, _)| !ids.contains(id));
    }

    /// Remove every registered file, then the folders, innermost (latest) first.
    fn remove_all(&mut self) {
        for (_, p, dir) in &self.entries {
            if !dir {
                let _ = std::fs::remove_file(p);
            }
        }
        for (_, p, dir) in self.entries.iter().rev() {
            if *dir {
                let _ = std::fs::remove_dir(p);
            }
        }
        self.entries.clear();
    }
}

/// Start the thread that cleans up on SIGINT, SIGTERM and SIGHUP (once per process; the
/// command-line program calls it first thing).
pub fn install() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let mut signals = match signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
            Ok(s) => s,
            Err(e) => {
                log::warn!("interrupts will not clean up staged outputs: {e}");
                return;
            }
        };
        let spawned = std::thread::Builder::new()
            .name("interrupt".into())
            .spawn(move || {
                if let Some(sig) = signals.forever().next() {
                    let mut r = registry();
                    let n = r.entries.len();
                    r.remove_all();
                    let name = signal_hook::low_level::signal_name(sig).unwrap_or("a signal");
                    // (a write that fails must not keep the process from ending)
                    let _ =
                        crate::errln!("interrupted by {name}: {n} unfinished output(s) removed");
                    // _exit: no destructors or atexit handlers while other threads may be
                    // inside the GL driver; the registry stays held until the end
                    unsafe { libc::_exit(128 + sig) };
                }
            });
        if let Err(e) = spawned {
            log::warn!("interrupts will not clean up staged outputs: {e}");
        }
    });
}
