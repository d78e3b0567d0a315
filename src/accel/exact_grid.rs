//! The exact uniform grid — ours, after Müller 2015 ch. 3.2 and 4.2, rebuilt on the GPU every
//! frame: triangle/box overlap registration, compact lists built by a count pass, a prefix sum
//! and a fill pass, and a 3D-DDA inside the intersection kernels that ends only at a hit inside
//! the current voxel (`glsl/exact_grid/`). Its image equals the base tracer's. CPU twin:
//! `reference::exact_grid`. With `--proximity-clouds` a fifth pass (`proximity.comp`) writes
//! every voxel's Chebyshev distance to the nearest non-empty voxel after the lists, and the
//! DDA jumps out of empty voxels by it (the streaming tracer's proximity clouds, `dda.glsl`).

use std::any::Any;
use std::sync::Arc;

use anyhow::Result;
use serde_json::json;

use super::grid_frame::GridMapping;
use super::grid_frame::{lists_of, resolution, GridFrame};
use super::interface::{Accelerator, BuildContext, Entry, FrameContext, LightTarget};
use super::options::{Accel, ExactGridOptions};
use crate::frame::FrameStats;
use crate::gl::resources::Ssbo;
use crate::gl::slots::ssbo;
use crate::gl::{Gl, Kernel};
use crate::scene::Scene;

/// Largest resolution: the prefix sum handles 2048 blocks of 1024 voxels.
pub const MAX_RESOLUTION: u32 = 128;

/// The largest distance the exact grid's per-frame pass computes (`glsl/exact_grid/
/// proximity.comp`, uniform `cloudCap`): each voxel scans its line outward only as far as its
/// distance so far, so the cap bounds the pass at 2·(cap − 1) reads per voxel and axis (without
/// it the empty voxels of a large grid scan their whole lines, which costs more than the jumps
/// save). A capped distance, min(d, cap), is still safe — it only claims a smaller cube empty —
/// and the separable passes compute exactly min(d, cap); the jumps then skip at most 2·cap − 1
/// voxels. The streaming grid's distances, computed once
/// on the CPU, are not capped.
pub const EXACT_GRID_CLOUD_CAP: u32 = 8;

/// The exact grid with `--grid auto`, without proximity clouds.
const PLAIN: Accel = Accel::ExactGrid(ExactGridOptions {
    resolution: None,
    proximity_clouds: false,
});

pub const ENTRY: Entry = Entry {
    label: "grid-exact",
    plain: PLAIN,
    records: false,
    variants: &[
        ("grid exact", PLAIN),
        (
            "grid exact pc",
            Accel::ExactGrid(ExactGridOptions {
                resolution: None,
                proximity_clouds: true,
            }),
        ),
    ],
    gpu: ExactGrid::create,
};

/// The compact lists: voxelCount (references per voxel), voxelStart (their prefix sum),
/// voxelFill (the fill pass's cursor), blockSums and gridTotal (the prefix sum's),
/// voxelTrisFilled (the references as filled) and voxelTris (ordered by id; both grown to the
/// count of every build), voxelDist and voxelDistTmp (the proximity clouds and the middle pass'
/// output; 4 bytes when the clouds are off).
struct Lists {
    voxel_count: Ssbo,
    voxel_start: Ssbo,
    voxel_fill: Ssbo,
    block_sums: Ssbo,
    grid_total: Ssbo,
    voxel_tris_filled: Ssbo,
    voxel_tris: Ssbo,
    voxel_dist: Ssbo,
    voxel_dist_tmp: Ssbo,
}

impl Lists {
    fn all(&self) -> [(&Ssbo, u32); 9] {
        [
            (&self.voxel_count, ssbo::VOXEL_COUNT),
            (&self.voxel_start, ssbo::VOXEL_START),
            (&self.voxel_fill, ssbo::VOXEL_FILL),
            (&self.block_sums, ssbo::BLOCK_SUMS),
            (&self.grid_total, ssbo::GRID_TOTAL),
            (&self.voxel_tris_filled, ssbo::VOXEL_TRIS_FILLED),
            (&self.voxel_tris, ssbo::VOXEL_TRIS),
            (&self.voxel_dist, ssbo::VOXEL_DIST),
            // bound by the proximity passes only
            (&self.voxel_dist_tmp, ssbo::DIST_OUT),
        ]
    }

    fn bind(&self, gl: &Gl) {
        for (b, slot) in self.all() {
            b.bind(gl, slot);
        }
    }
}

pub struct ExactGrid {
    gl: Arc<Gl>,
    frame: GridFrame,
    triangles: usize,
    count: Kernel,
    scan: Kernel,
    fill: Kernel,
    order: Kernel,
    intersect1: Kernel,
    intersect2: Kernel,
    /// `--proximity-clouds`: the distance pass
    proximity: Option<Kernel>,
    lists: Lists,
    max_ssbo: i64,
    /// triangle references of the last build
    refs: u64,
}

/// What decides the size of the grid's buffers, for a refusal.
const SIZED_BY: &str = "--grid (N³ voxels) with the scene (its references)";

