//! The thesis' uniform grid (Müller 2015, ch. 2.1.1, 3.2, 4.2), rebuilt on the GPU every frame
//! so that scenes may move — faithful: the build kernel registers each triangle along its
//! edges into fixed-size voxel lists (`voxelslist`, `voxelcontains`, cleared with
//! glClearBufferData), the traversal kernel writes each ray's non-empty voxels into
//! `rayslist`/`raycontains`, and the intersection kernels walk those lists (Listings 17–22,
//! Algorithms 2–3; `glsl/thesis_grid/`). What it loses is counted: `dropped_triangle_refs` (a
//! voxel list was full), `ray_list_overflows` (a ray list was full); what it cannot see
//! (triangle interiors away from the edges) shows in the image. CPU twin:
//! `reference::thesis_grid`.

use std::any::Any;

use anyhow::{bail, Result};
use glam::Vec3;
use serde_json::json;

use super::grid_frame::GridMapping;
use super::grid_frame::{lists_of, resolution, GridFrame};
use super::interface::{Accelerator, BuildContext, Entry, FrameContext, LightTarget};
use super::options::{Accel, ThesisGridOptions};
use crate::frame::FrameStats;
use crate::gl::resources::Ssbo;
use crate::gl::slots::ssbo;
use crate::gl::{Gl, Kernel};
use crate::scene::Scene;

/// Largest resolution: the per-ray lists sort up to 3N crossings with BubbleSort (and
/// llvmpipe's loop limit).
pub const MAX_RESOLUTION: u32 = 64;

pub const ENTRY: Entry = Entry {
    label: "grid-thesis",
    plain: PLAIN,
    records: false,
    variants: &[("grid thesis", PLAIN)],
    gpu: ThesisGrid::create,
};

/// The thesis grid with Listing 17's list lengths and `--grid auto`.
const PLAIN: Accel = Accel::ThesisGrid(ThesisGridOptions {
    resolution: None,
    voxel_array_length: 512,
    ray_array_length: None,
});

pub struct ThesisGrid {
    frame: GridFrame,
    triangles: usize,
    build: Kernel,
    order: Kernel,
    traversal: Kernel,
    intersect1: Kernel,
    intersect2: Kernel,
    /// VerticesInVoxel in the thesis' GLSL, though it holds triangle ids (Listing 19); in
    /// ascending triangle id once the order pass has run
    voxelslist: Ssbo,
    /// ContainedVertices in the thesis' GLSL: the fill level of every voxel list
    voxelcontains: Ssbo,
    rayslist: Ssbo,
    raycontains: Ssbo,
    voxel_array_length: u32,
    ray_array_length: u32,
}

impl ThesisGrid {
    fn create(b: &BuildContext, scene: &Scene, o: &Accel) -> Result<Box<dyn Accelerator>> {
        let Accel::ThesisGrid(o) = o else {
            unreachable!("made from its own options")
        };
        let n = resolution(scene, o.resolution, "thesis", MAX_RESOLUTION)?;
        let frame = GridFrame::new(scene, n);
        let (n, n3) = (frame.n, frame.voxels());
        let l = o.voxel_array_length;
        let r = o.ray_array_length.unwrap_or(3 * n);
        if l == 0 || r == 0 {
            bail!("voxel_array_length and ray_array_length must be positive");
        }
        let defs = [
            frame.define(),
            ("voxel_array_length", l.to_string()),
            ("ray_array_length", r.to_string()),
        ];
        let pixels = (b.width * b.height) as usize;
        let max = b.info.max_ssbo_block_size;
        let ssbo = |name, bytes, by: &str| Ssbo::sized(b.gl, name, bytes, None, max, by);
        let (voxels, rays) = ("--grid", "the image size");
        let (voxel_lists, ray_lists) = (
            "--grid with --voxel-array-length",
            "the image size with --ray-array-length",
        );
        Ok(Box::new(ThesisGrid {
            triangles: scene.triangle_count(),
            build: b.kernel("thesis_grid/build.comp", &defs, "build")?,
            order: b.kernel("thesis_grid/order.comp", &defs, "grid_order")?,
            traversal: b.kernel("thesis_grid/traversal.comp", &defs, "traversal")?,
            intersect1: b.kernel("thesis_grid/intersect1.comp", &defs, "intersect1")?,
            intersect2: b.kernel("thesis_grid/intersect2.comp", &defs, "intersect2")?,
            voxelslist: ssbo("voxelslist", 4 * n3 * l as usize, voxel_lists)?,
            voxelcontains: ssbo("voxelcontains", 4 * n3, voxels)?,
            rayslist: ssbo("rayslist", 4 * pixels * r as usize, ray_lists)?,
            raycontains: ssbo("raycontains", 4 * pixels, rays)?,
            voxel_array_length: l,
            ray_array_length: r,
            frame,
        }))
    }

