//! CPU reference of the uniform grid (Müller 2015, ch. 3.2): Algorithms 2 and 3 with the
//! special cases of Fig. 13, the thesis' edge-walk registration of triangles, and the exact
//! variant's triangle/box overlap registration and 3D-DDA — the same arithmetic as the GLSL in
//! `glsl/common/grid.glsl`, `glsl/thesis_grid/` and `glsl/exact_grid/`, in f32. Shared by
//! the CPU twins of both grids (`thesis_grid.rs`, `exact_grid.rs`).

use glam::{IVec3, Vec3};

use super::proximity::cloud_jump;
use crate::accel::tribox::tri_box_overlap;

/// clipToGrid: the parameter interval [enter, exit] of ro + t·rd (grid space) inside the grid
/// box [-1, 1]³ (empty when enter > exit).
pub fn clip_to_grid(ro: Vec3, rd: Vec3) -> (f32, f32) {
    let inv = Vec3::ONE / rd;
    let t0 = (Vec3::NEG_ONE - ro) * inv;
    let t1 = (Vec3::ONE - ro) * inv;
    let (tn, tf) = (t0.min(t1), t0.max(t1));
    (tn.max_element(), tf.min_element())
}

/// The 3D-DDA of `glsl/exact_grid/dda.glsl` (Amanatides & Woo 1987).
#[derive(Debug, Clone, Copy)]
pub struct Walk {
    pub voxel: IVec3,
    step: IVec3,
    t_max: Vec3,
    t_delta: Vec3,
    t_end: f32,
    /// the ray in grid space (origin, direction, 1/direction), for a proximity-cloud jump
    rog: Vec3,
    rdg: Vec3,
    inv: Vec3,
}

impl Walk {
    /// beginWalk: a walk of rog + t·rdg (grid space) for t in [0, t_end]; `None` if the ray
    /// misses the grid.
    pub fn begin(space: &GridSpace, rog: Vec3, rdg: Vec3, t_end: f32) -> Option<Walk> {
        let (enter, exit) = clip_to_grid(rog, rdg);
        let t0 = enter.max(0.0);
        let t_end = exit.min(t_end);
        if t0 > t_end {
            return None;
        }
        let voxel = space.clamp(space.get_voxel(rog + t0 * rdg));
        let step = IVec3::new(sgn(rdg.x), sgn(rdg.y), sgn(rdg.z));
        let up = Vec3::select(rdg.cmpgt(Vec3::ZERO), Vec3::ONE, Vec3::ZERO);
        let next_face = (voxel.as_vec3() + up) * space.vx_edge() - 1.0;
        let inv = Vec3::ONE / rdg;
        let t_max = Vec3::select(
            rdg.cmpeq(Vec3::ZERO),
            Vec3::INFINITY,
            (next_face - rog) * inv,
        );
        let t_delta = (space.vx_edge() * inv).abs();
        Some(Walk {
            voxel,
            step,
            t_max,
            t_delta,
            t_end,
            rog,
            rdg,
            inv,
        })
    }

    /// voxelExit: the parameter at which the ray leaves the current voxel.
    pub fn exit(&self) -> f32 {
        self.t_max.min_element()
    }

    /// The parameter at which the walk ends (grid exit or ray end).
    pub fn t_end(&self) -> f32 {
        self.t_end
    }

    /// stepWalk: into the next voxel; false when the walk has ended.
    pub fn step(&mut self, space: &GridSpace) -> bool {
        let exit = self.exit();
        if exit > self.t_end {
            return false;
        }
        let d = if self.t_max.x == exit {
            0
        } else if self.t_max.y == exit {
            1
        } else {
            2
        };
        self.voxel[d] += self.step[d];
        self.t_max[d] += self.t_delta[d];
        space.voxel_id(self.voxel).is_some()
    }
}

impl Walk {
    /// planeT: the parameter of the face that voxel column `k` of axis `a` is left through
    /// (the one beyond it in the direction of travel), as beginWalk computes tMax; +∞ for an
    /// axis the ray does not move along.
    fn plane_t(&self, space: &GridSpace, a: usize, k: i32) -> f32 {
        if self.step[a] == 0 {
            return f32::INFINITY;
        }
        let up = (self.step[a] > 0) as i32;
        let face = (k + up) as f32 * space.vx_edge() - 1.0;
        (face - self.rog[a]) * self.inv[a]
    }

    /// jumpWalk (`glsl/exact_grid/dda.glsl`), the streaming tracer's proximity-cloud jump in the
    /// exact grid: the current voxel is empty and its distance `dist` ≥ 2, so the cube of voxels
    /// within Chebyshev radius dist − 1 around it is empty; leave it where the ray does. The
    /// exit axis' voxel is the first beyond the cube's face, the others the exit point's
    /// (within the cube) as the plane parameters place it; tMax is recomputed for the landing
    /// voxel. False when the cube is left beyond the walk's end or the grid. The landing is
    /// `proximity::cloud_jump`, shared with `StreamGrid::jump` (here in grid space: voxel
    /// faces at k·vx_edge − 1).
    pub fn jump(&mut self, space: &GridSpace, dist: u32) -> bool {
        let dims = IVec3::splat(space.n as i32);
        let landed = cloud_jump(
            self.voxel,
            dist,
            dims,
            self.step,
            self.t_end,
            |a, k| self.plane_t(space, a, k),
            |t| space.get_voxel(self.rog + t * self.rdg),
        );
        let Some(v) = landed else { return false };
        self.voxel = v;
        self.t_max = Vec3::new(
            self.plane_t(space, 0, v.x),
            self.plane_t(space, 1, v.y),
            self.plane_t(space, 2, v.z),
        );
        true
    }
}