impl ExactGrid {
    fn create(b: &BuildContext, scene: &Scene, o: &Accel) -> Result<Box<dyn Accelerator>> {
        let Accel::ExactGrid(o) = o else {
            unreachable!("made from its own options")
        };
        let n = resolution(scene, o.resolution, "exact", MAX_RESOLUTION)?;
        let frame = GridFrame::new(scene, n);
        let n3 = frame.voxels();
        let defs = [frame.define()];
        let max_ssbo = b.info.max_ssbo_block_size;
        // the voxel arrays are --grid's (N³), the reference lists the scene's with --grid
        let ssbo = |name, bytes| Ssbo::sized(b.gl, name, bytes, None, max_ssbo, SIZED_BY);
        let dist_bytes = if o.proximity_clouds { 4 * n3 } else { 4 };
        let lists = Lists {
            voxel_count: ssbo("voxelCount", 4 * n3)?,
            voxel_start: ssbo("voxelStart", 4 * n3)?,
            voxel_fill: ssbo("voxelFill", 4 * n3)?,
            block_sums: ssbo("blockSums", 4 * n3.div_ceil(1024))?,
            grid_total: ssbo("gridTotal", 16)?,
            // grown to the number of references on the first build
            voxel_tris_filled: ssbo("voxelTrisFilled", 4 * scene.triangle_count())?,
            voxel_tris: ssbo("voxelTris", 4 * scene.triangle_count())?,
            voxel_dist: ssbo("voxelDist", dist_bytes)?,
            voxel_dist_tmp: ssbo("voxelDistTmp", dist_bytes)?,
        };
        let proximity = o
            .proximity_clouds
            .then(|| b.kernel("exact_grid/proximity.comp", &defs, "grid_proximity"))
            .transpose()?;
        Ok(Box::new(ExactGrid {
            gl: b.gl.clone(),
            triangles: scene.triangle_count(),
            count: b.kernel("exact_grid/count.comp", &defs, "grid_count")?,
            scan: b.kernel("exact_grid/scan.comp", &defs, "grid_scan")?,
            fill: b.kernel("exact_grid/fill.comp", &defs, "grid_fill")?,
            order: b.kernel("exact_grid/order.comp", &[], "grid_order")?,
            intersect1: b.kernel("exact_grid/intersect1.comp", &defs, "intersect1")?,
            intersect2: b.kernel("exact_grid/intersect2.comp", &defs, "intersect2")?,
            proximity,
            lists,
            max_ssbo,
            refs: 0,
            frame,
        }))
    }

    /// The prefix sum over the voxel counts, in three phases (block sums, their sum, offsets).
    fn scan(&self, f: &mut FrameContext) {
        let n3 = self.frame.voxels() as u32;
        let blocks = n3.div_ceil(1024);
        let k = &self.scan;
        k.use_program();
        k.set_i32("voxelTotal", n3 as i32);
        k.set_i32("blockCount", blocks as i32);
        for (phase, groups) in [(0, blocks), (1, 1), (2, blocks)] {
            k.set_i32("scanPhase", phase);
            k.dispatch_1d(f.timers, groups);
        }
    }

    /// Sort every voxel's list by triangle id (`glsl/exact_grid/order.comp`).
    fn order(&self, f: &mut FrameContext, total: u32) {
        let k = &self.order;
        k.use_program();
        k.set_i32("referenceCount", total as i32);
        k.set_i32("voxelTotal", self.frame.voxels() as i32);
        k.dispatch_1d(f.timers, total.div_ceil(128).max(1));
    }

    /// The proximity clouds (`glsl/exact_grid/proximity.comp`): the x pass from the counts into
    /// voxelDist, y into voxelDistTmp, z back into voxelDist.
    fn proximity(&self, f: &mut FrameContext) {
        let Some(k) = &self.proximity else { return };
        let (gl, l) = (f.gl, &self.lists);
        let groups = (self.frame.voxels() as u32).div_ceil(128);
        k.use_program();
        self.frame.set_uniforms(k);
        k.set_i32("cloudCap", EXACT_GRID_CLOUD_CAP.min(self.frame.n) as i32);
        let passes = [
            (&l.voxel_dist_tmp, &l.voxel_dist),
            (&l.voxel_dist, &l.voxel_dist_tmp),
            (&l.voxel_dist_tmp, &l.voxel_dist),
        ];
        for (axis, (input, output)) in passes.into_iter().enumerate() {
            input.bind(gl, ssbo::DIST_IN);
            output.bind(gl, ssbo::DIST_OUT);
            k.set_i32("axis", axis as i32);
            k.set_i32("fromCounts", (axis == 0) as i32);
            k.dispatch_1d(f.timers, groups);
        }
    }

    /// The proximity-cloud distances of the last build (`--proximity-clouds`), for tests.
    pub fn read_distances(&self, gl: &Gl) -> Option<Vec<u32>> {
        let n3 = self.frame.voxels();
        let d = self
            .proximity
            .as_ref()
            .map(|_| self.lists.voxel_dist.read_u32(gl));
        d.map(|d| d[..n3].to_vec())
    }

