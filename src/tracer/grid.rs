//! The uniform grid of Müller 2015 (ch. 2.1.1, 3.2, 4.2), rebuilt on the GPU every frame so
//! that scenes may move, in two variants:
//!
//! - `thesis` (faithful): the build kernel registers each triangle along its edges into
//!   fixed-size voxel lists (`voxelslist`, `voxelcontains`, cleared with glClearBufferData),
//!   the traversal kernel writes each ray's non-empty voxels into `rayslist`/`raycontains`, and
//!   the intersection kernels walk those lists (Listings 17–22, Algorithms 2–3). What it loses
//!   is counted: `dropped_triangle_refs` (a voxel list was full), `ray_list_overflows` (a ray
//!   list was full); what it cannot see (triangle interiors away from the edges) shows in the
//!   image.
//! - `exact`: triangle/box overlap, compact lists built by a count pass, a prefix sum and a
//!   fill pass, and a 3D-DDA inside the intersection kernels that stops only at a hit inside
//!   the current voxel. Its image equals the base tracer's.

use std::sync::Arc;

use anyhow::{bail, Result};
use glam::{Mat4, Vec3};
use glow::HasContext;
use serde_json::json;

use super::pipeline::{RayPipeline, Stages};
use super::{Frame, FrameStats, GridOptions, GridVariant, RenderOptions, Tracer};
use crate::gl::resources::Ssbo;
use crate::gl::{Gl, GlInfo, ShaderSource};
use crate::scene::{Camera, Scene};

/// Largest grid resolution per variant: the thesis' per-ray lists sort up to 3N crossings with
/// BubbleSort (and llvmpipe's loop limit), the exact grid's prefix sum handles 2048 blocks of
/// 1024 voxels.
pub const MAX_RESOLUTION_THESIS: u32 = 64;
pub const MAX_RESOLUTION_EXACT: u32 = 128;

/// `--grid auto`: N = cbrt(T / 5), i.e. about five triangles per voxel if the triangles filled
/// the box evenly, within 4..=64. It gives 24 for the 69451-triangle bunny, the resolution the
/// thesis found fastest (ch. 5.3).
pub fn auto_resolution(triangles: usize) -> u32 {
    ((triangles as f64 / 5.0).cbrt().round() as u32).clamp(4, 64)
}

/// SSBO binding points of the grid buffers (see the grid kernels).
mod binding {
    pub const B10: u32 = 10;
    pub const B11: u32 = 11;
    pub const B12: u32 = 12;
    pub const B13: u32 = 13;
    pub const B14: u32 = 14;
    pub const B15: u32 = 15;
}

enum Variant {
    Thesis {
        build: glow::Program,
        traversal: glow::Program,
        intersect1: glow::Program,
        intersect2: glow::Program,
        voxelslist: Ssbo,
        voxelcontains: Ssbo,
        rayslist: Ssbo,
        raycontains: Ssbo,
        ray_array_length: u32,
    },
    Exact {
        count: glow::Program,
        scan: glow::Program,
        fill: glow::Program,
        intersect1: glow::Program,
        intersect2: glow::Program,
        voxel_count: Ssbo,
        voxel_start: Ssbo,
        voxel_fill: Ssbo,
        block_sums: Ssbo,
        grid_total: Ssbo,
        voxel_tris: Ssbo,
        /// triangle references of the last build
        refs: u64,
    },
}

struct GridStages {
    n: u32,
    variant: Variant,
    triangles: usize,
    /// object-space bounds of every object, for the per-frame scene bounds
    object_bounds: Vec<(Vec3, Vec3)>,
    center: Vec3,
    scale: f32,
    max_ssbo: i64,
}

