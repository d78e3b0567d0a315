//! The SAH BVH's fused pass (ours, the default of `--tracer bvh`): a pass of Fig. 8 in one
//! kernel (`glsl/bvh/fused.glsl` under its entry files), over the block lists of the image's
//! 8×8 blocks where one tree is walked (the blocks that may hit, those whose rays all miss),
//! or a pixel an invocation under the two levels; the entry pass before it, and in a first
//! pass the miss blocks left to the pipeline's clear. The pipeline's part comes through
//! [`PassHost`]; the counts it sums afterwards ([`FusedRun`]).

use crate::accel::interface::{
    set_camera, BuildContext, FrameContext, FusedPasses, FusedRun, PassHost,
};
use crate::gl::resources::{GpuTimers, Ssbo, TextureBuffers};
use crate::gl::slots::ssbo;
use crate::gl::{Gl, Kernel};
use crate::scene::CameraRays;
use anyhow::Result;

/// Invocations of a work group of `glsl/bvh/entry.comp` (`BVH_ENTRY_GROUP`), one block each.
pub(super) const ENTRY_GROUP: u32 = 64;

/// The fused pass (`glsl/bvh/fused.glsl`): each pixel's counts in record 0 (the first
/// light's beside the closest hit's where it is a point light), else the first light's at
/// record 1; the other lights' at record 2 where the scene has more than one light
/// (`pipeline::mueller2015::records`). With block lists (`lists`: one tree) two kernels, a
/// work group per block: the blocks whose rays may hit (`glsl/bvh/fused_pass.comp`) and those
/// whose rays all miss (`glsl/bvh/fused_miss.comp`, timed as `fused_miss`;
/// `glsl/bvh/block_lists.glsl`); without (two levels, `Bvh::create`) one, a pixel an
/// invocation (`glsl/bvh/fused_instances.comp`). `eye`: the variant that computes the eye rays
/// in place (`PASS_EYE_RAYS`).
pub(super) fn fused_kernels(
    b: &BuildContext,
    defs: &[(&'static str, String)],
    f: FusedPasses,
    lists: bool,
    eye: bool,
) -> Result<Vec<Kernel>> {
    let variant = [
        ("PASS_EYE_RAYS", (eye as i32).to_string()),
        (
            "EYE_PASS_STORES_RAYS",
            (f.rays.eye_pass_stores_rays as i32).to_string(),
        ),
    ];
    let kernel = |file, timer| fused_kernel(b, &[defs, &variant[..]].concat(), f, file, timer);
    match lists {
        true => Ok(vec![
            kernel("bvh/fused_pass.comp", "fused_pass")?,
            kernel("bvh/fused_miss.comp", "fused_miss")?,
        ]),
        false => Ok(vec![kernel("bvh/fused_instances.comp", "fused_pass")?]),
    }
}

/// The fused pass' kernels (`glsl/bvh/fused.glsl`): the pass in one kernel, or with one tree in
/// two over the block lists (the blocks that may hit, those that cannot); no kernel without.
pub(super) struct Fused {
    /// the kernels of the passes whose rays are in the ray-state images, compiled only where
    /// some pass takes them ([`FusedPasses::rays`]; empty with the four kernels)
    pub(super) loaded: Vec<Kernel>,
    /// those of the first pass computing its eye rays in place (`PASS_EYE_RAYS`), likewise
    pub(super) eye: Vec<Kernel>,
    /// the entry pass of the first pass computing its eye rays in place (where one does; the
    /// other passes' is [`Bvh::entry`])
    pub(super) eye_entry: Option<Kernel>,
    /// whether the pass [`crate::accel::Accelerator::fused_pass`] prepared last computes its eye rays in place
    pub(super) in_place: bool,
    pub(super) lists: Option<BlockLists>,
    /// the most walks one per-pixel record counts: 1, or with the fused pass a hit's feelers
    pub(super) walks_per_record: u64,
    /// the most events those walks may count (`max_pixel_events`: the counts over the block
    /// lists sum a block's 64 pixels, the others 16)
    pub(super) max_events: u64,
}

impl Fused {
    /// The kernels of the pass [`crate::accel::Accelerator::fused_pass`] prepared last.
    pub(super) fn pass_kernels(&self) -> &[Kernel] {
        let kernels = if self.in_place {
            &self.eye
        } else {
            &self.loaded
        };
        assert!(!kernels.is_empty(), "no fused kernels for this pass' rays");
        kernels
    }
}

/// The fused pass' block lists (`glsl/bvh/block_lists.glsl`): the image's blocks that may hit
/// and those that cannot, each list a dispatch command, a count and a word per block.
pub(super) struct BlockLists {
    pub(super) buffer: Ssbo,
    /// empties the lists before each entry pass and writes their dispatch commands after it
    /// (`glsl/bvh/block_lists.comp`)
    pub(super) kernel: Kernel,
}

impl BlockLists {
    pub(super) fn new(
        b: &BuildContext,
        defs: &[(&'static str, String)],
        blocks: u32,
    ) -> Result<BlockLists> {
        let words = 16 + 2 * blocks as usize;
        let max_block = b.info.max_ssbo_block_size;
        let buffer = Ssbo::new(b.gl, "bvh_block_lists", 4 * words, None, max_block)?;
        // timed with the entry pass, a part of intersect1: the pass' set-up
        let kernel = b.kernel("bvh/block_lists.comp", defs, "intersect1")?;
        Ok(BlockLists { buffer, kernel })
    }

    /// Both lists emptied for the entry pass to fill (`finish` unset), or their dispatch
    /// commands written from what it filled (set); the buffer bound for the entry pass, the
    /// fused kernels and the pass' counts over the lists (`pixel_counts`' `BLOCK_LISTED`).
    pub(super) fn step(&self, gl: &Gl, timers: &mut GpuTimers, finish: bool) {
        self.buffer.bind(gl, ssbo::BVH_BLOCK_LISTS);
        self.kernel.use_program();
        self.kernel.set_i32("finish", finish as i32);
        self.kernel.dispatch_1d(timers, 1);
    }
}

pub(super) fn fused_kernel(
    b: &BuildContext,
    defs: &[(&'static str, String)],
    f: FusedPasses,
    file: &str,
    timer: &'static str,
) -> Result<Kernel> {
    let extra = [
        ("SCENE_IMAGES", (b.scene_images as i32).to_string()),
        ("RECORD_FIRST_LIGHT", "1".to_string()),
        (
            "RECORD_OTHER_LIGHTS",
            if f.lights > 1 { "2" } else { "0" }.to_string(),
        ),
        (
            "FIRST_LIGHT_PACKED",
            (f.first_light_point as i32).to_string(),
        ),
    ];
    b.kernel(file, &[defs, &extra[..]].concat(), timer)
}

/// The entry pass of the blocks' rays (`glsl/bvh/entry.comp`) over the tree as uploaded: its
/// word buffer and the image's blocks.
pub(super) struct EntryPass<'a> {
    pub(super) buffers: Option<&'a TextureBuffers>,
    pub(super) blocks: u32,
}

impl EntryPass<'_> {
    /// The word buffer's images bound with `access` (nothing before the first build).
    pub(super) fn bind(&self, gl: &Gl, access: u32) {
        if let Some(b) = self.buffers {
            b.bind_images(gl, access);
        }
    }

    /// Dispatch `kernel`, the entry pass of the loaded rays or of eye rays computed in place
    /// (`eye`), over every block: it writes the blocks' entries into the word buffer.
    pub(super) fn dispatch(&self, f: &mut FrameContext, kernel: &Kernel, eye: Option<&CameraRays>) {
        self.bind(f.gl, glow::READ_WRITE);
        kernel.use_program();
        if let Some(cam) = eye {
            set_camera(kernel, cam);
        }
        kernel.dispatch_1d(f.timers, self.blocks.div_ceil(ENTRY_GROUP));
        self.bind(f.gl, glow::READ_ONLY);
    }
}

impl Fused {
    /// A pass in the fused kernels ([`crate::accel::Accelerator::fused_pass`]): the entry pass
    /// (`entry` over the loaded rays, or this pass' own over eye rays in place), the pipeline's
    /// uniforms through `host`, the miss blocks left to its clear in a first pass, the kernels;
    /// `None` where the BVH was made without them (the four kernels).
    pub(super) fn run(
        &mut self,
        f: &mut FrameContext,
        eye: Option<&CameraRays>,
        host: &dyn PassHost,
        (entry_pass, entry): (&EntryPass, &Kernel),
    ) -> Option<FusedRun> {
        if self.loaded.is_empty() && self.eye.is_empty() {
            return None;
        }
        self.in_place = eye.is_some();
        self.entry_pass(f, eye, entry_pass, entry);
        for k in self.pass_kernels() {
            k.use_program();
            if let Some(cam) = eye {
                set_camera(k, cam);
            }
            host.set_uniforms(k);
        }
        host.frame_work(f.gl, f.timers);
        // Ours: in the first pass every pixel's eye ray is active, so a block whose rays all
        // miss the tree (the miss list) ends as a clear leaves it, its counts one ray traced
        // that visited nothing a pixel — where no AOVs keep the first hits (eye rays in place)
        // and no texel of the ray state needs storing: the frame's clear left them inactive
        // (docs/design/frame.md, "The fused pass")
        let run = FusedRun {
            lists: self.lists.is_some(),
            clears: eye.is_some() && self.lists.is_some(),
        };
        if run.clears {
            host.fill_misses(f.gl, f.timers);
        }
        self.dispatch(f, !run.clears);
        Some(run)
    }

    /// The entry pass of the pass' rays, its block lists emptied before it and their dispatch
    /// commands written after it.
    fn entry_pass(
        &self,
        f: &mut FrameContext,
        eye: Option<&CameraRays>,
        entry_pass: &EntryPass,
        entry: &Kernel,
    ) {
        if let Some(lists) = &self.lists {
            lists.step(f.gl, f.timers, false);
        }
        let kernel = match eye {
            Some(_) => self.eye_entry.as_ref(),
            None => Some(entry),
        };
        let kernel = kernel.expect("the entry pass of the rays the frame's passes take");
        entry_pass.dispatch(f, kernel, eye);
        if let Some(lists) = &self.lists {
            // the lists' dispatch commands from what the entry pass counted
            lists.step(f.gl, f.timers, true);
        }
    }

    /// Dispatch the fused kernels of the pass, their uniforms set; without `misses` not the
    /// one for the blocks whose rays all miss (their pixels were filled by clears).
    fn dispatch(&self, f: &mut FrameContext, misses: bool) {
        let kernels = self.pass_kernels();
        match &self.lists {
            Some(lists) => {
                // the blocks that may hit, then the others: each list in one dispatch, whatever
                // the tiles (glsl/bvh/block_lists.glsl)
                let dispatched = if misses { 2 } else { 1 };
                for (list, k) in kernels.iter().enumerate().take(dispatched) {
                    k.use_program();
                    k.set_i32("listThreads", f.pixels.threads as i32);
                    let command = 16 * list as i32;
                    k.dispatch_indirect(f.timers, lists.buffer.buffer.raw(), command);
                }
            }
            None => {
                let k = &kernels[0];
                k.use_program();
                k.dispatch_pixels(f.timers, f.pixels);
            }
        }
    }
}
