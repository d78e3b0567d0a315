//! Standard output and standard error as fallible writes.
//!
//! `println!` and `eprintln!` panic when the write fails: a reader that closed the pipe
//! (`gpgpu-rt info --json | head -1`) or a full disk (`> /dev/full`) ended the program with
//! exit status 101 and a backtrace. Every line a command prints goes through [`out`] and
//! [`err`] instead (the [`outln!`](crate::outln) and [`errln!`](crate::errln) macros), which
//! return the error with the stream named, so it travels up like any other error: staged
//! outputs are removed on the way, and the program's `main` ends with [`exit_for`]:
//!
//! - a closed pipe ends the program quietly, killed by SIGPIPE as other Unix tools are (the
//!   shell reports 141);
//! - any other write error is a message and exit status 1 (the message itself is dropped when
//!   standard error is what failed).

use std::fmt;
use std::io::{self, Write};
use std::process::ExitCode;

/// Which stream a failed write was to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    Stdout,
    Stderr,
}

/// A failed write to standard output or standard error.
#[derive(Debug, thiserror::Error)]
#[error("writing to standard {}", .stream.name())]
pub struct ConsoleError {
    pub stream: Stream,
    #[source]
    pub source: io::Error,
}

impl Stream {
    fn name(self) -> &'static str {
        match self {
            Stream::Stdout => "output",
            Stream::Stderr => "error",
        }
    }
}

/// Write `args` and a newline to standard output, whole (one lock for the line).
pub fn out(args: fmt::Arguments) -> Result<(), ConsoleError> {
    let mut s = io::stdout().lock();
    s.write_fmt(args)
        .and_then(|()| s.write_all(b"\n"))
        .and_then(|()| s.flush())
        .map_err(|source| ConsoleError {
            stream: Stream::Stdout,
            source,
        })
}

/// Write `args` and a newline to standard error.
pub fn err(args: fmt::Arguments) -> Result<(), ConsoleError> {
    let mut s = io::stderr().lock();
    s.write_fmt(args)
        .and_then(|()| s.write_all(b"\n"))
        .map_err(|source| ConsoleError {
            stream: Stream::Stderr,
            source,
        })
}

/// A line to standard output; `?` passes a failed write up.
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => { $crate::output::console::out(format_args!($($arg)*)) };
}

/// A line to standard error; `?` passes a failed write up.
#[macro_export]
macro_rules! errln {
    ($($arg:tt)*) => { $crate::output::console::err(format_args!($($arg)*)) };
}

/// The exit of a command that failed with `e`: quiet on a closed pipe (SIGPIPE, as other Unix
/// tools), else `error: …` on standard error (when it can still be written) and status 1.
pub fn exit_for(e: &anyhow::Error) -> ExitCode {
    let console = e.chain().find_map(|c| c.downcast_ref::<ConsoleError>());
    if let Some(c) = console {
        if c.source.kind() == io::ErrorKind::BrokenPipe {
            die_of_sigpipe();
        }
    }
    let _ = err(format_args!("error: {e:#}"));
    ExitCode::FAILURE
}

/// End the process as SIGPIPE's default action does. Rust ignores SIGPIPE so that writes
/// return EPIPE; the default is restored only here, after everything was cleaned up.
fn die_of_sigpipe() -> ! {
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        libc::raise(libc::SIGPIPE);
    }
    std::process::exit(128 + 13)
}
