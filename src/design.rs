//! The designs — a pipeline with its accelerator — as one value, [`Design`], made into a
//! renderer by one factory, [`Design::renderer`]; and the one table of them, [`REGISTRY`], that
//! `render`, `view`, `parity`, the bench and the tests enumerate.
//!
//! A design is one of the four pipelines of [`crate::pipeline`] with its options; Müller 2015's
//! pipeline takes one of the accelerators of [`crate::accel`] ([`accelerators`]). A [`Row`] says how the
//! command line selects a design and which options belong to it, so that the command line
//! refuses, with one message, an option the chosen design would ignore.
//!
//! Adding a design or an accelerator takes the steps of `docs/architecture.md` ("Adding a
//! design or an accelerator"): its CPU twin, its options (a variant of [`Accel`]), its GPU type,
//! its GLSL folder, one row here, its bench configuration. `tests/registry.rs` walks the
//! table, so that a place forgotten fails.

use std::sync::Arc;

use anyhow::{bail, Result};
use serde::Serialize;

use crate::accel::{self, Accel};
use crate::gl::{Gl, GlInfo, ShaderSource};
use crate::pipeline::klee2016::{SoftShadowOptions, SoftShadowRenderer};
use crate::pipeline::mueller2015::{RayTracer, RenderOptions};
use crate::pipeline::stream::{StreamOptions, StreamRenderer};
use crate::pipeline::wagner2018::{WagnerOptions, WagnerRenderer};
use crate::pipeline::Renderer;
use crate::reference::{self, CpuAccelerator, MakeTwin};
use crate::scene::{Scene, ShadowMode};

/// The four pipelines — how rays flow through the GPU — named as their modules and their
/// shader folders.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Pipeline {
    /// Four compute kernels (eye rays → intersect1 → intersect2 → shading), Müller 2015.
    Mueller2015,
    /// One kernel per pixel over Wagner's BVH in three textures, Wagner 2018.
    Wagner2018,
    /// Fragment programs over a viewport-sized quad, looped until an occlusion query counts
    /// no fragment, the streaming tracer.
    Stream,
    /// G-buffer, shadow pass over the Cascaded Line Space, screen-filling quad, Klee 2016.
    Klee2016,
}

impl Pipeline {
    /// The work it reproduces.
    pub fn source(self) -> &'static str {
        match self {
            Pipeline::Mueller2015 => "Müller 2015",
            Pipeline::Wagner2018 => "Wagner 2018",
            Pipeline::Stream => "the streaming tracer",
            Pipeline::Klee2016 => "Klee 2016",
        }
    }

    /// Its module under `src/pipeline/` and its folder under `glsl/` (the same name).
    pub fn folder(self) -> &'static str {
        match self {
            Pipeline::Mueller2015 => "mueller2015",
            Pipeline::Wagner2018 => "wagner2018",
            Pipeline::Stream => "stream",
            Pipeline::Klee2016 => "klee2016",
        }
    }
}

/// The options every design takes (the image, the outputs, the GL device).
pub const COMMON_OPTIONS: &[&str] = &[
    "output", "width", "height", "aov-dir", "stats", "frames", "device", "glsl-dir", "driver",
];

/// The defaults of the design options where the command line gives none, which
/// [`Design::plain`] takes too.
pub use crate::limits::defaults;

/// The options of Müller 2015's pipeline, whatever its accelerator (`light-samples`: the
/// feelers towards each area light, ours after Klee 2016).
const MUELLER: &[&str] = &[
    "tracer",
    "refl-depth",
    "shadow-flags",
    "tile",
    "light-samples",
];

