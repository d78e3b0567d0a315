//! Time the SAH BVH build of a scene's triangles on the CPU, step by step (no GPU needed):
//! `cargo run --release --example bvh_build -- scenes/dragon.toml [REPEATS]`.
//! Prints the best of REPEATS (default 5) for the whole build and for its parts.

use std::path::Path;
use std::time::Instant;

use gpgpu_rt::accel::bvh::BvhTree as Bvh;
use gpgpu_rt::scene::Scene;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| "scenes/dragon.toml".into());
    let repeats: usize = args.next().map_or(Ok(5), |s| s.parse())?;
    let scene = Scene::load(Path::new(&path))?;
    let (mut build, mut upload_data) = (f64::INFINITY, f64::INFINITY);
    let mut stats = None;
    for _ in 0..repeats {
        let triangles = scene.world_triangles();
        let start = Instant::now();
        let bvh = Bvh::new(triangles);
        build = build.min(start.elapsed().as_secs_f64() * 1e3);
        let start = Instant::now();
        std::hint::black_box(bvh.gpu_words());
        upload_data = upload_data.min(start.elapsed().as_secs_f64() * 1e3);
        stats = Some(bvh.stats);
    }
    println!(
        "{path}: {} triangles, {} threads: build {build:.1} ms (best of {repeats}), words for upload {upload_data:.1} ms; {:?}",
        scene.triangle_count(),
        rayon::current_num_threads(),
        stats.expect("at least one build")
    );
    Ok(())
}
