//! Two levels (`--bvh-instances`, ours; issue 34 item 4, the alternative to the refit): one
//! SAH tree per object, built once over its object-space triangles, under a list of
//! instances — each object's world box and the inverse of its model matrix. A frame that moves
//! objects rewrites only the instances' texels (a few hundred bytes, on the host), never a
//! tree: a rigid motion costs no tree quality and no refit. A ray tests every instance's box
//! and walks the tree of each one it enters with its origin and direction taken into the
//! object's space (`glsl/bvh/traverse.glsl`'s `traverseScene`); t, the barycentrics and the
//! triangle ids are those of world space, since the transform is affine and the direction is
//! not normalised. The list is not a tree: the thesis' scenes have 2–7 objects (a top tree over
//! them is the step for scenes of many; docs/design/bvh.md, "Two levels").
//!
//! The word buffer (`glsl/bvh/words.glsl`): texel 0 holds the instance count K; then an
//! [`InstanceRecord`] per instance, [`INSTANCE_TEXELS`] texels each; then each object's tree
//! as [`BvhTree::gpu_words`] lays it out, moved to its base texel — its miss links (record
//! texels) moved with it, its leaf triangles' ids made the scene's and their `zero1` word the
//! instance + 1 (`glsl/bvh/hit_record.glsl` finds the instance of a hit from it).

use anyhow::{bail, Result};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use super::layout::{Aabb, BvhStats, NodeRecord, HEADER_WORDS, OCTANTS, TRIANGLE_WORDS};
use super::tree::BvhTree;

/// One instance in the word buffer: five texels, 80 bytes (`glsl/bvh/words.glsl`'s
/// `instanceRay`, `glsl/bvh/traverse.glsl`'s `traverseScene`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct InstanceRecord {
    /// bytes 0–11: the low corner of the object's world box
    pub lo: [f32; 3],
    /// bytes 12–15: the texel of its tree's header
    pub tree: u32,
    /// bytes 16–27: the high corner of the world box
    pub hi: [f32; 3],
    /// bytes 28–31: 0
    pub zero: u32,
    /// bytes 32–79: the first three rows of the inverse of its model matrix (world to object
    /// space: p' = rows · (p, 1))
    pub inverse: [[f32; 4]; 3],
}
const _: () = assert!(std::mem::size_of::<InstanceRecord>() == 80);

/// Texels of an [`InstanceRecord`] (`BVH_INSTANCE_TEXELS`).
pub const INSTANCE_TEXELS: usize = std::mem::size_of::<InstanceRecord>() / 16;

/// The instances of `scene`: its objects with triangles (`BVH_INSTANCE_COUNT` of the kernels).
pub fn instance_count(scene: &crate::scene::Scene) -> usize {
    scene
        .objects
        .iter()
        .filter(|o| has_triangles(&o.mesh.positions))
        .count()
}

fn has_triangles(positions: &[Vec3]) -> bool {
    positions.len() >= 3
}

/// The objects' trees and where they lie in the word buffer.
pub struct Instances {
    /// one tree per object with triangles, in object space (triangle id: its index in the
    /// object)
    pub trees: Vec<BvhTree>,
    /// the object of each tree (objects without triangles have none)
    pub objects: Vec<usize>,
    /// the scene's id of each tree's first triangle
    first_ids: Vec<u32>,
    /// the texel of each tree's header in the word buffer
    pub bases: Vec<u32>,
}

impl Instances {
    /// Build a tree per object over `objects` (each a triangle soup in object space, scene
    /// order).
    pub fn new(objects: &[Vec<Vec3>]) -> Instances {
        let mut out = Instances {
            trees: Vec::new(),
            objects: Vec::new(),
            first_ids: Vec::new(),
            bases: Vec::new(),
        };
        let mut first = 0u32;
        let mut base = 1 + INSTANCE_TEXELS * objects.iter().filter(|o| has_triangles(o)).count();
        for (k, positions) in objects.iter().enumerate() {
            let triangles: Vec<[Vec3; 3]> = positions
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect();
            let count = triangles.len() as u32;
            if has_triangles(positions) {
                let tree = BvhTree::new(triangles);
                out.objects.push(k);
                out.first_ids.push(first);
                out.bases.push(base as u32);
                base += tree.stats.bytes / 16;
                out.trees.push(tree);
            }
            first += count;
        }
        out
    }

