//! Müller 2015, ch. 5.3 "Vergleich der beiden Ray-Tracer": the Stanford bunny (69451
//! triangles), one light, no reflections, base tracer vs the grid at several resolutions (FPS:
//! Fig. 23, triangle tests: Fig. 24); and the dragon with the grid at 28³ (the thesis' base
//! tracer timed out on it). Published: bunny 0.8804 FPS base vs 4.8339 FPS with the grid at
//! 24³, 1,137,720,816 vs 287,728,727.1 tests per frame; dragon (204088 triangles) 1.396 FPS.

use anyhow::Result;

use super::protocol::Protocol;
use super::sweep::{self, resolution_chart};
use super::thesis_bvh;
use crate::bench::common::format::{int, num, ratio, table};
use crate::bench::common::section::Section;
use crate::bench::published::thesis::{self as p, Published};
use crate::bench::report::plots::{Chart, Figure, Series, Style, BLACK_INDEX};
use crate::bench::runner::args::Scale;
use crate::bench::runner::config::{variant_name, Config, GridVariant, Sizing, Tracer};
use crate::bench::runner::outcome::Outcome;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;

pub const PROTOCOL: Protocol = Protocol {
    name: "thesis-5.3",
    title: "base tracer vs uniform grid: bunny and dragon (Müller 2015, ch. 5.3, Fig. 23, 24)",
    run,
    units: Units::Configs,
};

pub const BUNNY: &str = "bunny.toml";
pub const DRAGON: &str = "dragon.toml";
pub const QUICK_RESOLUTIONS: &[u32] = &[8, 16, 24, 32];
pub const FULL_RESOLUTIONS: &[u32] = &[8, 12, 16, 20, 24, 28, 32, 40];

/// What a run of the protocol measures.
struct Plan {
    sizing: Sizing,
    resolutions: Vec<u32>,
    variants: Vec<GridVariant>,
    /// The base tracer renders the dragon too (at full scale only: it needs a GPU).
    dragon_base: bool,
}

fn run(p: &Protocol, bench: &mut Bench) -> Result<Section> {
    let plan = Plan {
        sizing: bench.sizing(sweep::QUICK, sweep::FULL),
        resolutions: bench.grid_resolutions(QUICK_RESOLUTIONS, FULL_RESOLUTIONS),
        variants: bench.variants(),
        dragon_base: bench.scale() == Scale::Full,
    };
    let outcomes = bench.measure(p.name, &plan.configs())?;
    let results = Results::of(&outcomes, dragon_mesh_triangles(bench));
    let markdown = setup_text(&plan, &results)
        + &comparison(&results, &plan.variants)
        + &tables(&results)
        + &thesis_bvh::table_text(&outcomes);
    let figures = figures(plan.sizing, &results);
    p.sweep_section(&bench.out, markdown, &outcomes, &figures)
}

impl Plan {
    /// The bunny without reflections (REFL_DEPTH 0), base and grid; the dragon with the grid
    /// at 28³ (the thesis' scene had a reflective floor, so REFL_DEPTH 1), and at full scale
    /// with the base tracer (202520 triangles per ray); the SAH BVH on both (ours).
    fn configs(&self) -> Vec<Config> {
        let (s, variants) = (self.sizing, &self.variants);
        let mut configs = vec![Config::new(BUNNY, Tracer::base(), 0, s)];
        configs.extend(sweep::grid_configs(
            BUNNY,
            0,
            s,
            variants,
            &self.resolutions,
        ));
        let dragon_res = [p::DRAGON_GRID_RESOLUTION];
        configs.extend(sweep::grid_configs(DRAGON, 1, s, variants, &dragon_res));
        if self.dragon_base {
            configs.push(Config::new(DRAGON, Tracer::base(), 1, s));
        }
        // the SAH BVH on both, with the grid's reflection depths
        configs.extend(thesis_bvh::configs(&[BUNNY], 0, s));
        configs.extend(thesis_bvh::configs(&[DRAGON], 1, s));
        configs
    }
}

/// The dragon mesh alone: the scene's largest object (the rest is the floor); 0 if unknown.
fn dragon_mesh_triangles(bench: &mut Bench) -> usize {
    let scene = bench.scene(DRAGON);
    let meshes = scene.map(|s| s.objects.iter().map(|o| o.mesh.triangle_count()).max());
    meshes.ok().flatten().unwrap_or(0)
}