/// One design of the registry.
pub struct Row {
    /// Its name in reports, `parity` and the tests: "grid-exact", "bvh-wagner".
    pub name: &'static str,
    pub pipeline: Pipeline,
    /// What it is, for messages: "Müller 2015's four kernels with the exact grid".
    pub title: &'static str,
    /// The command-line values that select it (`--shadows` with any value selects Klee 2016's,
    /// whatever `--tracer` says, which is then refused).
    pub select: &'static [(&'static str, &'static str)],
    /// The accelerator of Müller 2015's pipeline (its GPU side and default options).
    pub accel: Option<&'static accel::Entry>,
    /// The accelerator's CPU twin, which the tests hold its GPU side against.
    pub twin: Option<MakeTwin>,
    /// The options, beyond [`COMMON_OPTIONS`], that belong to it (long names without `--`),
    /// in groups (those of its pipeline, of its accelerator).
    pub options: &'static [&'static [&'static str]],
    /// Its shader folders under `glsl/` (beside `glsl/common/`).
    pub glsl: &'static [&'static str],
    /// Host bytes per triangle it takes while it is built and uploaded, beyond the loaded mesh
    /// (checked before it is built; `tests/memory_estimates.rs` holds each against the peak of
    /// the allocations): what it builds, stages and uploads, counted in `host_bytes`.
    pub host_bytes_per_triangle: u64,
}

impl std::fmt::Debug for Row {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "design `{}`", self.name)
    }
}

impl Row {
    /// "--tracer grid --grid-variant exact", "--shadows".
    pub fn command_line(&self) -> String {
        if self.pipeline == Pipeline::Klee2016 {
            return "--shadows".into();
        }
        let v: Vec<String> = self
            .select
            .iter()
            .map(|(o, v)| format!("--{o} {v}"))
            .collect();
        v.join(" ")
    }

    /// The options, beyond [`COMMON_OPTIONS`], that belong to it.
    pub fn options(&self) -> impl Iterator<Item = &'static str> {
        self.options.iter().flat_map(|group| group.iter().copied())
    }

    /// Whether `option` (a long name) belongs to it.
    pub fn takes(&self, option: &str) -> bool {
        COMMON_OPTIONS.contains(&option) || self.options().any(|o| o == option)
    }
}

/// What every design keeps per triangle, and what a software driver's copy of an upload costs
/// (its GPU memory is the host's): [`Row::host_bytes_per_triangle`] of each row.
mod host_bytes {
    /// The world-space triangles (36) and attributes (136) every design makes.
    pub const WORLD: u64 = 36 + 136;
    /// Vertex arrays on the GPU: positions, normals, colours, texture coordinates, material.
    pub const UPLOAD: u64 = 136;
    /// The SAH BVH: builder boxes, centres and ids (24 + 12 + 4), at most 2n nodes of 32 bytes
    /// and their GPU copy, the wide layout built from them.
    pub const SAH_BVH: u64 = 40 + 2 * 32 * 2 + 2 * 64;
    /// Wagner's BVH: builder (24 + 12 + 4 + 4), 2n nodes of 48; its six textures (node bounds
    /// and integers 2·48, ids 4, vertices, normals, colours 3·48) staged, owned and copied by
    /// the driver.
    pub const WAGNER: u64 = 44 + 2 * 48 + 3 * (2 * 48 + 4 + 3 * 48);
    /// The streaming tracer's textures: two of four RGB32F slices per triangle, staged and in the
    /// driver (padded to four channels), and the copy of the scene the renderer keeps.
    pub const STREAM: u64 = 2 * 4 * (12 + 16) + 136;
    /// Klee 2016's N-tree is checked as it is built (`budget::Tracker`), not per triangle.
    pub const KLEE: u64 = 0;
}

/// The options of the uniform grids of Müller 2015's pipeline.
const GRID: &[&str] = &["grid", "grid-variant"];

