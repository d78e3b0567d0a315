//! The SAH BVH — ours, after Wagner 2018 ch. 3.2 and 4.2: built on the CPU
//! (binned SAH, rayon: [`build`], [`layout`]) and uploaded into one image buffer of 32-bit words
//! (a copy of the nodes for each ray octant, then the leaf triangles), traversed in the
//! intersection kernels without a stack, near child first (`glsl/bvh/`). Objects move every
//! frame in the bench protocols: whenever a model matrix changed since the last frame, the BVH
//! is refitted on the GPU ([`refit`]: the build's topology, new boxes), or rebuilt on the CPU
//! where the last refit had grown its SAH cost past [`REBUILD_GROWTH`] times the last build's;
//! a still scene keeps its tree. Its image equals the base tracer's. CPU twin:
//! `reference::bvh` (the walks of [`BvhTree`]).

use std::any::Any;
use std::cell::Cell;
use std::sync::Arc;

use anyhow::{anyhow, bail, Result};
use bytemuck::Zeroable;
use glam::{Mat4, Vec3};
use glow::HasContext;
use serde_json::json;

use super::{
    max_pixel_events, set_camera, Accel, Accelerator, BuildContext, BvhLevels, BvhOptions,
    BvhPasses, Entry, FrameContext, FusedPasses, FusedRun, LightTarget, PassHost,
    PIXELS_PER_INVOCATION,
};
use crate::frame::FrameStats;
use crate::gl::kernel::PIXEL_GROUP;
use crate::gl::resources::Owned;
use crate::gl::resources::{GpuTimers, Ssbo, TexelData, TextureBuffers};
use crate::gl::slots::{image, ssbo};
use crate::gl::{Gl, GlInfo, Kernel};
use crate::scene::{transform_triangles, CameraRays, Scene};

mod build;
pub mod instances;
pub mod layout;
mod planes;
pub mod refit;
pub mod tree;
pub use instances::{instance_count, InstanceRecord, Instances, INSTANCE_TEXELS};
pub use layout::{
    block_of, Aabb, BvhStats, EntryTexel, Header, LeafTriangle, Node, NodeRecord, BINS, BLOCK, END,
    HEADER_WORDS, LEAF_COUNT_BITS, LEAF_SIZE, MAX_DEPTH, MAX_LEAF, NODE_WORDS, OCTANTS,
    PARALLEL_BUILD, SAH_DEPTH, TRIANGLE_WORDS,
};
pub use planes::{Grid, Planes, RayGrid, GRID_STEPS};
pub use refit::{Refit, RefitKernels, REBUILD_GROWTH, REFIT_GROUP, REFIT_TIMER};
pub use tree::{octant_planes, BvhTree};

/// The fastest configuration (`docs/design/bvh.md`, "The default"): the fused pass over one
/// tree.
const PLAIN: Accel = Accel::Bvh(BvhOptions {
    passes: BvhPasses::Fused,
    levels: BvhLevels::One,
});

pub const ENTRY: Entry = Entry {
    label: "bvh",
    plain: PLAIN,
    // the two levels find the twin's hits with counts of their own (`tests/bvh_instances.rs`)
    records: true,
    variants: &[
        ("bvh", PLAIN),
        (
            "bvh four-kernels",
            Accel::Bvh(BvhOptions {
                passes: BvhPasses::FourKernels,
                levels: BvhLevels::One,
            }),
        ),
    ],
    gpu: Bvh::create,
};