/// The outcomes the report reads, by scene and tracer.
struct Results<'a> {
    bunny_base: Option<&'a Outcome>,
    bunny_grid: Vec<&'a Outcome>,
    dragon_base: Option<&'a Outcome>,
    dragon_grid: Vec<&'a Outcome>,
    /// Triangles of the bunny's and the dragon's scenes, and of the dragon mesh alone.
    bunny_triangles: usize,
    dragon_triangles: usize,
    dragon_mesh: usize,
}

impl<'a> Results<'a> {
    fn of(outcomes: &'a [Outcome], dragon_mesh: usize) -> Results<'a> {
        let triangles = |scene: &str| {
            let o = outcomes.iter().find(|o| o.config.scene == scene);
            o.map_or(0, |o| o.triangles)
        };
        Results {
            bunny_base: sweep::base_outcome(outcomes, BUNNY),
            bunny_grid: sweep::grid_outcomes(outcomes, BUNNY),
            dragon_base: sweep::base_outcome(outcomes, DRAGON),
            dragon_grid: sweep::grid_outcomes(outcomes, DRAGON),
            bunny_triangles: triangles(BUNNY),
            dragon_triangles: triangles(DRAGON),
            dragon_mesh,
        }
    }

    /// The bunny's base tracer, if it was measured without error.
    fn bunny_base_ok(&self) -> Option<&'a Outcome> {
        self.bunny_base.filter(|b| b.ok())
    }

    /// The successful grid configuration of `variant` at `resolution` among `grid`.
    fn grid_at(grid: &[&'a Outcome], variant: GridVariant, resolution: u32) -> Option<&'a Outcome> {
        grid.iter()
            .copied()
            .find(|o| o.ok() && o.config.tracer.grid() == Some((variant, resolution)))
    }

    /// The bunny with the grid at 24³ (the thesis' published resolution).
    fn grid24(&self, v: GridVariant) -> Option<&'a Outcome> {
        Self::grid_at(&self.bunny_grid, v, p::BUNNY_GRID_RESOLUTION)
    }

    /// The dragon with the grid at 28³.
    fn dragon28(&self, v: GridVariant) -> Option<&'a Outcome> {
        Self::grid_at(&self.dragon_grid, v, p::DRAGON_GRID_RESOLUTION)
    }

    /// "202,520 (1,568 fewer; 210,712 with the floor)".
    fn dragon_mesh_text(&self) -> Option<String> {
        let (difference, side) = self.dragon_difference();
        (self.dragon_mesh > 0).then(|| {
            format!(
                "{} ({difference} {side}; {} with the floor)",
                int(self.dragon_mesh as f64),
                int(self.dragon_triangles as f64)
            )
        })
    }

    /// How many triangles our dragon mesh has fewer or more than the thesis': ("1,568", "fewer").
    fn dragon_difference(&self) -> (String, &'static str) {
        let d = self.dragon_mesh as f64 - p::DRAGON_TRIANGLES as f64;
        (int(d.abs()), if d <= 0.0 { "fewer" } else { "more" })
    }

    /// The dragon with the base tracer: FPS and tests, why not, or not run.
    fn dragon_base_text(&self) -> Option<String> {
        match self.dragon_base {
            None => Some("not run at this scale".into()),
            Some(b) if b.ok() => {
                let tests = b.tests().map(|t| t.mean).unwrap_or(0.0);
                Some(format!(
                    "{} FPS, {} mean tests",
                    num(b.mean_fps()?),
                    int(tests)
                ))
            }
            Some(b) => Some(format!("failed: {}", b.error.as_deref().unwrap_or(""))),
        }
    }
}

fn setup_text(plan: &Plan, r: &Results) -> String {
    let s = plan.sizing;
    let dragon_base = if plan.dragon_base {
        " The base tracer also renders the dragon here (the thesis' timed out)."
    } else {
        " The base tracer does not render the dragon at quick scale (a brute-force dragon frame takes \
         seconds on llvmpipe); `--scale full` adds it."
    };
    let (difference, side) = r.dragon_difference();
    format!(
        "Setup (thesis): the bunny ({} triangles), one light, no reflections; the dragon ({}) in a scene with \
         one light and a reflective floor. Ours: `scenes/{BUNNY}` ({} triangles, REFL_DEPTH 0) and \
         `scenes/{DRAGON}` ({} triangles: Stanford's `dragon_vrip_res2` decimation of {} triangles, the closest \
         available to the thesis' mesh, {difference} triangles {side}, and a reflective floor; REFL_DEPTH 1), {} \
         pixels, {} angles of the rotation, {} warm-up frame(s), grid resolutions {} for the bunny and 28³ \
         for the dragon, variants {}.{dragon_base}\n\n",
        int(p::BUNNY_TRIANGLES as f64),
        int(p::DRAGON_TRIANGLES as f64),
        int(r.bunny_triangles as f64),
        int(r.dragon_triangles as f64),
        int(r.dragon_mesh as f64),
        s.size(),
        s.angles,
        s.warmup,
        sweep::resolutions_text(&plan.resolutions),
        sweep::variants_text(&plan.variants),
    )
}