/// Every design, in the order reports list them.
pub const REGISTRY: &[Row] = &[
    Row {
        name: "base",
        pipeline: Pipeline::Mueller2015,
        title: "Müller 2015's four kernels with the base tracer (every ray against every triangle)",
        select: &[("tracer", "base")],
        accel: Some(&accel::brute_force::ENTRY),
        twin: Some(reference::brute_force::twin),
        options: &[MUELLER],
        glsl: &["mueller2015", "brute_force"],
        host_bytes_per_triangle: host_bytes::WORLD + host_bytes::UPLOAD,
    },
    Row {
        name: "grid-thesis",
        pipeline: Pipeline::Mueller2015,
        title: "Müller 2015's four kernels with the thesis' uniform grid",
        select: &[("tracer", "grid"), ("grid-variant", "thesis")],
        accel: Some(&accel::thesis_grid::ENTRY),
        twin: Some(reference::thesis_grid::twin),
        options: &[MUELLER, GRID, &["voxel-array-length", "ray-array-length"]],
        glsl: &["mueller2015", "thesis_grid"],
        host_bytes_per_triangle: host_bytes::WORLD + host_bytes::UPLOAD,
    },
    Row {
        name: "grid-exact",
        pipeline: Pipeline::Mueller2015,
        title: "Müller 2015's four kernels with the exact uniform grid",
        select: &[("tracer", "grid"), ("grid-variant", "exact")],
        accel: Some(&accel::exact_grid::ENTRY),
        twin: Some(reference::exact_grid::twin),
        options: &[MUELLER, GRID, &["proximity-clouds"]],
        glsl: &["mueller2015", "exact_grid"],
        host_bytes_per_triangle: host_bytes::WORLD + host_bytes::UPLOAD,
    },
    Row {
        name: "bvh",
        pipeline: Pipeline::Mueller2015,
        title: "Müller 2015's pipeline with our SAH BVH (a pass in one kernel, or the four \
                kernels with --four-kernels)",
        select: &[("tracer", "bvh"), ("bvh-variant", "sah")],
        accel: Some(&accel::bvh::ENTRY),
        twin: Some(reference::bvh::twin),
        options: &[
            MUELLER,
            &[
                "bvh-variant",
                "four-kernels",
                "fused-passes",
                "bvh-levels",
                "bvh-instances",
            ],
        ],
        glsl: &["mueller2015", "bvh"],
        host_bytes_per_triangle: host_bytes::WORLD + host_bytes::UPLOAD + host_bytes::SAH_BVH,
    },
    Row {
        name: "bvh-wagner",
        pipeline: Pipeline::Wagner2018,
        title: "Wagner 2018's kernel (one light, hard shadows, no reflection) over his BVH",
        select: &[("tracer", "bvh"), ("bvh-variant", "wagner")],
        accel: None,
        twin: None,
        options: &[&["tracer", "bvh-variant", "tile"]],
        glsl: &["wagner2018"],
        host_bytes_per_triangle: host_bytes::WORLD + host_bytes::WAGNER,
    },
    Row {
        name: "stream",
        pipeline: Pipeline::Stream,
        title: "the streaming tracer (fragment programs, a static grid)",
        select: &[("tracer", "stream")],
        accel: None,
        twin: None,
        options: &[&[
            "tracer",
            "refl-depth",
            "grid",
            "proximity-clouds",
            "stream-steps",
            "stream-max-calls",
            "stream-naive-shadows",
            "stream-no-mask",
            "stream-single-sided",
        ]],
        glsl: &["stream"],
        host_bytes_per_triangle: host_bytes::WORLD + host_bytes::STREAM,
    },
    Row {
        name: "linespace",
        pipeline: Pipeline::Klee2016,
        title: "Klee 2016's soft shadows (N-tree, Cascaded Line Space)",
        select: &[],
        accel: None,
        twin: None,
        options: &[&[
            "shadows",
            "light-samples",
            "ntree-n",
            "ntree-depth",
            "klee-shading",
            "tile",
        ]],
        glsl: &["klee2016"],
        host_bytes_per_triangle: host_bytes::KLEE,
    },
];

/// The accelerators of Müller 2015's pipeline, in the registry's order.
pub fn accelerators() -> impl Iterator<Item = &'static accel::Entry> {
    REGISTRY.iter().filter_map(|r| r.accel)
}

/// The CPU twin of `accel` over `scene`, from its row of the registry.
pub fn twin(scene: &Scene, accel: &Accel) -> Result<Box<dyn CpuAccelerator>> {
    let row = row(accel.entry().label)?;
    let make = row
        .twin
        .ok_or_else(|| anyhow::anyhow!("{row:?} names no CPU twin"))?;
    make(scene, accel)
}

