//! Müller 2015, ch. 5.3 "Vergleich der beiden Ray-Tracer": the Stanford bunny (69451
//! triangles), one light, no reflections, base tracer vs the grid at several resolutions (FPS:
//! Fig. 23, triangle tests: Fig. 24); and the dragon with the grid at 28³ (the thesis' base
//! tracer timed out on it). Published: bunny 0.8804 FPS base vs 4.8339 FPS with the grid at
//! 24³, 1,137,720,816 vs 287,728,727.1 tests per frame; dragon (204088 triangles) 1.396 FPS.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;

use super::plots::{self, Chart, Series, Style, BLACK_INDEX};
use super::published::{self as p, Published};
use super::report::{self, int, num, ratio, Section};
use super::runner::{rotation_angles, variant_name, Bench, Config, Sizing, TracerSpec};
use super::sweep;
use super::{Protocol, Scale, FULL_SIZE, QUICK_SIZE};
use gpgpu_rt::accel::GridVariant;

pub struct Thesis53;

pub const BUNNY: &str = "bunny.toml";
pub const DRAGON: &str = "dragon.toml";
/// Quick: 4 angles, 1 warm-up frame. Full: 36 angles (every 10°), 3 warm-up frames.
pub const QUICK: Sizing = Sizing {
    width: QUICK_SIZE.0,
    height: QUICK_SIZE.1,
    angles: 4,
    warmup: 1,
};
pub const FULL: Sizing = Sizing {
    width: FULL_SIZE.0,
    height: FULL_SIZE.1,
    angles: 36,
    warmup: 3,
};
pub const QUICK_RESOLUTIONS: &[u32] = &[8, 16, 24, 32];
pub const FULL_RESOLUTIONS: &[u32] = &[8, 12, 16, 20, 24, 28, 32, 40];

