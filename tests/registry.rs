//! The registry of designs (`design::REGISTRY`) walked row by row, so that a design added in one
//! place and forgotten in another fails here: its command-line values select it, its options
//! exist on the command line and are refused for the designs they do not belong to, its shader
//! folders and its pipeline module exist and are documented, its accelerator (Müller 2015's
//! pipeline) is the one `--tracer` picks, and it renders.

mod common;

use std::path::Path;

use common::*;
use gpgpu_rt::accel::Accel;
use gpgpu_rt::design::{self, Design, Pipeline, Row, COMMON_OPTIONS, REGISTRY};

/// The value `row` selects for a selecting option, else the command line's default.
fn selected(row: &Row, option: &str) -> String {
    let given = row.select.iter().find(|(o, _)| *o == option);
    let default = match option {
        "tracer" => "bvh",
        "bvh-variant" => "sah",
        "grid-variant" => "exact",
        _ => "",
    };
    given.map_or(default, |(_, v)| v).to_string()
}

#[test]
fn every_row_is_selected_by_its_own_values_and_named_once() {
    for row in REGISTRY {
        let soft = row.pipeline == Pipeline::Klee2016;
        let found = design::select(soft, |o| selected(row, o)).unwrap();
        assert_eq!(found.name, row.name, "{row:?} selects {found:?}");
        assert_eq!(design::row(row.name).unwrap().name, row.name);
        assert_eq!(
            REGISTRY.iter().filter(|r| r.name == row.name).count(),
            1,
            "{row:?} named twice"
        );
        assert!(!row.title.is_empty() && !row.glsl.is_empty(), "{row:?}");
    }
}

#[test]
fn each_accelerator_is_the_one_its_tracer_picks() {
    for row in REGISTRY {
        let Some(entry) = row.accel else {
            assert_ne!(
                row.pipeline,
                Pipeline::Mueller2015,
                "{row:?} has no accelerator"
            );
            continue;
        };
        assert_eq!(row.pipeline, Pipeline::Mueller2015, "{row:?}");
        assert_eq!(entry.label, row.name);
        assert_eq!(selected(row, "tracer"), entry.plain.tracer(), "{row:?}");
        // its options, and each variant's, name it as theirs
        for accel in std::iter::once(&entry.plain).chain(entry.variants.iter().map(|v| &v.1)) {
            assert!(std::ptr::eq(accel.entry(), entry), "{row:?}: {accel:?}");
        }
        let variant = match entry.plain {
            Accel::ThesisGrid(_) => Some("thesis"),
            Accel::ExactGrid(_) => Some("exact"),
            _ => None,
        };
        if let Some(v) = variant {
            assert_eq!(selected(row, "grid-variant"), v, "{row:?}");
        }
        // its twin is made over a scene for each variant (the oracle the tests compare its GPU
        // side with)
        let scene = load("cow.toml");
        assert!(row.twin.is_some(), "{row:?} names no CPU twin");
        for (label, accel) in entry.variants {
            gpgpu_rt::design::twin(&scene, accel)
                .unwrap_or_else(|e| panic!("{row:?}, {label}: twin: {e:#}"));
        }
    }
}

