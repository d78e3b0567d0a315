//! The output-sensitive CPU build of the line spaces (`linespace_cpu`: one mask per child
//! position, OR-ed) against the definitions it replaces: the mask against the exact shaft test
//! of every shaft, and whole line spaces against the hierarchical build (`build_linespace`,
//! itself checked against brute force in tests/linespace.rs) on random nodes and real trees.

mod common;

use common::lattice;
use common::Rng;
use gpgpu_rt::pipeline::klee2016::linespace_cpu::{build_linespaces, cell_mask};
use gpgpu_rt::pipeline::klee2016::ntree::{
    build_linespace, entry_index, face_rect, get_bit, shaft_hits_cell, NTree, FACES,
};
use rayon::prelude::*;

#[test]
fn cell_masks_hold_exactly_the_shafts_that_cut_the_cell() {
    for n in 2..=6u32 {
        let mut set = 0usize;
        for c in 0..n.pow(3) {
            let cell = [c % n, (c / n) % n, c / (n * n)];
            let mask = cell_mask(n, cell);
            let corner = cell.map(|v| v as i32);
            for s in 0..FACES {
                for e in s + 1..FACES {
                    for i in 0..n.pow(4) {
                        let (su, sv, eu, ev) =
                            (i % n, (i / n) % n, (i / (n * n)) % n, i / n.pow(3));
                        let a = lattice(&face_rect(n, s, su, su + 1, sv, sv + 1));
                        let b = lattice(&face_rect(n, e, eu, eu + 1, ev, ev + 1));
                        let idx = entry_index(n, s, su, sv, e, eu, ev).unwrap();
                        let want = shaft_hits_cell(a, b, corner);
                        assert_eq!(
                            get_bit(&mask, idx),
                            want,
                            "N {n} cell {cell:?} sides {s} {e} cells ({su}, {sv}) ({eu}, {ev})"
                        );
                        set += want as usize;
                    }
                }
            }
        }
        assert!(set > 0, "N {n}: no shaft cuts any cell");
    }
}

/// The new build of `nodes` against the hierarchical one, node by node.
fn equals_hierarchical(n: u32, nodes: &[Vec<bool>], what: &str) {
    let words = gpgpu_rt::pipeline::klee2016::ntree::linespace_words(n);
    let built = build_linespaces(n, nodes);
    assert_eq!(built.len(), nodes.len() * words, "{what}");
    let old: Vec<Vec<u32>> = nodes.par_iter().map(|f| build_linespace(n, f)).collect();
    for (i, old) in old.iter().enumerate() {
        let differ = (0..old.len())
            .filter(|&w| built[i * words + w] != old[w])
            .count();
        assert_eq!(differ, 0, "{what}: node {i}, {differ} words differ");
    }
}

#[test]
fn random_nodes_equal_the_hierarchical_build() {
    let mut rng = Rng(0x9E3779B97F4A7C15);
    for n in [2u32, 3, 5, 7, 10, 13, 16] {
        let nodes: Vec<Vec<bool>> = [0.0, 0.002, 0.03, 0.2, 1.0]
            .iter()
            .map(|&d| (0..n.pow(3)).map(|_| rng.unit() < d).collect())
            .collect();
        equals_hierarchical(n, &nodes, &format!("random nodes at N {n}"));
    }
}

/// Every inner node's geometry flags of `scene`'s N-tree at N, depth.
fn tree_nodes(scene: &str, n: u32, depth: u32) -> Vec<Vec<bool>> {
    let tris = common::load(scene).world_triangles();
    let tree = NTree::build_nodes(&tris, n, depth).unwrap();
    let groups = tree.inner_groups();
    groups.iter().map(|&g| tree.group_filled(g)).collect()
}

#[test]
fn sphere_and_bunny_trees_equal_the_hierarchical_build() {
    equals_hierarchical(7, &tree_nodes("sphere.toml", 7, 3), "sphere N 7");
    equals_hierarchical(10, &tree_nodes("bunny_area.toml", 10, 3), "bunny N 10");
}

#[test]
fn the_tree_build_uses_the_same_bits() {
    // NTree::build (what `--linespace-build cpu` runs) against the hierarchical definition
    let tris = common::load("sphere.toml").world_triangles();
    let tree = NTree::build(&tris, 4, 4).unwrap();
    for (i, &g) in tree.inner_groups().iter().enumerate() {
        assert_eq!(
            tree.linespace(i),
            &build_linespace(4, &tree.group_filled(g))[..],
            "line space {i}"
        );
    }
}
