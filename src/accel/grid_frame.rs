//! What both uniform grids do every frame before they build (Müller 2015, Fig. 15): map the
//! scene's current bounds onto the thesis' grid space [-1, 1)³ and hand the mapping to their
//! kernels (`glsl/common/grid.glsl`).

use glam::{Mat4, Vec3};

use crate::gl::Kernel;
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

/// The resolution `--grid` asks for (`requested`; `None`: [`super::options::auto_resolution`]),
/// checked against the largest of the grid `variant` ("thesis", "exact").
pub fn resolution(
    scene: &Scene,
    requested: Option<u32>,
    variant: &str,
    max: u32,
) -> anyhow::Result<u32> {
    let n = requested.unwrap_or_else(|| super::options::auto_resolution(scene.triangle_count()));
    if n == 0 || n > max {
        anyhow::bail!("--grid {n}: the {variant} grid supports 1..={max} voxels per axis");
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

/// The scene-to-grid mapping of `glsl/common/grid.glsl`: grid = (p − centre) · scale, which
/// puts the scene's current bounds onto [-1, 1)³ with one scale (so ray parameters are the
/// same in scene and grid space).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridMapping {
    pub center: Vec3,
    pub scale: f32,
}

impl GridMapping {
    /// The mapping for the objects' object-space bounds under their model matrices, slightly
    /// enlarged so the far faces stay inside — what the GPU grids compute every frame.
    pub fn of_objects(object_bounds: &[(Vec3, Vec3)], models: &[Mat4]) -> GridMapping {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for ((olo, ohi), m) in object_bounds.iter().zip(models) {
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
        GridMapping {
            center: (lo + hi) * 0.5,
            scale: 2.0 / extent,
        }
    }

    /// The mapping of a scene as loaded (every object at its model matrix).
    pub fn of_scene(scene: &crate::scene::Scene) -> GridMapping {
        let bounds: Vec<_> = scene.objects.iter().map(|o| o.mesh.bounds()).collect();
        let models: Vec<_> = scene.objects.iter().map(|o| o.model).collect();
        Self::of_objects(&bounds, &models)
    }

    /// toGridSpace
    pub fn to_grid(&self, p: Vec3) -> Vec3 {
        (p - self.center) * self.scale
    }

    /// A scene-space triangle in grid space.
    pub fn triangle(&self, t: &[Vec3; 3]) -> [Vec3; 3] {
        t.map(|p| self.to_grid(p))
    }
}
