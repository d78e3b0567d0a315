//! `accel-compare` (issue 15): every acceleration structure under the same conditions — the
//! comparison the streaming tracer wishes for ("a full scale comparison of different ray shooting
//! acceleration schemes as had been done for software implementations": Havran et al. 2000,
//! "Statistical Comparison of Ray-Shooting Efficiency Schemes") and none of the four sources
//! could make.
//!
//! - Accelerators in Müller 2015's pipeline (four compute kernels, the same eye rays, feelers
//!   and shading): brute force (`base`), the uniform grid as the thesis builds it and exact,
//!   the exact grid with proximity clouds, our SAH BVH. In their own pipelines, marked so:
//!   Wagner 2018's BVH megakernel and the streaming tracer's grid (fragment passes, with and
//!   without proximity clouds).
//! - Scenes: every shipped scene of every source, the area scenes' geometry lit by a point
//!   light at the area light's centre, and the teapot in a stadium (`stadium.toml`).
//! - Per configuration (camera and objects fixed): build ms, memory bytes, and per kind of ray
//!   (primary, feelers to the first light, to all lights, reflection; Müller's pipeline and the
//!   stream count and time them apart, `pipeline::ray_kinds`) Mrays/s, triangle tests and
//!   voxels/nodes visited per ray; the frame's Mrays/s (all rays over all of the frame's GPU
//!   time, the one figure every pipeline has); agreement of the first hits with the CPU
//!   reference ([`crate::bench::runner::judge`]).
//!
//! The tables, figures and analysis are in [`crate::bench::report::accel_compare`], which reads
//! the rows and the [`Plan`] of the comparison.

use std::sync::LazyLock;

use anyhow::Result;

use super::protocol::Protocol;
use crate::bench::common::section::Section;
use crate::bench::report::accel_compare::{self as report, Accelerator, Plan, Row, Work};
use crate::bench::runner::args::Scale;
use crate::bench::runner::config::{BvhVariant, Config, GridVariant, Sizing, Tracer};
use crate::bench::runner::outcome::Outcome;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;
use gpgpu_rt::accel::auto_resolution;
use gpgpu_rt::design::{self, Pipeline};
use gpgpu_rt::frame::{FrameStats, RAY_KINDS};
use gpgpu_rt::pipeline::stream::grid::auto_dims;

pub const ACCEL_COMPARE: Protocol = Protocol {
    name: "accel-compare",
    title: "every acceleration structure on the same pipeline, scenes and rays (ours)",
    run,
    units: Units::Configs,
};

/// Quick: 32², 2 frames after 1 (every configuration in a few seconds on llvmpipe). Full:
/// 512², 5 frames after 2.
pub const QUICK: Sizing = Sizing {
    width: 32,
    height: 32,
    angles: 2,
    warmup: 1,
};
pub const FULL: Sizing = Sizing::full(5, 2);

/// Every shipped scene of every source (the area scenes for their geometry), and the stadium.
pub const SCENES: [&str; 15] = [
    "square.toml",
    "sphere.toml",
    "knight.toml",
    "torus_knot.toml",
    "bunny_low.toml",
    "sparse_room.toml",
    "cow.toml",
    "stadium.toml",
    "teapot1.toml",
    "teapot3.toml",
    "teapot6.toml",
    "bunny.toml",
    "bunny_area.toml",
    "dragon.toml",
    "dragon_area.toml",
];

/// The stadium: where the uniform grid is expected to break.
pub const STADIUM: &str = "stadium.toml";

/// At `--scale quick` the base tracer runs only up to this many triangles (above, its frame
/// takes tens of seconds on llvmpipe; the CPU reference still judges the first hits).
pub const QUICK_BASE_MAX_TRIANGLES: usize = 30_000;
/// At `--scale quick` Wagner's faithful build (recursive, as the thesis') only up to this many
/// triangles (above it takes minutes, as the thesis says of 100k).
pub const QUICK_WAGNER_MAX_TRIANGLES: usize = 50_000;

