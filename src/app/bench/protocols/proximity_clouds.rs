//! The streaming tracer's evaluation (ch. 4, Tables 1–3): milliseconds per frame of the streaming
//! grid tracer, with (pc) and without (g) proximity clouds, on the four scenes of Fig. 4–7 at
//! 256², 512², 768², best of several runs.
//!
//! - `proximity-clouds-table1`: ray casting, eye rays only (the scenes' lights removed);
//! - `proximity-clouds-table2`: shadow casting, eye and shadow rays;
//! - `proximity-clouds-table3`: ray tracing, eye, shadow and reflection rays, two levels of recursion.
//!
//! Every scene is measured with `--tracer stream` at the paper's grid (g, and pc where the
//! paper has it) and with the compute exact grid (`--tracer grid`, cubic: the paper's largest
//! axis) on the same frames; a sparse scene (`sparse_room.toml`) is added, where skipping empty
//! cells should pay. The report is in [`crate::bench::report::proximity_clouds`], and reads the
//! run's [`Plan`].

use anyhow::Result;

use super::protocol::Protocol;
use crate::bench::common::section::Section;
use crate::bench::published::proximity_clouds::{self as pp, PaperScene};
use crate::bench::report::proximity_clouds::{self as report, Plan};
use crate::bench::runner::config::{Config, GridVariant, Sizing, Tracer};
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;

/// The sparse scene (not in the paper): a small detailed object in a large empty room.
pub const SPARSE: PaperScene =
    PaperScene::new("sparse_room.toml", "Sparse room", 1776, [32, 32, 32], true);

/// Quick: image sides 64, 128, 192 (the paper's 256 : 512 : 768 scaled by ¼), the best of 5
/// frames after 1 warm-up frame. Full: the paper's sides, the best of 10 frames after 2.
pub const QUICK: Sizing = Sizing::quick(5, 1);
pub const FULL: Sizing = Sizing::full(10, 2);
pub const QUICK_SIDES: &[u32] = &[64, 128, 192];
pub const FULL_SIDES: &[u32] = &pp::SIZES;
/// Stream vs compute grid on the Stanford bunny at 512² with the 128³ grid (ours), in
/// Table 1 at every scale.
pub const BUNNY_SIDE: u32 = 512;

pub const PROXIMITY_CLOUDS_TABLE1: Protocol = Protocol {
    name: "proximity-clouds-table1",
    title: "Ray casting, eye rays only: streaming grid g and pc vs compute grid (the streaming \
            tracer, Table 1)",
    run: |p, bench| run(p, bench, 1),
    units: Units::Configs,
};

pub const PROXIMITY_CLOUDS_TABLE2: Protocol = Protocol {
    name: "proximity-clouds-table2",
    title: "Shadow casting, eye and shadow rays: streaming grid g and pc vs compute grid (the \
            streaming tracer, Table 2)",
    run: |p, bench| run(p, bench, 2),
    units: Units::Configs,
};

pub const PROXIMITY_CLOUDS_TABLE3: Protocol = Protocol {
    name: "proximity-clouds-table3",
    title: "Ray tracing, eye, shadow and reflection rays (two levels of recursion): streaming \
            grid g and pc vs compute grid (the streaming tracer, Table 3)",
    run: |p, bench| run(p, bench, 3),
    units: Units::Configs,
};

/// How a run is planned and what it measures; the plan itself is what the report reads.
impl Plan {
    pub fn of(bench: &Bench, table: u32) -> Plan {
        let square = |s: &[u32]| s.iter().map(|&n| (n, n)).collect::<Vec<_>>();
        let sizes = bench.sizes(&square(QUICK_SIDES), &square(FULL_SIDES));
        let mut sides: Vec<u32> = sizes.iter().map(|&(w, _)| w).collect();
        sides.sort();
        sides.dedup();
        Plan {
            table,
            sides,
            frames: bench.sizing(QUICK, FULL),
            bunny_512: table == 1 && !bench.sizes_given(),
            sparse: SPARSE,
            bunny_side: BUNNY_SIDE,
        }
    }

    /// Shadow rays in Tables 2 and 3; reflection rays (two bounces) in Table 3.
    pub fn shadows(&self) -> bool {
        self.table >= 2
    }
    pub fn refl_depth(&self) -> u32 {
        if self.table == 3 {
            2
        } else {
            0
        }
    }

