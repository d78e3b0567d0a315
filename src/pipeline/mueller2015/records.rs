//! Hit records and per-pixel counts (ours, `glsl/bvh/records.glsl`): for an accelerator
//! whose intersect1 only stores the closest hit of each pixel and whose intersection kernels
//! store their work counts per pixel ([`crate::accel::Accelerator::records`], the SAH BVH).
//! After its intersect1 the pipeline evaluates the hits (`glsl/bvh/evaluate_hit.comp`:
//! Listings 13 and 14, which the thesis runs inside intersect1) and after each intersection
//! dispatch adds the counts to the 64-bit counters (`glsl/bvh/pixel_counts.comp`), both under
//! the same counter bank and ray kind. So `gpu_ms.intersect1` is the closest-hit search alone,
//! as a ray-tracing kernel like Embree's `rtcIntersect1` measures it, and `evaluate_hit`,
//! `pixel_counts` are timed apart.

use anyhow::Result;
use bytemuck::{Pod, Zeroable};

use super::options::COUNTERS;
use crate::accel::PIXELS_PER_INVOCATION;
use crate::gl::resources::{bind_image_unit, GpuTimers, Owned, Ssbo};
use crate::gl::slots::{image, ssbo};
use crate::gl::{Defines, Gl, GlInfo, Kernel, PixelGrid, ShaderSource};

/// One pixel's record (`pixelRecord` in `glsl/bvh/records.glsl`, a uvec4): 16 bytes, which the
/// intersection kernels write (`packCounts`; intersect1 the hit record too) and `evaluate_hit`,
/// `pixel_counts` read; the host only allocates them.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct PixelRecord {
    /// bytes 0–3: the ray–triangle tests (bits 0–30) and whether a loop of the pixel's walk was
    /// cut short (bit 31)
    pub tests_truncated: u32,
    /// bytes 4–7: the nodes visited (bits 0–30) and whether the pixel's ray was traced (bit 31)
    pub nodes_traced: u32,
    /// bytes 8–11 (intersect1 only): the hit record, the word address of the closest hit's
    /// [`LeafTriangle`](crate::accel::bvh::LeafTriangle) in the BVH's word buffer (−1: no hit)
    pub hit: i32,
    /// bytes 12–15: unused (the fused pass packs the first point light's feeler counts in
    /// bytes 8–15 of its record 0 instead of a hit record: [`Record::PackedHigh`])
    pub unused: u32,
}
const _: () = assert!(std::mem::size_of::<PixelRecord>() == 16);

/// Which of a pixel's records `pixel_counts.comp` adds up, and how they are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Record {
    /// record i of every pixel, its counts packed in two words ([`PixelRecord`])
    Packed(u32),
    /// record i, its counts packed in words 2–3 (the fused pass' first-light feelers)
    PackedHigh(u32),
    /// record i, its counts as four words (tests, nodes, rays, truncated): the fused pass'
    /// feeler records, which sum several feelers
    Plain(u32),
}

/// Records per pixel of the fused pass (`glsl/bvh/fused.glsl`): record 0 the closest
/// hit's counts (and a first point light's feelers' beside them), record 1 an area light's
/// samples' as the first light, record 2 the other lights' feelers'.
pub const FUSED_RECORDS: u32 = 3;

/// The work group size of `pixel_counts.comp` (its `COUNT_GROUP`).
const COUNT_GROUP: u32 = 64;

/// The per-pixel record buffer (counts and hit record) and the two kernels that read it.
pub struct Records {
    records: Ssbo,
    evaluate_hit: Kernel,
    pixel_counts: Kernel,
    /// its variant over the fused pass' block lists (`BLOCK_LISTED`), where a fused pass may
    /// run over them (`accel::FusedRun::lists`)
    block_counts: Option<Kernel>,
    hit_list: HitList,
    /// the records as an RGBA32UI image buffer for `pixel_counts` (`RECORD_IMAGE`), where the
    /// GL has the unit ([`Ssbo::texel_view`])
    view: Option<Owned<glow::Texture>>,
    pixels: u32,
    /// the image's 8×8 blocks (the fused pass' block lists hold each once)
    blocks: u32,
}

/// Words before the hit list's entries: two dispatch commands and the count
/// (`HIT_LIST_ENTRIES` in `glsl/bvh/hit_list.glsl`).
const HIT_LIST_HEADER_WORDS: usize = 16;

/// The pass' hit list (`glsl/bvh/hit_list.glsl`, ours): the pixels whose ray hit something,
/// appended by `evaluate_hit`, which the pass' intersect2 dispatches and their counts work
/// through by indirect dispatches instead of the image.
struct HitList {
    buffer: Ssbo,
    /// empties the list before `evaluate_hit`, writes the dispatch commands after it
    /// (`glsl/bvh/hit_list.comp`)
    kernel: Kernel,
}

impl HitList {
    /// Byte offsets of the two dispatch commands: intersect2's, then `pixel_counts`'.
    const FEELERS: i32 = 0;
    const COUNTS: i32 = 16;

