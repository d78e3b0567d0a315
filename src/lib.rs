//! gpgpu-rt: GPU ray tracing in OpenGL 4.5 compute shaders, after Müller 2015 (the base
//! tracer and the per-frame uniform grid) and related designs. See the README.

pub mod accel;
pub mod design;
pub mod frame;
pub mod gl;
pub mod limits;
pub mod output;
pub mod pipeline;
pub mod progress;
pub mod reference;
pub mod scene;

/// The version and the commit the binary was built from (`-dirty` where tracked files had
/// changes; `build.rs`): `gpgpu-rt --version`, and every report and statistics file.
pub const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("GPGPU_RT_COMMIT"),
    ")"
);
