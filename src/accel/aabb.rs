//! The axis-aligned box of the BVH builders (`accel::bvh`'s and `pipeline::wagner2018::bvh`'s).

use glam::Vec3;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub lo: Vec3,
    pub hi: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        lo: Vec3::splat(f32::INFINITY),
        hi: Vec3::splat(f32::NEG_INFINITY),
    };

    pub fn of_triangle(t: &[Vec3; 3]) -> Aabb {
        Aabb {
            lo: t[0].min(t[1]).min(t[2]),
            hi: t[0].max(t[1]).max(t[2]),
        }
    }

    pub fn grow(&mut self, o: &Aabb) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
    }

    pub fn grow_point(&mut self, p: Vec3) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    /// xdim·ydim + ydim·zdim + zdim·xdim: half the surface area, eq. 4.1 of Wagner 2018
    /// without the triangle count (0 for an empty box).
    pub fn half_area(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    /// [`Aabb::half_area`] in f64 (Wagner's build compares costs in double precision).
    pub fn half_area_f64(&self) -> f64 {
        let d = (self.hi - self.lo).max(Vec3::ZERO).as_dvec3();
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    pub fn contains(&self, o: &Aabb) -> bool {
        self.lo.cmple(o.lo).all() && o.hi.cmple(self.hi).all()
    }
}
