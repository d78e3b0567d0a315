//! Müller 2015, ch. 5.1 "Einfluss der Anzahl der Dreiecke": the base tracer on the scenes with
//! 1, 3 and 6 reflective teapots on a floor (14592, 27392, 46592 triangles), one light,
//! reflection depth 1, the scene rotated through 360° with one frame per degree; FPS (Fig. 19)
//! and triangle tests (Fig. 20) per frame.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;

use super::plots::{self, Chart, Series, Style};
use super::published::{self, TEAPOT_TRIANGLES};
use super::report::{self, int, mmm, num, table, Section};
use super::runner::{rotation_angles, Bench, Config, Sizing, TracerSpec};
use super::{Protocol, FULL_SIZE, QUICK_SIZE};

pub struct Thesis51;

/// Quick: 8 angles (every 45°), 1 warm-up frame. Full: 360 angles (every degree), 5 warm-up.
pub const QUICK: Sizing = Sizing {
    width: QUICK_SIZE.0,
    height: QUICK_SIZE.1,
    angles: 8,
    warmup: 1,
};
pub const FULL: Sizing = Sizing {
    width: FULL_SIZE.0,
    height: FULL_SIZE.1,
    angles: 360,
    warmup: 5,
};

impl Protocol for Thesis51 {
    fn name(&self) -> &'static str {
        "thesis-5.1"
    }

    fn title(&self) -> &'static str {
        "influence of the number of triangles, base tracer (Müller 2015, ch. 5.1, Fig. 19, 20)"
    }

    fn run(&self, bench: &mut Bench) -> Result<Section> {
        let s = bench.sizing(QUICK, FULL);
        let angles = rotation_angles(s.angles);
        let configs: Vec<Config> = TEAPOT_TRIANGLES
            .iter()
            .map(|(name, _)| Config {
                scene: format!("{name}.toml"),
                tracer: TracerSpec::Base,
                refl_depth: 1,
                width: s.width,
                height: s.height,
                angles: angles.clone(),
                warmup: s.warmup,
            })
            .collect();
        let outcomes = bench.measure(self.name(), &configs)?;

        // Fig. 19 and 20: one curve per scene over the rotation
        let style = if s.angles > 60 {
            Style::Line
        } else {
            Style::LinePoints
        };
        let curve = |f: &dyn Fn(&super::runner::FrameRecord) -> f64| -> Vec<Series> {
            outcomes
                .iter()
                .enumerate()
                .map(|(i, o)| {
                    Series::new(
                        format!(
                            "{} ({} triangles)",
                            o.config.scene_name(),
                            int(o.triangles as f64)
                        ),
                        o.frames.iter().map(|fr| (fr.angle, f(fr))).collect(),
                        style,
                        i,
                    )
                })
                .collect()
        };
        let size = format!("{}×{}", s.width, s.height);
        let fig19 = PathBuf::from("fig19_fps.png");
        plots::save(
            &bench.out.join(&fig19),
            900,
            480,
            &[Chart {
                title: format!("Fig. 19 (ours): FPS of the base tracer over the rotation, {size}"),
                x_label: "rotation of the scene (degrees)".into(),
                y_label: "FPS".into(),
                series: curve(&|f| f.fps()),
                x_range: Some((0.0, 360.0)),
                log_y: false,
            }],
        )?;
        let fig20 = PathBuf::from("fig20_tests.png");
        plots::save(
            &bench.out.join(&fig20),
            900,
            480,
            &[Chart {
                title: format!("Fig. 20 (ours): triangle tests per frame, base tracer, {size}"),
                x_label: "rotation of the scene (degrees)".into(),
                y_label: "triangle tests per frame".into(),
                series: curve(&|f| f.tests() as f64),
                x_range: Some((0.0, 360.0)),
                log_y: false,
            }],
        )?;

        // the report section
        let mut md = String::new();
        let _ = writeln!(
            md,
            "Setup (thesis): {}. Ours: `scenes/teapot1.toml`, `teapot3.toml`, `teapot6.toml`, reflection depth \
             1, one light, {size} pixels, {} angles ({}), {} warm-up frame(s) per scene.\n",
            published::SEC51_SETUP,
            s.angles,
            if s.angles == 360 {
                "one per degree, as the thesis".to_string()
            } else {
                format!("every {}°", super::plots::si(360.0 / s.angles as f64))
            },
            s.warmup
        );
        let rows: Vec<Vec<String>> = outcomes
            .iter()
            .map(|o| {
                let published = TEAPOT_TRIANGLES
                    .iter()
                    .find(|t| t.0 == o.config.scene_name())
                    .map(|t| t.1)
                    .unwrap_or(0);
                vec![
                    o.config.scene_name().to_string(),
                    format!("{} / {}", int(o.triangles as f64), int(published as f64)),
                    mmm(o.fps(), num),
                    o.mean_fps().map(num).unwrap_or("–".into()),
                    mmm(o.gpu_ms(), num),
                    mmm(o.tests(), int),
                    o.tests().map(|t| int(t.mean)).unwrap_or("–".into()),
                    o.fps()
                        .map(|f| format!("{:.0} %", 100.0 * f.spread()))
                        .unwrap_or("–".into()),
                ]
            })
            .collect();
        md.push_str(&table(
            &[
                "scene",
                "triangles (ours / thesis)",
                "FPS",
                "FPS (run)",
                "GPU ms",
                "triangle tests per frame",
                "mean tests",
                "FPS spread (max−min)/median",
            ],
            &rows,
        ));

        let _ = writeln!(
            md,
            "\nThe thesis gives Fig. 19 and 20 as plots only; its text states these findings, set here beside ours:\n"
        );
        let mut cmp = Vec::new();
        let ok: Vec<_> = outcomes.iter().filter(|o| o.ok()).collect();
        if let (Some(first), Some(last)) = (ok.first(), ok.last()) {
            if first.config.scene != last.config.scene {
                if let (Some(f1), Some(f6)) = (first.fps(), last.fps()) {
                    cmp.push(vec![
                        published::SEC51_FINDINGS[0].to_string(),
                        format!(
                            "FPS {} / {} = {} (median), triangles {} / {} = {}; FPS × triangles: {}",
                            first.config.scene_name(),
                            last.config.scene_name(),
                            report::ratio(Some(f1.median / f6.median)),
                            last.config.scene_name(),
                            first.config.scene_name(),
                            report::ratio(Some(last.triangles as f64 / first.triangles as f64)),
                            ok.iter()
                                .filter_map(|o| o.fps().map(|f| format!("{} {}", o.config.scene_name(), int(f.median * o.triangles as f64))))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ]);
                }
            }
        }
        cmp.push(vec![
            published::SEC51_FINDINGS[1].to_string(),
            format!(
                "FPS spread (max−min)/median: {}",
                ok.iter()
                    .filter_map(|o| o.fps().map(|f| format!(
                        "{} {:.0} %",
                        o.config.scene_name(),
                        100.0 * f.spread()
                    )))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ]);
        cmp.push(vec![
            published::SEC51_FINDINGS[2].to_string(),
            format!(
                "tests spread (max−min)/median: {}; tests per frame / triangles (rays that tested every \
                 triangle): {}",
                ok.iter()
                    .filter_map(|o| o.tests().map(|t| format!("{} {:.0} %", o.config.scene_name(), 100.0 * t.spread())))
                    .collect::<Vec<_>>()
                    .join(", "),
                ok.iter()
                    .filter_map(|o| o.tests().map(|t| format!("{} {}", o.config.scene_name(), int(t.median / o.triangles as f64))))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ]);
        cmp.push(vec![
            published::SEC51_FINDINGS[3].to_string(),
            "see the curves of Fig. 20 (ours); with reflection depth 1 a ray reflects once"
                .to_string(),
        ]);
        md.push_str(&table(&["Müller 2015", "ours"], &cmp));
        md.push('\n');
        Ok(Section::of_sweep(
            self,
            md,
            &outcomes,
            vec![(fig19, "Fig. 19 (ours)"), (fig20, "Fig. 20 (ours)")],
        ))
    }
}
