//! OpenGL plumbing: the headless context, program loading, and small resource helpers.

pub mod context;
pub mod program;
pub mod resources;

pub use context::{check_error, Gl, GlContext, GlInfo};
pub use program::{compile_program, Defines, ShaderSource};
