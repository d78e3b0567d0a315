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

use anyhow::{bail, Result};
use bytemuck::Zeroable;
use glam::{Mat4, Vec3};
use serde_json::json;

use super::interface::{
    max_pixel_events, Accelerator, BuildContext, Entry, FrameContext, FusedRun, LightTarget,
    PassHost, PIXELS_PER_INVOCATION,
};
use super::options::{Accel, BvhLevels, BvhOptions, BvhPasses};
use crate::frame::FrameStats;
use crate::gl::kernel::PIXEL_GROUP;
use crate::gl::resources::{TexelData, TextureBuffers};
use crate::gl::slots::image;
use crate::gl::{Gl, GlInfo, Kernel};
use crate::scene::{transform_triangles, CameraRays, Scene};

mod build;
mod fused;
pub mod instances;
pub mod layout;
mod moving;
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

use fused::{fused_kernels, BlockLists, EntryPass, Fused, ENTRY_GROUP};
use moving::{refit_kernels, Moving};

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

pub struct Bvh {
    gl: Arc<Gl>,
    /// the entry point of each block of intersect1's rays (`glsl/bvh/entry.comp`), into the
    /// last texels of the word buffer: one per 8×8 pixels, row by row (`glsl/bvh/entries.glsl`)
    entry: Kernel,
    /// the blocks of the image
    blocks: u32,
    /// the four kernels' intersect1 and intersect2 (`--four-kernels`; `None` for the fused pass,
    /// which runs kernels of its own)
    four: Option<[Kernel; 2]>,
    /// the fused pass' kernels and block lists (empty with the four kernels)
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
            four: match b.fused {
                Some(_) => None,
                None => Some([
                    b.kernel("bvh/intersect1.comp", &defs, "intersect1")?,
                    b.kernel("bvh/intersect2.comp", &defs, "intersect2")?,
                ]),
            },
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
                 the fused pass, fewer lights or light samples)",
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
        self.moving.drop_pending();
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

    /// The blocks' entry pass `entry` (`glsl/bvh/entry.comp`; with `eye`'s camera where it
    /// computes the eye rays in place), the word buffer bound for it to write its entries and
    /// then for the walks to read them.
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
    /// the last refit (for tests; the frames read it without waiting).
    pub fn sah_growth(&self) -> Result<f64> {
        self.moving.read_cost(&self.gl, true)?;
        Ok(self.moving.cost.get() / self.stats.sah_cost)
    }

    /// Refit the tree on the GPU to this frame's world-space vertices ([`moving`]).
    fn refit(&mut self, f: &mut FrameContext) -> Result<()> {
        self.bind(f.gl, glow::READ_WRITE);
        let buffers = self.buffers.as_ref().expect("a built tree's buffers");
        self.moving.run(f, buffers)?;
        self.built_for = Some(f.models.to_vec());
        Ok(())
    }

    /// The entry pass over this tree as uploaded.
    fn entry_pass(&self) -> EntryPass<'_> {
        EntryPass {
            buffers: self.buffers.as_ref(),
            blocks: self.blocks,
        }
    }

    /// intersect1 and intersect2 of the four kernels, which the pipeline asks for only where the
    /// BVH was made without its fused pass.
    fn four_kernels(&self) -> &[Kernel; 2] {
        self.four
            .as_ref()
            .expect("the four kernels' intersection kernels: made with --four-kernels")
    }

    fn bind(&self, gl: &Gl, access: u32) {
        self.entry_pass().bind(gl, access);
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
        self.moving.read_cost(&self.gl, false)?;
        let growth = self.moving.cost.get() / self.stats.sah_cost;
        if self.moving.refit.is_some() && growth <= REBUILD_GROWTH {
            return self.refit(f);
        }
        self.rebuilt = true;
        self.rebuild(f.models)
    }

    fn closest_hit(&mut self, f: &mut FrameContext, _pass: u32) -> &Kernel {
        self.entry_pass().dispatch(f, &self.entry, None);
        let k = &self.four_kernels()[0];
        k.use_program();
        k
    }

    fn occluded(&mut self, f: &mut FrameContext, _target: &LightTarget) -> &Kernel {
        self.bind(f.gl, glow::READ_ONLY);
        let k = &self.four_kernels()[1];
        k.use_program();
        k
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
        let _ = self.moving.read_cost(&self.gl, false);
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
        // the fields, not entry_pass(): the pass borrows self.fused mutably beside them
        let entry = EntryPass {
            buffers: self.buffers.as_ref(),
            blocks: self.blocks,
        };
        self.fused.run(f, eye, host, (&entry, &self.entry))
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