impl Protocol for Thesis53 {
    fn name(&self) -> &'static str {
        "thesis-5.3"
    }

    fn title(&self) -> &'static str {
        "base tracer vs uniform grid: bunny and dragon (Müller 2015, ch. 5.3, Fig. 23, 24)"
    }

    fn run(&self, bench: &mut Bench) -> Result<Section> {
        let s = bench.sizing(QUICK, FULL);
        let angles = rotation_angles(s.angles);
        let resolutions = bench.grid_resolutions(QUICK_RESOLUTIONS, FULL_RESOLUTIONS);
        let variants = bench.variants();
        let full = bench.scale() == Scale::Full;
        let base = |scene: &str, refl_depth: u32| Config {
            scene: scene.into(),
            tracer: TracerSpec::Base,
            refl_depth,
            width: s.width,
            height: s.height,
            angles: angles.clone(),
            warmup: s.warmup,
        };
        // the bunny: no reflections (REFL_DEPTH 0), base and grid
        let mut configs = vec![base(BUNNY, 0)];
        configs.extend(sweep::grid_configs(
            BUNNY,
            0,
            s,
            &angles,
            &variants,
            &resolutions,
        ));
        // the dragon: grid 28³; the thesis' scene had a reflective floor, so REFL_DEPTH 1. The
        // base tracer only at full scale (it needs a GPU: 202520 triangles per ray).
        configs.extend(sweep::grid_configs(
            DRAGON,
            1,
            s,
            &angles,
            &variants,
            &[p::DRAGON_GRID_RESOLUTION],
        ));
        if full {
            configs.push(base(DRAGON, 1));
        }
        let outcomes = bench.measure(self.name(), &configs)?;

        let bunny_base = sweep::base_outcome(&outcomes, BUNNY);
        let bunny_grid = sweep::grid_outcomes(&outcomes, BUNNY);
        let dragon_base = sweep::base_outcome(&outcomes, DRAGON);
        let dragon_grid = sweep::grid_outcomes(&outcomes, DRAGON);
        let size = format!("{}×{}", s.width, s.height);

        // Fig. 23: FPS by resolution with the base tracer as a line; speed-up with the thesis' point
        let fps = sweep::variant_curves(&bunny_grid, |o| o.mean_fps());
        let mut fps_series = fps.clone();
        fps_series.extend(
            bunny_base
                .and_then(|b| b.mean_fps())
                .and_then(|y| sweep::reference_line("base tracer", y, &fps, 2)),
        );
        let mut speedup = sweep::variant_curves(&bunny_grid, |o| sweep::speedup(o, bunny_base));
        speedup.push(Series::new(
            "Müller 2015, 24³",
            vec![(p::BUNNY_GRID_RESOLUTION as f64, p::bunny_speedup())],
            Style::Crosses,
            BLACK_INDEX,
        ));
        let fig23 = PathBuf::from("fig23_bunny_fps.png");
        plots::save(
            &bench.out.join(&fig23),
            640,
            460,
            &[
                Chart {
                    title: format!("Fig. 23 (ours): bunny, FPS, {size}"),
                    x_label: "grid resolution N (N³ voxels)".into(),
                    y_label: "FPS (frames / total time)".into(),
                    series: fps_series,
                    x_range: None,
                    log_y: true,
                },
                Chart {
                    title: "speed-up of the grid over the base tracer".into(),
                    x_label: "grid resolution N (N³ voxels)".into(),
                    y_label: "FPS grid / FPS base".into(),
                    series: speedup,
                    x_range: None,
                    log_y: true,
                },
            ],
        )?;
        // Fig. 24: tests by resolution; test reduction with the thesis' point
        let tests = sweep::variant_curves(&bunny_grid, |o| o.tests().map(|t| t.mean));
        let mut test_series = tests.clone();
        test_series.extend(
            bunny_base
                .and_then(|b| b.tests())
                .and_then(|t| sweep::reference_line("base tracer", t.mean, &tests, 2)),
        );
        let mut reduction =
            sweep::variant_curves(&bunny_grid, |o| sweep::test_reduction(o, bunny_base));
        reduction.push(Series::new(
            "Müller 2015, 24³",
            vec![(p::BUNNY_GRID_RESOLUTION as f64, p::bunny_test_reduction())],
            Style::Crosses,
            BLACK_INDEX,
        ));
        let fig24 = PathBuf::from("fig24_bunny_tests.png");
        plots::save(
            &bench.out.join(&fig24),
            640,
            460,
            &[
                Chart {
                    title: format!("Fig. 24 (ours): bunny, mean triangle tests per frame, {size}"),
                    x_label: "grid resolution N (N³ voxels)".into(),
                    y_label: "mean triangle tests per frame".into(),
                    series: test_series,
                    x_range: None,
                    log_y: true,
                },
                Chart {
                    title: "test reduction: base / grid".into(),
                    x_label: "grid resolution N (N³ voxels)".into(),
                    y_label: "tests base / tests grid".into(),
                    series: reduction,
                    x_range: None,
                    log_y: true,
                },
            ],
        )?;

        // the report section
        let mut md = String::new();
        let bunny_tris = outcomes
            .iter()
            .find(|o| o.config.scene == BUNNY)
            .map(|o| o.triangles)
            .unwrap_or(0);
        let dragon_tris = outcomes
            .iter()
            .find(|o| o.config.scene == DRAGON)
            .map(|o| o.triangles)
            .unwrap_or(0);
        // the dragon mesh alone: the scene's largest object (the rest is the floor)
        let dragon_mesh = bench
            .scene(DRAGON)
            .map(|s| {
                s.objects
                    .iter()
                    .map(|o| o.mesh.triangle_count())
                    .max()
                    .unwrap_or(0)
            })
            .unwrap_or(0);
        let _ = writeln!(
            md,
            "Setup (thesis): the bunny ({} triangles), one light, no reflections; the dragon ({}) in a scene with \
             one light and a reflective floor. Ours: `scenes/{BUNNY}` ({} triangles, REFL_DEPTH 0) and \
             `scenes/{DRAGON}` ({} triangles: Stanford's `dragon_vrip_res2` decimation of {} triangles, the closest \
             available to the thesis' mesh, {} triangles {}, and a reflective floor; REFL_DEPTH 1), {size} \
             pixels, {} angles of the rotation, {} warm-up frame(s), grid resolutions {} for the bunny and 28³ \
             for the dragon, variants {}.{}\n",
            int(p::BUNNY_TRIANGLES as f64),
            int(p::DRAGON_TRIANGLES as f64),
            int(bunny_tris as f64),
            int(dragon_tris as f64),
            int(dragon_mesh as f64),
            int((p::DRAGON_TRIANGLES as f64 - dragon_mesh as f64).abs()),
            if dragon_mesh as u64 <= p::DRAGON_TRIANGLES { "fewer" } else { "more" },
            s.angles,
            s.warmup,
            resolutions.iter().map(|r| format!("{r}³")).collect::<Vec<_>>().join(", "),
            variants.iter().map(|v| variant_name(*v)).collect::<Vec<_>>().join(", "),
            if full {
                " The base tracer also renders the dragon here (the thesis' timed out)."
            } else {
                " The base tracer does not render the dragon at quick scale (a brute-force dragon frame takes \
                 seconds on llvmpipe); `--scale full` adds it."
            }
        );

        // published vs ours
        let grid24 = |v: GridVariant| {
            bunny_grid.iter().copied().find(|o| {
                o.ok()
                    && o.config.tracer
                        == TracerSpec::Grid {
                            variant: v,
                            resolution: p::BUNNY_GRID_RESOLUTION,
                        }
            })
        };
        let dragon28 = |v: GridVariant| {
            dragon_grid.iter().copied().find(|o| {
                o.ok()
                    && o.config.tracer
                        == TracerSpec::Grid {
                            variant: v,
                            resolution: p::DRAGON_GRID_RESOLUTION,
                        }
            })
        };
        let cols: Vec<GridVariant> = variants.clone();
        let mut header = vec!["quantity".to_string(), "Müller 2015 (GTX 780)".to_string()];
        header.extend(
            cols.iter()
                .map(|v| format!("ours, {} variant", variant_name(*v))),
        );
        let mut rows: Vec<Vec<String>> = Vec::new();
        let mut row =
            |what: String, published: String, ours: &dyn Fn(GridVariant) -> Option<String>| {
                let mut r = vec![what, published];
                r.extend(
                    cols.iter()
                        .map(|v| ours(*v).unwrap_or_else(|| "not measured".into())),
                );
                rows.push(r);
            };
        let pubv = |x: &Published| format!("{} ({})", x.printed, x.figure);
        row(
            "bunny, base tracer, FPS (run)".into(),
            pubv(&p::BUNNY_BASE_FPS),
            &|_| {
                bunny_base
                    .filter(|b| b.ok())
                    .and_then(|b| b.mean_fps())
                    .map(num)
            },
        );
        row(
            "bunny, grid 24³, FPS (run)".into(),
            pubv(&p::BUNNY_GRID_FPS),
            &|v| grid24(v)?.mean_fps().map(num),
        );
        row(
            "**bunny, speed-up grid 24³ / base**".into(),
            format!(
                "**{}** (4.8339 / 0.8804; stated: ×{})",
                ratio(Some(p::bunny_speedup())),
                p::BUNNY_SPEEDUP_STATED.printed
            ),
            &|v| {
                Some(format!(
                    "**{}**",
                    ratio(sweep::speedup(grid24(v)?, bunny_base)?.into())
                ))
            },
        );
        row(
            "bunny, base tracer, mean tests per frame".into(),
            pubv(&p::BUNNY_BASE_TESTS),
            &|_| {
                bunny_base
                    .filter(|b| b.ok())
                    .and_then(|b| b.tests())
                    .map(|t| int(t.mean))
            },
        );
        row(
            "bunny, grid 24³, mean tests per frame".into(),
            pubv(&p::BUNNY_GRID_TESTS),
            &|v| grid24(v)?.tests().map(|t| int(t.mean)),
        );
        row(
            "**bunny, test reduction base / grid 24³**".into(),
            format!(
                "**{}** (\"only a quarter\")",
                ratio(Some(p::bunny_test_reduction()))
            ),
            &|v| {
                Some(format!(
                    "**{}**",
                    ratio(sweep::test_reduction(grid24(v)?, bunny_base)?.into())
                ))
            },
        );
        row(
            "dragon mesh, triangles".into(),
            format!("{} (ch. 5.3)", int(p::DRAGON_TRIANGLES as f64)),
            &|_| {
                (dragon_mesh > 0).then(|| {
                    let d = dragon_mesh as f64 - p::DRAGON_TRIANGLES as f64;
                    let side = if d < 0.0 { "fewer" } else { "more" };
                    format!(
                        "{} ({} {side}; {} with the floor)",
                        int(dragon_mesh as f64),
                        int(d.abs()),
                        int(dragon_tris as f64)
                    )
                })
            },
        );
        row(
            "dragon, grid 28³, FPS (run)".into(),
            pubv(&p::DRAGON_GRID_FPS),
            &|v| dragon28(v)?.mean_fps().map(num),
        );
        row(
            "**dragon grid 28³ FPS / bunny grid 24³ FPS**".into(),
            format!(
                "**{}** (1.396 / 4.8339)",
                ratio(Some(p::DRAGON_GRID_FPS.value / p::BUNNY_GRID_FPS.value))
            ),
            &|v| {
                Some(format!(
                    "**{}**",
                    ratio(Some(dragon28(v)?.mean_fps()? / grid24(v)?.mean_fps()?))
                ))
            },
        );
        row(
            "dragon, grid 28³, mean tests per frame".into(),
            "not given".into(),
            &|v| dragon28(v)?.tests().map(|t| int(t.mean)),
        );
        row(
            "dragon, base tracer".into(),
            format!("no frame: {}", p::DRAGON_BASE),
            &|_| match dragon_base {
                None => Some("not run at this scale".into()),
                Some(b) if b.ok() => b.mean_fps().map(|f| {
                    format!(
                        "{} FPS, {} mean tests",
                        num(f),
                        int(b.tests().map(|t| t.mean).unwrap_or(0.0))
                    )
                }),
                Some(b) => Some(format!("failed: {}", b.error.as_deref().unwrap_or(""))),
            },
        );
        let header_refs: Vec<&str> = header.iter().map(String::as_str).collect();
        md.push_str(&report::table(&header_refs, &rows));
        let _ = writeln!(
            md,
            "\nBold rows are the hardware-independent comparisons. FPS (run) = frames / total wall time; the \
             speed-up is its ratio, the test reduction the ratio of mean tests per frame. Fig. 23 and 24 show \
             further resolutions as plots only; the text gives the 24³ values above. The thesis variant is the \
             faithful design (triangles registered along their edges into fixed-size voxel lists, per-ray voxel \
             lists): its counts are the ones to set beside the published ones. The exact variant is our corrected \
             design (triangle/box overlap, compact lists, 3D-DDA) and tests far fewer triangles.\n"
        );
        let _ = writeln!(md, "### Bunny, every configuration\n");
        md.push_str(&sweep::resolution_table(&bunny_grid, bunny_base));
        let _ = writeln!(md, "\n### Dragon\n");
        md.push_str(&sweep::resolution_table(&dragon_grid, dragon_base));
        md.push('\n');
        Ok(Section::of_sweep(
            self,
            md,
            &outcomes,
            vec![(fig23, "Fig. 23 (ours)"), (fig24, "Fig. 24 (ours)")],
        ))
    }
}
