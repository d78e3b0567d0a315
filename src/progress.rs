//! Progress of a build that can take long (an N-tree's line spaces at depth 4, a stream grid
//! of 512³ cells): a bar on stderr, drawn only when stderr is a terminal, so that a long build
//! is never silent and a pipe or a log gets no control characters.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar over `total` steps of `what`, or nothing when the work is small (`total` below
/// `worth_showing`).
pub struct Progress(Option<ProgressBar>);

impl Progress {
    pub fn new(what: &str, total: u64, worth_showing: u64) -> Progress {
        if total < worth_showing {
            return Progress(None);
        }
        let pb = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        pb.set_style(
            ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len}, {elapsed} (ETA {eta})")
                .expect("a valid template")
                .progress_chars("=> "),
        );
        pb.set_prefix(what.to_string());
        Progress(Some(pb))
    }

    /// `n` more steps done (callable from several threads).
    pub fn inc(&self, n: u64) {
        if let Some(pb) = &self.0 {
            pb.inc(n);
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(pb) = &self.0 {
            pb.finish_and_clear();
        }
    }
}

/// What the program is doing now, for the progress line of a long `render` or `view` load
/// ([`Ticker`]): the stage the command set ([`stage`]) and the kernel last dispatched with its
/// tile ([`kernel`], from every per-pixel dispatch).
#[derive(Debug, Clone, Default)]
struct Activity {
    stage: String,
    pass: Option<(u32, u32)>,
    kernel: Option<(&'static str, usize, usize)>,
}

static ACTIVITY: std::sync::Mutex<Activity> = std::sync::Mutex::new(Activity {
    stage: String::new(),
    pass: None,
    kernel: None,
});

fn activity() -> std::sync::MutexGuard<'static, Activity> {
    ACTIVITY.lock().unwrap_or_else(|e| e.into_inner())
}

/// The command's stage ("loading the scene", "frame 2 of 5"); the kernel shown is cleared.
pub fn stage(what: impl Into<String>) {
    let mut a = activity();
    a.stage = what.into();
    a.pass = None;
    a.kernel = None;
}

/// Pass `pass` (from 0: the primary rays) of `passes` within the frame (Müller 2015's Fig. 8:
/// a pass per reflection depth).
pub fn pass(pass: u32, passes: u32) {
    activity().pass = Some((pass + 1, passes));
}

/// The kernel `name` was dispatched over tile `tile` (from 1) of `tiles`.
pub fn kernel(name: &'static str, tile: usize, tiles: usize) {
    activity().kernel = Some((name, tile, tiles));
}

/// The progress line's text now: "frame 1 of 1, pass 2 of 2: intersect1, tile 3 of 16".
fn describe() -> String {
    let a = activity().clone();
    let stage = match a.pass {
        Some((i, n)) if n > 1 => format!("{}, pass {i} of {n}", a.stage),
        _ => a.stage,
    };
    match a.kernel {
        Some((k, _, 1)) => format!("{stage}: {k}"),
        Some((k, i, n)) => format!("{stage}: {k}, tile {i} of {n}"),
        None => stage,
    }
}

/// How long a command runs silently before its progress line appears.
pub const QUIET_FOR: std::time::Duration = std::time::Duration::from_secs(2);

/// A spinner on stderr with the elapsed time and [`describe`]'s text, drawn from a thread of
/// its own once the command has run for [`QUIET_FOR`], while it lives; never where stderr is not
/// a terminal (indicatif's stderr target hides itself there) or when `quiet`.
pub struct Ticker {
    done: Option<std::sync::mpsc::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Ticker {
    pub fn start(quiet: bool) -> Ticker {
        use std::io::IsTerminal as _;
        if quiet || !std::io::stderr().is_terminal() {
            return Ticker {
                done: None,
                thread: None,
            };
        }
        let (tx, rx) = std::sync::mpsc::channel::<()>();
        let start = std::time::Instant::now();
        let thread = std::thread::Builder::new()
            .name("progress".into())
            .spawn(move || {
                // quiet for the first seconds: a short render prints only its summary
                if rx.recv_timeout(QUIET_FOR).is_ok() {
                    return;
                }
                let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
                pb.set_style(
                    ProgressStyle::with_template("{spinner} {prefix} {msg}")
                        .expect("a valid template"),
                );
                loop {
                    pb.set_prefix(format!("{:.0} s", start.elapsed().as_secs_f64()));
                    pb.set_message(describe());
                    pb.tick();
                    match rx.recv_timeout(std::time::Duration::from_millis(200)) {
                        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
                        _ => break,
                    }
                }
                pb.finish_and_clear();
            })
            .ok();
        Ticker {
            done: Some(tx),
            thread,
        }
    }
}

impl Drop for Ticker {
    fn drop(&mut self) {
        drop(self.done.take());
        if let Some(t) = self.thread.take() {
            let _ = t.join(); // the line is cleared before the command prints its summary
        }
    }
}
