//! Minimal reproductions of the driver faults `docs/drivers.md` describes, each a compute
//! kernel of a few lines whose result the GL specification fixes. Run it on each driver:
//!
//! ```sh
//! cargo run --release --example driver_repro                  # the first EGL device (llvmpipe here)
//! mkdir -m 700 -p /tmp/xdg; XDG_RUNTIME_DIR=/tmp/xdg MESA_LOADER_DRIVER_OVERRIDE=zink \
//!   GALLIUM_DRIVER=zink LIBGL_ALWAYS_SOFTWARE=1 cargo run --release --example driver_repro
//! ```
//!
//! Each line says what the specification requires and what the driver gave. The kernels do
//! not use the project's GLSL: what fails here fails in any program.

use anyhow::{anyhow, bail, Result};
use glow::HasContext;
use gpgpu_rt::gl::{Gl, GlContext};

/// Compile `source`, bind a storage buffer of `bytes` bytes at each of `bindings` and a
/// 64-byte result buffer at binding 7, dispatch one work group and read the result back.
fn run(gl: &Gl, source: &str, bindings: &[(u32, usize)]) -> Result<[i32; 4]> {
    // SAFETY: objects of our own on the current context, deleted before returning.
    unsafe {
        let shader = gl
            .create_shader(glow::COMPUTE_SHADER)
            .map_err(|e| anyhow!(e))?;
        gl.shader_source(shader, source);
        gl.compile_shader(shader);
        if !gl.get_shader_compile_status(shader) {
            bail!("compile error: {}", gl.get_shader_info_log(shader));
        }
        let program = gl.create_program().map_err(|e| anyhow!(e))?;
        gl.attach_shader(program, shader);
        gl.link_program(program);
        if !gl.get_program_link_status(program) {
            bail!("link error: {}", gl.get_program_info_log(program));
        }
        let mut buffers = Vec::new();
        for &(binding, bytes) in bindings.iter().chain(&[(7, 64)]) {
            let b = gl.create_buffer().map_err(|e| anyhow!(e))?;
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(b));
            let zeros = vec![0u8; bytes];
            gl.buffer_storage(glow::SHADER_STORAGE_BUFFER, bytes as i32, Some(&zeros), 0);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, binding, Some(b));
            buffers.push(b);
        }
        gl.use_program(Some(program));
        gl.dispatch_compute(1, 1, 1);
        gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
        let mut out = [0i32; 4];
        let result = *buffers.last().expect("the result buffer");
        gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(result));
        gl.get_buffer_sub_data(
            glow::SHADER_STORAGE_BUFFER,
            0,
            bytemuck::cast_slice_mut(&mut out),
        );
        for b in buffers {
            gl.delete_buffer(b);
        }
        gl.delete_program(program);
        gl.delete_shader(shader);
        Ok(out)
    }
}

/// GLSL 4.60 §4.1.9, GL 4.6 §7.8: `length()` of a runtime-sized array is computed from the
/// size of the buffer bound to its block. Mesa 22.3's zink returns another buffer's size when
/// the program declares a block it does not use — which one depends on the blocks' names.
fn length_of_runtime_sized_array(gl: &Gl) -> Result<()> {
    for unused in ["ColorBuffer", "AbcBuffer", "ZedBuffer"] {
        let source = format!(
            "#version 450 core\nlayout(local_size_x = 1) in;\n\
             layout(std430, binding = 0) readonly buffer VertexBuffer {{ vec4 vertex[]; }};\n\
             layout(std430, binding = 2) readonly buffer {unused} {{ vec4 unused[]; }};\n\
             layout(std430, binding = 7) buffer Result {{ int result[]; }};\n\
             void main() {{ result[0] = vertex.length(); }}\n"
        );
        let got = run(gl, &source, &[(0, 16 * 100), (2, 16 * 50)])?[0];
        println!(
            "length(): vertex[] over 1600 bytes, unused block `{unused}` declared: \
             {got} (the specification: 100){}",
            if got == 100 { "" } else { "  <-- WRONG" }
        );
    }
    Ok(())
}

/// GLSL allows arrays of bool in private memory, indexed by any integer. lavapipe (Mesa 22.3),
/// under zink, fails to create the compute pipeline (`vkCreateComputePipelines failed
/// (VK_ERROR_UNKNOWN)` on stderr) and the dispatch does nothing, or the process crashes later.
fn dynamically_indexed_bool_array(gl: &Gl) -> Result<()> {
    let source = "#version 450 core\nlayout(local_size_x = 1) in;\n\
                  layout(std430, binding = 7) buffer Result { int result[]; };\n\
                  bool flags[10];\n\
                  void main() {\n\
                      for (int i = 0; i < 10; i++) flags[i] = i == 3;\n\
                      int j = int(gl_WorkGroupID.x) + 3;  // 3, not a constant\n\
                      result[0] = flags[j] ? 7 : 1;\n\
                  }\n";
    let got = run(gl, source, &[])?[0];
    println!(
        "bool flags[10], flags[3] read through a dynamic index: {got} (the specification: 7){}",
        if got == 7 { "" } else { "  <-- WRONG" }
    );
    Ok(())
}

fn main() -> Result<()> {
    let ctx = GlContext::headless(None)?;
    println!("{} — {}", ctx.info.renderer, ctx.info.version);
    length_of_runtime_sized_array(&ctx.gl)?;
    dynamically_indexed_bool_array(&ctx.gl)?;
    Ok(())
}
