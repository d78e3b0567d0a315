//! The GPU's choices, run on this machine: every design's comparisons with its CPU twin (the
//! test files below) run again under `GPGPU_RT_PROFILE=gpu` — no loop limit kept, no ray
//! prefetch, one dispatch thread, the line spaces built on the GPU, 8 compute image units (the
//! paths without the scene's image buffers), the ballot as a GPU with GL_ARB_shader_ballot
//! takes it (`gl::profile`). The plain run of the suite is the `llvmpipe` profile's. Where the
//! `gpu` profile asks llvmpipe for a loop past its limit, the design refuses, naming the limit:
//! those tests are skipped below and the refusal is tested here instead.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::*;
use gpgpu_rt::gl::{ProfileChoice, ProfileName};
use gpgpu_rt::pipeline::Renderer;

/// The test files that compare a design with its twin, and the tests in them that the `gpu`
/// profile refuses on llvmpipe (the base tracer over the 69,451-triangle bunny in one loop;
/// Klee 2016's shadow pass on the bunny, whose busiest invocations run more iterations than
/// their share of llvmpipe's limit once no budget splits them).
const FILES: &[(&str, &[&str])] = &[
    ("accel", &[]),
    ("aovs", &[]),
    ("area_lights", &[]),
    (
        "base_tracer",
        &[
            "bunny_brute_force_tests_every_triangle_once_per_pixel",
            "a_loop_the_implementation_cuts_short_is_refused",
        ],
    ),
    ("bvh", &["bvh_gives_the_base_tracers_image"]),
    ("bvh_instances", &[]),
    ("bvh_refit", &[]),
    ("edge_cases", &[]),
    ("fused_passes", &[]),
    ("grid", &["exact_grid_gives_the_base_tracers_image"]),
    (
        "linespace",
        &[
            "gpu_agrees_with_cpu_and_linespace_differs_from_exact_only_by_conservative_shafts",
            "linespace_fast_gives_linespace_values_with_fewer_tests_gpu_equals_twin",
            "table2_variants_as_defined_gpu_equals_twin",
        ],
    ),
    ("linespace_build", &[]),
    ("proximity", &[]),
    ("ray_kinds", &[]),
    ("stream", &[]),
    ("wagner", &[]),
];

/// The newest test executable of `file` beside this one (cargo builds every test file of the
/// package before it runs any: `target/<profile>/deps/<file>-<hash>`).
fn test_executable(file: &str) -> PathBuf {
    let me = std::env::current_exe().expect("the test's path");
    let deps = me.parent().expect("the deps folder");
    let prefix = format!("{file}-");
    let newest = std::fs::read_dir(deps)
        .expect("the deps folder lists")
        .flatten()
        .filter(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            name.strip_prefix(&prefix)
                .is_some_and(|hash| hash.len() == 16 && hash.chars().all(|c| c.is_ascii_hexdigit()))
        })
        .max_by_key(|e| e.metadata().and_then(|m| m.modified()).ok());
    let exe = newest
        .unwrap_or_else(|| {
            panic!(
                "no test executable of tests/{file}.rs in {}",
                deps.display()
            )
        })
        .path();
    // an executable older than the library was linked with an older one (`cargo test --test
    // profiles` alone does not rebuild the others): refuse rather than test stale code
    let modified = |p: &std::path::Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let library = std::fs::read_dir(deps)
        .expect("the deps folder lists")
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            let name = p.file_name().unwrap_or_default().to_string_lossy();
            name.starts_with("libgpgpu_rt-") && name.ends_with(".rlib")
        })
        .filter_map(|p| modified(&p))
        .max();
    assert!(
        library <= modified(&exe),
        "{} is older than the library: run the whole suite (cargo test --release), which builds \
         every test file first",
        exe.display()
    );
    exe
}

#[test]
fn every_design_agrees_with_its_twin_under_the_gpu_profile() {
    let mut failed = Vec::new();
    for (file, skipped) in FILES {
        let mut c = Command::new(test_executable(file));
        c.current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("GPGPU_RT_PROFILE", "gpu")
            .arg("--quiet");
        for s in *skipped {
            c.args(["--skip", s]);
        }
        let o = c.output().expect("the test executable runs");
        let out = String::from_utf8_lossy(&o.stdout);
        let summary = out
            .lines()
            .rfind(|l| l.starts_with("test result"))
            .unwrap_or("");
        eprintln!("tests/{file}.rs under the gpu profile: {summary}");
        if !o.status.success() || !summary.contains(" passed") || summary.contains(" 0 passed") {
            failed.push(format!(
                "tests/{file}.rs:\n{out}{}",
                String::from_utf8_lossy(&o.stderr)
            ));
        }
    }
    assert!(
        failed.is_empty(),
        "under GPGPU_RT_PROFILE=gpu:\n{}",
        failed.join("\n")
    );
}

/// What the `gpu` profile asks of llvmpipe that its loop limit forbids is refused with the
/// limit named, never rendered short: the base tracer's one loop over the bunny's triangles,
/// Klee 2016's exact shadow pass without a budget at 5×5 rays.
#[test]
fn the_gpu_profile_refuses_what_llvmpipes_loop_limit_would_cut() {
    let ctx = context();
    let Some(limit) = ctx.info.implementation_loop_limit() else {
        eprintln!("SKIPPED: this GL implementation has no loop limit");
        return;
    };
    let gpu = ctx
        .info
        .with_profile(ProfileChoice::Forced(ProfileName::Gpu));
    assert_eq!(gpu.profile.loop_limit, None);
    let shaders = gpgpu_rt::gl::ShaderSource::default();
    let bunny = load("bunny.toml");
    let made = gpgpu_rt::pipeline::mueller2015::RayTracer::new(
        ctx.gl.clone(),
        &gpu,
        &bunny,
        &shaders,
        options(8, 8, 0),
    );
    let e = format!(
        "{:#}",
        made.err().expect("the base tracer's one loop is refused")
    );
    let iterations = limit.iterations.to_string();
    assert!(e.contains("gpu profile") && e.contains(&iterations), "{e}");
    // under the llvmpipe profile the same frame is split and rendered
    assert!(ray_tracer(&ctx, &bunny, options(8, 8, 0))
        .render(&bunny.camera)
        .is_ok());

    // through the environment, as a user sets it: exact soft shadows at 5×5 rays
    let o = Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("GPGPU_RT_PROFILE", "gpu")
        .args(["render", "scenes/bunny_area.toml", "--shadows", "exact"])
        .args([
            "--light-samples",
            "5x5",
            "--width",
            "48",
            "--height",
            "48",
            "-o",
        ])
        .arg(std::env::temp_dir().join("gpgpu-rt-profiles-refused.png"))
        .output()
        .expect("the binary runs");
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("gpu profile") && e.contains(&iterations), "{e}");
}
