//! The boxes of the kernels' node records as 16-bit planes on a grid over the root's box (ours;
//! `docs/design/bvh.md`, step 23): a record is one texel, where the box as floats took
//! two, and a slab's distance is the plane's grid step count times one per-ray factor plus
//! another. The CPU twin tests the same boxes with the same arithmetic ([`RayGrid::t`]).

use glam::Vec3;

use super::layout::{Aabb, Node};

/// Steps of the grid per axis: a plane is a step count 0..=GRID_STEPS (16 bits).
pub const GRID_STEPS: u32 = u16::MAX as u32;

/// The grid: plane q of axis a lies at `origin[a] + q·step[a]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub origin: Vec3,
    pub step: Vec3,
}

/// A node's box on the grid: the step counts of its low planes x, y, z (rounded down) and of
/// its high planes (rounded up), so that it holds the node's float box.
pub type Planes = [u16; 6];

impl Grid {
    /// The grid over `root` (the root node's box): its low corner and, per axis, the smallest
    /// float step whose [`GRID_STEPS`] steps reach the high side, and no smaller than 2^-40 of
    /// the axis's coordinates, so that the planes `origin + q·step` are distinct in f64 on a
    /// flat axis too. A root that is no box (no triangles) gets the unit grid at 0.
    pub fn over(root: &Aabb) -> Grid {
        if !(root.lo.is_finite() && root.hi.is_finite() && root.lo.cmple(root.hi).all()) {
            return Grid {
                origin: Vec3::ZERO,
                step: Vec3::ONE,
            };
        }
        let step = |a: usize| {
            let extent = root.hi[a] as f64 - root.lo[a] as f64;
            let spacing = root.lo[a].abs().max(root.hi[a].abs()) * (-40f32).exp2();
            let mut s = ((extent / GRID_STEPS as f64) as f32).max(spacing.max(f32::MIN_POSITIVE));
            while (s as f64) * (GRID_STEPS as f64) < extent {
                s = s.next_up();
            }
            s
        };
        Grid {
            origin: root.lo,
            step: Vec3::new(step(0), step(1), step(2)),
        }
    }

    /// Plane q of axis a, in f64 (exact but for a rounding of some 2^-53 of the coordinates,
    /// far below the boxes' padding).
    pub fn plane(&self, a: usize, q: u16) -> f64 {
        self.origin[a] as f64 + q as f64 * self.step[a] as f64
    }

    /// The node's box on the grid: the tightest planes that hold its float box ([`Grid::plane`]).
    pub fn planes(&self, node: &Node) -> Planes {
        let max = GRID_STEPS as f64;
        let mut q = [0u16; 6];
        for a in 0..3 {
            let (o, s) = (self.origin[a] as f64, self.step[a] as f64);
            let at = |q: f64| self.plane(a, q as u16);
            let (lo, hi) = (node.lo[a] as f64, node.hi[a] as f64);
            // the quotients' rounding may leave them a step off the tightest planes
            let mut l = ((lo - o) / s).floor().clamp(0.0, max);
            while l > 0.0 && at(l) > lo {
                l -= 1.0;
            }
            while l < max && at(l + 1.0) <= lo {
                l += 1.0;
            }
            let mut h = ((hi - o) / s).ceil().clamp(0.0, max);
            while h < max && at(h) < hi {
                h += 1.0;
            }
            while h > 0.0 && at(h - 1.0) >= hi {
                h -= 1.0;
            }
            debug_assert!(l <= h, "axis {a}: planes {l} > {h}");
            (q[a], q[3 + a]) = (l as u16, h as u16);
        }
        q
    }