/// The scene-to-grid mapping of `glsl/common/grid.glsl` for the program in use.
fn grid_uniforms(p: &RayPipeline, prog: glow::Program, center: Vec3, scale: f32) {
    p.uniform_vec4(prog, "gridCenter", center.into(), 0.0);
    // SAFETY: setting a uniform of the program in use.
    unsafe {
        let loc = p.gl.get_uniform_location(prog, "gridScale");
        p.gl.uniform_1_f32(loc.as_ref(), scale);
    }
}

impl GridStages {
    fn set_grid_uniforms(&self, p: &RayPipeline, prog: glow::Program) {
        grid_uniforms(p, prog, self.center, self.scale);
    }

    /// The scene's bounds from the objects' bounds and current model matrices, mapped onto
    /// [-1, 1)³ with one scale (slightly enlarged so the far faces stay inside).
    fn update_bounds(&mut self, models: &[Mat4]) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for ((olo, ohi), m) in self.object_bounds.iter().zip(models) {
            for k in 0..8 {
                let c = Vec3::new(
                    if k & 1 == 0 { olo.x } else { ohi.x },
                    if k & 2 == 0 { olo.y } else { ohi.y },
                    if k & 4 == 0 { olo.z } else { ohi.z },
                );
                let w = m.transform_point3(c);
                lo = lo.min(w);
                hi = hi.max(w);
            }
        }
        let extent = (hi - lo).max_element().max(1e-6) * 1.001;
        self.center = (lo + hi) * 0.5;
        self.scale = 2.0 / extent;
    }

    /// GPU memory of the grid buffers (`grid_bytes`).
    fn bytes(&self) -> usize {
        self.buffers().iter().map(|b| b.bytes).sum()
    }

    fn programs(&self) -> Vec<glow::Program> {
        match &self.variant {
            Variant::Thesis {
                build,
                traversal,
                intersect1,
                intersect2,
                ..
            } => vec![*build, *traversal, *intersect1, *intersect2],
            Variant::Exact {
                count,
                scan,
                fill,
                intersect1,
                intersect2,
                ..
            } => vec![*count, *scan, *fill, *intersect1, *intersect2],
        }
    }

    fn buffers(&self) -> Vec<&Ssbo> {
        match &self.variant {
            Variant::Thesis {
                voxelslist,
                voxelcontains,
                rayslist,
                raycontains,
                ..
            } => vec![voxelslist, voxelcontains, rayslist, raycontains],
            Variant::Exact {
                voxel_count,
                voxel_start,
                voxel_fill,
                block_sums,
                grid_total,
                voxel_tris,
                ..
            } => vec![
                voxel_count,
                voxel_start,
                voxel_fill,
                block_sums,
                grid_total,
                voxel_tris,
            ],
        }
    }
}