    /// The texels before the first tree: the count, then the instances as `models` place them
    /// (the model matrix of every object of the scene). An instance needs the inverse of its
    /// model matrix, found in doubles (a tiny scale, which the scene accepts, keeps an inverse
    /// in floats): a singular one (an object scaled flat) is refused by name.
    pub fn table(&self, models: &[Mat4]) -> Result<Vec<u32>> {
        let mut words = vec![self.trees.len() as u32, 0, 0, 0];
        for (i, tree) in self.trees.iter().enumerate() {
            let model = models[self.objects[i]];
            let world = world_box(tree, model);
            let exact = model.as_dmat4();
            let inverse = exact.inverse().as_mat4();
            if exact.determinant() == 0.0 || !inverse.is_finite() {
                bail!(
                    "object {} has a model matrix without an inverse (determinant {}): \
                     --bvh-instances takes every ray into each object's own space; scale the \
                     object by a nonzero factor on every axis, or leave out --bvh-instances",
                    self.objects[i],
                    exact.determinant()
                );
            }
            let record = InstanceRecord {
                lo: world.lo.to_array(),
                tree: self.bases[i],
                hi: world.hi.to_array(),
                zero: 0,
                inverse: [0, 1, 2].map(|r| inverse.row(r).to_array()),
            };
            words.extend_from_slice(bytemuck::cast_slice(&[record]));
        }
        Ok(words)
    }

    /// The whole buffer: [`Instances::table`], then every tree at its base texel.
    pub fn gpu_words(&self, models: &[Mat4]) -> Result<Vec<u32>> {
        let mut words = self.table(models)?;
        for (i, tree) in self.trees.iter().enumerate() {
            debug_assert_eq!(words.len(), 4 * self.bases[i] as usize);
            let mut tree_words = tree.gpu_words();
            self.relocate(i, tree, &mut tree_words);
            words.extend_from_slice(&tree_words);
        }
        Ok(words)
    }

    /// Tree `i`'s words at its base texel: every miss link (a record's texel) moved by the
    /// base, every leaf triangle's id made the scene's, its `zero1` word the instance + 1.
    fn relocate(&self, i: usize, tree: &BvhTree, words: &mut [u32]) {
        let base = self.bases[i] as i32;
        let records = OCTANTS * tree.nodes.len();
        let (_, rest) = words.split_at_mut(HEADER_WORDS);
        let (octants, triangles) = rest.split_at_mut(4 * records);
        for r in bytemuck::cast_slice_mut::<u32, NodeRecord>(octants) {
            if r.reference >= 0 {
                r.reference += base;
            }
        }
        for t in triangles.chunks_exact_mut(TRIANGLE_WORDS) {
            t[3] += self.first_ids[i];
            t[7] = i as u32 + 1;
        }
    }

    /// The trees' facts together: nodes, leaves and bytes summed, the deepest depth, the
    /// build times summed, and the SAH costs summed (each in its own object's space).
    pub fn stats(&self) -> BvhStats {
        let mut s = BvhStats::default();
        for t in &self.trees {
            s.nodes += t.stats.nodes;
            s.leaves += t.stats.leaves;
            s.depth = s.depth.max(t.stats.depth);
            s.sah_cost += t.stats.sah_cost;
            s.bytes += t.stats.bytes;
            s.build_ms += t.stats.build_ms;
        }
        s.bytes += 16 * (1 + INSTANCE_TEXELS * self.trees.len());
        s
    }