    /// The per-ray factors of the slab distances of a ray with origin `ro` and 1/direction `inv`,
    /// clamped to the finite floats (as the kernels do): an overflow to ±∞ could otherwise make
    /// 0·∞ or ∞ − ∞, where the distance is only far.
    pub fn ray(&self, ro: Vec3, inv: Vec3) -> RayGrid {
        let finite = |v: Vec3| v.clamp(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
        RayGrid {
            a: finite(self.step * inv),
            b: finite((self.origin - ro) * inv),
        }
    }
}

/// A ray's distance to plane q of axis k is `q·a[k] + b[k]` = (origin + q·step − ro)/rd, rounded
/// after the product and after the sum, as the kernels compute it on llvmpipe
/// (`glsl/bvh/traverse.glsl`, `boxEntered`; Mesa lowers `fma` to a multiply and an add there).
#[derive(Debug, Clone, Copy)]
pub struct RayGrid {
    pub a: Vec3,
    pub b: Vec3,
}

impl RayGrid {
    /// The distances to the planes q (one per axis), as the floats' bits.
    pub fn t(&self, q: [u16; 3]) -> [i32; 3] {
        [0, 1, 2].map(|k| (q[k] as f32 * self.a[k] + self.b[k]).to_bits() as i32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(lo: [f32; 3], hi: [f32; 3]) -> Node {
        Node {
            lo,
            first: 0,
            hi,
            meta: 1,
        }
    }

    fn at(g: &Grid, a: usize, q: u16) -> f64 {
        g.plane(a, q)
    }

    #[test]
    fn the_grid_planes_hold_each_box_within_a_step() {
        let root = Aabb {
            lo: Vec3::new(-3.0, 1e-3, 1e6),
            hi: Vec3::new(5.0, 1e-3 + 1e-9, 1e6 + 7.0),
        };
        let g = Grid::over(&root);
        let full = g.planes(&node(root.lo.into(), root.hi.into()));
        for a in 0..3 {
            assert_eq!(g.origin[a], root.lo[a]);
            assert!(
                at(&g, a, u16::MAX) >= root.hi[a] as f64,
                "axis {a} reaches the high side"
            );
            assert!(
                at(&g, a, u16::MAX - 1) < root.hi[a] as f64,
                "{a}: the smallest step"
            );
            assert_eq!((full[a], full[3 + a]), (0, u16::MAX));
        }
        let mut s = 99u32;
        let mut rnd = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1u32 << 24) as f32
        };
        for _ in 0..2000 {
            let (mut lo, mut hi) = ([0f32; 3], [0f32; 3]);
            for a in 0..3 {
                let (x, y) = (rnd(), rnd());
                let p = |t: f32| root.lo[a] + t * (root.hi[a] - root.lo[a]);
                (lo[a], hi[a]) = (p(x.min(y)), p(x.max(y)));
            }
            let q = g.planes(&node(lo, hi));
            for a in 0..3 {
                let (l, h) = (q[a], q[3 + a]);
                assert!(at(&g, a, l) <= lo[a] as f64 && at(&g, a, h) >= hi[a] as f64);
                assert!(
                    l == u16::MAX || at(&g, a, l + 1) > lo[a] as f64,
                    "low plane a step too far"
                );
                assert!(
                    h == 0 || at(&g, a, h - 1) < hi[a] as f64,
                    "high plane a step too far"
                );
            }
        }
    }

    #[test]
    fn a_flat_or_empty_root_gets_a_grid_that_holds_it() {
        let flat = Aabb {
            lo: Vec3::new(0.0, 2.0, -1.0),
            hi: Vec3::new(1.0, 2.0, 1.0),
        };
        let g = Grid::over(&flat);
        assert!(g.step.y > 0.0);
        let q = g.planes(&node(flat.lo.into(), flat.hi.into()));
        assert_eq!((q[1], q[4]), (0, 0), "the flat axis: one plane");
        assert!(at(&g, 1, 1) > 2.0, "distinct planes");
        assert_eq!((q[0], q[3], q[2], q[5]), (0, u16::MAX, 0, u16::MAX));
        let empty = Grid::over(&Aabb::EMPTY);
        assert_eq!((empty.origin, empty.step), (Vec3::ZERO, Vec3::ONE));
    }

    #[test]
    fn a_ray_s_plane_distances_are_the_planes_of_the_grid() {
        let g = Grid {
            origin: Vec3::new(1.0, -2.0, 0.5),
            step: Vec3::new(0.25, 0.5, 2.0),
        };
        let (ro, inv) = (Vec3::new(0.0, 1.0, -1.0), Vec3::new(2.0, -4.0, 0.5));
        let t = g.ray(ro, inv).t([4, 2, 3]);
        // planes x = 2, y = −1, z = 6.5: (plane − ro)·inv, exact in floats here
        let want = [4.0f32, 8.0, 3.75].map(|t| t.to_bits() as i32);
        assert_eq!(t, want);
        // factors beyond the floats are clamped: far planes, never NaN
        let huge = Grid {
            origin: Vec3::splat(1e30),
            step: Vec3::splat(1e30),
        };
        let r = huge.ray(Vec3::splat(-1e30), Vec3::new(1e20, -1e20, 1.0));
        assert!(r.a.is_finite() && r.b.is_finite());
        for q in [0, 1, u16::MAX] {
            assert!(r
                .t([q; 3])
                .iter()
                .all(|&t| !f32::from_bits(t as u32).is_nan()));
        }
    }
}