impl Stages for GridStages {
    fn prepare_frame(&mut self, p: &mut RayPipeline) -> Result<()> {
        self.update_bounds(&p.models);
        let gl = p.gl.clone();
        let tri_groups = (self.triangles as u32).div_ceil(128);
        let n3 = (self.n * self.n * self.n) as i32;
        match &mut self.variant {
            Variant::Thesis {
                build,
                voxelslist,
                voxelcontains,
                ..
            } => {
                // Fig. 15: empty the lists, then the build kernel, every frame
                let timers = &mut p.timers;
                timers.time(&gl, "grid_clear", || {
                    voxelslist.clear_u32(&gl, u32::MAX); // -1
                    voxelcontains.clear_u32(&gl, 0);
                });
                voxelslist.bind(&gl, binding::B10);
                voxelcontains.bind(&gl, binding::B11);
                let prog = *build;
                p.use_program(prog);
                self.set_grid_uniforms(p, prog);
                p.dispatch_1d("build", tri_groups);
            }
            Variant::Exact {
                count,
                scan,
                fill,
                voxel_count,
                voxel_start,
                voxel_fill,
                block_sums,
                grid_total,
                voxel_tris,
                refs,
                ..
            } => {
                let (count, scan, fill) = (*count, *scan, *fill);
                p.timers.time(&gl, "grid_clear", || {
                    voxel_count.clear_u32(&gl, 0);
                    voxel_fill.clear_u32(&gl, 0);
                });
                voxel_count.bind(&gl, binding::B10);
                voxel_start.bind(&gl, binding::B11);
                voxel_fill.bind(&gl, binding::B12);
                block_sums.bind(&gl, binding::B13);
                grid_total.bind(&gl, binding::B14);
                p.use_program(count);
                let (center, scale) = (self.center, self.scale);
                grid_uniforms(p, count, center, scale);
                p.dispatch_1d("grid_count", tri_groups);
                p.use_program(scan);
                let blocks = (n3 as u32).div_ceil(1024);
                p.uniform_i32(scan, "voxelTotal", n3);
                p.uniform_i32(scan, "blockCount", blocks as i32);
                for (phase, groups) in [(0, blocks), (1, 1), (2, blocks)] {
                    p.uniform_i32(scan, "scanPhase", phase);
                    p.dispatch_1d("grid_scan", groups);
                }
                // the number of references sizes the compact lists
                let total = grid_total.read_u32(&gl)[0] as usize;
                *refs = total as u64;
                if 4 * total > voxel_tris.bytes {
                    let bytes = (4 * total + 4 * total / 2).max(16);
                    voxel_tris.delete(&gl);
                    *voxel_tris = Ssbo::new(&gl, "voxelTris", bytes, None, self.max_ssbo)?;
                }
                voxel_tris.bind(&gl, binding::B15);
                p.use_program(fill);
                grid_uniforms(p, fill, center, scale);
                p.dispatch_1d("grid_fill", tri_groups);
            }
        }
        Ok(())
    }

    fn intersect1(&mut self, p: &mut RayPipeline, pass: u32) {
        let prog = match &self.variant {
            Variant::Thesis {
                traversal,
                intersect1,
                ..
            } => {
                self.traverse(p, *traversal, 0, None);
                *intersect1
            }
            Variant::Exact { intersect1, .. } => *intersect1,
        };
        p.use_program(prog);
        self.set_grid_uniforms(p, prog);
        p.uniform_vec4(prog, "backgroundColor", p.background, 1.0);
        p.uniform_i32(prog, "storePrimaryHit", (pass == 0) as i32);
        p.uniform_i32(prog, "textures", 0);
        p.dispatch_pixels(prog, "intersect1");
    }

    fn intersect2(&mut self, p: &mut RayPipeline, light: usize) {
        let prog = match &self.variant {
            Variant::Thesis {
                traversal,
                intersect2,
                ..
            } => {
                self.traverse(p, *traversal, 1, Some(light));
                *intersect2
            }
            Variant::Exact { intersect2, .. } => *intersect2,
        };
        p.use_program(prog);
        self.set_grid_uniforms(p, prog);
        p.uniform_i32(prog, "lightSource", light as i32);
        p.dispatch_pixels(prog, "intersect2");
    }

    fn finish_stats(&mut self, stats: &mut FrameStats) {
        let build: f64 = [
            "grid_clear",
            "build",
            "grid_count",
            "grid_scan",
            "grid_fill",
        ]
        .iter()
        .filter_map(|k| stats.gpu_ms.get(*k))
        .sum();
        let f = &mut stats.facts;
        f.insert("grid_resolution".into(), json!(self.n));
        f.insert("grid_bytes".into(), json!(self.bytes()));
        f.insert("grid_build_ms".into(), json!(build));
        match &self.variant {
            Variant::Thesis {
                ray_array_length, ..
            } => {
                f.insert("grid_variant".into(), json!("thesis"));
                f.insert(
                    "voxel_array_length".into(),
                    json!(self.voxel_array_length()),
                );
                f.insert("ray_array_length".into(), json!(ray_array_length));
            }
            Variant::Exact { refs, .. } => {
                f.insert("grid_variant".into(), json!("exact"));
                f.insert("grid_triangle_refs".into(), json!(refs));
                // the exact grid loses nothing
                stats.events.insert("dropped_triangle_refs".into(), 0);
                stats.events.insert("ray_list_overflows".into(), 0);
            }
        }
    }
}

