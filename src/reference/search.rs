//! What every CPU twin shares: a hit, a shadow feeler, the closest hit among triangles and
//! the triangle test (Algorithm 1), and the twin's interface. Below the twins and the
//! reference's pixel loop, which both read it.

use glam::Vec3;

use crate::accel::Accel;
use crate::scene::Scene;

/// A closest hit: ray parameter, triangle id and barycentric (u, v).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub id: usize,
    pub u: f32,
    pub v: f32,
}

/// The CPU twin of an accelerator (`crate::accel`): the same searches as its intersect1 and
/// intersect2 kernels, in f32 with the same arithmetic, so the tests can hold every GPU
/// accelerator against its twin. Each returns the number of ray–triangle tests it made.
pub trait CpuAccelerator: Send + Sync {
    /// The closest hit of ro + t·rd (t > 0) other than triangle `last`; equal distances go to
    /// the lower triangle id.
    fn closest_hit(&self, ro: Vec3, rd: Vec3, last: i32) -> (Option<Hit>, u64);
    /// Whether the shadow feeler is blocked (Listing 15).
    fn occluded(&self, feeler: &Feeler) -> (bool, u64);
}

/// Makes the CPU twin of an accelerator (`accel::Accel`, its own variant) over the scene as
/// loaded: the oracle its GPU side is held against. Each accelerator's row of
/// `design::REGISTRY` names its twin.
pub type MakeTwin = fn(&Scene, &Accel) -> anyhow::Result<Box<dyn CpuAccelerator>>;

/// A shadow feeler: blocked by a triangle other than `last` hit at `offset` < t <
/// `light_distance` along ro + t·rd.
#[derive(Debug, Clone, Copy)]
pub struct Feeler {
    pub ro: Vec3,
    pub rd: Vec3,
    pub light_distance: f32,
    pub offset: f32,
    pub last: i32,
}

impl Feeler {
    /// The feeler of Listing 15 from the hit point `p` (normal `n`, triangle `last`) towards a
    /// point light, as `common/intersect2_main.glsl` sets it up; `None` where the light is in
    /// the back half-space of the hit point (shadow without a test).
    pub fn towards(p: Vec3, n: Vec3, last: i32, light: Vec3, offset: f32) -> Option<Feeler> {
        let to_light = light - p;
        let dist = to_light.length();
        let rd = to_light / dist;
        (n.dot(rd) > 0.0).then_some(Feeler {
            ro: p,
            rd,
            light_distance: dist,
            offset,
            last,
        })
    }

    /// Whether one of the triangles `ids` (in order, `last` skipped) blocks the feeler,
    /// stopping at the first that does; every test made is added to `tests`.
    pub fn blocked_among(
        &self,
        triangles: &[[Vec3; 3]],
        ids: impl IntoIterator<Item = usize>,
        tests: &mut u64,
    ) -> bool {
        ids.into_iter().filter(|&i| i as i32 != self.last).any(|i| {
            *tests += 1;
            let v = &triangles[i];
            intersect_triangle(self.ro, self.rd, v[0], v[1], v[2])
                .is_some_and(|(t, _, _)| t > self.offset && t < self.light_distance)
        })
    }
}

/// The closest hit among the triangles `ids` (`last` skipped) of ro + t·rd, kept in `best`
/// (equal distances: the lower id, as intersect1's loops); every test made is added to
/// `tests`.
pub fn closest_among(
    best: &mut Option<Hit>,
    triangles: &[[Vec3; 3]],
    ids: impl IntoIterator<Item = usize>,
    (ro, rd, last): (Vec3, Vec3, i32),
    tests: &mut u64,
) {
    for id in ids.into_iter().filter(|&i| i as i32 != last) {
        *tests += 1;
        let v = &triangles[id];
        if let Some((t, u, v)) = intersect_triangle(ro, rd, v[0], v[1], v[2]) {
            if best.is_none_or(|b| t < b.t || (t == b.t && id < b.id)) {
                *best = Some(Hit { t, id, u, v });
            }
        }
    }
}

/// Algorithm 1 (Möller–Trumbore without a determinant epsilon), as `glsl/common/intersect.glsl`.
#[inline]
pub fn intersect_triangle(
    r0: Vec3,
    rd: Vec3,
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
) -> Option<(f32, f32, f32)> {
    let edge1 = v1 - v0;
    let edge2 = v2 - v0;
    let pvec = rd.cross(edge2);
    let det = edge1.dot(pvec);
    let inv_det = 1.0 / det;
    let tvec = r0 - v0;
    let u = inv_det * tvec.dot(pvec);
    let qvec = tvec.cross(edge1);
    let v = inv_det * rd.dot(qvec);
    let t = inv_det * edge2.dot(qvec);
    if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 {
        Some((t, u, v))
    } else {
        None
    }
}