    /// The most events one walk of the two levels can count: every instance's box, and every
    /// node and leaf triangle of every tree.
    pub fn events(&self) -> u64 {
        let per_tree = |t: &BvhTree| t.stats.nodes.max(t.tris.len()) as u64;
        self.trees.len() as u64 + self.trees.iter().map(per_tree).sum::<u64>()
    }
}

/// The world box of `tree`'s root box placed by `model`: the box of its 8 corners, widened by
/// 10^-5 of its extent against the corners' rounding (the root box holds the tree's padded
/// boxes; a ray that enters no world box walks no tree).
pub fn world_box(tree: &BvhTree, model: Mat4) -> Aabb {
    let root = &tree.nodes[0];
    let (lo, hi) = (Vec3::from(root.lo), Vec3::from(root.hi));
    let mut world = Aabb::EMPTY;
    for c in 0..8 {
        let corner = Vec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo);
        world.grow_point(model.transform_point3(corner));
    }
    let extent = (world.hi - world.lo)
        .max_element()
        .max(world.hi.abs().max_element())
        .max(world.lo.abs().max_element());
    let pad = Vec3::splat(1e-5 * extent.max(1e-20));
    Aabb {
        lo: world.lo - pad,
        hi: world.hi + pad,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(z: f32) -> Vec<Vec3> {
        [(0., 0.), (1., 0.), (1., 1.), (0., 0.), (1., 1.), (0., 1.)]
            .map(|(x, y)| Vec3::new(x, y, z))
            .to_vec()
    }

    /// The trees lie one after the other from their bases, their links moved there, their
    /// triangles' ids the scene's and tagged with their instance; an object without triangles
    /// has no instance.
    #[test]
    fn words_place_every_tree_at_its_base() {
        let objects = vec![quad(0.0), Vec::new(), quad(1.0)];
        let inst = Instances::new(&objects);
        assert_eq!(inst.objects, vec![0, 2]);
        let models = [
            Mat4::IDENTITY,
            Mat4::IDENTITY,
            Mat4::from_translation(Vec3::X),
        ];
        let words = inst.gpu_words(&models).unwrap();
        assert_eq!(words[0], 2);
        assert_eq!(words.len(), inst.stats().bytes / 4);
        for (i, tree) in inst.trees.iter().enumerate() {
            let base = inst.bases[i] as usize;
            let record: InstanceRecord =
                bytemuck::pod_read_unaligned(bytemuck::cast_slice(&words[4 + 20 * i..24 + 20 * i]));
            assert_eq!(record.tree as usize, base);
            let own = tree.gpu_words();
            let at = |w: usize| words[4 * base + w];
            assert_eq!(at(0), own[0], "the header's node count");
            let links = (0..OCTANTS * tree.nodes.len()).map(|r| HEADER_WORDS + 4 * r + 3);
            for w in links {
                let (moved, own) = (at(w) as i32, own[w] as i32);
                assert_eq!(moved, if own >= 0 { own + base as i32 } else { own });
            }
            for (s, &id) in tree.tris.iter().enumerate() {
                let w = tree.triangle_base() + TRIANGLE_WORDS * s;
                assert_eq!(at(w + 3), id + 2 * i as u32, "the scene's triangle id");
                assert_eq!(at(w + 7), i as u32 + 1, "the instance + 1");
            }
        }
        // the second instance's world box: its quad moved one unit along x
        let second: InstanceRecord =
            bytemuck::pod_read_unaligned(bytemuck::cast_slice(&words[24..44]));
        assert!((second.lo[0] - 1.0).abs() < 1e-4 && (second.hi[0] - 2.0).abs() < 1e-4);
        assert_eq!(second.inverse[0][3], -1.0, "the inverse moves back");
    }

    /// An object scaled flat has no inverse: refused, naming the object.
    #[test]
    fn a_singular_model_matrix_is_refused() {
        let inst = Instances::new(&[quad(0.0), quad(1.0)]);
        let flat = Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0));
        let err = inst.table(&[Mat4::IDENTITY, flat]).unwrap_err().to_string();
        assert!(err.contains("object 1") && err.contains("inverse"), "{err}");
    }
}