/// The long options `gpgpu-rt render --help` lists.
fn render_options() -> Vec<String> {
    let o = run(&["render", "--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout).to_string();
    help.split_whitespace()
        .filter_map(|w| w.strip_prefix("--"))
        .map(|w| {
            w.trim_end_matches(|c: char| !c.is_ascii_alphanumeric())
                .to_string()
        })
        .collect()
}

#[test]
fn every_option_of_every_row_is_on_the_command_line_and_refused_elsewhere() {
    let listed = render_options();
    let all: Vec<&str> = REGISTRY.iter().flat_map(|r| r.options()).collect();
    for o in all
        .iter()
        .chain(COMMON_OPTIONS.iter().filter(|o| **o != "driver"))
    {
        assert!(
            listed.iter().any(|l| l == o),
            "--{o} is not an option of render"
        );
    }
    // for each point-light row, an option of another row is refused with one message naming
    // this row and the rows that take the option
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let cow = scene_path("cow.toml");
    for row in REGISTRY.iter().filter(|r| r.pipeline != Pipeline::Klee2016) {
        let foreign = *all
            .iter()
            .find(|o| !row.takes(o))
            .expect("a foreign option");
        let value: &[&str] = match foreign {
            "grid" => &["8"],
            "grid-variant" => &["thesis"],
            "voxel-array-length" | "ray-array-length" | "stream-steps" | "stream-max-calls"
            | "ntree-n" => &["8"],
            "light-samples" => &["2x2"],
            "refl-depth" | "tile" => &["1"],
            "shadow-flags" => &["rgba"],
            "bvh-variant" => &["sah"],
            "klee-shading" => &["fig7"],
            "tracer" => &["base"],
            "shadows" => panic!("--shadows chooses Klee 2016's design: not a foreign option"),
            _ => &[],
        };
        let mut args = vec!["render", cow.to_str().unwrap(), "-o", png.to_str().unwrap()];
        let select: Vec<String> = (row.select.iter())
            .flat_map(|(o, v)| [format!("--{o}"), v.to_string()])
            .collect();
        args.extend(select.iter().map(String::as_str));
        let flag = format!("--{foreign}");
        args.push(&flag);
        args.extend_from_slice(value);
        let o = run(&args);
        let err = stderr(&o);
        assert!(!o.status.success(), "{row:?} took {flag}");
        let takers = REGISTRY
            .iter()
            .filter(|r| r.options().any(|o| o == foreign));
        for needle in [flag.clone(), format!("uses {}", row.name)]
            .into_iter()
            .chain(takers.map(|r| r.name.to_string()))
        {
            assert!(err.contains(&needle), "{row:?} with {flag}: {err}");
        }
        assert!(!png.exists(), "{row:?}: refused, yet written");
    }
}

#[test]
fn every_row_has_its_folders_and_its_documentation() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap();
    let (readme, architecture) = (read("README.md"), read("docs/architecture.md"));
    for row in REGISTRY {
        let module = root.join("src/pipeline").join(row.pipeline.folder());
        assert!(module.is_dir(), "{row:?}: no {}", module.display());
        assert!(
            row.glsl.contains(&row.pipeline.folder()),
            "{row:?}: its pipeline's shader folder"
        );
        for folder in row.glsl {
            let dir = root.join("glsl").join(folder);
            let kernels = std::fs::read_dir(&dir)
                .unwrap_or_else(|e| panic!("{row:?}: {}: {e}", dir.display()))
                .count();
            assert!(kernels > 0, "{row:?}: {} is empty", dir.display());
            let named = format!("glsl/{folder}/");
            assert!(
                readme.contains(&named),
                "{row:?}: the README's table lacks {named}"
            );
            assert!(
                architecture.contains(&named),
                "{row:?}: docs/architecture.md lacks {named}"
            );
        }
        // an accelerator's GPU type is named as its shader folder
        for folder in row.glsl.iter().filter(|_| row.accel.is_some()) {
            let (file, dir) = (
                format!("src/accel/{folder}.rs"),
                format!("src/accel/{folder}"),
            );
            assert!(
                *folder == row.pipeline.folder()
                    || root.join(&file).exists()
                    || root.join(&dir).is_dir(),
                "{row:?}: no {file} beside glsl/{folder}/"
            );
        }
    }
}

#[test]
fn every_row_renders() {
    let ctx = context();
    let point = load("cow.toml");
    let area = load("bunny_area.toml");
    for row in REGISTRY {
        let scene = match row.pipeline {
            Pipeline::Klee2016 => &area,
            _ => &point,
        };
        let design = Design::plain(row, 16, 16, 0);
        assert_eq!(design.row().name, row.name);
        let f = renderer(&ctx, scene, &design)
            .render(&scene.camera)
            .unwrap_or_else(|e| panic!("{row:?}: {e:#}"));
        assert_eq!((f.width, f.height), (16, 16));
        assert!(
            f.stats.total_triangle_tests() > 0,
            "{row:?}: no triangle tested"
        );
        let lit = f.color.iter().filter(|c| c[0] + c[1] + c[2] > 0.0).count();
        assert!(lit > 16, "{row:?}: {lit} lit pixels");
    }
}

/// The designs that light an area light are those that take `--light-samples` (Müller 2015's
/// pipeline, with its feelers per sample, and Klee 2016's); the others refuse such a scene by
/// name rather than ignore the light.
#[test]
fn area_lights_are_lit_by_the_rows_that_take_light_samples() {
    let ctx = context();
    // the area light alone (Klee 2016's pipeline refuses point lights beside it)
    let mut area = load("cow_area.toml");
    area.lights.clear();
    for row in REGISTRY {
        let design = Design::plain(row, 16, 16, 0);
        let made = design.renderer(ctx.gl.clone(), &ctx.info, &area, &Default::default());
        match (row.takes("light-samples"), made) {
            (true, Ok(mut r)) => {
                let f = r
                    .render(&area.camera)
                    .unwrap_or_else(|e| panic!("{row:?}: {e:#}"));
                assert!(f.stats.total_triangle_tests() > 0, "{row:?}");
            }
            (true, Err(e)) => panic!("{row:?} takes --light-samples but refuses: {e:#}"),
            (false, Ok(_)) => panic!("{row:?} would ignore the area light"),
            (false, Err(e)) => {
                let msg = e.to_string();
                assert!(
                    msg.contains("[[area_light]]") && msg.contains("ignored"),
                    "{msg}"
                );
            }
        }
    }
}
