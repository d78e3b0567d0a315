//! Hostile input, third round: numbers that are no finite numbers are refused with the option
//! named before anything renders, and a turning scene's pose stays finite for any step and
//! count of frames. (Each case was accepted before: `--turn NaN`, `inf` and `1e39` rendered a
//! background-only image or NaN rays, exit 0; `--tolerance 2` was taken.)

mod common;

use common::*;

#[test]
fn numbers_that_are_not_finite_are_refused_with_the_option() {
    let scene = scene_path("teapot1.toml");
    let scene = scene.to_str().unwrap();
    for value in ["NaN", "inf", "-inf", "1e39", "-1e39"] {
        let turn = format!("--turn={value}");
        let o = run(&["render", scene, "--width", "8", "--height", "8"]
            .into_iter()
            .chain(["--rotate", "objects", &turn, "-o", "/dev/null"])
            .collect::<Vec<_>>());
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{value}: {err}");
        assert!(
            err.contains("--turn") && err.contains("not a finite number"),
            "{err}"
        );
    }
    for (option, value) in [
        ("--tolerance", "NaN"),
        ("--tolerance", "2"),
        ("--count-tolerance", "-0.5"),
    ] {
        let given = format!("{option}={value}");
        let o = run(&["parity", "--list", &given]);
        assert_eq!(o.status.code(), Some(2), "{option} {value}: {}", stderr(&o));
        assert!(stderr(&o).contains(option), "{}", stderr(&o));
    }
}

/// A step so large that its product with the frame count passes what an f32 holds still gives
/// a finite pose: the rays of the last frame are finite and hit the scene.
#[test]
fn a_turning_pose_stays_finite_for_any_step() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_path("teapot1.toml");
    let aovs = dir.path().join("aovs");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
        "--rotate",
        "camera",
        "--turn",
        "3e38",
        "--frames",
        "3",
        "--aov-dir",
        aovs.to_str().unwrap(),
        "-o",
        dir.path().join("x.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(aovs.join("ray_origin.npy")).unwrap();
    let origins: Vec<f32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
    assert!(origins.iter().all(|v| v.is_finite()), "finite ray origins");
    let bytes = std::fs::read(aovs.join("triangle_id.npy")).unwrap();
    let ids: Vec<i32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
    assert!(ids.iter().any(|&id| id >= 0), "the turned scene is hit");
}