    fn bind(&self, f: &FrameContext) {
        self.voxelslist.bind(f.gl, ssbo::VOXELSLIST);
        self.voxelcontains.bind(f.gl, ssbo::VOXELCONTAINS);
        self.rayslist.bind(f.gl, ssbo::RAYSLIST);
        self.raycontains.bind(f.gl, ssbo::RAYCONTAINS);
    }

    /// The traversal kernel (Listing 21): every ray's non-empty voxels into `rayslist` — the
    /// primary or reflected rays (mode 0) or the shadow feelers towards `light` (mode 1).
    fn traverse(&self, f: &mut FrameContext, feelers: Option<&LightTarget>) {
        self.bind(f);
        let k = &self.traversal;
        k.use_program();
        self.frame.set_uniforms(k);
        k.set_i32("traversalMode", feelers.is_some() as i32);
        let none = LightTarget::Point {
            light: 0,
            position: Vec3::ZERO,
        };
        feelers.unwrap_or(&none).set_uniforms(k);
        k.dispatch_pixels(f.timers, f.pixels);
    }

    /// The order pass (`glsl/thesis_grid/order.comp`): every voxel's list sorted in place into
    /// ascending triangle id, so that shadow feelers test the same triangles in every run.
    fn order_lists(&self, f: &mut FrameContext) {
        let k = &self.order;
        k.use_program();
        let voxels = self.frame.voxels() as u32;
        k.set_i32("voxelTotal", voxels as i32);
        k.dispatch_1d(f.timers, voxels.div_ceil(64));
    }

    /// The voxel lists of the last build read back (triangle ids in storage order) and the
    /// mapping used. For tests and inspection.
    pub fn read_lists(&self, gl: &Gl) -> (Vec<Vec<i32>>, GridMapping) {
        let l = self.voxel_array_length as usize;
        let fill = self.voxelcontains.read_u32(gl);
        let lists = lists_of(self.frame.voxels(), &self.voxelslist.read_u32(gl), |v| {
            (v * l, fill[v] as usize)
        });
        (lists, self.frame.mapping)
    }

    pub fn resolution(&self) -> u32 {
        self.frame.n
    }
}

impl Accelerator for ThesisGrid {
    fn build(&mut self, f: &mut FrameContext) -> Result<()> {
        self.frame.update(f.models);
        // Fig. 15: empty the lists, then the build kernel, every frame; then the order pass
        // (ours) sorts every list
        let (gl, list, contains) = (f.gl, &self.voxelslist, &self.voxelcontains);
        f.timers.time(gl, "grid_clear", || {
            list.clear_u32(gl, u32::MAX); // -1
            contains.clear_u32(gl, 0);
        });
        self.bind(f);
        self.build.use_program();
        self.frame.set_uniforms(&self.build);
        self.build
            .dispatch_1d(f.timers, (self.triangles as u32).div_ceil(128));
        self.order_lists(f);
        Ok(())
    }

    fn closest_hit(&mut self, f: &mut FrameContext, _pass: u32) -> &Kernel {
        self.traverse(f, None);
        self.intersect1.use_program();
        self.frame.set_uniforms(&self.intersect1);
        &self.intersect1
    }

    fn occluded(&mut self, f: &mut FrameContext, target: &LightTarget) -> &Kernel {
        self.traverse(f, Some(target));
        self.intersect2.use_program();
        self.frame.set_uniforms(&self.intersect2);
        &self.intersect2
    }

    fn stats(&self, stats: &mut FrameStats) {
        let build: f64 = ["grid_clear", "build", "grid_order"]
            .iter()
            .filter_map(|k| stats.gpu_ms.get(*k))
            .sum();
        let bytes: usize = [
            &self.voxelslist,
            &self.voxelcontains,
            &self.rayslist,
            &self.raycontains,
        ]
        .iter()
        .map(|b| b.bytes)
        .sum();
        let f = &mut stats.facts;
        f.insert("grid_resolution".into(), json!(self.frame.n));
        f.insert("grid_bytes".into(), json!(bytes));
        f.insert("grid_build_ms".into(), json!(build));
        f.insert("grid_variant".into(), json!("thesis"));
        f.insert("voxel_array_length".into(), json!(self.voxel_array_length));
        f.insert("ray_array_length".into(), json!(self.ray_array_length));
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
