//! A kernel: one GLSL program with its uniforms looked up once, the name its GPU time is
//! recorded under, and the dispatch helpers every design shares (over the image in tiles, or
//! one-dimensional). Resources are bound by the named slots of [`super::slots`], never by bare
//! numbers.

use std::collections::HashMap;
use std::ffi::CStr;
use std::sync::Arc;

use anyhow::{bail, Result};
use glow::HasContext;

use super::resources::GpuTimers;
use super::resources::Owned;
use super::{compile_program, Defines, Gl, ShaderSource};
use super::{crash, sync};

/// The work group size of the per-pixel kernels (`local_size_x = local_size_y = 8`).
pub const PIXEL_GROUP: u32 = 8;

/// One GLSL program: a compute kernel, or a vertex + fragment program of a raster pass.
pub struct Kernel {
    gl: Arc<Gl>,
    program: Owned<glow::Program>,
    /// The name its dispatches are timed under (the key of `gpu_ms`).
    timer: &'static str,
    uniforms: HashMap<String, glow::UniformLocation>,
    /// What the crash handler says if the driver faults while this program is in use.
    crash_note: &'static CStr,
}

/// The image size and tiling of a per-pixel dispatch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelGrid {
    pub width: u32,
    pub height: u32,
    /// Dispatches cover at most tile×tile pixels (0: the whole image in one dispatch).
    pub tile: u32,
    /// The threads that split a dispatch's work groups in contiguous shares
    /// ([`super::Profile::dispatch_threads`]).
    pub threads: u32,
}

impl PixelGrid {
    /// Check the tile size: a multiple of the work group size, or 0.
    pub fn new(width: u32, height: u32, tile: u32, threads: u32) -> Result<PixelGrid> {
        if !tile.is_multiple_of(PIXEL_GROUP) {
            bail!(
                "--tile {tile} must be a multiple of {PIXEL_GROUP} (the kernels' work group size)"
            );
        }
        Ok(PixelGrid {
            width,
            height,
            tile,
            threads: threads.max(1),
        })
    }

    /// The stride s through the `rows` work-group rows of a tile (`tileRowStride` in
    /// `glsl/common/images.glsl`): dispatch row y < rows − 1 covers the tile's row
    /// y·s mod (rows − 1), the last row itself — one row each, as s is coprime to rows − 1.
    /// Where `threads` (> 1) divide the rows, s is their number: the shuffle that gives the
    /// share of thread t (dispatch rows t·rows/threads and on) the tile's rows t, t + threads,
    /// t + 2·threads, …, neighbours of the other threads' rows, so the shares cost the same
    /// wherever the image is busy. Otherwise the integer nearest (rows − 1)/φ coprime to
    /// rows − 1, which spreads every contiguous share over the tile.
    pub fn row_stride(rows: u32, threads: u32) -> u32 {
        if threads > 1 && rows.is_multiple_of(threads) {
            return threads;
        }
        let m = Self::row_modulus(rows);
        let start = ((m as f64) * 0.618_033_988_75).round().max(1.0) as u32;
        (start..)
            .find(|&s| gcd(s, m) == 1)
            .expect("m + 1 is coprime to m")
    }

    /// The tile's row that dispatch row `y` of `rows` covers (as `pixelPosition` computes it).
    pub fn tile_row(y: u32, rows: u32, stride: u32) -> u32 {
        if y + 1 == rows {
            y
        } else {
            y * stride % Self::row_modulus(rows)
        }
    }

    /// The modulus of the rows' order: rows − 1 (at least 1; the last row stays in place).
    fn row_modulus(rows: u32) -> u32 {
        rows.saturating_sub(1).max(1)
    }

    /// The tiles as (x, y, width, height), row by row.
    pub fn tiles(&self) -> Vec<(u32, u32, u32, u32)> {
        let (w, h) = (self.width, self.height);
        let tile = if self.tile == 0 { w.max(h) } else { self.tile } as usize;
        let mut out = Vec::new();
        for ty in (0..h).step_by(tile) {
            for tx in (0..w).step_by(tile) {
                out.push((tx, ty, (tile as u32).min(w - tx), (tile as u32).min(h - ty)));
            }
        }
        out
    }
}

impl Kernel {
    /// Compile `file` (below `glsl/`) as a compute kernel timed under `timer`.
    pub fn compute(
        gl: &Arc<Gl>,
        shaders: &ShaderSource,
        file: &str,
        defines: &Defines,
        timer: &'static str,
    ) -> Result<Kernel> {
        Self::program(gl, shaders, &[(glow::COMPUTE_SHADER, file)], defines, timer)
    }

