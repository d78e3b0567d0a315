//! A moving scene over one tree: the GPU refit of the last build's topology ([`super::refit`]),
//! the SAH cost it leaves read back without a wait (a fence, an owned GL object), and the
//! rebuild policy that rebuilds on the CPU once a refit grew the cost past
//! [`super::REBUILD_GROWTH`] times the build's.

use std::cell::Cell;

use anyhow::{anyhow, Result};
use glow::HasContext;

use super::planes::GRID_STEPS;
use super::refit::{Refit, RefitKernels, REFIT_GROUP, REFIT_TIMER};
use crate::accel::interface::{BuildContext, FrameContext};
use crate::gl::resources::{Owned, TextureBuffers};
use crate::gl::slots::{image, ssbo};
use crate::gl::Gl;

/// The refit of the last build's tree ([`refit`]) and what the rebuild policy knows of it.
pub(super) struct Moving {
    pub(super) kernels: RefitKernels,
    /// the last build's refit buffers
    pub(super) refit: Option<Refit>,
    /// refits since the last build
    pub(super) refits: u64,
    /// the SAH cost of the tree as the last refit whose cost was read left it (the last build's
    /// after a build)
    pub(super) cost: Cell<f64>,
    /// the fence after the last refit, while its cost is not read: the host reads it once the
    /// GPU has passed the fence, without waiting ([`Moving::read_cost`])
    pub(super) pending: Cell<Option<Owned<glow::Fence>>>,
    /// `GL_MAX_SHADER_STORAGE_BLOCK_SIZE`, for the refit's buffers
    pub(super) max_block: i64,
    /// the compute image units of the profile, for the refit's image-buffer views
    pub(super) max_units: i32,
    /// the next refit is preceded by one abandoned halfway (`Bvh::abandon_next_refit_halfway`)
    pub(super) abandon_next: Cell<bool>,
}

/// The refit's kernels (`glsl/bvh/refit_*.comp`), with the BVH's defines, timed together
/// ([`Refit::run`]).
pub(super) fn refit_kernels(
    b: &BuildContext,
    defs: &[(&'static str, String)],
) -> Result<RefitKernels> {
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

impl Moving {
    /// Read the last refit's SAH cost (32 bytes) once the GPU has finished the refit: with
    /// `wait`, now; without, only if it has (a fence), else the cost stays the one before and
    /// is read at a later frame. So a frame never waits for its refit; the rebuild a refit's
    /// growth calls for comes at the first moving frame after its cost was read — the next
    /// frame, where the frame's statistics (timer queries) waited for the GPU anyway, else a
    /// frame or more later (docs/design/bvh.md, "Moving objects").
    pub(super) fn read_cost(&self, gl: &Gl, wait: bool) -> Result<()> {
        let Some(fence) = self.pending.take() else {
            return Ok(());
        };
        let timeout = if wait { i32::MAX } else { 0 };
        loop {
            // SAFETY: a fence of ours, alive while `fence` is (deleted as it drops).
            let flush = glow::SYNC_FLUSH_COMMANDS_BIT;
            let state = unsafe { gl.client_wait_sync(fence.raw(), flush, timeout) };
            match state {
                glow::TIMEOUT_EXPIRED if wait => continue,
                glow::TIMEOUT_EXPIRED => {
                    self.pending.set(Some(fence));
                    return Ok(());
                }
                _ => break,
            }
        }
        drop(fence);
        let refit = self.refit.as_ref().expect("a refit before its fence");
        self.cost.set(refit.sah_cost(gl)?);
        Ok(())
    }

    /// Forget the last refit's cost unread (a rebuild replaces it).
    pub(super) fn drop_pending(&self) {
        drop(self.pending.take());
    }

    /// Refit the tree in `buffers` on the GPU to this frame's world-space vertices (the
    /// scene's `vertex` SSBO, bound; the word buffer's images bound for writing); its SAH cost
    /// is read later ([`Moving::read_cost`]).
    pub(super) fn run(&mut self, f: &mut FrameContext, buffers: &TextureBuffers) -> Result<()> {
        let refit = self.refit.as_ref().expect("a tree to refit");
        let storage = buffers.bind_storage(f.gl, 0, ssbo::BVH_WORDS, self.max_block);
        if self.abandon_next.take() {
            refit.run_abandoned(f.gl, f.timers, &self.kernels, storage);
        }
        refit.run(f.gl, f.timers, &self.kernels, storage);
        self.drop_pending();
        // SAFETY: a fence on a current context, owned (deleted as it drops).
        let fence = unsafe { f.gl.fence_sync(glow::SYNC_GPU_COMMANDS_COMPLETE, 0) };
        let fence = fence.map_err(|e| anyhow!("glFenceSync: {e}"))?;
        self.pending.set(Some(Owned::new(f.gl, fence)));
        self.refits += 1;
        Ok(())
    }
}