    /// The tracers of `scene`: stream g, stream pc (where the paper has pc), the compute exact
    /// grid g (cubic, the paper's largest axis), and its pc column (`--tracer grid
    /// --proximity-clouds`) where the paper has pc.
    pub fn tracers(scene: &PaperScene) -> Vec<Tracer> {
        let stream = |pc| Tracer::stream(scene.grid, pc, false, false);
        let resolution = scene.grid.into_iter().max().unwrap_or(1);
        let mut v = vec![stream(false)];
        if scene.pc {
            v.push(stream(true));
        }
        v.push(Tracer::uniform_grid(GridVariant::Exact, resolution));
        if scene.pc {
            v.push(Tracer::grid_pc(resolution));
        }
        v
    }

    /// Table 2 measures the paper's shadow-ray optimisations ("roughly 20 % speedup compared
    /// to the naive implementation of shadow rays") on its dense scenes, each switched off
    /// beside stream g: the any-hit search (`--stream-naive-shadows`), the masking
    /// (`--stream-no-mask`), and both.
    fn naive(&self, scene: &PaperScene) -> Vec<Tracer> {
        let dense = pp::SCENES.iter().any(|s| s.file == scene.file);
        if self.table != 2 || !dense {
            return Vec::new();
        }
        [(true, false), (false, true), (true, true)]
            .map(|(naive_shadows, no_mask)| {
                Tracer::stream(scene.grid, false, naive_shadows, no_mask)
            })
            .to_vec()
    }

    /// Every scene of the table and the sparse room, every tracer, every side; and the
    /// Stanford bunny at 512² where [`Plan::bunny_512`] says so.
    pub fn configs(&self) -> Vec<Config> {
        let scenes = pp::SCENES.iter().chain(std::iter::once(&SPARSE));
        let mut v = Vec::new();
        for scene in scenes {
            for tracer in Plan::tracers(scene).into_iter().chain(self.naive(scene)) {
                for &side in &self.sides {
                    v.push(self.config(scene, tracer.clone(), side));
                }
            }
        }
        if self.bunny_512 && !self.sides.contains(&BUNNY_SIDE) {
            for tracer in Plan::tracers(&pp::STANFORD_BUNNY) {
                v.push(self.config(&pp::STANFORD_BUNNY, tracer, BUNNY_SIDE));
            }
        }
        v
    }

    fn config(&self, scene: &PaperScene, tracer: Tracer, side: u32) -> Config {
        Config {
            refl_depth: self.refl_depth(),
            shadows: self.shadows(),
            ..Config::fixed(scene.file, tracer, (side, side), self.frames)
        }
    }
}

fn run(p: &Protocol, bench: &mut Bench, table: u32) -> Result<Section> {
    let plan = Plan::of(bench, table);
    let outcomes = bench.measure(p.name, &plan.configs())?;
    let markdown = report::markdown(&plan, &outcomes);
    let figures = report::figures(p.name, &plan, &outcomes);
    let file = report::write_csv(&bench.out, p.name, &plan, &outcomes)?;
    let mut s = p.sweep_section(&bench.out, markdown, &outcomes, &figures)?;
    s.files.push(file);
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_papers_grids_and_columns() {
        let stream = |s: &PaperScene| -> Vec<String> {
            Plan::tracers(s).iter().map(|t| t.label()).collect()
        };
        assert_eq!(
            stream(&pp::KNIGHT),
            [
                "stream g 14x16x14",
                "stream pc 14x16x14",
                "grid exact 16³",
                "grid exact-pc 16"
            ]
        );
        assert_eq!(
            stream(&pp::TORUS_KNOT),
            [
                "stream g 16",
                "stream pc 16",
                "grid exact 16³",
                "grid exact-pc 16"
            ]
        );
        assert_eq!(
            stream(&pp::STANFORD_BUNNY),
            ["stream g 128", "grid exact 128³"]
        );
        let plan = Plan {
            table: 3,
            sides: vec![256, 512, 768],
            frames: FULL,
            bunny_512: false,
            sparse: SPARSE,
            bunny_side: BUNNY_SIDE,
        };
        let configs = plan.configs();
        // 3 scenes × 4 tracers + the Stanford bunny × 2 + the sparse room × 4, at 3 sides
        assert_eq!(configs.len(), (12 + 2 + 4) * 3);
        assert!(configs.iter().all(|c| c.refl_depth == 2 && c.shadows));
        let t1 = Plan {
            table: 1,
            sides: vec![64, 128, 192],
            bunny_512: true,
            ..plan
        };
        let configs = t1.configs();
        assert!(configs.iter().all(|c| c.refl_depth == 0 && !c.shadows));
        // the Stanford bunny at 512², stream g and the compute grid at 128³
        let bunny: Vec<String> = configs
            .iter()
            .filter(|c| c.width == BUNNY_SIDE)
            .map(|c| c.label())
            .collect();
        assert_eq!(bunny, ["bunny, stream g 128", "bunny, grid exact 128³"]);
    }
}