/// The configuration of accelerator `a` on a scene of `t` triangles: the grids at `--grid auto`'s
/// N = ∛(T/5), the stream's at the paper's ∛T per axis.
fn tracer(a: &Accelerator, t: usize) -> Tracer {
    let resolution = auto_resolution(t);
    match (a.row.name, a.proximity_clouds) {
        ("grid-exact", true) => Tracer::grid_pc(resolution),
        ("stream", pc) => Tracer::stream(auto_dims(t).to_array(), pc, false, false),
        ("grid-thesis", _) => Tracer::uniform_grid(GridVariant::Thesis, resolution),
        ("grid-exact", _) => Tracer::uniform_grid(GridVariant::Exact, resolution),
        ("bvh", _) => Tracer::bvh(BvhVariant::Sah),
        ("bvh-wagner", _) => Tracer::bvh(BvhVariant::Wagner),
        ("base", _) => Tracer::base(),
        (other, _) => unreachable!("accel-compare has no configuration of `{other}`"),
    }
}

/// The tables' names of the designs (the columns of the reports since the first run).
const NAMES: [(&str, bool, &str); 8] = [
    ("base", false, "base"),
    ("grid-thesis", false, "grid thesis"),
    ("grid-exact", false, "grid exact"),
    ("grid-exact", true, "grid exact+pc"),
    ("bvh", false, "bvh sah"),
    ("bvh-wagner", false, "bvh wagner"),
    ("stream", false, "stream g"),
    ("stream", true, "stream pc"),
];

/// Every point-light design of the registry, with and without proximity clouds where it takes
/// them, in the registry's order.
pub static ACCELERATORS: LazyLock<Vec<Accelerator>> = LazyLock::new(|| {
    let rows = design::REGISTRY
        .iter()
        .filter(|r| r.pipeline != Pipeline::Klee2016);
    rows.flat_map(|row| {
        let clouds = [false, true].into_iter();
        clouds
            .filter(|&pc| !pc || row.takes("proximity-clouds"))
            .map(move |pc| {
                let name = NAMES
                    .iter()
                    .find(|(r, c, _)| (*r, *c) == (row.name, pc))
                    .map_or(row.name, |n| n.2);
                Accelerator {
                    name,
                    row,
                    proximity_clouds: pc,
                }
            })
    })
    .collect()
});

/// The accelerator a configuration's tracer belongs to.
pub fn accelerator_of(spec: &Tracer) -> &'static Accelerator {
    let key = (spec.row().name, spec.proximity_clouds());
    ACCELERATORS
        .iter()
        .find(|a| (a.row.name, a.proximity_clouds) == key)
        .expect("every configuration's design is compared")
}

/// Whether `a` runs on a scene of `triangles` triangles at `scale`.
fn runs(a: &Accelerator, triangles: usize, scale: Scale) -> bool {
    scale == Scale::Full
        || match a.name {
            "base" => triangles <= QUICK_BASE_MAX_TRIANGLES,
            "bvh wagner" => triangles <= QUICK_WAGNER_MAX_TRIANGLES,
            _ => true,
        }
}

/// Every scene with every accelerator that runs on it, camera and objects fixed, at the scene's
/// reflection depth, first hits judged.
fn configs(bench: &mut Bench) -> Result<Vec<Config>> {
    let s = bench.sizing(QUICK, FULL);
    let scale = bench.scale();
    let mut v = Vec::new();
    for scene in SCENES {
        let loaded = bench.scene(scene)?;
        let (t, refl) = (loaded.triangle_count(), loaded.settings.refl_depth);
        for a in ACCELERATORS.iter().filter(|a| runs(a, t, scale)) {
            let mut c = Config::fixed(scene, tracer(a, t), (s.width, s.height), s);
            c.refl_depth = refl;
            c.judge = true;
            v.push(c);
        }
    }
    Ok(v)
}

fn run(p: &Protocol, bench: &mut Bench) -> Result<Section> {
    let configs = configs(bench)?;
    let outcomes = bench.measure(p.name, &configs)?;
    let rows = rows(&outcomes);
    let file = report::write_csv(&bench.out, p.name, &rows)?;
    let plan = Plan {
        accelerators: ACCELERATORS.as_slice(),
        stadium: STADIUM,
        quick_base_max_triangles: QUICK_BASE_MAX_TRIANGLES,
        quick_wagner_max_triangles: QUICK_WAGNER_MAX_TRIANGLES,
        sizing: bench.sizing(QUICK, FULL),
        scale: bench.scale(),
    };
    let markdown = report::markdown(&plan, &rows);
    let figures = report::figures(&plan, &rows);
    let mut s = p.sweep_section(&bench.out, markdown, &outcomes, &figures)?;
    s.files.push(file);
    Ok(s)
}