/// The row named `name`.
pub fn row(name: &str) -> Result<&'static Row> {
    REGISTRY.iter().find(|r| r.name == name).ok_or_else(|| {
        let names: Vec<_> = REGISTRY.iter().map(|r| r.name).collect();
        anyhow::anyhow!("no design `{name}` (designs: {})", names.join(", "))
    })
}

/// The row the command line selects: Klee 2016's with `soft`, else the one whose selecting
/// values `value` (an option's long name → its value, given or default) all match.
pub fn select(soft: bool, value: impl Fn(&str) -> String) -> Result<&'static Row> {
    if soft {
        return row("linespace");
    }
    REGISTRY
        .iter()
        .filter(|r| r.pipeline != Pipeline::Klee2016)
        .find(|r| r.select.iter().all(|(o, v)| value(o) == *v))
        .ok_or_else(|| anyhow::anyhow!("no design for --tracer {}", value("tracer")))
}

/// The options among `given` (long names) that do not belong to `row`, refused in one message
/// that says, for each, which designs take it; `chosen` says how the row was chosen ("from
/// --shadows"). `Ok` when every given option belongs.
pub fn refuse_foreign(row: &Row, given: &[String], chosen: &str) -> Result<()> {
    let foreign: Vec<&String> = given.iter().filter(|o| !row.takes(o)).collect();
    if foreign.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = foreign.iter().map(|o| format!("--{o}")).collect();
    let homes: Vec<String> = foreign
        .iter()
        .map(|o| {
            let takers: Vec<String> = REGISTRY
                .iter()
                .filter(|r| r.options().any(|t| t == o.as_str()))
                .map(|r| format!("{} ({})", r.name, r.command_line()))
                .collect();
            format!("--{o} applies to {} only", takers.join(", "))
        })
        .collect();
    bail!(
        "{} {} not apply: this render uses {} — {}, {chosen}. {}",
        names.join(", "),
        if names.len() == 1 { "does" } else { "do" },
        row.name,
        row.title,
        homes.join("; ")
    )
}

/// A design with its options: what a renderer is made from.
#[derive(Debug, Clone)]
pub enum Design {
    /// Müller 2015's four compute kernels with the accelerator `tracer` (and grid variant).
    Mueller2015(RenderOptions),
    Wagner2018(WagnerOptions),
    Stream(StreamOptions),
    Klee2016(SoftShadowOptions),
}

impl Design {
    /// The design of `row` at `width`×`height` with `refl_depth` reflection passes where it
    /// reflects, and the command line's [`defaults`] otherwise: the grid's resolution from the
    /// triangle count, bitwise shadow flags, the line space; no AOVs.
    pub fn plain(row: &Row, width: u32, height: u32, refl_depth: u32) -> Design {
        match (row.pipeline, row.accel) {
            (Pipeline::Mueller2015, Some(entry)) => {
                Design::Mueller2015(RenderOptions::new(entry.plain, width, height, refl_depth))
            }
            (Pipeline::Wagner2018, _) => Design::Wagner2018(WagnerOptions {
                width,
                height,
                tile: defaults::TILE,
                aovs: false,
            }),
            (Pipeline::Stream, _) => Design::Stream(StreamOptions::new(width, height, refl_depth)),
            (Pipeline::Klee2016, _) => Design::Klee2016(SoftShadowOptions {
                mode: ShadowMode::Linespace,
                samples_u: defaults::LIGHT_SAMPLES.0,
                samples_v: defaults::LIGHT_SAMPLES.1,
                ntree_n: defaults::NTREE_N,
                ntree_depth: defaults::NTREE_DEPTH,
                width,
                height,
                tile: defaults::TILE,
                shading: Default::default(),
                linespace_build: Default::default(),
            }),
            (Pipeline::Mueller2015, None) => {
                unreachable!("Müller 2015's rows name their accelerator")
            }
        }
    }

