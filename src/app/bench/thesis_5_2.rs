//! Müller 2015, ch. 5.2 "Einfluss der Auflösung des Uniform Grids": the grid tracer on the
//! six-teapot scene of ch. 5.1 at resolutions 4³ … 40³, both grid variants; FPS (Fig. 21) and
//! mean triangle tests per frame (Fig. 22) per resolution. The base tracer on the same scene is
//! measured too, as the reference for speed-ups (the thesis' figures show the grid only).

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;

use super::plots::{self, Chart};
use super::published;
use super::report::{self, Section};
use super::runner::{rotation_angles, variant_name, Bench, Config, Sizing, TracerSpec};
use super::sweep;
use super::{Protocol, FULL_SIZE, QUICK_SIZE};

pub struct Thesis52;

pub const SCENE: &str = "teapot6.toml";
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
pub const QUICK_RESOLUTIONS: &[u32] = &[4, 8, 12, 16, 20, 24, 32, 40];
pub const FULL_RESOLUTIONS: &[u32] = &[4, 8, 12, 16, 20, 24, 28, 32, 36, 40];

impl Protocol for Thesis52 {
    fn name(&self) -> &'static str {
        "thesis-5.2"
    }

    fn title(&self) -> &'static str {
        "influence of the grid resolution (Müller 2015, ch. 5.2, Fig. 21, 22)"
    }

    fn run(&self, bench: &mut Bench) -> Result<Section> {
        let s = bench.sizing(QUICK, FULL);
        let angles = rotation_angles(s.angles);
        let resolutions = bench.grid_resolutions(QUICK_RESOLUTIONS, FULL_RESOLUTIONS);
        let variants = bench.variants();
        let mut configs = vec![Config {
            scene: SCENE.into(),
            tracer: TracerSpec::Base,
            refl_depth: 1,
            width: s.width,
            height: s.height,
            angles: angles.clone(),
            warmup: s.warmup,
        }];
        configs.extend(sweep::grid_configs(
            SCENE,
            1,
            s,
            &angles,
            &variants,
            &resolutions,
        ));
        let outcomes = bench.measure(self.name(), &configs)?;
        let base = sweep::base_outcome(&outcomes, SCENE);
        let grid = sweep::grid_outcomes(&outcomes, SCENE);

        let size = format!("{}×{}", s.width, s.height);
        let fps_curves = sweep::variant_curves(&grid, |o| o.mean_fps());
        let mut fps_series = fps_curves.clone();
        if let Some(l) = base
            .and_then(|b| b.mean_fps())
            .and_then(|y| sweep::reference_line("base tracer", y, &fps_curves, 2))
        {
            fps_series.push(l);
        }
        let test_curves = sweep::variant_curves(&grid, |o| o.tests().map(|t| t.mean));
        let fig21 = PathBuf::from("fig21_fps_vs_resolution.png");
        plots::save(
            &bench.out.join(&fig21),
            900,
            480,
            &[Chart {
                title: format!("Fig. 21 (ours): FPS by grid resolution, six teapots, {size}"),
                x_label: "grid resolution N (N³ voxels)".into(),
                y_label: "FPS (frames / total time)".into(),
                series: fps_series,
                x_range: None,
                log_y: true,
            }],
        )?;
        let fig22 = PathBuf::from("fig22_tests_vs_resolution.png");
        plots::save(
            &bench.out.join(&fig22),
            900,
            480,
            &[Chart {
                title: format!(
                    "Fig. 22 (ours): mean triangle tests per frame by grid resolution, {size}"
                ),
                x_label: "grid resolution N (N³ voxels)".into(),
                y_label: "mean triangle tests per frame".into(),
                series: test_curves,
                x_range: None,
                log_y: true,
            }],
        )?;

        let mut md = String::new();
        let _ = writeln!(
            md,
            "Setup (thesis): {}; the text does not say how many frames per resolution. Ours: \
             `scenes/{SCENE}`, reflection depth 1, {size} pixels, {} angles of the rotation, {} warm-up \
             frame(s) per configuration, resolutions {}, variants {}; the base tracer on the same frames \
             as the reference for speed-up (FPS (run) ratio) and test reduction (mean tests ratio).\n",
            published::SEC52_SETUP,
            s.angles,
            s.warmup,
            resolutions.iter().map(|r| format!("{r}³")).collect::<Vec<_>>().join(", "),
            variants.iter().map(|v| variant_name(*v)).collect::<Vec<_>>().join(", ")
        );
        md.push_str(&sweep::resolution_table(&grid, base));
        let _ = writeln!(
            md,
            "\nThe thesis gives Fig. 21 and 22 as plots only; its text states these findings, set here beside ours:\n"
        );
        let best = sweep::best_resolutions(&grid);
        let (lo, hi) = published::SEC52_OPTIMUM;
        let best_text = if best.is_empty() {
            "no grid configuration was measured".to_string()
        } else {
            best.iter()
                .map(|(v, r, fps)| {
                    format!(
                        "{} variant: best at {r}³ ({} FPS){}",
                        variant_name(*v),
                        report::num(*fps),
                        if (lo..=hi).contains(r) {
                            ", inside 12³–20³"
                        } else {
                            ", outside 12³–20³"
                        }
                    )
                })
                .collect::<Vec<_>>()
                .join("; ")
        };
        let monotone = [
            gpgpu_rt::accel::GridVariant::Thesis,
            gpgpu_rt::accel::GridVariant::Exact,
        ]
        .into_iter()
        .filter_map(|v| {
            let t: Vec<(u32, f64)> = grid
                .iter()
                .filter(|o| o.ok() && o.config.tracer.variant() == Some(v))
                .filter_map(|o| Some((o.config.tracer.resolution()?, o.tests()?.mean)))
                .collect();
            (t.len() >= 2).then(|| {
                let rises = t.windows(2).filter(|w| w[1].1 > w[0].1).count();
                format!(
                    "{} variant: mean tests {} → {} from {}³ to {}³, rising in {rises} of {} steps",
                    variant_name(v),
                    report::int(t[0].1),
                    report::int(t[t.len() - 1].1),
                    t[0].0,
                    t[t.len() - 1].0,
                    t.len() - 1
                )
            })
        })
        .collect::<Vec<_>>()
        .join("; ");
        let rows = vec![
            vec![published::SEC52_FINDINGS[0].to_string(), best_text],
            vec![
                published::SEC52_FINDINGS[1].to_string(),
                if monotone.is_empty() { "–".into() } else { monotone },
            ],
            vec![
                published::SEC52_FINDINGS[2].to_string(),
                "see the grid MiB column (the thesis variant's fixed lists: voxels × list length × 4 bytes)".into(),
            ],
        ];
        md.push_str(&report::table(&["Müller 2015", "ours"], &rows));
        md.push('\n');
        Ok(Section::of_sweep(
            self,
            md,
            &outcomes,
            vec![(fig21, "Fig. 21 (ours)"), (fig22, "Fig. 22 (ours)")],
        ))
    }
}
