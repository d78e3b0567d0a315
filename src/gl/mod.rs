//! OpenGL plumbing: the headless context, program loading, and small resource helpers.

pub mod barrier_bits;
pub mod context;
pub mod crash;
pub mod defines;
pub mod driver;
pub mod kernel;
pub mod profile;
pub mod program;
pub mod resources;
pub mod slots;
pub mod sync;

pub use context::{
    alloc_error, check_alloc, check_error, gl_error_name, ComputeLimits, Gl, GlContext, GlInfo,
};
pub use defines::Defines;
pub use kernel::{Kernel, PixelGrid};
pub use profile::{Profile, ProfileChoice, ProfileName, PROFILE_ENV};
pub use program::{compile_program, ShaderSource, GLSL_DIR_ENV};