    /// Compile and link the stages `(kind, file)` into one program timed under `timer`.
    pub fn program(
        gl: &Arc<Gl>,
        shaders: &ShaderSource,
        stages: &[(u32, &str)],
        defines: &Defines,
        timer: &'static str,
    ) -> Result<Kernel> {
        let program = compile_program(gl, shaders, stages, defines)?;
        let files: Vec<String> = stages
            .iter()
            .map(|(_, f)| shaders.display_name(f))
            .collect();
        let files: Vec<&str> = files.iter().map(String::as_str).collect();
        let renderer = super::context::gl_string(gl, glow::RENDERER);
        let crash_note = crash::keep(&crash::message(timer, &files, &renderer));
        // SAFETY: queries of the program we just linked.
        let uniforms = unsafe {
            let program = program.raw();
            (0..gl.get_active_uniforms(program))
                .filter_map(|i| gl.get_active_uniform(program, i))
                .filter_map(|u| {
                    let name = u.name.trim_end_matches("[0]").to_string();
                    gl.get_uniform_location(program, &name).map(|l| (name, l))
                })
                .collect()
        };
        Ok(Kernel {
            gl: gl.clone(),
            program,
            timer,
            uniforms,
            crash_note,
        })
    }

    pub fn timer(&self) -> &'static str {
        self.timer
    }

    /// Make this program current (and the one a driver crash is reported against).
    pub fn use_program(&self) {
        crash::note_program(self.crash_note);
        // SAFETY: binding our own program.
        unsafe { self.gl.use_program(Some(self.program.raw())) };
    }

    /// The location of `name`; `None` where the program has no such active uniform (the
    /// compiler may remove an unused one: setting it is then a no-op, as in GL).
    fn loc(&self, name: &str) -> Option<&glow::UniformLocation> {
        self.uniforms.get(name)
    }

    // The setters act on the program in use (call `use_program` first).
    pub fn set_i32(&self, name: &str, v: i32) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_1_i32(self.loc(name), v) };
    }
    pub fn set_f32(&self, name: &str, v: f32) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_1_f32(self.loc(name), v) };
    }
    pub fn set_i32_slice(&self, name: &str, v: &[i32]) {
        // SAFETY: a uniform array of the program in use, of at least v.len() elements.
        unsafe { self.gl.uniform_1_i32_slice(self.loc(name), v) };
    }
    pub fn set_ivec2(&self, name: &str, v: [i32; 2]) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_2_i32(self.loc(name), v[0], v[1]) };
    }
    pub fn set_ivec3(&self, name: &str, v: [i32; 3]) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_3_i32(self.loc(name), v[0], v[1], v[2]) };
    }
    pub fn set_ivec4(&self, name: &str, v: [i32; 4]) {
        // SAFETY: a uniform of the program in use.
        unsafe {
            self.gl
                .uniform_4_i32(self.loc(name), v[0], v[1], v[2], v[3])
        };
    }
    pub fn set_vec2(&self, name: &str, v: [f32; 2]) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_2_f32(self.loc(name), v[0], v[1]) };
    }
    pub fn set_vec3(&self, name: &str, v: [f32; 3]) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_3_f32_slice(self.loc(name), &v) };
    }
    pub fn set_vec4(&self, name: &str, v: [f32; 3], w: f32) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_4_f32(self.loc(name), v[0], v[1], v[2], w) };
    }
    pub fn set_vec4_slice(&self, name: &str, v: &[[f32; 4]]) {
        let flat: Vec<f32> = v.iter().flatten().copied().collect();
        // SAFETY: a uniform vec4 array of the program in use, of at least v.len() elements.
        unsafe { self.gl.uniform_4_f32_slice(self.loc(name), &flat) };
    }
    pub fn set_mat3(&self, name: &str, m: &[f32; 9]) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_matrix_3_f32_slice(self.loc(name), false, m) };
    }
    pub fn set_mat4(&self, name: &str, m: &[f32; 16]) {
        // SAFETY: a uniform of the program in use.
        unsafe { self.gl.uniform_matrix_4_f32_slice(self.loc(name), false, m) };
    }

    /// Dispatch this kernel (in use) over the image in tiles of `grid`, timed together, the
    /// tile's origin in the uniform `tileOffset`; one barrier before the first tile ([`sync`]:
    /// the tiles write disjoint pixels).
    pub fn dispatch_pixels(&self, timers: &mut GpuTimers, grid: PixelGrid) {
        self.dispatch_pixel_groups(timers, grid, PIXEL_GROUP);
    }

    /// [`Kernel::dispatch_pixels`] for a kernel of `group`×`group` work groups (Wagner 2018's
    /// 16×16); the tiles should be multiples of `group`.
    pub fn dispatch_pixel_groups(&self, timers: &mut GpuTimers, grid: PixelGrid, group: u32) {
        let gl = &self.gl;
        sync::before(gl, sync::SHADER);
        // one pair of timer queries around all the tiles: a query pair per tile would add its
        // own cost to every tile on a GPU, where a tile takes microseconds
        timers.time(gl, self.timer, || {
            let tiles = grid.tiles();
            for (i, &(tx, ty, tw, th)) in tiles.iter().enumerate() {
                crate::progress::kernel(self.timer, i + 1, tiles.len());
                self.set_ivec2("tileOffset", [tx as i32, ty as i32]);
                let rows = th.div_ceil(group);
                let stride = PixelGrid::row_stride(rows, grid.threads);
                self.set_i32("tileRowStride", stride as i32);
                // SAFETY: dispatch of the program in use.
                unsafe { gl.dispatch_compute(tw.div_ceil(group), th.div_ceil(group), 1) }
            }
        });
        sync::after_pass(gl);
    }

    /// Dispatch the work groups of the indirect command at byte `offset` of `commands`
    /// (`glDispatchComputeIndirect`), which an earlier kernel wrote ([`sync`]: the command's
    /// bit too).
    pub fn dispatch_indirect(&self, timers: &mut GpuTimers, commands: glow::Buffer, offset: i32) {
        let gl = &self.gl;
        sync::before(gl, sync::SHADER | glow::COMMAND_BARRIER_BIT);
        // SAFETY: an existing buffer bound as the indirect command buffer, the command inside
        // it; the program in use.
        timers.time(gl, self.timer, || unsafe {
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, Some(commands));
            gl.dispatch_compute_indirect(offset);
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, None);
        });
        sync::after_pass(gl);
    }

    /// Dispatch this kernel (in use) with `groups` one-dimensional work groups, timed, with the
    /// barriers of [`sync`].
    pub fn dispatch_1d(&self, timers: &mut GpuTimers, groups: u32) {
        let gl = &self.gl;
        sync::before(gl, sync::SHADER);
        if groups > 0 {
            // SAFETY: dispatch of the program in use.
            timers.time(gl, self.timer, || unsafe {
                gl.dispatch_compute(groups, 1, 1)
            });
        }
        sync::after_pass(gl);
    }
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_rows_visit_every_row_once_and_load_each_share_alike() {
        for threads in 1..=8u32 {
            for rows in 1..=300u32 {
                let s = PixelGrid::row_stride(rows, threads);
                let map: Vec<u32> = (0..rows).map(|y| PixelGrid::tile_row(y, rows, s)).collect();
                let mut seen = map.clone();
                seen.sort_unstable();
                let all: Vec<u32> = (0..rows).collect();
                assert_eq!(seen, all, "{rows} rows, {threads} threads, stride {s}");
                if threads > 1 && rows % threads == 0 {
                    // thread t's contiguous share of the dispatch rows: the tile's rows t,
                    // t + threads, ...
                    for (y, &row) in map.iter().enumerate() {
                        let t = y as u32 / (rows / threads);
                        assert_eq!(row % threads, t, "{rows} rows, {threads} threads, y {y}");
                    }
                } else if rows >= 16 {
                    // each half of the dispatch rows covers both halves of the tile about equally
                    let top = map[..(rows / 2) as usize].iter().filter(|&&r| r < rows / 2);
                    let share = top.count() as f64 / (rows / 2) as f64;
                    assert!((0.3..=0.7).contains(&share), "{rows} rows: {share}");
                }
            }
        }
    }

    #[test]
    fn tiles_cover_the_image_once() {
        let g = PixelGrid::new(100, 37, 32, 2).unwrap();
        let tiles = g.tiles();
        let area: u32 = tiles.iter().map(|t| t.2 * t.3).sum();
        assert_eq!(area, 100 * 37);
        assert_eq!(tiles.len(), 4 * 2);
        assert_eq!(tiles.last(), Some(&(96, 32, 4, 5)));
        assert_eq!(
            PixelGrid::new(100, 37, 0, 1).unwrap().tiles(),
            vec![(0, 0, 100, 37)]
        );
        assert!(PixelGrid::new(8, 8, 12, 1).is_err());
    }
}
