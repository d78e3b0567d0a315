//! An accelerator's options as one value, [`Accel`] (a variant each, with its own options
//! type), and the command line's variant names that select the uniform grid's and the BVH's.

use serde::Serialize;

/// The two uniform-grid designs (Müller 2015, ch. 3.2, 4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum GridVariant {
    /// Faithful: triangles registered along their edges into fixed-size voxel lists, per-ray
    /// voxel lists from the traversal kernel (Listings 17–22).
    Thesis,
    /// Exact: triangle/box overlap, compact lists (count, prefix sum, fill), 3D-DDA in the
    /// intersection kernels.
    #[default]
    Exact,
}

/// The two BVH designs of `--tracer bvh` (`--bvh-variant`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, clap::ValueEnum, Serialize, Default,
)]
#[serde(rename_all = "lowercase")]
pub enum BvhVariant {
    /// Ours: a binned-SAH BVH, an accelerator of Müller 2015's four-kernel pipeline
    /// ([`bvh::Bvh`]).
    #[default]
    Sah,
    /// Wagner 2018, faithful: Listings 4.3/4.4 with eq. 4.1, three textures (Fig. 4.3), one
    /// kernel per pixel with Lambert shading and a hard shadow — its own pipeline
    /// (`pipeline::wagner2018`).
    Wagner,
}

impl BvhVariant {
    /// The `--bvh-variant` value.
    pub fn name(self) -> &'static str {
        match self {
            BvhVariant::Sah => "sah",
            BvhVariant::Wagner => "wagner",
        }
    }
}

/// An accelerator of Müller 2015's pipeline with its own options: the one value `--tracer` and
/// the options of its group make (`design::Design::Mueller2015`), which cannot hold another
/// accelerator's option. Its variant names the accelerator; [`Accel::entry`] its registry
/// entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "accelerator", rename_all = "kebab-case")]
pub enum Accel {
    /// The thesis' base tracer: every ray against every triangle (Müller 2015, ch. 3.1, 4.1).
    Base,
    /// The thesis' uniform grid rebuilt every frame (Müller 2015, ch. 3.2, 4.2, Listings 17–22).
    ThesisGrid(ThesisGridOptions),
    /// The exact uniform grid rebuilt every frame (ours: overlap test, compact lists, 3D-DDA).
    ExactGrid(ExactGridOptions),
    /// Our SAH BVH, refitted or rebuilt when an object moved (after Wagner 2018 ch. 3.2, 4.2).
    Bvh(BvhOptions),
}

/// `--grid-variant thesis`: the thesis' fixed-size lists.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ThesisGridOptions {
    /// N of the N³ voxels; `None`: chosen from the triangle count (`--grid auto`).
    pub resolution: Option<u32>,
    /// Triangle ids per voxel list (Listing 17: 512).
    pub voxel_array_length: u32,
    /// Voxel ids per ray list; `None`: 3·N as Listing 17.
    pub ray_array_length: Option<u32>,
}

impl Default for ThesisGridOptions {
    fn default() -> Self {
        ThesisGridOptions {
            resolution: None,
            voxel_array_length: 512,
            ray_array_length: None,
        }
    }
}

/// `--grid-variant exact`: compact lists, walked by a 3D-DDA.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
pub struct ExactGridOptions {
    /// N of the N³ voxels; `None`: chosen from the triangle count (`--grid auto`).
    pub resolution: Option<u32>,
    /// Skip empty cells by their proximity-cloud distances (`--proximity-clouds`).
    pub proximity_clouds: bool,
}

/// Our SAH BVH's two variants, each with kernels of its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
pub struct BvhOptions {
    pub passes: BvhPasses,
    pub levels: BvhLevels,
}

/// How a pass of Fig. 8 runs over the SAH BVH.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum BvhPasses {
    /// Ours, the default: the closest hit (Listings 13–14), the shadow feelers (Listing 15) and
    /// the shading (Listing 16) of a pass in one kernel (`glsl/bvh/fused.glsl`): the same
    /// image and counts as the four kernels, without storing and reloading the ray state.
    #[default]
    Fused,
    /// Müller 2015's four kernels (`--four-kernels`): eye rays, intersect1, intersect2 per
    /// light, shading, communicating through the ray-state textures.
    FourKernels,
}

/// How the SAH BVH holds the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum BvhLevels {
    /// One tree over the world-space scene, refitted or rebuilt when an object moves.
    #[default]
    One,
    /// Ours (`--bvh-instances`): a tree per object, built once in object space, under the
    /// objects' instances (`bvh::instances`) — a moving object costs its instance's update.
    Two,
}

impl Accel {
    /// The `--tracer` value that selects it.
    pub fn tracer(&self) -> &'static str {
        match self {
            Accel::Base => "base",
            Accel::ThesisGrid(_) | Accel::ExactGrid(_) => "grid",
            Accel::Bvh(_) => "bvh",
        }
    }

    /// The grid's N where `--grid` fixes it (`None`: auto, or not a grid).
    pub fn grid_resolution(&self) -> Option<u32> {
        match self {
            Accel::ThesisGrid(o) => o.resolution,
            Accel::ExactGrid(o) => o.resolution,
            _ => None,
        }
    }

    /// Whether the grid skips empty cells by proximity clouds.
    pub fn proximity_clouds(&self) -> bool {
        matches!(self, Accel::ExactGrid(o) if o.proximity_clouds)
    }

    /// Whether a pass runs in the SAH BVH's fused kernel.
    pub fn fused(&self) -> bool {
        matches!(self, Accel::Bvh(o) if o.passes == BvhPasses::Fused)
    }

    /// It with the grid's N fixed at `n` (the grids; the others have no resolution).
    pub fn with_grid_resolution(self, n: u32) -> Accel {
        match self {
            Accel::ThesisGrid(o) => Accel::ThesisGrid(ThesisGridOptions {
                resolution: Some(n),
                ..o
            }),
            Accel::ExactGrid(o) => Accel::ExactGrid(ExactGridOptions {
                resolution: Some(n),
                ..o
            }),
            other => other,
        }
    }

    /// Whether the SAH BVH keeps the objects in their own space under instances.
    pub fn instances(&self) -> bool {
        matches!(self, Accel::Bvh(o) if o.levels == BvhLevels::Two)
    }

    /// The settings that name the configuration, for the statistics ("bvh_passes": "fused").
    pub fn settings(&self) -> Vec<(&'static str, serde_json::Value)> {
        use serde_json::json;
        match self {
            Accel::Base => vec![],
            Accel::ThesisGrid(_) => vec![("grid_variant", json!(GridVariant::Thesis))],
            Accel::ExactGrid(o) => [("grid_variant", json!(GridVariant::Exact))]
                .into_iter()
                .chain(
                    o.proximity_clouds
                        .then_some(("proximity_clouds", json!(true))),
                )
                .collect(),
            Accel::Bvh(o) => vec![
                ("bvh_variant", json!(BvhVariant::Sah)),
                ("bvh_passes", json!(o.passes)),
                ("bvh_levels", json!(o.levels)),
            ],
        }
    }
}

/// `--grid auto`: N = cbrt(T / 5), i.e. about five triangles per voxel if the triangles filled
/// the box evenly, within 4..=64. It gives 24 for the 69451-triangle bunny, the resolution the
/// thesis found fastest (ch. 5.3).
pub fn auto_resolution(triangles: usize) -> u32 {
    ((triangles as f64 / 5.0).cbrt().round() as u32).clamp(4, 64)
}
