//! The viewer's frame bookkeeping: whether to draw the next frame ([`Picture`]), the frames
//! counted toward `--frames` ([`FrameCount`]), and frames per second and title refreshes
//! ([`Clock`]).

use std::time::{Duration, Instant};

use super::renderer::Stats;

/// How often the frames per second are measured.
const FPS_INTERVAL: Duration = Duration::from_millis(500);
/// How often the title is refreshed while rendering.
const TITLE_INTERVAL: Duration = Duration::from_millis(250);

/// Whether to draw the next frame, and what the last one gave.
pub struct Picture {
    /// Render continuously (not paused).
    pub continuous: bool,
    /// Something changed: render the next frame even when paused.
    pub dirty: bool,
    /// The last render failed: do not retry until something changes.
    pub render_failed: bool,
    /// A frame has been rendered into the current renderer's output texture.
    pub has_frame: bool,
    pub last_stats: Option<Stats>,
}

impl Picture {
    pub fn new() -> Picture {
        Picture {
            continuous: true,
            dirty: true,
            render_failed: false,
            has_frame: false,
            last_stats: None,
        }
    }

    /// Render the next frame?
    pub fn wanted(&self) -> bool {
        (self.continuous || self.dirty) && !self.render_failed
    }

    /// A new renderer or new options: the next frame is rendered, the old statistics go.
    pub fn reset(&mut self) {
        self.has_frame = false;
        self.last_stats = None;
        self.render_failed = false;
        self.dirty = true;
    }

    /// The camera moved: render again (also after a failed frame).
    pub fn moved(&mut self) {
        self.dirty = true;
        self.render_failed = false;
    }

    /// Space: pause or resume continuous rendering.
    pub fn toggle_pause(&mut self) {
        self.continuous = !self.continuous;
        self.dirty = true;
    }
}

/// The frames rendered, and those counted toward `--frames` (or the `--screenshot`'s one).
pub struct FrameCount {
    /// Frames rendered (all).
    pub rendered: u64,
    /// Frames counted toward the target.
    counted: u64,
    /// `--wait-reload`: frames count only after a successful reload.
    counting: bool,
    /// Frames to count before exiting (`--frames`, with `--screenshot` by default 1); `None`:
    /// run until the window closes.
    target: Option<u64>,
    /// The target is reached: nothing more is drawn while the event loop winds down.
    pub finished: bool,
}

impl FrameCount {
    pub fn new(frames: Option<u64>, screenshot: bool, wait_reload: bool) -> FrameCount {
        FrameCount {
            rendered: 0,
            counted: 0,
            counting: !wait_reload,
            target: (frames.is_some() || screenshot).then(|| frames.unwrap_or(1)),
            finished: false,
        }
    }

    /// A frame was rendered: its number.
    pub fn add(&mut self) -> u64 {
        self.rendered += 1;
        if self.counting {
            self.counted += 1;
        }
        self.rendered
    }

    /// A reload succeeded: from now on frames count (`--wait-reload`).
    pub fn start_counting(&mut self) {
        self.counting = true;
    }

    /// Frames are counted toward an exit (`--frames` or `--screenshot`).
    pub fn has_target(&self) -> bool {
        self.target.is_some()
    }

    /// The target is reached.
    pub fn done(&self) -> bool {
        self.target.is_some_and(|t| self.counted >= t)
    }
}

/// Frames per second, and when the title was last refreshed.
pub struct Clock {
    frames: u32,
    since: Instant,
    fps: Option<f64>,
    title_at: Instant,
}

impl Clock {
    pub fn new() -> Clock {
        Clock {
            frames: 0,
            since: Instant::now(),
            fps: None,
            title_at: Instant::now(),
        }
    }

    /// A frame was rendered.
    pub fn frame(&mut self) {
        self.frames += 1;
    }

    /// After a frame is shown: measure the frames per second every half second.
    pub fn tick(&mut self) {
        let elapsed = self.since.elapsed();
        if elapsed >= FPS_INTERVAL {
            self.fps = Some(self.frames as f64 / elapsed.as_secs_f64());
            self.frames = 0;
            self.since = Instant::now();
        }
    }

    pub fn fps(&self) -> Option<f64> {
        self.fps
    }

    /// Refresh the title now? Always with `now`, else at most every quarter second.
    pub fn title_due(&mut self, now: bool) -> bool {
        if !now && self.title_at.elapsed() < TITLE_INTERVAL {
            return false;
        }
        self.title_at = Instant::now();
        true
    }
}
