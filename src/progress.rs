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
