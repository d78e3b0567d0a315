//! Magnitudes f32 cannot shade (issue 14, class 3): a scene far from the origin renders as it
//! does at the origin, and one beyond the bounds of `scene::magnitudes` is refused with the
//! object, its extent and the limit, never rendered wrong with exit status 0.

mod common;

use std::path::PathBuf;

use gpgpu_rt::scene::Scene;

/// `sphere.toml` with the camera, the light and the sphere scaled by `k` (the camera's near
/// distance, 0.05, is not: the image plane stays 0.05 in front of a camera at 4·k).
fn sphere_scaled(k: f64) -> String {
    format!(
        "[camera]\nposition = [0.0, {:e}, {:e}]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 40.0\n\
         [[light]]\nposition = [0.0, {:e}, {:e}]\ncolor = [1.0, 1.0, 1.0]\n\
         [[object]]\ntype = \"sphere\"\nradius = {:e}\nstacks = 16\nslices = 24\n",
        k,
        4.0 * k,
        6.0 * k,
        1.5 * k,
        k
    )
}

fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gpgpu-rt-magnitudes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn refusal(name: &str, text: &str) -> String {
    Scene::load(&write(name, text))
        .expect_err("the scene must be refused")
        .to_string()
}

#[test]
fn a_scene_scaled_by_a_million_shows_the_same_triangles() {
    let ctx = common::context();
    let mut opts = common::options(48, 48, 0);
    opts.accel = common::BVH_FOUR_KERNELS;
    let ids = |k: f64| {
        let scene = Scene::load(&write(&format!("sphere{k}.toml"), &sphere_scaled(k))).unwrap();
        let frame = common::render_gpu(&ctx, &scene, opts.clone());
        frame.aovs.unwrap().triangle_id
    };
    let (one, far) = (ids(1.0), ids(1.0e6));
    let hits = one.iter().filter(|&&t| t >= 0).count();
    let differ = one.iter().zip(&far).filter(|(a, b)| a != b).count();
    // Before the eye rays were built from the camera-relative offset, every ray of the scaled
    // scene pointed along a rounding error and nothing was hit. Measured: 0 of 2304 pixels
    // differ (the ray directions are the same vectors up to rounding, and no triangle edge lies
    // within a rounding of a pixel centre here); a few pixels at silhouettes are allowed.
    assert!(hits > 500, "the sphere covers {hits} pixels");
    assert!(
        differ <= 4,
        "{differ} of {} pixels show another triangle at scale 1e6",
        one.len()
    );
}

#[test]
fn a_floor_beyond_the_dynamic_range_is_refused_with_its_extent() {
    let floor = |size: &str| {
        format!(
            "[camera]\nposition = [0.0, 2.2, 4.2]\nlook_at = [0.0, 0.5, 0.0]\n\
             [[light]]\nposition = [3.0, 5.0, 3.0]\ncolor = [1.0, 1.0, 1.0]\n\
             [[object]]\ntype = \"floor\"\nname = \"ground\"\nsize = {size}\nquads = 4\n"
        )
    };
    // 2^20 × the viewing distance 4.53 is 4.75e6: a floor of size 9e6 reaches 4.5e6
    Scene::load(&write("floor_ok.toml", &floor("9.0e6"))).expect("within the range");
    let e = refusal("floor_far.toml", &floor("5.0e9"));
    assert!(e.contains("floor_far.toml"), "{e}");
    assert!(e.contains("'ground'") && e.contains("2.500e9"), "{e}");
    assert!(e.contains("2^20") && e.contains("4.751e6"), "{e}");
}

#[test]
fn overflowing_and_underflowing_magnitudes_are_refused() {
    let e = refusal(
        "light_far.toml",
        &sphere_scaled(1.0).replace(
            "position = [0.0, 6e0, 1.5e0]",
            "position = [0.0, 3e19, 1.5]",
        ),
    );
    assert!(e.contains("light 1") && e.contains("2^60"), "{e}");
    // the camera 4e12 away (the range would allow 4e18) from an object at 2e18
    let far = sphere_scaled(1.0)
        .replace("position = [0.0, 1e0, 4e0]", "position = [0.0, 0.0, 4e12]")
        .replace("radius = 1e0", "radius = 2e18");
    let e = refusal("far.toml", &far);
    assert!(e.contains("'sphere#0'") && e.contains("2^60"), "{e}");
    let e = refusal("tiny.toml", &sphere_scaled(1.0e-14));
    assert!(e.contains("2^-40"), "{e}");
    // a distant light alone is fine: it is a direction and a distance
    Scene::load(&write(
        "sun.toml",
        &sphere_scaled(1.0).replace(
            "position = [0.0, 6e0, 1.5e0]",
            "position = [0.0, 1e15, 1.5]",
        ),
    ))
    .expect("a distant light");
}