/// The hierarchy as uploaded (`glsl/bvh/traverse.glsl`): the node records of every octant and
/// the leaf triangles in one image buffer of 32-bit words ([`BvhTree::gpu_words`]), the records
/// addressed by texel and the triangles by word in the kernels' ints — which cannot overflow:
/// `TextureBuffer::new` refuses a buffer of 2^31 bytes or more (or beyond
/// `GL_MAX_TEXTURE_BUFFER_SIZE`), naming it. After them a texel per block of the image for
/// `glsl/bvh/entry.comp` to write its entry point into ([`EntryTexel`]), 0 (no entry) until it
/// does: the same image unit, so the BVH binds no more than GL 4.5's 8.
/// With `--bvh-instances` the words are [`Instances::gpu_words`]'s, and an entry belongs to one
/// instance.
fn upload(gl: &Arc<Gl>, mut words: Vec<u32>, blocks: u32) -> Result<TextureBuffers> {
    let entries = vec![EntryTexel::zeroed(); blocks as usize];
    words.extend_from_slice(bytemuck::cast_slice(&entries));
    let data = TexelData::new;
    TextureBuffers::upload(
        gl,
        [data(
            "bvh",
            glow::RGBA32UI,
            16,
            bytemuck::cast_slice(&words),
            image::BVH,
        )],
    )
}

/// Bits of a texel index of the word buffer: its 16-byte texels number fewer than 2^27, as
/// `TextureBuffer::new` refuses a buffer of 2^31 bytes or more. `glsl/bvh/words.glsl` masks the
/// index to them (no valid index changes), which lets llvmpipe's LLVM see that it is not
/// negative (`docs/design/bvh.md`, step 19).
const TEXEL_INDEX_BITS: u32 = 27;

/// `BVH_TEXEL_INDEX_MASK` ([`TEXEL_INDEX_BITS`]) for every kernel that reads the word buffer
/// (`glsl/bvh/words.glsl`): the BVH's own, and `evaluate_hit` (`glsl/bvh/hit_record.glsl`).
pub fn texel_index_mask() -> (&'static str, String) {
    (
        "BVH_TEXEL_INDEX_MASK",
        format!("{:#x}u", (1u32 << TEXEL_INDEX_BITS) - 1),
    )
}

/// The 8×8 blocks of a `width` × `height` image, columns and rows: each has an entry point
/// (`glsl/bvh/entry.comp`) and, with the fused pass' block lists, a place in one of them.
pub fn image_blocks(width: u32, height: u32) -> (u32, u32) {
    (width.div_ceil(BLOCK), height.div_ceil(BLOCK))
}