/// GLSL's sign() as an int.
fn sgn(x: f32) -> i32 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// A uniform grid of `n`³ voxels over [-1, 1)³ (the thesis' scene space).
#[derive(Debug, Clone, Copy)]
pub struct GridSpace {
    pub n: u32,
}

impl GridSpace {
    /// length of a voxel edge (Listing 19)
    pub fn vx_edge(&self) -> f32 {
        2.0 / self.n as f32
    }

    /// Listing 18 / Eq. 6 (with floor, as the kernels).
    pub fn get_voxel(&self, p: Vec3) -> IVec3 {
        ((p + Vec3::ONE) / self.vx_edge()).floor().as_ivec3()
    }

    pub fn clamp(&self, v: IVec3) -> IVec3 {
        v.clamp(IVec3::ZERO, IVec3::splat(self.n as i32 - 1))
    }

    pub fn voxel_id(&self, v: IVec3) -> Option<usize> {
        let n = self.n as i32;
        if v.cmpge(IVec3::ZERO).all() && v.cmplt(IVec3::splat(n)).all() {
            Some((v.z * n * n + v.y * n + v.x) as usize)
        } else {
            None
        }
    }

    /// Algorithms 2 and 3: the voxels the segment p0 -> p1 passes, in order, from vox_min to
    /// vox_max (start voxel first). Equal crossing parameters (the segment passes a voxel edge
    /// or corner, Fig. 13): the moves along axes with positive direction are made together
    /// first, then those with negative direction. Algorithm 2's `a` is the voxel edge
    /// (`vx_edge`); its printed `t = (i·a − 1 − rd_x)/rd_x` and `i = i + direction·a` are
    /// corrected as in `glsl/thesis_grid/voxelwalk.glsl` (origin p0, step 1).
    pub fn traverse_connection(
        &self,
        p0: Vec3,
        p1: Vec3,
        vox_min: IVec3,
        vox_max: IVec3,
    ) -> Vec<IVec3> {
        let rd = p1 - p0;
        let t_max = 1.0f32;
        let mut list: Vec<(f32, usize)> = Vec::new();
        for d in 0..3 {
            // a NaN component is skipped as 0 is (as the kernel: voxelwalk.glsl)
            if rd[d] == 0.0 || rd[d].is_nan() {
                continue;
            }
            let direction = if rd[d] > 0.0 { 1 } else { -1 };
            let (mut i, mut j) = (vox_min[d], vox_max[d]);
            if rd[d] > 0.0 {
                i += 1;
                j += 1;
            }
            while i != j {
                let t = (i as f32 * self.vx_edge() - 1.0 - p0[d]) / rd[d];
                if i >= 0 {
                    list.push((t.min(t_max), d));
                }
                i += direction;
            }
        }
        // BubbleSort (stable: equal parameters keep their axis order, as in the kernel)
        let n = list.len();
        for end in (1..n).rev() {
            let mut swapped = false;
            for k in 0..end {
                if list[k].0 > list[k + 1].0 {
                    list.swap(k, k + 1);
                    swapped = true;
                }
            }
            if !swapped {
                break;
            }
        }
        let mut current = vox_min;
        let mut out = vec![current];
        let mut k = 0;
        while k < list.len() {
            let mut g = k;
            while g + 1 < list.len() && list[g + 1].0 == list[k].0 {
                g += 1;
            }
            let (mut pos, mut neg) = (IVec3::ZERO, IVec3::ZERO);
            for &(_, d) in &list[k..=g] {
                if rd[d] > 0.0 {
                    pos[d] = 1;
                } else {
                    neg[d] = -1;
                }
            }
            if pos != IVec3::ZERO {
                current += pos;
                out.push(current);
            }
            if neg != IVec3::ZERO {
                current += neg;
                out.push(current);
            }
            k = g + 1;
        }
        out
    }

    /// The thesis' build: the voxels of a triangle's vertices and of its edge walks (each
    /// vertex voxel once; walks skip vertex voxels), as `glsl/build.comp` stores them.
    pub fn thesis_voxels(&self, tri: [Vec3; 3]) -> Vec<usize> {
        let vox = tri.map(|p| self.clamp(self.get_voxel(p)));
        let ids = vox.map(|v| self.voxel_id(v).expect("clamped"));
        let mut out = Vec::new();
        for (k, id) in ids.iter().enumerate() {
            if !ids[..k].contains(id) {
                out.push(*id);
            }
        }
        for k in 0..3 {
            let l = (k + 1) % 3;
            if vox[k] != vox[l] {
                for v in self.traverse_connection(tri[k], tri[l], vox[k], vox[l]) {
                    if let Some(id) = self.voxel_id(v) {
                        if !ids.contains(&id) {
                            out.push(id);
                        }
                    }
                }
            }
        }
        out
    }

    /// The exact grid: every voxel whose box (enlarged by the kernels' margin) the triangle
    /// overlaps.
    pub fn exact_voxels(&self, tri: [Vec3; 3]) -> Vec<usize> {
        let e = self.vx_edge();
        let margin = Vec3::splat(e * 1e-4);
        let lo = self.clamp(self.get_voxel(tri[0].min(tri[1]).min(tri[2]) - margin));
        let hi = self.clamp(self.get_voxel(tri[0].max(tri[1]).max(tri[2]) + margin));
        let half = Vec3::splat(0.5 * e) + margin;
        let mut out = Vec::new();
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let c = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * e - 1.0;
                    if tri_box_overlap(c, half, tri) {
                        out.push(self.voxel_id(IVec3::new(x, y, z)).expect("clamped"));
                    }
                }
            }
        }
        out
    }
}
