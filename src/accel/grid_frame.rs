//! What both uniform grids do every frame before they build (Müller 2015, Fig. 15): map the
//! scene's current bounds onto the thesis' grid space [-1, 1)³ and hand the mapping to their
//! kernels (`glsl/common/grid.glsl`).

use glam::Vec3;

use crate::gl::Kernel;
use crate::reference::grid::GridMapping;
use crate::scene::Scene;

/// The grid's resolution and this frame's scene-to-grid mapping.
pub struct GridFrame {
    /// N of the N³ voxels.
    pub n: u32,
    /// object-space bounds of every object, for the per-frame scene bounds
    object_bounds: Vec<(Vec3, Vec3)>,
    pub mapping: GridMapping,
}

impl GridFrame {
    pub fn new(scene: &Scene, n: u32) -> GridFrame {
        GridFrame {
            n,
            object_bounds: scene.objects.iter().map(|o| o.mesh.bounds()).collect(),
            mapping: GridMapping::of_scene(scene),
        }
    }

    /// N³
    pub fn voxels(&self) -> usize {
        (self.n as usize).pow(3)
    }

    /// The scene's bounds under this frame's model matrices.
    pub fn update(&mut self, models: &[glam::Mat4]) {
        self.mapping = GridMapping::of_objects(&self.object_bounds, models);
    }

    /// The mapping's uniforms (gridCenter, gridScale) of `kernel`, which is in use.
    pub fn set_uniforms(&self, kernel: &Kernel) {
        kernel.set_vec4("gridCenter", self.mapping.center.into(), 0.0);
        kernel.set_f32("gridScale", self.mapping.scale);
    }

    /// The `#define` voxel_amount of Listing 17.
    pub fn define(&self) -> (&'static str, String) {
        ("voxel_amount", self.n.to_string())
    }
}

/// The resolution `--grid` asks for (`auto`: [`super::auto_resolution`]), checked against the
/// variant's largest.
pub fn resolution(scene: &Scene, options: &super::GridOptions, max: u32) -> anyhow::Result<u32> {
    let n = options
        .resolution
        .unwrap_or_else(|| super::auto_resolution(scene.triangle_count()));
    if n == 0 || n > max {
        anyhow::bail!(
            "--grid {n}: the {:?} grid supports 1..={max} voxels per axis",
            options.variant
        );
    }
    Ok(n)
}

/// Triangle references as the kernels store them: the ids of every voxel, from a flat buffer.
pub fn lists_of(n3: usize, ids: &[u32], range: impl Fn(usize) -> (usize, usize)) -> Vec<Vec<i32>> {
    (0..n3)
        .map(|v| {
            let (start, len) = range(v);
            ids[start..start + len].iter().map(|&x| x as i32).collect()
        })
        .collect()
}
