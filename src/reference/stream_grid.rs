//! The CPU twin of the streaming ray tracer's static grid (the streaming tracer, ch. 3; the grid
//! and its build: `pipeline::stream::grid`): walked with the 3D-DDA of Amanatides and Woo exactly
//! as `glsl/stream/grid.glsl` walks it (the same f32 arithmetic, the same order of cells and of
//! triangle tests), so the tests can hold the GPU's hits and counts against it.

use glam::{IVec3, Vec3};

use super::proximity::{cells_between, cloud_jump};
use super::search::{closest_among, intersect_triangle, CpuAccelerator, Feeler, Hit};
use crate::pipeline::stream::grid::StreamGrid;

/// What a walk counted: triangle tests, cells entered, proximity-cloud jumps, and the empty
/// cells the jumps skipped (those the 3D-DDA would have entered between the cell a jump leaves
/// and the one it lands in).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WalkCounts {
    pub tests: u64,
    pub cells: u64,
    pub jumps: u64,
    pub skipped: u64,
}

/// What a walk looks for: the closest hit (eye and reflection rays; ties: the lower id), any
/// hit within (offset, limit) — the paper's shadow-ray optimisation, "determining any (instead
/// of closest) intersection closer than the given light source is sufficient" — or, the naive
/// shadow ray it improves on, the closest hit beyond offset wherever it lies, a blocker when
/// that is before the light (`--stream-naive-shadows`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rule {
    Closest,
    AnyHit(f32),
    NaiveShadow(f32),
}

/// One ray's walk state: Fig. 2's cell and tMax (the triangles processed are the loop's).
struct Walk {
    cell: IVec3,
    t_max: Vec3,
}

/// A ray as the traversal kernel reads it: origin, direction, the triangle to skip (the one
/// it starts on), and its t limit (the light for a shadow ray, +∞ else).
#[derive(Debug, Clone, Copy)]
pub struct StreamRay {
    pub o: Vec3,
    pub d: Vec3,
    pub skip: i32,
    pub limit: f32,
}

impl StreamGrid {
    /// The masking kernel's start of a walk (`glsl/stream/mask.frag`): `None` for a ray that
    /// misses the box (or whose box segment begins beyond its limit).
    fn begin(&self, r: &StreamRay) -> Option<Walk> {
        let (enter, exit) = self.bx.clip(r.o, r.d);
        let t0 = enter.max(0.0);
        if t0 > exit.min(r.limit) {
            return None;
        }
        let cell = self.bx.cell_of(r.o + t0 * r.d);
        Some(Walk {
            cell,
            t_max: self.bx.t_max(r.o, r.d, cell),
        })
    }

    /// stepCell: into the next cell along the axis of the smallest tMax (ties: x, y, z);
    /// false when the walk left the grid.
    fn step(&self, r: &StreamRay, w: &mut Walk) -> bool {
        let exit = w.t_max.min_element();
        let a = if w.t_max.x == exit {
            0
        } else if w.t_max.y == exit {
            1
        } else {
            2
        };
        w.cell[a] += if r.d[a] > 0.0 { 1 } else { -1 };
        if self.bx.index(w.cell).is_none() {
            return false;
        }
        w.t_max[a] = self.bx.plane_t(r.o, r.d, a, w.cell[a]);
        true
    }

    /// jumpCloud: leave the cube of cells within Chebyshev distance `dist − 1` of the current
    /// cell (all empty) where the ray leaves it; false when that is beyond the grid or the
    /// ray's limit. The exit axis' cell is the first beyond the cube's face; the others are
    /// the exit point's (within the cube's range), placed by the DDA's plane parameters
    /// (`proximity::cloud_jump`, shared with the exact grid's `grid::Walk::jump`).
    fn jump(&self, r: &StreamRay, w: &mut Walk, dist: u32) -> bool {
        let sign = |x: f32| (x > 0.0) as i32 - (x < 0.0) as i32;
        let step = IVec3::new(sign(r.d.x), sign(r.d.y), sign(r.d.z));
        let landed = cloud_jump(
            w.cell,
            dist,
            self.bx.dims.as_ivec3(),
            step,
            r.limit,
            |a, k| self.bx.plane_t(r.o, r.d, a, k),
            |t| {
                ((r.o + t * r.d - self.bx.min) / self.bx.cell)
                    .floor()
                    .as_ivec3()
            },
        );
        let Some(cell) = landed else { return false };
        *w = Walk {
            cell,
            t_max: self.bx.t_max(r.o, r.d, cell),
        };
        true
    }