    /// Word of the pass' count (`HIT_LIST_COUNT`).
    const COUNT: usize = 8;
    /// Word of the frame's entries over its passes (`HIT_LIST_FRAME_ENTRIES`).
    const FRAME_ENTRIES: usize = 9;

    fn step(&self, timers: &mut GpuTimers, finish: bool, first_pass: bool) {
        self.kernel.use_program();
        self.kernel.set_i32("finish", finish as i32);
        self.kernel.set_i32("firstPass", first_pass as i32);
        self.kernel.dispatch_1d(timers, 1);
    }
}

/// The counter slot of `name` (an entry of [`COUNTERS`]).
fn slot(name: &str) -> i32 {
    COUNTERS.iter().position(|c| *c == name).expect("a counter") as i32
}

impl Records {
    pub fn new(
        gl: &std::sync::Arc<Gl>,
        info: &GlInfo,
        shaders: &ShaderSource,
        defines: &Defines,
        (w, h): (u32, u32),
        per_pixel: u32,
        block_lists: bool,
    ) -> Result<Records> {
        let count = (w as usize) * (h as usize) * per_pixel as usize;
        let max = info.max_ssbo_block_size;
        let bytes = std::mem::size_of::<PixelRecord>() * count;
        let records = Ssbo::new(gl, "pixel records", bytes, None, max)?;
        let view = records.texel_view(
            gl,
            info.profile.image_units,
            image::PIXEL_RECORDS,
            glow::RGBA32UI,
        )?;
        let (mask, mask_value) = crate::accel::bvh::texel_index_mask();
        // the fused pass' block lists, which pixel_counts' BLOCK_LISTED variant sums over
        let blocks = crate::accel::bvh::image_blocks(w, h);
        let defines = defines
            .clone()
            .set("PIXELS_PER_INVOCATION", PIXELS_PER_INVOCATION)
            .set("COUNT_GROUP", COUNT_GROUP)
            // 32-bit record stores only: these kernels do not store records (evaluate_hit
            // enables 64-bit integers for its ballot alone: HIT_LIST_BALLOT)
            .set("RECORD_STORE_64", 0)
            .set("RECORD_IMAGE", view.is_some() as i32)
            .set("MAX_GROUPS_X", info.max_groups_x())
            .set("HIT_LIST_BALLOT", info.profile.hit_list_ballot as i32)
            .set(mask, mask_value)
            // evaluate_hit's hit records of two levels (glsl/bvh/words.glsl's instanceRay)
            .set("BVH_INSTANCE_TEXELS", crate::accel::bvh::INSTANCE_TEXELS)
            .set("BVH_BLOCKS_X", blocks.0)
            .set("BVH_ENTRY_TEXELS", blocks.0 * blocks.1);
        let compute = |file, timer| Kernel::compute(gl, shaders, file, &defines, timer);
        let counts = |listed: bool| {
            let d = defines.clone().set("BLOCK_LISTED", listed as i32);
            Kernel::compute(gl, shaders, "bvh/pixel_counts.comp", &d, "pixel_counts")
        };
        let list_bytes = 4 * (HIT_LIST_HEADER_WORDS + (w as usize) * (h as usize));
        Ok(Records {
            records,
            evaluate_hit: compute("bvh/evaluate_hit.comp", "evaluate_hit")?,
            pixel_counts: counts(false)?,
            block_counts: block_lists.then(|| counts(true)).transpose()?,
            hit_list: HitList {
                buffer: Ssbo::new(gl, "hit list", list_bytes, None, max)?,
                // the list is a part of the hit's evaluation: timed with it
                kernel: compute("bvh/hit_list.comp", "evaluate_hit")?,
            },
            view,
            pixels: w * h,
            blocks: blocks.0 * blocks.1,
        })
    }

    pub fn bind(&self, gl: &Gl) {
        self.records.bind(gl, ssbo::PIXEL_RECORDS);
        self.hit_list.buffer.bind(gl, ssbo::HIT_LIST);
        if let Some(v) = &self.view {
            let (access, format) = (glow::READ_ONLY, glow::RGBA32UI);
            bind_image_unit(gl, image::PIXEL_RECORDS, v.raw(), access, format);
        }
    }

    /// After intersect1: evaluate the hits (Listings 13, 14) into the hit list, then count.
    pub fn after_closest_hit(
        &self,
        timers: &mut GpuTimers,
        grid: PixelGrid,
        background: [f32; 3],
        first_pass: bool,
    ) {
        self.hit_list.step(timers, false, first_pass);
        let k = &self.evaluate_hit;
        k.use_program();
        k.set_vec4("backgroundColor", background, 1.0);
        k.set_i32("storePrimaryHit", first_pass as i32);
        k.dispatch_pixels(timers, grid);
        self.hit_list.step(timers, true, first_pass);
        self.add_counts(timers, "intersect1");
    }

