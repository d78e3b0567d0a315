//! The binding slots of every GPU resource, in one table shared by the Rust side and the GLSL
//! side: each constant here is injected into every kernel as a `#define` (`SSBO_VOXELSLIST`,
//! `IMAGE_RAY_ORIGIN`, `SAMPLER_TEXTURES`, ...), and the kernels name their
//! `layout(binding = ...)` by it. No binding or unit number is written anywhere else.
//!
//! Slots of different designs may share a number (a program binds one design's resources);
//! the names say whose they are.

use super::defines::Defines;

macro_rules! slot_table {
    ($(#[$doc:meta])* $module:ident, $prefix:literal { $($(#[$d:meta])* $name:ident = $value:expr,)* }) => {
        $(#[$doc])*
        pub mod $module {
            $($(#[$d])* pub const $name: u32 = $value;)*
            /// (GLSL `#define` name, slot) of every slot of this kind.
            pub const TABLE: &[(&str, u32)] = &[$((concat!($prefix, stringify!($name)), $value),)*];
        }
    };
}

slot_table! {
    /// Shader storage buffer bindings (`layout(std430, binding = SSBO_...)`).
    ssbo, "SSBO_" {
        // the scene SSBOs of Müller 2015 ch. 3.1.2 (glsl/common/scene.glsl)
        VERTEX = 0,
        NORMAL = 1,
        COLOR = 2,
        TEXCOORD = 3,
        TRI_MATERIAL = 4,
        MATERIAL = 5,
        LIGHT_POS = 6,
        LIGHT_COLOR = 7,
        /// the 64-bit counters of every design (glsl/common/counters.glsl)
        COUNTERS = 8,
        // the thesis grid, Listings 17–22 (glsl/thesis_grid/); the thesis' names
        VOXELSLIST = 10,
        VOXELCONTAINS = 11,
        RAYSLIST = 12,
        RAYCONTAINS = 13,
        // the exact grid (glsl/exact_grid/)
        VOXEL_COUNT = 10,
        VOXEL_START = 11,
        VOXEL_FILL = 12,
        BLOCK_SUMS = 13,
        GRID_TOTAL = 14,
        VOXEL_TRIS = 15,
        /// the lists as the fill pass leaves them, before the order pass
        VOXEL_TRIS_FILLED = 16,
        /// proximity-cloud distances per voxel (--proximity-clouds), and the two buffers one
        /// pass of glsl/exact_grid/proximity.comp reads and writes
        VOXEL_DIST = 17,
        DIST_IN = 18,
        DIST_OUT = 19,
        /// Müller's pipeline, for the designs that keep the closest-hit search apart from the
        /// hit's evaluation and count per pixel (glsl/bvh/records.glsl): per pixel its work
        /// counts and hit record
        PIXEL_RECORDS = 21,
        /// the transform pass' object-space positions and normals (its VBOs), read by the
        /// moved objects' compute pass (glsl/mueller2015/transform_moved.comp)
        TRANSFORM_POSITIONS = 22,
        TRANSFORM_NORMALS = 23,
        /// the SAH BVH's fused pass: its blocks sorted by the entry pass into those with rays
        /// that may hit and those without, and the two dispatches' work-group counts
        /// (glsl/bvh/block_lists.glsl)
        BVH_BLOCK_LISTS = 24,
        /// the SAH BVH's hit list: the pixels whose ray hit something in the pass, which
        /// its intersect2 dispatches work through, and their dispatch commands
        /// (glsl/bvh/hit_list.glsl)
        HIT_LIST = 25,
        // the SAH BVH's GPU refit (glsl/bvh/refit.glsl): the tree's topology as the host lays
        // it out once per build (src/accel/bvh/refit.rs), and every node's float box and
        // subtree SAH cost as the refit's passes write them
        REFIT_TOPOLOGY = 10,
        REFIT_BOXES = 11,
        /// and per inner node the arrivals of its children (glsl/bvh/refit_leaves.comp)
        REFIT_ARRIVALS = 12,
        /// and the BVH's word buffer itself (the image buffer the walks read), which the
        /// refit's passes store into as a storage buffer where it fits one
        BVH_WORDS = 13,
        // Klee 2016's shadow pass (glsl/klee2016/linespace_shadow.comp)
        TRI_VERTEX = 0,
        LEAF_TRIANGLES = 1,
        /// Klee 2016's line-space build (glsl/klee2016/linespace_build.comp): per inner node
        /// its children's geometry flags, one N-bit row per (y, z)
        LS_OCCUPANCY = 2,
        /// and their summed-volume tables
        LS_SAT = 3,
    }
}

slot_table! {
    /// Image units (`layout(rgba32f, binding = IMAGE_...) uniform image2D`).
    image, "IMAGE_" {
        // the ray-state textures of Müller 2015 ch. 3.1.2 (glsl/common/images.glsl)
        RAY_ORIGIN = 0,
        RAY_DIR = 1,
        NORMAL = 2,
        COLOR_BUFFER = 3,
        SHADOW = 4,
        FINAL = 5,
        PRIMARY_HIT = 6,
        // Klee 2016's shadow pass: the G-buffer, the shadow values, the line spaces
        GBUFFER_POSITION = 0,
        GBUFFER_NORMAL = 1,
        GBUFFER_DIFFUSE = 2,
        SHADOW_VALUE = 3,
        LINESPACE = 4,
        /// the first ray of every batch that completed a pixel's rays, a bit per ray (128)
        SHADOW_BATCHES = 5,
        // Wagner 2018's kernel (glsl/wagner2018/raytrace.comp): the image it renders (ch. 4.3's
        // surface), and ours for the AOVs: the first hit (t, triangle id, u, v), the primary
        // ray's direction, the normal at the hit (w: 1 lit, 0 in shadow)
        WAGNER_OUTPUT = 0,
        WAGNER_HIT = 1,
        WAGNER_RAY = 2,
        WAGNER_NORMAL = 3,
        /// the SAH BVH's texture buffer, read as an image buffer (glsl/bvh/words.glsl): the
        /// node records of every ray octant, the leaf triangles, and the entry point of each
        /// 8×8 block of intersect1's rays (glsl/bvh/entries.glsl). Unit 7, the last of the 8
        /// that GL 4.5 guarantees (`GL_MAX_IMAGE_UNITS`), beside the ray-state images 0–6 that
        /// its kernels bind too
        BVH = 7,
        /// the scene's vertex normals and colours (the SSBOs NORMAL, COLOR) read as image
        /// buffers by the SAH BVH's hit evaluations (glsl/bvh/vertex_attributes.glsl,
        /// SCENE_IMAGES): beyond the 8 units GL 4.5 guarantees, so only where
        /// `GL_MAX_IMAGE_UNITS` has them
        SCENE_NORMAL = 8,
        SCENE_COLOR = 9,
        /// the lights' positions and colours (the SSBOs LIGHT_POS, LIGHT_COLOR) read as
        /// image buffers by shading's light loop (SCENE_IMAGES, glsl/mueller2015/shade.glsl),
        /// the same way
        SCENE_LIGHT_POS = 10,
        SCENE_LIGHT_COLOR = 11,
        /// the world-space vertices (the SSBO VERTEX) read the same way by the SAH BVH's
        /// refit (glsl/bvh/refit_leaves.comp)
        SCENE_VERTEX = 13,
        /// the SAH BVH refit's topology and boxes (the SSBOs REFIT_TOPOLOGY, REFIT_BOXES) read
        /// the same way by its records' pass (glsl/bvh/refit_records.comp)
        REFIT_TOPOLOGY = 14,
        REFIT_BOXES = 15,
        /// the transform pass' object-space positions and normals (its VBOs, tightly packed
        /// floats) read as R32F image buffers by the moved objects' compute pass
        /// (glsl/mueller2015/transform_moved.comp, TRANSFORM_VIEWS)
        TRANSFORM_POSITIONS = 16,
        TRANSFORM_NORMALS = 17,
        /// the SAH BVH's per-pixel records (the SSBO PIXEL_RECORDS) read as an RGBA32UI image
        /// buffer by glsl/bvh/pixel_counts.comp (RECORD_IMAGE), the same way, where
        /// `GL_MAX_IMAGE_UNITS` has the unit
        PIXEL_RECORDS = 12,
    }
}

slot_table! {
    /// Texture units of samplers (`layout(binding = SAMPLER_...) uniform sampler...`).
    sampler, "SAMPLER_" {
        /// the scene's texture array (intersect1)
        TEXTURES = 0,
        /// Klee 2016's node pool (a texture buffer)
        NODE_POOL = 1,
        /// the texture a screen-filling quad shows
        QUAD_COLOR = 0,
        /// Wagner 2018's BVH in three textures (Fig. 4.3, texture buffers): the boxes (centre,
        /// half extent), the node integers (leaf flag, children / triangle range), the
        /// triangle ids grouped per leaf
        WAGNER_BVH_BOUNDS = 1,
        WAGNER_BVH_NODES = 2,
        WAGNER_BVH_TRIANGLES = 3,
        /// ... and its triangles: world-space vertices, normals, colours (3 texels each)
        WAGNER_VERTICES = 4,
        WAGNER_NORMALS = 5,
        WAGNER_COLORS = 6,
        /// the streaming tracer (glsl/stream/): the ray textures (Fig. 1) and the
        /// eye or reflection ray's hit record
        STREAM_RAY_ORIGIN = 0,
        STREAM_RAY_DIR = 1,
        STREAM_HIT = 2,
        /// ... the grid and the triangles in texture memory (Fig. 3): cells (3D), references
        /// (a texture buffer), triangle vertices and normals (3D, 4 depth slices)
        STREAM_CELLS = 3,
        STREAM_REFS = 4,
        STREAM_TRI_VERTEX = 5,
        STREAM_TRI_NORMAL = 6,
        /// ... the traversal state set a traverse call reads (Fig. 2's three textures)
        STREAM_READ_TMAX = 7,
        STREAM_READ_CELL = 8,
        STREAM_READ_HIT = 9,
        /// ... both sets' ray state and hit record, for the early-Z pass, the hit record and
        /// the shading
        STREAM_STATE_A = 10,
        STREAM_STATE_B = 11,
        STREAM_HIT_A = 12,
        STREAM_HIT_B = 13,
    }
}

/// The `#define`s of every slot, which every program gets.
pub fn defines() -> Defines {
    let mut d = Defines::new();
    for (name, slot) in ssbo::TABLE.iter().chain(image::TABLE).chain(sampler::TABLE) {
        d = d.set(name, slot);
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_within_a_kind() {
        for table in [ssbo::TABLE, image::TABLE, sampler::TABLE] {
            let mut names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
            names.sort();
            let n = names.len();
            names.dedup();
            assert_eq!(names.len(), n);
        }
    }

    /// Every image unit and texture unit is one that GL 4.5 guarantees to a compute shader
    /// (`GL_MAX_IMAGE_UNITS` ≥ 8, `GL_MAX_COMPUTE_TEXTURE_IMAGE_UNITS` ≥ 16): the designs run
    /// on any GL 4.5 implementation, not only on llvmpipe's 192 units. The exceptions are the
    /// scene's image-buffer views, which `gpu_scene::vertex_views` binds only where
    /// `GL_MAX_IMAGE_UNITS` has them (else the kernels read the SSBOs: `SCENE_IMAGES` 0), and
    /// the pixel records' view (`mueller2015::records`; else `RECORD_IMAGE` 0).
    #[test]
    fn units_are_within_gl_4_5_minimums() {
        let optional = [
            "IMAGE_SCENE_NORMAL",
            "IMAGE_SCENE_COLOR",
            "IMAGE_SCENE_LIGHT_POS",
            "IMAGE_SCENE_LIGHT_COLOR",
            "IMAGE_PIXEL_RECORDS",
            "IMAGE_SCENE_VERTEX",
            "IMAGE_REFIT_TOPOLOGY",
            "IMAGE_REFIT_BOXES",
            "IMAGE_TRANSFORM_POSITIONS",
            "IMAGE_TRANSFORM_NORMALS",
        ];
        for (table, units) in [(image::TABLE, 8), (sampler::TABLE, 16)] {
            for (name, slot) in table {
                let gated = optional.contains(name);
                assert!(
                    *slot < units || gated,
                    "{name} = {slot}: GL 4.5 guarantees {units} units"
                );
            }
        }
    }
}