    /// Walk ray `r` as the traverse-and-intersect kernel does, finding what `rule` asks for.
    /// Returns the hit and the counts.
    pub fn trace(&self, r: &StreamRay, rule: Rule, proximity: bool) -> (Option<Hit>, WalkCounts) {
        let mut n = WalkCounts::default();
        let mut best: Option<Hit> = None;
        // the masking kernel clips to the light; a naive shadow ray then walks on past it
        let Some(mut w) = self.begin(r) else {
            return (None, n);
        };
        let walk = match rule {
            Rule::NaiveShadow(_) => StreamRay {
                limit: f32::INFINITY,
                ..*r
            },
            _ => *r,
        };
        loop {
            n.cells += 1;
            let cell = self.bx.index(w.cell).expect("inside");
            let (first, count) = self.cells[cell];
            let list = &self.refs[first as usize..(first + count) as usize];
            let ids = list.iter().map(|&i| i as usize);
            match rule {
                Rule::AnyHit(offset) => {
                    if let Some(h) = self.first_blocker(r, list, offset, &mut n.tests) {
                        return (Some(h), n);
                    }
                }
                Rule::Closest => {
                    let ray = (r.o, r.d, r.skip);
                    closest_among(&mut best, &self.triangles, ids, ray, &mut n.tests);
                }
                Rule::NaiveShadow(offset) => {
                    self.closest_beyond(&mut best, r, ids, offset, &mut n.tests);
                }
            }
            let exit = w.t_max.min_element();
            if best.is_some_and(|b| b.t <= exit) || exit > walk.limit {
                break;
            }
            let dist = self.proximity[cell];
            let moved = if proximity && count == 0 && dist >= 2 {
                n.jumps += 1;
                let from = w.cell;
                let landed = self.jump(&walk, &mut w, dist);
                if landed {
                    n.skipped += cells_between(from, w.cell);
                }
                landed
            } else {
                self.step(&walk, &mut w)
            };
            if !moved {
                break;
            }
        }
        if let Rule::NaiveShadow(_) = rule {
            // the naive shadow ray's verdict: its closest hit lies before the light
            best = best.filter(|h| h.t < r.limit);
        }
        (best, n)
    }

    /// The closest-hit rule over `ids` among the hits beyond `offset` (the ray's own triangle
    /// skipped): the naive shadow ray's search.
    fn closest_beyond(
        &self,
        best: &mut Option<Hit>,
        r: &StreamRay,
        ids: impl Iterator<Item = usize>,
        offset: f32,
        tests: &mut u64,
    ) {
        for id in ids.filter(|&i| i as i32 != r.skip) {
            *tests += 1;
            let v = &self.triangles[id];
            let Some((t, u, vv)) = intersect_triangle(r.o, r.d, v[0], v[1], v[2]) else {
                continue;
            };
            if t > offset && best.is_none_or(|b| t < b.t || (t == b.t && id < b.id)) {
                *best = Some(Hit { t, id, u, v: vv });
            }
        }
    }

    /// The first triangle of `list` (in order, the ray's own skipped) hit within
    /// (offset, limit): the shadow ray's any hit.
    fn first_blocker(
        &self,
        r: &StreamRay,
        list: &[u32],
        offset: f32,
        tests: &mut u64,
    ) -> Option<Hit> {
        for &id in list.iter().filter(|&&i| i as i32 != r.skip) {
            *tests += 1;
            let v = &self.triangles[id as usize];
            if let Some((t, u, vv)) = intersect_triangle(r.o, r.d, v[0], v[1], v[2]) {
                if t > offset && t < r.limit {
                    let id = id as usize;
                    return Some(Hit { t, id, u, v: vv });
                }
            }
        }
        None
    }
}

/// The grid as a [`CpuAccelerator`] (closest hits and shadow feelers, without proximity
/// clouds — they change the counts, not the hits).
impl CpuAccelerator for StreamGrid {
    fn closest_hit(&self, ro: Vec3, rd: Vec3, last: i32) -> (Option<Hit>, u64) {
        let r = StreamRay {
            o: ro,
            d: rd,
            skip: last,
            limit: f32::INFINITY,
        };
        let (h, n) = self.trace(&r, Rule::Closest, false);
        (h, n.tests)
    }

    fn occluded(&self, f: &Feeler) -> (bool, u64) {
        let r = StreamRay {
            o: f.ro,
            d: f.rd,
            skip: f.last,
            limit: f.light_distance,
        };
        let (h, n) = self.trace(&r, Rule::AnyHit(f.offset), false);
        (h.is_some(), n.tests)
    }
}