    /// An intersect2 dispatch (`feelers`, in use, its light's uniforms set) over the pass' hit
    /// list — one dispatch, whatever the tiles of the other kernels: its work is the hits' —
    /// then its counts, the triangle tests under intersect2.
    pub fn trace_feelers(&self, feelers: &Kernel, timers: &mut GpuTimers, threads: u32) {
        let buffer = self.hit_list.buffer.buffer.raw();
        feelers.set_i32("listThreads", threads as i32);
        feelers.dispatch_indirect(timers, buffer, HitList::FEELERS);
        let k = self.counts_program(&self.pixel_counts, Record::Packed(0), true);
        k.set_ivec4("countSlots", count_slots("intersect2"));
        k.dispatch_indirect(timers, buffer, HitList::COUNTS);
    }

    /// The pixels the frame's hit lists held, over all its passes: those whose feelers
    /// intersect2 traced (read back after the frame).
    pub fn hit_list_pixels(&self, gl: &Gl) -> u32 {
        let mut words = [0u8; 4 * (HitList::FRAME_ENTRIES + 1)];
        self.hit_list.buffer.read_bytes(gl, &mut words);
        bytemuck::pod_read_unaligned(&words[4 * HitList::FRAME_ENTRIES..])
    }

    /// The pixel indices (`y · width + x`, GL rows) the last pass' hit list holds, in the
    /// order they were appended (read back after the frame).
    pub fn hit_list_entries(&self, gl: &Gl) -> Vec<u32> {
        let mut head = [0u8; 4 * HIT_LIST_HEADER_WORDS];
        self.hit_list.buffer.read_bytes(gl, &mut head);
        let count: u32 = bytemuck::pod_read_unaligned(&head[4 * HitList::COUNT..][..4]);
        // a count past the pixels would be a kernel's fault: read no more than the list holds
        let n = count.min(self.pixels) as usize;
        let mut bytes = vec![0u8; 4 * (HIT_LIST_HEADER_WORDS + n)];
        self.hit_list.buffer.read_bytes(gl, &mut bytes);
        let mut entries: Vec<u32> =
            bytemuck::pod_collect_to_vec(&bytes[4 * HIT_LIST_HEADER_WORDS..]);
        // a count past the pixels is kept visible as entries no pixel has
        entries.resize(count as usize, u32::MAX);
        entries
    }

    /// After an intersection dispatch whose triangle tests count under `tests`: add every
    /// pixel's counts to the bound bank.
    pub fn add_counts(&self, timers: &mut GpuTimers, tests: &str) {
        self.add_record_counts(timers, tests, Record::Packed(0));
    }

    /// Add every pixel's `record` (the fused pass keeps three a pixel:
    /// `glsl/bvh/fused.glsl`) to the bound bank, its triangle tests under `tests`.
    pub fn add_record_counts(&self, timers: &mut GpuTimers, tests: &str, record: Record) {
        let k = self.counts_program(&self.pixel_counts, record, false);
        k.set_ivec4("countSlots", count_slots(tests));
        k.dispatch_1d(
            timers,
            self.pixels.div_ceil(PIXELS_PER_INVOCATION * COUNT_GROUP),
        );
    }

    /// The fused pass' `record` added to the bound bank over its block lists (`BLOCK_LISTED` in
    /// `glsl/bvh/pixel_counts.comp`; the accelerator's lists bound: `BlockLists::step`), the triangle tests under
    /// `tests`: the hit blocks' pixels' records, and the miss blocks' — or, where
    /// `misses_cleared` (the first pass' clears stood for the miss kernel, which wrote no
    /// record), for each miss-block pixel an eye ray traced that visited nothing in record 0,
    /// nothing in the others.
    pub fn add_block_counts(
        &self,
        timers: &mut GpuTimers,
        tests: &str,
        record: Record,
        misses_cleared: bool,
    ) {
        let k = self.block_counts.as_ref();
        let k = k.expect("block counts where the accelerator keeps block lists");
        let k = self.counts_program(k, record, false);
        k.set_i32("missesCleared", misses_cleared as i32);
        k.set_ivec4("countSlots", count_slots(tests));
        k.dispatch_1d(timers, self.blocks.div_ceil(COUNT_GROUP));
    }

    /// `k` (a variant of `glsl/bvh/pixel_counts.comp`) in use, set to sum `record` of every
    /// pixel or, with `listed`, the hit list's records.
    fn counts_program<'k>(&self, k: &'k Kernel, record: Record, listed: bool) -> &'k Kernel {
        k.use_program();
        let (index, plain, high) = match record {
            Record::Packed(i) => (i, false, false),
            Record::PackedHigh(i) => (i, false, true),
            Record::Plain(i) => (i, true, false),
        };
        k.set_i32("recordBase", (index * self.pixels) as i32);
        k.set_i32("plainRecords", plain as i32);
        k.set_i32("packedHigh", high as i32);
        k.set_i32("hitListed", listed as i32);
        k
    }
}

/// The counter slots of a record's four counts, its triangle tests under `tests`.
fn count_slots(tests: &str) -> [i32; 4] {
    [
        slot(tests),
        slot("nodes_visited"),
        slot("truncated_rays"),
        slot("rays"),
    ]
}