    /// Its row of the registry.
    pub fn row(&self) -> &'static Row {
        let name = match self {
            Design::Mueller2015(o) => o.accel.entry().label,
            Design::Wagner2018(_) => "bvh-wagner",
            Design::Stream(_) => "stream",
            Design::Klee2016(_) => "linespace",
        };
        row(name).expect("every design has a row")
    }

    /// The image size (width, height).
    pub fn size(&self) -> (u32, u32) {
        match self {
            Design::Mueller2015(o) => (o.width, o.height),
            Design::Wagner2018(o) => (o.width, o.height),
            Design::Stream(o) => (o.width, o.height),
            Design::Klee2016(o) => (o.width, o.height),
        }
    }

    /// Keep the AOVs of its frames (the point-light designs; Klee 2016's has none).
    pub fn keep_aovs(&mut self) {
        match self {
            Design::Mueller2015(o) => o.aovs = true,
            Design::Wagner2018(o) => o.aovs = true,
            Design::Stream(o) => o.aovs = true,
            Design::Klee2016(_) => {}
        }
    }

    /// Whether the renderer keeps the AOVs of its frames.
    pub fn aovs(&self) -> bool {
        match self {
            Design::Mueller2015(o) => o.aovs,
            Design::Wagner2018(o) => o.aovs,
            Design::Stream(o) => o.aovs,
            Design::Klee2016(_) => false,
        }
    }

    /// The renderer for `scene`, after the checks every design shares (image size, host memory
    /// for the frame and for the scene as this design builds it, the kind of lights).
    pub fn renderer(
        &self,
        gl: Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
    ) -> Result<Box<dyn Renderer>> {
        self.check(scene)?;
        Ok(match self.clone() {
            Design::Mueller2015(o) => Box::new(RayTracer::new(gl, info, scene, shaders, o)?),
            Design::Wagner2018(o) => Box::new(WagnerRenderer::new(gl, info, scene, shaders, o)?),
            Design::Stream(o) => Box::new(StreamRenderer::new(gl, info, scene, shaders, o)?),
            Design::Klee2016(o) => Box::new(SoftShadowRenderer::new(gl, info, scene, shaders, o)?),
        })
    }

    fn check(&self, scene: &Scene) -> Result<()> {
        use crate::limits::{check, GRID_RES, IMAGE_SIDE, REFL_DEPTH};
        let (w, h) = self.size();
        check("the image width", w, &IMAGE_SIDE).map_err(anyhow::Error::msg)?;
        check("the image height", h, &IMAGE_SIDE).map_err(anyhow::Error::msg)?;
        let (refl_depth, grid) = match self {
            Design::Mueller2015(o) => (o.refl_depth, o.accel.grid_resolution().map(|n| [n; 3])),
            Design::Stream(o) => (o.refl_depth, o.dims),
            _ => (0, None),
        };
        check("the reflection depth", refl_depth, &REFL_DEPTH).map_err(anyhow::Error::msg)?;
        for n in grid.unwrap_or([1; 3]) {
            check("the grid resolution", n, &GRID_RES).map_err(anyhow::Error::msg)?;
        }
        crate::frame::check_host(w, h, self.aovs()).map_err(anyhow::Error::msg)?;
        let row = self.row();
        // Müller 2015's pipeline casts feelers towards area-light samples (ours), Klee 2016's
        // is made for them; the others light with point lights only
        let lights_areas = matches!(row.pipeline, Pipeline::Mueller2015 | Pipeline::Klee2016);
        if !lights_areas && !scene.area_lights.is_empty() {
            bail!(
                "{}: {} lights with [[light]]s only; the scene's {} [[area_light]](s) would be \
                 ignored (render it with --shadows, or with Müller 2015's pipeline: --tracer \
                 base|grid|bvh --bvh-variant sah)",
                scene.path.display(),
                row.title,
                scene.area_lights.len()
            );
        }
        if row.host_bytes_per_triangle == 0 {
            return Ok(());
        }
        let triangles = scene.triangle_count() as u64;
        crate::scene::budget::reserve(
            &format!("building and uploading the scene's {triangles} triangles"),
            "the scene with --tracer",
            triangles.saturating_mul(row.host_bytes_per_triangle),
        )
        .map_err(|e| anyhow::anyhow!("{}: {e}", scene.path.display()))
    }
}