/// Our value in a row of the comparison, per grid variant: a cell as it is, or a
/// hardware-independent ratio (shown in bold).
enum Ours {
    Cell(fn(&Results, GridVariant) -> Option<String>),
    Ratio(fn(&Results, GridVariant) -> Option<f64>),
}

/// "**×5.49**".
fn bold_ratio(x: f64) -> String {
    format!("**{}**", ratio(Some(x)))
}

/// A row of the comparison: the quantity, the published value, ours per variant.
struct Row {
    quantity: String,
    published: String,
    ours: Ours,
}

impl Row {
    /// A published number: the quantity in the thesis' words, the number with its figure.
    fn published(n: &Published, ours: fn(&Results, GridVariant) -> Option<String>) -> Row {
        Row::new(n.what, n.cited(), ours)
    }

    fn new(
        quantity: &str,
        published: String,
        ours: fn(&Results, GridVariant) -> Option<String>,
    ) -> Row {
        Row {
            quantity: quantity.into(),
            published,
            ours: Ours::Cell(ours),
        }
    }

    /// A hardware-independent ratio, in bold: the published ratio with a note, and ours.
    fn ratio(
        quantity: &str,
        published: f64,
        note: &str,
        ours: fn(&Results, GridVariant) -> Option<f64>,
    ) -> Row {
        Row {
            quantity: format!("**{quantity}**"),
            published: format!("{} {note}", bold_ratio(published)),
            ours: Ours::Ratio(ours),
        }
    }

    /// Our cell for `variant`; `None` where it was not measured.
    fn ours(&self, r: &Results, variant: GridVariant) -> Option<String> {
        match self.ours {
            Ours::Cell(f) => f(r, variant),
            Ours::Ratio(f) => f(r, variant).map(bold_ratio),
        }
    }
}

/// "287,728,727": the mean triangle tests per frame.
fn mean_tests(o: &Outcome) -> Option<String> {
    o.tests().map(|t| int(t.mean))
}

/// The published numbers, row by row, with ours beside them.
fn comparison_rows() -> Vec<Row> {
    vec![
        Row::published(&p::BUNNY_BASE_FPS, |r, _| {
            r.bunny_base_ok()?.mean_fps().map(num)
        }),
        Row::published(&p::BUNNY_GRID_FPS, |r, v| r.grid24(v)?.mean_fps().map(num)),
        Row::ratio(
            p::BUNNY_SPEEDUP_STATED.what,
            p::bunny_speedup(),
            &format!(
                "(4.8339 / 0.8804; stated: ×{})",
                p::BUNNY_SPEEDUP_STATED.printed
            ),
            |r, v| sweep::speedup(r.grid24(v)?, r.bunny_base),
        ),
        Row::published(&p::BUNNY_BASE_TESTS, |r, _| mean_tests(r.bunny_base_ok()?)),
        Row::published(&p::BUNNY_GRID_TESTS, |r, v| mean_tests(r.grid24(v)?)),
        Row::ratio(
            "bunny, test reduction base / grid 24³",
            p::bunny_test_reduction(),
            "(\"only a quarter\")",
            |r, v| sweep::test_reduction(r.grid24(v)?, r.bunny_base),
        ),
        Row::new(
            "dragon mesh, triangles",
            format!("{} (ch. 5.3)", int(p::DRAGON_TRIANGLES as f64)),
            |r, _| r.dragon_mesh_text(),
        ),
        Row::published(&p::DRAGON_GRID_FPS, |r, v| {
            r.dragon28(v)?.mean_fps().map(num)
        }),
        Row::ratio(
            "dragon grid 28³ FPS / bunny grid 24³ FPS",
            p::DRAGON_GRID_FPS.value() / p::BUNNY_GRID_FPS.value(),
            "(1.396 / 4.8339)",
            |r, v| Some(r.dragon28(v)?.mean_fps()? / r.grid24(v)?.mean_fps()?),
        ),
        Row::new(
            "dragon, grid 28³, mean tests per frame",
            "not given".into(),
            |r, v| mean_tests(r.dragon28(v)?),
        ),
        Row::new(
            "dragon, base tracer",
            format!("no frame: {}", p::DRAGON_BASE),
            |r, _| r.dragon_base_text(),
        ),
    ]
}