/// The kernels' #defines: the word buffer's record sizes ([`HEADER_WORDS`], [`NODE_WORDS`],
/// [`TRIANGLE_WORDS`]), leaf references ([`LEAF_COUNT_BITS`]), texel indices
/// ([`TEXEL_INDEX_BITS`]) and its last texels, the entries of the image's blocks (columns ×
/// rows: `BVH_BLOCKS_X` × `BVH_ENTRY_TEXELS / BVH_BLOCKS_X`); the kernels store hit records and
/// per-pixel counts (`Accelerator::records`, `glsl/bvh/records.glsl`), in one store of two 64-bit
/// words where the GL implementation has 64-bit integers (`RECORD_STORE_64`); where the
/// profile asks for it (llvmpipe) intersect1 loads the next work group's rays ahead (`PREFETCH_RAYS`,
/// `glsl/bvh/intersect1_main.glsl`); the size of an instance ([`instances`]; whether the walks
/// start at the instances is the pipeline's `BVH_INSTANCES`, which the hit evaluation needs too).
fn kernel_defines(info: &GlInfo, blocks: (u32, u32)) -> [(&'static str, String); 11] {
    [
        ("MAX_GROUPS_X", info.max_groups_x().to_string()),
        ("BVH_INSTANCE_TEXELS", INSTANCE_TEXELS.to_string()),
        ("BVH_ENTRY_TEXELS", (blocks.0 * blocks.1).to_string()),
        ("BVH_BLOCKS_X", blocks.0.to_string()),
        (
            "RECORD_STORE_64",
            (info.profile.record_store_64 as i32).to_string(),
        ),
        (
            "PREFETCH_RAYS",
            (info.profile.prefetch_rays as i32).to_string(),
        ),
        ("BVH_HEADER_WORDS", HEADER_WORDS.to_string()),
        texel_index_mask(),
        ("BVH_NODE_WORDS", NODE_WORDS.to_string()),
        ("BVH_LEAF_COUNT_BITS", LEAF_COUNT_BITS.to_string()),
        ("BVH_TRIANGLE_WORDS", TRIANGLE_WORDS.to_string()),
    ]
}

/// The refit's kernels (`glsl/bvh/refit_*.comp`), with the BVH's defines, timed together
/// ([`Refit::run`]).
fn refit_kernels(b: &BuildContext, defs: &[(&'static str, String)]) -> Result<RefitKernels> {
    let extra = [
        ("REFIT_GROUP", REFIT_GROUP.to_string()),
        ("SCENE_IMAGES", (b.scene_images as i32).to_string()),
        // the records' pass reads through image buffers where the units exist (Refit::run)
        (
            "REFIT_VIEWS",
            ((b.info.profile.image_units as u32 > image::REFIT_BOXES) as i32).to_string(),
        ),
        ("BVH_GRID_STEPS", GRID_STEPS.to_string()),
    ];
    let defs = [defs, &extra[..]].concat();
    let kernel = |file| b.kernel(file, &defs, REFIT_TIMER);
    Ok(RefitKernels {
        leaves: kernel("bvh/refit_leaves.comp")?,
        records: kernel("bvh/refit_records.comp")?,
    })
}

/// The fused pass (`glsl/bvh/fused.glsl`): each pixel's counts in record 0 (the first
/// light's beside the closest hit's where it is a point light), else the first light's at
/// record 1; the other lights' at record 2 where the scene has more than one light
/// (`pipeline::mueller2015::records`). With block lists (`lists`: one tree) two kernels, a
/// work group per block: the blocks whose rays may hit (`glsl/bvh/fused_pass.comp`) and those
/// whose rays all miss (`glsl/bvh/fused_miss.comp`, timed as `fused_miss`;
/// `glsl/bvh/block_lists.glsl`); without (two levels, [`Bvh::create`]) one, a pixel an
/// invocation (`glsl/bvh/fused_instances.comp`). `eye`: the variant that computes the eye rays
/// in place (`PASS_EYE_RAYS`).
fn fused_kernels(
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

/// `--fused-passes` (`glsl/bvh/fused.glsl`): the pass in one kernel, or with one tree in
/// two over the block lists (the blocks that may hit, those that cannot); no kernel without.
struct Fused {
    /// the kernels of the passes whose rays are in the ray-state images, compiled only where
    /// some pass takes them ([`FusedPasses::rays`]; empty without `--fused-passes`)
    loaded: Vec<Kernel>,
    /// those of the first pass computing its eye rays in place (`PASS_EYE_RAYS`), likewise
    eye: Vec<Kernel>,
    /// the entry pass of the first pass computing its eye rays in place (where one does; the
    /// other passes' is [`Bvh::entry`])
    eye_entry: Option<Kernel>,
    /// whether the pass [`Accelerator::fused_pass`] prepared last computes its eye rays in place
    in_place: bool,
    lists: Option<BlockLists>,
    /// the most walks one per-pixel record counts: 1, or with the fused pass a hit's feelers
    walks_per_record: u64,
    /// the most events those walks may count (`max_pixel_events`: the counts over the block
    /// lists sum a block's 64 pixels, the others 16)
    max_events: u64,
}

impl Fused {
    /// The kernels of the pass [`Accelerator::fused_pass`] prepared last.
    fn pass_kernels(&self) -> &[Kernel] {
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
struct BlockLists {
    buffer: Ssbo,
    /// empties the lists before each entry pass and writes their dispatch commands after it
    /// (`glsl/bvh/block_lists.comp`)
    kernel: Kernel,
}

impl BlockLists {
    fn new(b: &BuildContext, defs: &[(&'static str, String)], blocks: u32) -> Result<BlockLists> {
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
    fn step(&self, gl: &Gl, timers: &mut GpuTimers, finish: bool) {
        self.buffer.bind(gl, ssbo::BVH_BLOCK_LISTS);
        self.kernel.use_program();
        self.kernel.set_i32("finish", finish as i32);
        self.kernel.dispatch_1d(timers, 1);
    }
}

fn fused_kernel(
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

/// Invocations of a work group of `glsl/bvh/entry.comp` (`BVH_ENTRY_GROUP`), one block each.
const ENTRY_GROUP: u32 = 64;
const _: () = assert!(
    BLOCK == PIXEL_GROUP,
    "a block is one work group of intersect1"
);

/// The BVH binds its word buffer (with its blocks' entries) at image unit [`image::BVH`], after
/// the pipeline's ray-state images: a GL implementation with fewer units (`GL_MAX_IMAGE_UNITS`;
/// GL 4.5 asks for 8, as many as the BVH binds) gets a clear error here, not a failed link.
fn image_units_suffice(max_image_units: i32) -> Result<()> {
    let needed = image::BVH as i32 + 1;
    if max_image_units < needed {
        bail!(
            "--tracer bvh binds image units up to {}, and a compute kernel may bind \
             {max_image_units} here (the least of GL_MAX_IMAGE_UNITS and \
             GL_MAX_COMPUTE_IMAGE_UNIFORMS); use --tracer base or grid",
            needed - 1
        );
    }
    Ok(())
}

/// The BVH's structure: one tree over the world-space scene (refitted or rebuilt when objects
/// move), or with `--bvh-instances` a tree per object under instances ([`instances`]), built at
/// the first frame (`None` before it), which moving objects update without a refit.
enum Levels {
    One,
    Two(Option<Instances>),
}

/// The refit of the last build's tree ([`refit`]) and what the rebuild policy knows of it.
struct Moving {
    kernels: RefitKernels,
    /// the last build's refit buffers
    refit: Option<Refit>,
    /// refits since the last build
    refits: u64,
    /// the SAH cost of the tree as the last refit whose cost was read left it (the last build's
    /// after a build)
    cost: Cell<f64>,
    /// the fence after the last refit, while its cost is not read: the host reads it once the
    /// GPU has passed the fence, without waiting ([`Bvh::read_cost`])
    pending: Cell<Option<Owned<glow::Fence>>>,
    /// `GL_MAX_SHADER_STORAGE_BLOCK_SIZE`, for the refit's buffers
    max_block: i64,
    /// the compute image units of the profile, for the refit's image-buffer views
    max_units: i32,
    /// the next refit is preceded by one abandoned halfway ([`Bvh::abandon_next_refit_halfway`])
    abandon_next: Cell<bool>,
}

pub struct Bvh {
    gl: Arc<Gl>,
    /// the entry point of each block of intersect1's rays (`glsl/bvh/entry.comp`), into the
    /// last texels of the word buffer: one per 8×8 pixels, row by row (`glsl/bvh/entries.glsl`)
    entry: Kernel,
    /// the blocks of the image
    blocks: u32,
    intersect1: Kernel,
    intersect2: Kernel,
    /// `--fused-passes`: the pass' kernels and block lists
    fused: Fused,
    /// object-space vertex positions of every object (triangle soup, scene order)
    objects: Vec<Vec<Vec3>>,
    /// one tree over the world-space scene, or a tree per object under instances
    levels: Levels,
    /// the model matrices of the tree as uploaded, built or refitted (`None`: not built yet)
    built_for: Option<Vec<Mat4>>,
    buffers: Option<TextureBuffers>,
    /// the last build's facts (its SAH cost: the refits' yardstick)
    stats: BvhStats,
    /// builds so far (the first, and one per frame after a refit that grew the SAH cost past
    /// [`REBUILD_GROWTH`])
    builds: u64,
    /// whether the last frame rebuilt
    rebuilt: bool,
    /// the GPU refit for frames in which objects moved
    moving: Moving,
    /// the last build's world transform, words (octant records, leaf triangles) and upload, ms
    upload_ms: f64,
    /// with instances: this frame's write of the instance table, ms (0 where nothing moved)
    instances_ms: f64,
}

impl Bvh {
    fn create(b: &BuildContext, scene: &Scene, o: &Accel) -> Result<Box<dyn Accelerator>> {
        image_units_suffice(b.info.profile.image_units)?;
        let blocks = image_blocks(b.width, b.height);
        // the fused pass over block lists: with one tree (an instance's empty entry leaves the
        // block's other instances to walk)
        let lists = b.fused.is_some() && !o.instances();
        let defs = kernel_defines(b.info, blocks);
        let entry_defs = [
            ("BVH_ENTRY_GROUP", ENTRY_GROUP.to_string()),
            ("BVH_BLOCK_LISTS", (lists as i32).to_string()),
        ];
        // timed as a part of intersect1: the closest-hit search of the passes
        let entry = |eye: bool| {
            let pass = [("PASS_EYE_RAYS", (eye as i32).to_string())];
            b.kernel(
                "bvh/entry.comp",
                &[&defs[..], &entry_defs[..], &pass[..]].concat(),
                "intersect1",
            )
        };
        let rays = b.fused.map(|f| f.rays);
        let fused = |eye: bool| match b.fused {
            Some(f) if (eye && f.rays.eye_in_place) || (!eye && f.rays.loaded) => {
                fused_kernels(b, &defs, f, lists, eye)
            }
            _ => Ok(Vec::new()),
        };
        Ok(Box::new(Bvh {
            gl: b.gl.clone(),
            entry: entry(false)?,
            blocks: blocks.0 * blocks.1,
            intersect1: b.kernel("bvh/intersect1.comp", &defs, "intersect1")?,
            intersect2: b.kernel("bvh/intersect2.comp", &defs, "intersect2")?,
            fused: Fused {
                loaded: fused(false)?,
                eye: fused(true)?,
                eye_entry: rays
                    .is_some_and(|r| r.eye_in_place)
                    .then(|| entry(true))
                    .transpose()?,
                in_place: false,
                lists: lists
                    .then(|| BlockLists::new(b, &defs, blocks.0 * blocks.1))
                    .transpose()?,
                walks_per_record: b.fused.map_or(1, |f| f.feelers.max(1)) as u64,
                max_events: max_pixel_events(match lists {
                    true => BLOCK * BLOCK,
                    false => PIXELS_PER_INVOCATION,
                }),
            },
            moving: Moving {
                kernels: refit_kernels(b, &defs)?,
                refit: None,
                refits: 0,
                cost: Cell::new(0.0),
                pending: Cell::new(None),
                max_block: b.info.max_ssbo_block_size,
                max_units: b.info.profile.image_units,
                abandon_next: Cell::new(false),
            },
            objects: scene
                .objects
                .iter()
                .map(|o| o.mesh.positions.clone())
                .collect(),
            levels: match o.instances() {
                true => Levels::Two(None),
                false => Levels::One,
            },
            built_for: None,
            buffers: None,
            stats: BvhStats::default(),
            builds: 0,
            rebuilt: false,
            upload_ms: 0.0,
            instances_ms: 0.0,
        }))
    }

    /// Build on the CPU and upload.
    fn rebuild(&mut self, models: &[Mat4]) -> Result<()> {
        let start = std::time::Instant::now();
        let bvh = BvhTree::new(transform_triangles(
            self.objects
                .iter()
                .map(Vec::as_slice)
                .zip(models.iter().copied()),
        ));
        let events = bvh.stats.nodes.max(bvh.tris.len()) as u64;
        if events * self.fused.walks_per_record > self.fused.max_events {
            bail!(
                "the BVH has {} nodes and {} leaf slots: {} walks of a pixel could count more than \
                 {} events, beyond the per-pixel counts' 32 bits; use a smaller scene (or, with \
                 --fused-passes, fewer lights or light samples)",
                bvh.stats.nodes,
                bvh.tris.len(),
                self.fused.walks_per_record,
                self.fused.max_events
            );
        }
        let buffers = upload(&self.gl, bvh.gpu_words(), self.blocks)?;
        let m = &self.moving;
        let refit = Refit::new(&self.gl, &bvh, m.max_block, m.max_units)?;
        // the old buffers (if any) drop after the new ones are made, as before
        self.buffers = Some(buffers);
        self.moving.refit = Some(refit);
        self.drop_pending();
        self.moving.refits = 0;
        self.moving.cost.set(bvh.stats.sah_cost);
        self.stats = bvh.stats;
        // the rest: the world transform, the words (octant records, leaf triangles), the upload
        self.upload_ms = start.elapsed().as_secs_f64() * 1e3 - bvh.stats.build_ms;
        self.built_for = Some(models.to_vec());
        self.builds += 1;
        Ok(())
    }

    /// `--bvh-instances`: build every object's tree and upload them under the instances the
    /// first time; after that write only the instances (their world boxes and inverse model
    /// matrices), a frame's whole update where objects moved.
    fn place_instances(&mut self, models: &[Mat4]) -> Result<()> {
        let start = std::time::Instant::now();
        match (&self.levels, &self.buffers) {
            (Levels::Two(Some(inst)), Some(buffers)) => {
                buffers.write_u32(&self.gl, 0, &inst.table(models)?);
                self.instances_ms = start.elapsed().as_secs_f64() * 1e3;
            }
            _ => {
                let inst = Instances::new(&self.objects);
                if inst.events() * self.fused.walks_per_record > self.fused.max_events {
                    bail!(
                        "the objects' trees have {} events a walk (instances, nodes, leaf slots): \
                         {} walks of a pixel could count more than {}, beyond the per-pixel \
                         counts' 32 bits; use a smaller scene",
                        inst.events(),
                        self.fused.walks_per_record,
                        self.fused.max_events
                    );
                }
                self.buffers = Some(upload(&self.gl, inst.gpu_words(models)?, self.blocks)?);
                self.stats = inst.stats();
                self.moving.cost.set(self.stats.sah_cost);
                self.levels = Levels::Two(Some(inst));
                self.rebuilt = true;
                self.builds += 1;
                // the words and their upload, after the trees
                self.upload_ms = start.elapsed().as_secs_f64() * 1e3 - self.stats.build_ms;
            }
        }
        self.built_for = Some(models.to_vec());
        Ok(())
    }

    /// The facts of the last build.
    pub fn build_stats(&self) -> BvhStats {
        self.stats
    }

    /// The number of builds so far.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// For tests: the word buffer as the GPU holds it ([`BvhTree::gpu_words`], then the block
    /// entries), empty before the first build.
    pub fn words(&self) -> Vec<u32> {
        let b = self.buffers.as_ref();
        b.map(|b| b.read_u32(&self.gl, 0)).unwrap_or_default()
    }

    /// For tests: the next refit is preceded by one whose boxes pass covers half the leaves and
    /// stops there, as a refit cut short would leave the buffers; the next must be whole.
    #[doc(hidden)]
    pub fn abandon_next_refit_halfway(&self) {
        self.moving.abandon_next.set(true);
    }

    /// The number of refits since the last build.
    pub fn refits(&self) -> u64 {
        self.moving.refits
    }

    /// The SAH cost of the tree as the last refit left it over the last build's (1 after a
    /// build): past [`REBUILD_GROWTH`], the next frame that moves an object rebuilds. Waits for
    /// the last refit (for tests; the frames read it without waiting: [`Bvh::read_cost`]).
    pub fn sah_growth(&self) -> Result<f64> {
        self.read_cost(true)?;
        Ok(self.moving.cost.get() / self.stats.sah_cost)
    }

    /// Read the last refit's SAH cost (32 bytes) once the GPU has finished the refit: with
    /// `wait`, now; without, only if it has (a fence), else the cost stays the one before and
    /// is read at a later frame. So a frame never waits for its refit; the rebuild a refit's
    /// growth calls for comes at the first moving frame after its cost was read — the next
    /// frame, where the frame's statistics (timer queries) waited for the GPU anyway, else a
    /// frame or more later (docs/design/bvh.md, "Moving objects").
    fn read_cost(&self, wait: bool) -> Result<()> {
        let Some(fence) = self.moving.pending.take() else {
            return Ok(());
        };
        let timeout = if wait { i32::MAX } else { 0 };
        loop {
            // SAFETY: a fence of ours, alive while `fence` is (deleted as it drops).
            let flush = glow::SYNC_FLUSH_COMMANDS_BIT;
            let state = unsafe { self.gl.client_wait_sync(fence.raw(), flush, timeout) };
            match state {
                glow::TIMEOUT_EXPIRED if wait => continue,
                glow::TIMEOUT_EXPIRED => {
                    self.moving.pending.set(Some(fence));
                    return Ok(());
                }
                _ => break,
            }
        }
        drop(fence);
        let refit = self
            .moving
            .refit
            .as_ref()
            .expect("a refit before its fence");
        self.moving.cost.set(refit.sah_cost(&self.gl)?);
        Ok(())
    }

    /// Forget the last refit's cost unread (a rebuild replaces it).
    fn drop_pending(&self) {
        drop(self.moving.pending.take());
    }

    /// Refit the tree on the GPU to this frame's world-space vertices (the scene's `vertex` SSBO,
    /// bound); its SAH cost is read later ([`Bvh::read_cost`]).
    fn refit(&mut self, f: &mut FrameContext) -> Result<()> {
        let refit = self.moving.refit.as_ref().expect("a tree to refit");
        self.bind(f.gl, glow::READ_WRITE);
        let buffers = self.buffers.as_ref().expect("a built tree's buffers");
        let storage = buffers.bind_storage(f.gl, 0, ssbo::BVH_WORDS, self.moving.max_block);
        if self.moving.abandon_next.take() {
            refit.run_abandoned(f.gl, f.timers, &self.moving.kernels, storage);
        }
        refit.run(f.gl, f.timers, &self.moving.kernels, storage);
        self.drop_pending();
        // SAFETY: a fence on a current context, owned (deleted as it drops).
        let fence = unsafe { f.gl.fence_sync(glow::SYNC_GPU_COMMANDS_COMPLETE, 0) };
        let fence = fence.map_err(|e| anyhow!("glFenceSync: {e}"))?;
        self.moving.pending.set(Some(Owned::new(f.gl, fence)));
        self.built_for = Some(f.models.to_vec());
        self.moving.refits += 1;
        Ok(())
    }

    /// The blocks' entry pass `entry` (`glsl/bvh/entry.comp`; with `eye`'s camera where it
    /// computes the eye rays in place), the word buffer bound for it to write its entries and
    /// then for the walks to read them.
    fn dispatch_entry(&self, f: &mut FrameContext, entry: &Kernel, eye: Option<&CameraRays>) {
        self.bind(f.gl, glow::READ_WRITE);
        entry.use_program();
        if let Some(cam) = eye {
            set_camera(entry, cam);
        }
        entry.dispatch_1d(f.timers, self.blocks.div_ceil(ENTRY_GROUP));
        self.bind(f.gl, glow::READ_ONLY);
    }

    /// Bind the word buffer with `access`: the entry kernel writes its last texels
    /// (`glow::READ_WRITE`), the others only read it (`glow::READ_ONLY`).
    /// The fused pass' entry pass (and its block lists around it) for the pass' rays: the eye
    /// rays of `eye` in place, or the loaded ray state.
    fn fused_entry(&mut self, f: &mut FrameContext, eye: Option<&CameraRays>) {
        self.fused.in_place = eye.is_some();
        if let Some(lists) = &self.fused.lists {
            lists.step(f.gl, f.timers, false);
        }
        let entry = match eye {
            Some(_) => self.fused.eye_entry.as_ref(),
            None => Some(&self.entry),
        };
        let entry = entry.expect("the entry pass of the rays the frame's passes take");
        self.dispatch_entry(f, entry, eye);
        if let Some(lists) = &self.fused.lists {
            // the lists' dispatch commands from what the entry pass counted
            lists.step(f.gl, f.timers, true);
        }
    }

    /// Dispatch the fused kernels of the pass, their uniforms set; without `misses` not the
    /// one for the blocks whose rays all miss (their pixels were filled by clears).
    fn dispatch_fused(&self, f: &mut FrameContext, misses: bool) {
        let kernels = self.fused.pass_kernels();
        match &self.fused.lists {
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

    fn bind(&self, gl: &Gl, access: u32) {
        if let Some(b) = &self.buffers {
            b.bind_images(gl, access);
        }
    }
}

impl Accelerator for Bvh {
    fn build(&mut self, f: &mut FrameContext) -> Result<()> {
        self.rebuilt = false;
        self.instances_ms = 0.0;
        if self.built_for.as_deref() == Some(f.models) {
            return Ok(());
        }
        if let Levels::Two(_) = self.levels {
            return self.place_instances(f.models);
        }
        self.read_cost(false)?;
        let growth = self.moving.cost.get() / self.stats.sah_cost;
        if self.moving.refit.is_some() && growth <= REBUILD_GROWTH {
            return self.refit(f);
        }
        self.rebuilt = true;
        self.rebuild(f.models)
    }

    fn closest_hit(&mut self, f: &mut FrameContext, _pass: u32) -> &Kernel {
        self.dispatch_entry(f, &self.entry, None);
        self.intersect1.use_program();
        &self.intersect1
    }

    fn occluded(&mut self, f: &mut FrameContext, _target: &LightTarget) -> &Kernel {
        self.bind(f.gl, glow::READ_ONLY);
        self.intersect2.use_program();
        &self.intersect2
    }

    fn stats(&self, stats: &mut FrameStats) {
        let s = &self.stats;
        let f = &mut stats.facts;
        f.insert("bvh_build_ms".into(), json!(s.build_ms));
        f.insert("bvh_upload_ms".into(), json!(self.upload_ms));
        if let Levels::Two(Some(inst)) = &self.levels {
            f.insert("bvh_instances".into(), json!(inst.trees.len()));
            f.insert("bvh_instances_ms".into(), json!(self.instances_ms));
        }
        f.insert("bvh_rebuilt".into(), json!(self.rebuilt));
        f.insert("bvh_nodes".into(), json!(s.nodes));
        f.insert("bvh_leaves".into(), json!(s.leaves));
        f.insert("bvh_depth".into(), json!(s.depth));
        f.insert("bvh_bytes".into(), json!(s.bytes));
        // the frame's timer queries were read: its refit is done, its cost read without a wait
        let _ = self.read_cost(false);
        f.insert("bvh_sah_cost".into(), json!(self.moving.cost.get()));
        f.insert("bvh_build_sah_cost".into(), json!(s.sah_cost));
        f.insert("bvh_refits".into(), json!(self.moving.refits));
        let refit_ms = stats.gpu_ms.get(REFIT_TIMER).copied().unwrap_or(0.0);
        f.insert("bvh_refit_ms".into(), json!(refit_ms));
    }

    fn fused_pass(
        &mut self,
        f: &mut FrameContext,
        _pass: u32,
        eye: Option<&CameraRays>,
        host: &dyn PassHost,
    ) -> Option<FusedRun> {
        if self.fused.loaded.is_empty() && self.fused.eye.is_empty() {
            return None;
        }
        self.fused_entry(f, eye);
        for k in self.fused.pass_kernels() {
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
            lists: self.fused.lists.is_some(),
            clears: eye.is_some() && self.fused.lists.is_some(),
        };
        if run.clears {
            host.fill_misses(f.gl, f.timers);
        }
        self.dispatch_fused(f, !run.clears);
        Some(run)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn too_few_image_units_are_refused_by_name() {
        let err = super::image_units_suffice(7).unwrap_err().to_string();
        assert!(
            err.contains("GL_MAX_IMAGE_UNITS") && err.contains("up to 7"),
            "{err}"
        );
        // GL 4.5's minimum suffices
        assert!(super::image_units_suffice(8).is_ok());
    }
}
