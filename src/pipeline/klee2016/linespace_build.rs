//! The N-tree's line spaces built on the GPU (ours; Klee 2016 builds them on the CPU, ch. 3.3
//! and 4.2): `glsl/klee2016/linespace_build.comp` computes every inner node's line space, one
//! 32-bit word per invocation, straight into the 3D R32UI texture of Listing 3 that the shadow
//! kernel reads. The node structure (which children have geometry) stays on the CPU
//! ([`NTree::build_nodes`]); the CPU build ([`NTree::build_linespaces_cpu`]) is the twin the
//! tests compare with bit for bit.

use std::sync::Arc;

use anyhow::{anyhow, Result};
use glow::HasContext;

use super::ntree::{self, NTree, PackedLinespaces};
use crate::gl::resources::{GpuTimers, Owned, Ssbo};
use crate::gl::slots::{image, ssbo};
use crate::gl::{Defines, Gl, GlInfo, Kernel, ShaderSource};

/// `--linespace-build`: where the line spaces are computed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum LinespaceBuild {
    /// The GPU on a hardware GPU, the CPU on a software rasteriser (llvmpipe, or zink over
    /// lavapipe), whose compute kernels run on the same cores and where the CPU build is
    /// faster (docs/design/linespace.md).
    #[default]
    Auto,
    /// The CPU build (`NTree::build_linespaces_cpu`), uploaded.
    Cpu,
    /// The GPU build (`glsl/klee2016/linespace_build.comp`).
    Gpu,
}

impl LinespaceBuild {
    /// Whether the GPU builds the line spaces on the GL implementation `info`.
    pub fn on_gpu(self, info: &GlInfo) -> bool {
        match self {
            LinespaceBuild::Auto => info.profile.linespace_build_on_gpu,
            LinespaceBuild::Cpu => false,
            LinespaceBuild::Gpu => true,
        }
    }
}

/// Invocations of a work group (the kernel's `local_size_x`).
const GROUP: u32 = 64;
/// Work groups of one dispatch at most (GL guarantees 65535 per dimension).
const MAX_GROUPS: u32 = 65535;

/// The line spaces as the GPU left them: the texture, its layout with the texels read back
/// (the CPU implementation reads them), and the time taken.
pub struct GpuLinespaces {
    pub texture: Owned<glow::Texture>,
    pub packed: PackedLinespaces,
    /// GPU time of the build's dispatches (timer queries).
    pub gpu_ms: f64,
}

/// A 3D R32UI texture of `packed`'s layout, all zeros.
pub fn r32ui_texture_3d(gl: &Arc<Gl>, packed: &PackedLinespaces) -> Result<Owned<glow::Texture>> {
    let (x, y, z) = (
        packed.tex_x_res as i32,
        packed.tex_y_res as i32,
        packed.tex_z_res as i32,
    );
    // SAFETY: texture creation on a current context.
    unsafe {
        let t = Owned::new(gl, gl.create_texture().map_err(|e| anyhow!(e))?);
        gl.bind_texture(glow::TEXTURE_3D, Some(t.raw()));
        gl.tex_storage_3d(glow::TEXTURE_3D, 1, glow::R32UI, x, y, z);
        for p in [glow::TEXTURE_MIN_FILTER, glow::TEXTURE_MAG_FILTER] {
            gl.tex_parameter_i32(glow::TEXTURE_3D, p, glow::NEAREST as i32);
        }
        gl.bind_texture(glow::TEXTURE_3D, None);
        // zeros: glTexStorage3D leaves the contents undefined, and the build stores only the
        // line spaces' words, not the padding after the last one (zink over lavapipe left
        // other values there, which a read-back compared with the CPU's zeros)
        gl.clear_tex_u32(t.raw(), glow::RED_INTEGER, [0; 4]);
        let bytes = 4 * packed.texel_count() as u64;
        crate::gl::check_alloc(gl, "the 3D line-space texture", bytes)?;
        Ok(t)
    }
}

/// Line spaces per dispatch: as many whole ones as [`MAX_GROUPS`] groups hold.
fn linespaces_per_dispatch(words: u32) -> u32 {
    ((MAX_GROUPS * GROUP) / words).max(1)
}

/// Build `tree`'s line spaces on the GPU into a new texture with Listing 3's layout (at most
/// `max_dim` texels per axis), read them back into the layout's texels (what the CPU twin
/// reads; `tree.linespaces` stays empty: the bits are held once on the host), and set `tree.linespace_build_ms` to the whole step's wall time
/// (occupancy rows, dispatches, read-back).
pub fn build(
    gl: &Arc<Gl>,
    info: &GlInfo,
    shaders: &ShaderSource,
    tree: &mut NTree,
    max_dim: u32,
) -> Result<GpuLinespaces> {
    let t0 = std::time::Instant::now();
    let words = ntree::linespace_words(tree.n) as u32;
    let mut packed = ntree::linespace_layout(words as usize, tree.linespace_count, max_dim)?;
    let texture = r32ui_texture_3d(gl, &packed)?;
    let upload = |name, words: &[u32]| {
        let bytes = bytemuck::cast_slice(words);
        Ssbo::new(gl, name, bytes.len(), Some(bytes), info.max_ssbo_block_size)
    };
    let rows = tree.occupancy_rows();
    let occupancy = upload("linespaceOccupancy", &rows)?;
    let sat = upload("linespaceSat", &tree.occupancy_sat(&rows))?;
    let defines = Defines::new().set("NTREE_N", tree.n);
    let kernel = Kernel::compute(
        gl,
        shaders,
        "klee2016/linespace_build.comp",
        &defines,
        "linespace_build",
    )?;
    let mut timers = GpuTimers::new(gl);
    kernel.use_program();
    kernel.set_i32("wordsPerLs", words as i32);
    kernel.set_i32("tex_x_res", packed.tex_x_res as i32);
    kernel.set_i32("tex_y_res", packed.tex_y_res as i32);
    kernel.set_i32("ls_y_size", packed.ls_y_size as i32);
    occupancy.bind(gl, ssbo::LS_OCCUPANCY);
    sat.bind(gl, ssbo::LS_SAT);
    // SAFETY: binding our texture to its image unit.
    unsafe {
        let (t, wo) = (Some(texture.raw()), glow::WRITE_ONLY);
        gl.bind_image_texture(image::LINESPACE, t, 0, true, 0, wo, glow::R32UI);
    }
    let count = tree.linespace_count as u32;
    let step = linespaces_per_dispatch(words);
    for begin in (0..count).step_by(step as usize) {
        let end = (begin + step).min(count);
        kernel.set_i32("lsBegin", begin as i32);
        kernel.set_i32("lsEnd", end as i32);
        kernel.dispatch_1d(&mut timers, ((end - begin) * words).div_ceil(GROUP));
    }
    crate::gl::check_error(gl, "building the line spaces on the GPU")?;
    let gpu_ms = timers.resolve(gl).values().sum();
    packed.texels = read_texture_3d(gl, texture.raw(), packed.texel_count());
    tree.linespace_build_ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(GpuLinespaces {
        texture,
        packed,
        gpu_ms,
    })
}

/// Read the `texels` R32UI texels of a 3D texture back.
pub fn read_texture_3d(gl: &Gl, texture: glow::Texture, texels: usize) -> Vec<u32> {
    let mut data = vec![0u32; texels];
    let layout = (glow::TEXTURE_3D, glow::RED_INTEGER, glow::UNSIGNED_INT);
    crate::gl::resources::read_tex_image(gl, texture, layout, &mut data);
    data
}