/// The rows of the outcomes.
pub fn rows(outcomes: &[Outcome]) -> Vec<Row> {
    outcomes.iter().map(row).collect()
}

fn row(o: &Outcome) -> Row {
    let frames: Vec<&FrameStats> = o.frames.iter().map(|f| &f.stats).collect();
    let n = frames.len().max(1) as f64;
    let mean = |f: &dyn Fn(&FrameStats) -> f64| frames.iter().map(|s| f(s)).sum::<f64>() / n;
    let last = frames.last();
    let kinds = RAY_KINDS.map(|k| {
        let count = |name: &str| {
            last.and_then(|s| s.ray_kinds.get(k))
                .map_or(0, |w| w.count(name))
        };
        Work {
            rays: count("rays") as f64,
            gpu_ms: mean(&|s| s.ray_kinds.get(k).map_or(0.0, |w| w.gpu_ms)),
            tests: last
                .and_then(|s| s.ray_kinds.get(k))
                .map_or(0, |w| w.triangle_tests) as f64,
            visits: (count("voxels_visited") + count("nodes_visited")) as f64,
        }
    });
    let visits = |s: &FrameStats| {
        let e = |k: &str| s.events.get(k).copied().unwrap_or(0);
        (e("voxels_visited") + e("nodes_visited")) as f64
    };
    // every pipeline counts the rays it traces: Müller's per kind, the others per frame
    let frame = Work {
        rays: last.map_or(0, |s| s.events.get("rays").copied().unwrap_or(0)) as f64,
        gpu_ms: mean(&|s| s.total_gpu_ms()),
        tests: last.map_or(0, |s| s.total_triangle_tests()) as f64,
        visits: last.map_or(0.0, |s| visits(s)),
    };
    let build = ["grid_build_ms", "bvh_build_ms", "proximity_ms"].map(|f| o.fact(f));
    let agreement = o.fact("first_hit_agreement").map(|a| {
        let judge = o.frames[0].stats.facts.get("first_hit_judge");
        let judge = judge.and_then(|j| j.as_str()).unwrap_or("?");
        (a, judge.to_string())
    });
    Row {
        scene: o.config.scene_name().to_string(),
        triangles: o.triangles,
        lights: o.lights,
        accelerator: accelerator_of(&o.config.tracer),
        tracer: o.config.tracer.label(),
        build_ms: build.iter().flatten().copied().reduce(|a, b| a + b),
        bytes: o.fact("grid_bytes").or(o.fact("bvh_bytes")),
        kinds,
        frame,
        agreement,
        lost: last.map_or(0, |s| {
            let e = |k: &str| s.events.get(k).copied().unwrap_or(0);
            e("dropped_triangle_refs") + e("ray_list_overflows")
        }),
        error: o.error.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every point-light design of the registry is compared, with and without proximity clouds
    /// where it takes them, and each configuration finds its way back to its accelerator.
    #[test]
    fn every_point_light_design_is_compared() {
        for row in design::REGISTRY {
            let pc = row.takes("proximity-clouds");
            let compared: Vec<bool> = ACCELERATORS
                .iter()
                .filter(|a| a.row.name == row.name)
                .map(|a| a.proximity_clouds)
                .collect();
            let want = match row.pipeline {
                Pipeline::Klee2016 => vec![],
                _ if pc => vec![false, true],
                _ => vec![false],
            };
            assert_eq!(compared, want, "{row:?}");
        }
        for a in ACCELERATORS.iter() {
            let spec = tracer(a, 70_000);
            assert_eq!(spec.row().name, a.row.name, "{}", a.name);
            assert_eq!(accelerator_of(&spec).name, a.name);
        }
        let names: Vec<&str> = ACCELERATORS.iter().map(|a| a.name).collect();
        assert_eq!(names, NAMES.map(|n| n.2), "the reports' columns");
    }
}