/// The table of published numbers and ours per variant, and what to compare.
fn comparison(r: &Results, variants: &[GridVariant]) -> String {
    let mut header = vec!["quantity".to_string(), "Müller 2015 (GTX 780)".to_string()];
    header.extend(
        variants
            .iter()
            .map(|v| format!("ours, {} variant", variant_name(*v))),
    );
    let rows: Vec<Vec<String>> = comparison_rows()
        .into_iter()
        .map(|row| {
            let mut cells = vec![row.quantity.clone(), row.published.clone()];
            let ours = variants.iter().map(|v| row.ours(r, *v));
            cells.extend(ours.map(|c| c.unwrap_or_else(|| "not measured".into())));
            cells
        })
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    table(&header, &rows)
        + "\nBold rows are the hardware-independent comparisons. Our mean FPS is FPS (run) = frames / total \
           wall time; the speed-up is its ratio, the test reduction the ratio of mean tests per frame. Fig. 23 \
           and 24 show further resolutions as plots only; the text gives the 24³ values above. The thesis \
           variant is the faithful design (triangles registered along their edges into fixed-size voxel lists, \
           per-ray voxel lists): its counts are the ones to set beside the published ones. The exact variant is \
           our corrected design (triangle/box overlap, compact lists, 3D-DDA) and tests far fewer triangles.\n\n"
}

/// Every configuration of the bunny and of the dragon.
fn tables(r: &Results) -> String {
    format!(
        "### Bunny, every configuration\n\n{}\n### Dragon\n\n{}",
        sweep::resolution_table(&r.bunny_grid, r.bunny_base),
        sweep::resolution_table(&r.dragon_grid, r.dragon_base)
    )
}

/// Fig. 23 and 24: a measure of the grid by resolution beside the base tracer's, and its ratio
/// to the base tracer with the thesis' value at 24³.
fn figures(s: Sizing, r: &Results) -> Vec<Figure> {
    let size = s.size();
    let fig23 = vec![
        measure_chart(
            r,
            format!("Fig. 23 (ours): bunny, FPS, {size}"),
            "FPS (frames / total time)",
            Outcome::mean_fps,
        ),
        ratio_chart(
            r,
            "speed-up of the grid over the base tracer",
            "FPS grid / FPS base",
            sweep::speedup,
            p::bunny_speedup(),
        ),
    ];
    let tests = |o: &Outcome| Some(o.tests()?.mean);
    let fig24 = vec![
        measure_chart(
            r,
            format!("Fig. 24 (ours): bunny, mean triangle tests per frame, {size}"),
            "mean triangle tests per frame",
            tests,
        ),
        ratio_chart(
            r,
            "test reduction: base / grid",
            "tests base / tests grid",
            sweep::test_reduction,
            p::bunny_test_reduction(),
        ),
    ];
    vec![
        Figure::new("fig23_bunny_fps.png", "Fig. 23 (ours)", (640, 460), fig23),
        Figure::new("fig24_bunny_tests.png", "Fig. 24 (ours)", (640, 460), fig24),
    ]
}

/// `f` of the bunny's grid by resolution, with the base tracer's as a dashed line.
fn measure_chart(
    r: &Results,
    title: String,
    y_label: &str,
    f: fn(&Outcome) -> Option<f64>,
) -> Chart {
    let curves = sweep::variant_curves(&r.bunny_grid, f);
    let base = r.bunny_base.and_then(f);
    resolution_chart(title, y_label, sweep::with_base_line(curves, base))
}

/// `ratio` of the bunny's grid to its base tracer by resolution, with the thesis' `published`
/// value at 24³.
fn ratio_chart(
    r: &Results,
    title: &str,
    y_label: &str,
    ratio: fn(&Outcome, Option<&Outcome>) -> Option<f64>,
    published: f64,
) -> Chart {
    let mut series = sweep::variant_curves(&r.bunny_grid, |o| ratio(o, r.bunny_base));
    let at_24 = vec![(p::BUNNY_GRID_RESOLUTION as f64, published)];
    series.push(Series::new(
        "Müller 2015, 24³",
        at_24,
        Style::Crosses,
        BLACK_INDEX,
    ));
    resolution_chart(title, y_label, series)
}