    /// Make room for `total` references (half again as many, so a moving scene rarely
    /// reallocates).
    fn reserve(&mut self, total: usize) -> Result<()> {
        if 4 * total > self.lists.voxel_tris.bytes {
            let bytes = (4 * total + 4 * total / 2).max(16);
            let l = &mut self.lists;
            for (b, name) in [
                (&mut l.voxel_tris_filled, "voxelTrisFilled"),
                (&mut l.voxel_tris, "voxelTris"),
            ] {
                // a 16-byte stand-in first, so the old buffer is deleted before the larger
                // one is made: the peak holds one of them, not both
                *b = Ssbo::sized(&self.gl, name, 16, None, self.max_ssbo, SIZED_BY)?;
                *b = Ssbo::sized(&self.gl, name, bytes, None, self.max_ssbo, SIZED_BY)?;
            }
        }
        Ok(())
    }

    /// The voxel lists of the last build read back (triangle ids in storage order) and the
    /// mapping used. For tests and inspection.
    pub fn read_lists(&self, gl: &Gl) -> (Vec<Vec<i32>>, GridMapping) {
        let count = self.lists.voxel_count.read_u32(gl);
        let start = self.lists.voxel_start.read_u32(gl);
        let tris = self.lists.voxel_tris.read_u32(gl);
        let lists = lists_of(self.frame.voxels(), &tris, |v| {
            (start[v] as usize, count[v] as usize)
        });
        (lists, self.frame.mapping)
    }

    /// The voxels of the last build whose fill pass registered another number of triangles than
    /// the count pass reserved (fewer leaves list slots unwritten, more is counted as
    /// truncated): 0 where the two programs agree on every overlap. For tests and inspection.
    pub fn count_fill_mismatches(&self, gl: &Gl) -> usize {
        let count = self.lists.voxel_count.read_u32(gl);
        let fill = self.lists.voxel_fill.read_u32(gl);
        count.iter().zip(&fill).filter(|(c, f)| c != f).count()
    }

    pub fn resolution(&self) -> u32 {
        self.frame.n
    }
}

impl Accelerator for ExactGrid {
    fn build(&mut self, f: &mut FrameContext) -> Result<()> {
        self.frame.update(f.models);
        let tri_groups = (self.triangles as u32).div_ceil(128);
        let (gl, l) = (f.gl, &self.lists);
        f.timers.time(gl, "grid_clear", || {
            l.voxel_count.clear_u32(gl, 0);
            l.voxel_fill.clear_u32(gl, 0);
        });
        self.lists.bind(gl);
        self.count.use_program();
        self.frame.set_uniforms(&self.count);
        self.count.dispatch_1d(f.timers, tri_groups);
        self.scan(f);
        // the number of references sizes the compact lists
        let total = self.lists.grid_total.read_u32(gl)[0] as usize;
        self.refs = total as u64;
        self.reserve(total)?;
        self.lists.bind(gl);
        self.fill.use_program();
        self.frame.set_uniforms(&self.fill);
        self.fill.dispatch_1d(f.timers, tri_groups);
        self.order(f, total as u32);
        self.proximity(f);
        Ok(())
    }

    fn closest_hit(&mut self, f: &mut FrameContext, _pass: u32) -> &Kernel {
        self.lists.bind(f.gl);
        self.intersect1.use_program();
        self.frame.set_uniforms(&self.intersect1);
        let clouds = self.proximity.is_some() as i32;
        self.intersect1.set_i32("proximityClouds", clouds);
        &self.intersect1
    }

    fn occluded(&mut self, f: &mut FrameContext, _target: &LightTarget) -> &Kernel {
        self.lists.bind(f.gl);
        self.intersect2.use_program();
        self.frame.set_uniforms(&self.intersect2);
        let clouds = self.proximity.is_some() as i32;
        self.intersect2.set_i32("proximityClouds", clouds);
        &self.intersect2
    }

    fn stats(&self, stats: &mut FrameStats) {
        let build: f64 = [
            "grid_clear",
            "grid_count",
            "grid_scan",
            "grid_fill",
            "grid_order",
            "grid_proximity",
        ]
        .iter()
        .filter_map(|k| stats.gpu_ms.get(*k))
        .sum();
        let bytes: usize = self.lists.all().iter().map(|(b, _)| b.bytes).sum();
        let f = &mut stats.facts;
        f.insert("grid_resolution".into(), json!(self.frame.n));
        f.insert("grid_bytes".into(), json!(bytes));
        f.insert("grid_build_ms".into(), json!(build));
        f.insert("grid_variant".into(), json!("exact"));
        f.insert("grid_triangle_refs".into(), json!(self.refs));
        f.insert("proximity_clouds".into(), json!(self.proximity.is_some()));
        if self.proximity.is_some() {
            // the distance pass alone (also in grid_build_ms)
            let ms = stats.gpu_ms.get("grid_proximity").copied().unwrap_or(0.0);
            f.insert("proximity_ms".into(), json!(ms));
        }
        // the exact grid loses nothing
        stats.events.insert("dropped_triangle_refs".into(), 0);
        stats.events.insert("ray_list_overflows".into(), 0);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