impl GridStages {
    /// The thesis variant's traversal.comp (Listing 21): every ray's non-empty voxels into
    /// `rayslist` — the primary or reflected rays (mode 0) or the shadow feelers towards
    /// `light` (mode 1).
    fn traverse(
        &self,
        p: &mut RayPipeline,
        traversal: glow::Program,
        mode: i32,
        light: Option<usize>,
    ) {
        self.bind_ray_lists(p);
        p.use_program(traversal);
        self.set_grid_uniforms(p, traversal);
        p.uniform_i32(traversal, "traversalMode", mode);
        if let Some(light) = light {
            p.uniform_i32(traversal, "lightSource", light as i32);
        }
        p.dispatch_pixels(traversal, "traversal");
    }

    fn bind_ray_lists(&self, p: &RayPipeline) {
        if let Variant::Thesis {
            voxelslist,
            voxelcontains,
            rayslist,
            raycontains,
            ..
        } = &self.variant
        {
            voxelslist.bind(&p.gl, binding::B10);
            voxelcontains.bind(&p.gl, binding::B11);
            rayslist.bind(&p.gl, binding::B12);
            raycontains.bind(&p.gl, binding::B13);
        }
    }

    fn voxel_array_length(&self) -> u32 {
        match &self.variant {
            Variant::Thesis { voxelslist, .. } => {
                (voxelslist.bytes / 4 / (self.n * self.n * self.n) as usize) as u32
            }
            Variant::Exact { .. } => 0,
        }
    }
}

/// The grid tracer: the shared pipeline plus the grid build and grid intersection kernels.
pub struct GridTracer {
    pipeline: RayPipeline,
    stages: GridStages,
}

impl GridTracer {
    pub fn new(
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
        options: RenderOptions,
    ) -> Result<GridTracer> {
        let g: GridOptions = options.grid;
        let n = g
            .resolution
            .unwrap_or_else(|| auto_resolution(scene.triangle_count()));
        let max = match g.variant {
            GridVariant::Thesis => MAX_RESOLUTION_THESIS,
            GridVariant::Exact => MAX_RESOLUTION_EXACT,
        };
        if n == 0 || n > max {
            bail!(
                "--grid {n}: the {:?} grid supports 1..={max} voxels per axis",
                g.variant
            );
        }
        let (w, h) = (options.width as usize, options.height as usize);
        let pipeline = RayPipeline::new(gl.clone(), info, scene, shaders, options)?;
        let max_ssbo = info.max_ssbo_block_size;
        let n3 = (n * n * n) as usize;
        let ssbo = |name, bytes| Ssbo::new(&gl, name, bytes, None, max_ssbo);
        let variant = match g.variant {
            GridVariant::Thesis => {
                let l = g.voxel_array_length;
                let r = g.ray_array_length.unwrap_or(3 * n);
                if l == 0 || r == 0 {
                    bail!("voxel_array_length and ray_array_length must be positive");
                }
                let defs = [
                    ("voxel_amount", n.to_string()),
                    ("voxel_array_length", l.to_string()),
                    ("ray_array_length", r.to_string()),
                ];
                Variant::Thesis {
                    build: pipeline.compute_program("build.comp", &defs)?,
                    traversal: pipeline.compute_program("traversal.comp", &defs)?,
                    intersect1: pipeline.compute_program("intersect1_grid.comp", &defs)?,
                    intersect2: pipeline.compute_program("intersect2_grid.comp", &defs)?,
                    voxelslist: ssbo("voxelslist", 4 * n3 * l as usize)?,
                    voxelcontains: ssbo("voxelcontains", 4 * n3)?,
                    rayslist: ssbo("rayslist", 4 * w * h * r as usize)?,
                    raycontains: ssbo("raycontains", 4 * w * h)?,
                    ray_array_length: r,
                }
            }
            GridVariant::Exact => {
                let defs = [("voxel_amount", n.to_string())];
                let blocks = n3.div_ceil(1024);
                Variant::Exact {
                    count: pipeline.compute_program("grid_count.comp", &defs)?,
                    scan: pipeline.compute_program("grid_scan.comp", &defs)?,
                    fill: pipeline.compute_program("grid_fill.comp", &defs)?,
                    intersect1: pipeline.compute_program("intersect1_dda.comp", &defs)?,
                    intersect2: pipeline.compute_program("intersect2_dda.comp", &defs)?,
                    voxel_count: ssbo("voxelCount", 4 * n3)?,
                    voxel_start: ssbo("voxelStart", 4 * n3)?,
                    voxel_fill: ssbo("voxelFill", 4 * n3)?,
                    block_sums: ssbo("blockSums", 4 * blocks)?,
                    grid_total: ssbo("gridTotal", 16)?,
                    // grown to the number of references on the first build
                    voxel_tris: ssbo("voxelTris", 4 * scene.triangle_count())?,
                    refs: 0,
                }
            }
        };
        let stages = GridStages {
            n,
            variant,
            triangles: scene.triangle_count(),
            object_bounds: scene.objects.iter().map(|o| o.mesh.bounds()).collect(),
            center: Vec3::ZERO,
            scale: 1.0,
            max_ssbo,
        };
        Ok(GridTracer { pipeline, stages })
    }

