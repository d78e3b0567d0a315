//! The line spaces built on the GPU (`glsl/klee2016/linespace_build.comp`) against the CPU
//! build, bit for bit; the integer shaft test they share against the f64 one.

mod common;

use common::lattice;
use gpgpu_rt::gl::ShaderSource;
use gpgpu_rt::pipeline::klee2016::linespace_build;
use gpgpu_rt::pipeline::klee2016::ntree::{
    self, face_rect, shaft_hits_box, shaft_hits_cell, Aabb, NTree, FACES,
};

#[test]
fn integer_shaft_test_gives_the_f64_tests_answers() {
    // every pair of boundary cells against every cell, for small N
    for n in 2..=5u32 {
        let mut hits = 0usize;
        for s in 0..FACES {
            for e in 0..FACES {
                if s == e {
                    continue;
                }
                for (su, sv, eu, ev) in itertools(n) {
                    let a = face_rect(n, s, su, su + 1, sv, sv + 1);
                    let b = face_rect(n, e, eu, eu + 1, ev, ev + 1);
                    for c in 0..n.pow(3) {
                        let cell = Aabb::cell(c % n, (c / n) % n, c / (n * n));
                        let f = shaft_hits_box(&a, &b, &cell);
                        let i = shaft_hits_cell(lattice(&a), lattice(&b), lattice(&cell).0);
                        assert_eq!(
                            f, i,
                            "N {n}: sides {s} {e} cells {su} {sv} {eu} {ev} cell {c}"
                        );
                        hits += f as usize;
                    }
                }
            }
        }
        assert!(hits > 0);
    }
    // rectangles of cells (the CPU build's halving) at the largest N, pseudo-random
    let n = 16u32;
    let mut x = 0x2545F4914F6CDD1Du64;
    let mut next = |m: u32| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % m as u64) as u32
    };
    for _ in 0..200_000 {
        let (s, e) = (next(6) as usize, next(6) as usize);
        if s == e {
            continue;
        }
        let mut rect = |f: usize| {
            let (u0, v0) = (next(n), next(n));
            let (u1, v1) = (u0 + 1 + next(n - u0), v0 + 1 + next(n - v0));
            face_rect(n, f, u0, u1, v0, v1)
        };
        let (a, b) = (rect(s), rect(e));
        let cell = Aabb::cell(next(n), next(n), next(n));
        assert_eq!(
            shaft_hits_box(&a, &b, &cell),
            shaft_hits_cell(lattice(&a), lattice(&b), lattice(&cell).0),
            "{a:?} {b:?} {cell:?}"
        );
    }
}

/// (su, sv, eu, ev) over 0..n each.
fn itertools(n: u32) -> impl Iterator<Item = (u32, u32, u32, u32)> {
    (0..n.pow(4)).map(move |i| (i % n, (i / n) % n, (i / (n * n)) % n, i / (n * n * n)))
}

/// The GPU's line spaces of `scene` at N, depth, read back from the texture, against the CPU's,
/// with the texture at most `max_dim` texels per axis.
fn gpu_equals_cpu(scene: &str, n: u32, depth: u32, max_dim: u32) {
    let ctx = common::context();
    let shaders = ShaderSource::default();
    let tris = common::load(scene).world_triangles();
    let cpu = NTree::build(&tris, n, depth).unwrap();
    let mut gpu = NTree::build_nodes(&tris, n, depth).unwrap();
    assert!(gpu.linespaces.is_empty());
    let built = linespace_build::build(&ctx.gl, &ctx.info, &shaders, &mut gpu, max_dim).unwrap();
    let what = format!("{scene} N {n} depth {depth} max_dim {max_dim}");
    assert_eq!(gpu.linespace_count, cpu.linespace_count, "{what}");
    let words = ntree::linespace_words(n);
    let packed = ntree::pack_linespaces(&cpu.linespaces, words, cpu.linespace_count, max_dim);
    let packed = packed.unwrap();
    // the whole texture, padding included, as the GPU left it (read back by the build)
    let texels = &built.packed.texels;
    assert_eq!(texels.len(), packed.texels.len(), "{what}");
    let differ = texels
        .iter()
        .zip(&packed.texels)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(
        differ,
        0,
        "{what}: {differ} of {} texels differ",
        texels.len()
    );
    let count = gpu.linespace_count as u32;
    let unpacked: Vec<u32> = (0..count).flat_map(|ls| built.packed.unpack(ls)).collect();
    assert!(unpacked == cpu.linespaces, "{what}: line spaces");
    assert!(cpu.linespaces.iter().any(|w| *w != 0), "{what}: no bit set");
}

#[test]
fn gpu_line_spaces_equal_the_cpu_build_on_small_scenes() {
    // (an odd N, and N = 2; the bunny test takes the default N = 10)
    gpu_equals_cpu("sphere.toml", 2, 3, 2048);
    // Listing 3's layout wrapping: line spaces over several rows, rows continued along z
    gpu_equals_cpu("sphere.toml", 7, 3, 64);
}

#[test]
fn gpu_line_spaces_equal_the_cpu_build_on_the_bunny() {
    gpu_equals_cpu("bunny_area.toml", 10, 3, 2048);
}
