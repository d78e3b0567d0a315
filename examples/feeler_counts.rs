//! The shadow feelers' walks, counted on the CPU twin (no GPU needed):
//!
//! ```sh
//! gpgpu-rt render scenes/bunny.toml --tracer bvh --refl-depth 0 --frames 1 \
//!     --width 512 --height 512 --aov-dir /tmp/aov -o /tmp/bunny.png
//! cargo run --release --example feeler_counts -- scenes/bunny.toml /tmp/aov
//! ```
//!
//! Each first hit of the AOV directory gets intersect2's feeler towards the scene's first
//! light (Listing 15, [`Feeler::towards`]); the program counts per feeler the nodes visited and
//! the triangle tests of intersect2's walk ([`Bvh::feeler_walk`]: from the root, near side first)
//! for blocked and unblocked feelers apart, beside the walks of two alternatives: from each 8×8
//! block's entry point, found for the block's feelers as `glsl/bvh/entry.comp` finds it for
//! the primary rays ([`Bvh::block_entry`]), and a walk in the other direction, from the light.

use std::ops::ControlFlow;
use std::path::Path;

use anyhow::{Context, Result};
use glam::Vec3;
use gpgpu_rt::accel::bvh::{block_of, BvhTree as Bvh};
use gpgpu_rt::reference::bvh::BlockEntry;
use gpgpu_rt::reference::Feeler;
use gpgpu_rt::scene::Scene;

/// An `.npy` of f32 or i32 values and its shape.
fn read_npy<T: npyz::Deserialize>(dir: &Path, name: &str) -> Result<(Vec<u64>, Vec<T>)> {
    let path = dir.join(name);
    let bytes = std::fs::read(&path).with_context(|| format!("{}", path.display()))?;
    let npy = npyz::NpyFile::new(&bytes[..]).with_context(|| format!("{}", path.display()))?;
    let shape = npy.shape().to_vec();
    Ok((shape, npy.into_vec::<T>()?))
}

/// Counts over a set of feelers.
#[derive(Default, Debug)]
struct Tally {
    feelers: u64,
    nodes: u64,
    tests: u64,
}

impl Tally {
    fn add(&mut self, nodes: u64, tests: u64) {
        self.feelers += 1;
        self.nodes += nodes;
        self.tests += tests;
    }
    fn line(&self, what: &str) {
        let f = self.feelers.max(1) as f64;
        println!(
            "{what:<40} {:>8} feelers {:>7.2} nodes {:>6.2} tests per feeler",
            self.feelers,
            self.nodes as f64 / f,
            self.tests as f64 / f
        );
    }
}

/// A walk from `entry` (or the root): blocked, tests, nodes.
fn walk(bvh: &Bvh, entry: Option<&BlockEntry>, f: &Feeler) -> (bool, u64, u64) {
    let (mut blocked, mut tests) = (false, 0);
    let nodes = bvh.traverse_from(entry, f.ro, f.rd, f.offset, f.light_distance, |ids| {
        let ids = ids.iter().map(|&i| i as usize);
        blocked = f.blocked_among(bvh.triangles(), ids, &mut tests);
        match blocked {
            true => ControlFlow::Break(()),
            false => ControlFlow::Continue(f.light_distance),
        }
    });
    (blocked, tests, nodes)
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let scene = Scene::load(Path::new(&args[1]))?;
    let dir = Path::new(&args[2]);
    let (shape, o) = read_npy::<f32>(dir, "ray_origin.npy")?;
    let (_, d) = read_npy::<f32>(dir, "ray_direction.npy")?;
    let (_, t) = read_npy::<f32>(dir, "hit_t.npy")?;
    let (_, id) = read_npy::<i32>(dir, "triangle_id.npy")?;
    let (_, n) = read_npy::<f32>(dir, "normal.npy")?;
    let (h, w) = (shape[0] as usize, shape[1] as usize);
    let bvh = Bvh::new(scene.world_triangles());
    let light = scene.lights[0].position;
    let offset = scene.settings.shadow_offset;
    let v = |a: &[f32], i: usize| Vec3::new(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
    // the feeler of pixel (x, y), GL's rows (from the bottom)
    let feeler = |x: u32, y: u32| {
        let i = (h - 1 - y as usize) * w + x as usize;
        let last = id[i];
        (last >= 0)
            .then(|| Feeler::towards(v(&o, i) + t[i] * v(&d, i), v(&n, i), last, light, offset))
            .flatten()
    };
    let entries = bvh.block_entries((w as u32, h as u32), |x, y| {
        feeler(x, y).map(|f| (f.ro, f.rd))
    });
    // per walk, unblocked and blocked feelers apart
    let mut root: [Tally; 2] = Default::default();
    let mut entry: [Tally; 2] = Default::default();
    let mut reverse: [Tally; 2] = Default::default();
    for (x, y) in (0..h as u32).flat_map(|y| (0..w as u32).map(move |x| (x, y))) {
        let Some(f) = feeler(x, y) else { continue };
        let (blocked, tests, nodes) = walk(&bvh, None, &f);
        root[blocked as usize].add(nodes, tests);
        let e = entries[block_of(w as u32, x, y)];
        let (b2, tests, nodes) = walk(&bvh, e.as_ref(), &f);
        assert_eq!(blocked, b2, "pixel ({x}, {y}) entry {e:?}");
        entry[blocked as usize].add(nodes, tests);
        // the same segment from the light: hits at 0 < t < light distance − offset
        let back = Feeler {
            ro: light,
            rd: -f.rd,
            light_distance: f.light_distance - offset,
            offset: 0.0,
            last: f.last,
        };
        let (_, tests, nodes) = walk(&bvh, None, &back);
        reverse[blocked as usize].add(nodes, tests);
    }
    for (k, what) in ["unblocked", "blocked"].iter().enumerate() {
        root[k].line(&format!("{what}: from the root"));
        entry[k].line(&format!("{what}: from the block's entry"));
        reverse[k].line(&format!("{what}: from the light"));
    }
    let bounds = entries.iter().flatten().count();
    println!("blocks {} with an entry {bounds}", entries.len());
    Ok(())
}