    /// N of the N³ voxels.
    pub fn resolution(&self) -> u32 {
        self.stages.n
    }

    /// The triangle lists of the last build read back from the GPU, one per voxel (ids in
    /// storage order), with the scene-to-grid mapping used (centre, scale): grid = (p - centre)
    /// · scale. For tests and inspection.
    pub fn read_lists(&self) -> (Vec<Vec<i32>>, Vec3, f32) {
        let gl = &self.pipeline.gl;
        let n3 = (self.stages.n * self.stages.n * self.stages.n) as usize;
        let lists = match &self.stages.variant {
            Variant::Thesis {
                voxelslist,
                voxelcontains,
                ..
            } => {
                let l = self.stages.voxel_array_length() as usize;
                let ids = voxelslist.read_u32(gl);
                let fill = voxelcontains.read_u32(gl);
                (0..n3)
                    .map(|v| {
                        ids[v * l..v * l + fill[v] as usize]
                            .iter()
                            .map(|&x| x as i32)
                            .collect()
                    })
                    .collect()
            }
            Variant::Exact {
                voxel_count,
                voxel_start,
                voxel_tris,
                ..
            } => {
                let count = voxel_count.read_u32(gl);
                let start = voxel_start.read_u32(gl);
                let tris = voxel_tris.read_u32(gl);
                (0..n3)
                    .map(|v| {
                        let s = start[v] as usize;
                        tris[s..s + count[v] as usize]
                            .iter()
                            .map(|&x| x as i32)
                            .collect()
                    })
                    .collect()
            }
        };
        (lists, self.stages.center, self.stages.scale)
    }
}

impl Tracer for GridTracer {
    fn name(&self) -> &'static str {
        "grid"
    }

    fn set_model(&mut self, object: usize, model: Mat4) {
        self.pipeline.models[object] = model;
    }

    fn output_texture(&self) -> glow::Texture {
        self.pipeline.images.final_color.texture
    }

    fn render(&mut self, camera: &Camera) -> Result<Frame> {
        self.pipeline.render(camera, &mut self.stages)
    }
}

impl Drop for GridTracer {
    fn drop(&mut self) {
        for prog in self.stages.programs() {
            self.pipeline.delete_program(prog);
        }
        for b in self.stages.buffers() {
            b.delete(&self.pipeline.gl);
        }
    }
}
