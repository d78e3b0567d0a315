//! The CPU twin of Wagner 2018's ray-tracing kernel (`glsl/wagner2018/raytrace.comp`): the same
//! functions with the same f32 arithmetic — `createRay` (Listing 4.1), `intersectTriangle`
//! (Listing 4.2, Möller–Trumbore with its ε), `intersectAABB` (Listing 4.5) — the same walk
//! through the hierarchy of [`WagnerBvh`] in the same order with the same counts, and
//! the same Lambert shading with one hard shadow ray. The tests hold the GPU against it.
//!
//! The walk (ch. 4.2.3: "test the root, then both children; the nearer hit is investigated
//! further until a leaf is found, whose triangles are all tested"): the root's box first (a
//! miss is a miss of the scene); at an inner node both children's boxes, the nearer hit (the
//! smaller `t` of Listing 4.5, the left child on a tie) next, the other onto a stack with its
//! entry distance; at a leaf all its triangles. Ours, because the thesis stops there: after a
//! leaf the walk goes on with the stack (a hit in a nearer box may lie behind a hit in a
//! farther, overlapping one, and a leaf may have no hit at all), and a box entered beyond the
//! closest hit so far (for a shadow ray: beyond the light) is skipped. Equal distances go to
//! the lower triangle id, so the closest hit is the brute-force one whatever the order.
//!
//! Every loop is bounded: one iteration visits a node, tests one triangle or pops one stack
//! entry, and a walk ends after [`LOOP_BUDGET`] iterations as truncated (llvmpipe ends an
//! invocation's loops after 65535 iterations in total; two walks of 32000 stay below it).

use glam::Vec3;

use super::search::Hit;
use crate::pipeline::wagner2018::bvh::{NodeKind, WagnerBvh};
use crate::pipeline::wagner2018::uniforms::{
    Lighting, Surface, WagnerCamera, EPSILON, LOOP_BUDGET, STACK,
};

/// A ray (Listing 4.1's `Ray(direction, origin)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
}

impl WagnerCamera {
    /// Listing 4.1 for pixel (x, y), y = 0 the top row. Ours: through the pixel's centre
    /// (+0.5), and the direction normalised (so `t` is a distance).
    pub fn create_ray(&self, x: u32, y: u32, width: u32, height: u32) -> Ray {
        let alpha = (x as f32 + 0.5) / width as f32;
        let beta = (y as f32 + 0.5) / height as f32;
        let x_direction = self.x_direction * alpha * self.x_scale;
        let y_direction = self.y_direction * beta * self.y_scale;
        let direction = self.direction + x_direction + y_direction;
        Ray {
            origin: self.position,
            direction: direction.normalize(),
        }
    }
}

/// Listing 4.2 (Möller–Trumbore): (t, u, v) of a hit. Ours: t = f(e2 · r) (the listing's
/// f(e2 · q) is a misprint: always 0), and only t > 0 is a hit (the listing returns t of either
/// sign and leaves the check to its caller).
#[inline]
pub fn intersect_triangle(ray: &Ray, tri: &[Vec3; 3]) -> Option<(f32, f32, f32)> {
    let (o, d) = (ray.origin, ray.direction);
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let q = d.cross(e2);
    let a = e1.dot(q);
    if a > -EPSILON && a < EPSILON {
        return None;
    }
    let f = 1.0 / a;
    let s = o - tri[0];
    let u = f * s.dot(q);
    if u < 0.0 {
        return None;
    }
    let r = s.cross(e1);
    let v = f * d.dot(r);
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    // the listing prints t = f(e2 · q), which is 0 (q = d × e2 is normal to e2): a misprint
    // of Möller and Trumbore's t = f(e2 · r)
    let t = f * e2.dot(r);
    (t > 0.0).then_some((t, u, v))
}

/// Listing 4.5 for the box of centre `ac` and half extents `h`: `t` as the listing returns it
/// (the entry distance, or the exit distance when the origin is inside), and ours, the entry
/// distance clamped to 0 (`tNear`, for skipping boxes beyond the closest hit).
#[inline]
pub fn intersect_aabb(ray: &Ray, ac: Vec3, h: Vec3) -> Option<(f32, f32)> {
    let mut tmin = f32::NEG_INFINITY;
    let mut tmax = f32::INFINITY;
    let p = ac - ray.origin;
    for i in 0..3 {
        let e = p[i];
        let f = ray.direction[i];
        if f.abs() > EPSILON {
            let mut t1 = (e + h[i]) / f;
            let mut t2 = (e - h[i]) / f;
            if t1 > t2 {
                std::mem::swap(&mut t1, &mut t2);
            }
            if t1 > tmin {
                tmin = t1;
            }
            if t2 < tmax {
                tmax = t2;
            }
            if tmin > tmax || tmax < 0.0 {
                return None;
            }
        } else if -e - h[i] > 0.0 || -e + h[i] < 0.0 {
            return None;
        }
    }
    if tmin > 0.0 {
        Some((tmin, tmin))
    } else {
        Some((tmax, 0.0))
    }
}

/// What a walk found and did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Trace {
    pub hit: Option<Hit>,
    pub tests: u64,
    pub nodes: u64,
    /// The walk ran out of [`LOOP_BUDGET`] or found the stack full.
    pub truncated: bool,
}

/// What a walk looks for: the closest hit, or any hit with `offset` < t < `limit` other than
/// triangle `skip` (a shadow ray).
#[derive(Debug, Clone, Copy)]
enum Query {
    Closest,
    Any { offset: f32, limit: f32, skip: u32 },
}

/// The walk's state between iterations (the kernel's locals).
struct Walk {
    limit: f32,
    node: Option<u32>,
    tri: u32,
    tri_end: u32,
    stack: Vec<(u32, f32)>,
}

impl WagnerBvh {
    /// The closest hit of `ray` (t > 0; equal t: the lower triangle id).
    pub fn closest_hit(&self, ray: &Ray) -> Trace {
        self.walk(ray, Query::Closest)
    }

    /// Whether a triangle other than `skip` lies on `ray` at `offset` < t < `distance` (the
    /// shadow ray: `trace.hit` is the first such triangle found).
    pub fn occluded(&self, ray: &Ray, offset: f32, distance: f32, skip: u32) -> Trace {
        let q = Query::Any {
            offset,
            limit: distance,
            skip,
        };
        self.walk(ray, q)
    }

    /// Whether the ray enters node `n`'s box at a distance ≤ `limit`: (`t` of Listing 4.5,
    /// entry distance).
    fn enter(&self, n: u32, ray: &Ray, limit: f32) -> Option<(f32, f32)> {
        let node = &self.nodes[n as usize];
        intersect_aabb(ray, node.centre, node.half).filter(|&(_, near)| near <= limit)
    }

    /// The walk of the module comment, as `traverse` in the kernel.
    fn walk(&self, ray: &Ray, q: Query) -> Trace {
        let mut tr = Trace::default();
        let limit = match q {
            Query::Closest => f32::INFINITY,
            Query::Any { limit, .. } => limit,
        };
        // the root first: a miss of its box is a miss of the scene
        if self.nodes.is_empty() || self.enter(0, ray, limit).is_none() {
            return tr;
        }
        let mut w = Walk {
            limit,
            node: Some(0),
            tri: 0,
            tri_end: 0,
            stack: Vec::with_capacity(STACK),
        };
        for _ in 0..LOOP_BUDGET {
            if w.tri < w.tri_end {
                let id = self.tri_ids[w.tri as usize];
                w.tri += 1;
                if self.test(ray, q, id, &mut w, &mut tr) {
                    return tr;
                }
            } else if let Some(n) = w.node.take() {
                tr.nodes += 1;
                self.visit(ray, n, &mut w, &mut tr);
            } else {
                let Some((n, near)) = w.stack.pop() else {
                    return tr;
                };
                if near <= w.limit {
                    w.node = Some(n);
                }
            }
        }
        tr.truncated = true;
        tr
    }

    /// A leaf: its triangles are next. An inner node: both children's boxes (Listing 4.5),
    /// the nearer next, the other onto the stack.
    fn visit(&self, ray: &Ray, n: u32, w: &mut Walk, tr: &mut Trace) {
        match self.nodes[n as usize].kind {
            NodeKind::Leaf { first, count } => (w.tri, w.tri_end) = (first, first + count),
            NodeKind::Inner { left, right } => {
                let l = self.enter(left, ray, w.limit);
                let r = self.enter(right, ray, w.limit);
                w.node = match (l, r) {
                    (Some((tl, nl)), Some((tr_, nr))) => {
                        let (near, far) = if tl <= tr_ {
                            (left, (right, nr))
                        } else {
                            (right, (left, nl))
                        };
                        if w.stack.len() < STACK {
                            w.stack.push(far);
                        } else {
                            tr.truncated = true;
                        }
                        Some(near)
                    }
                    (Some(_), None) => Some(left),
                    (None, Some(_)) => Some(right),
                    (None, None) => None,
                };
            }
        }
    }

    /// Test triangle `id` (Listing 4.2); true when the walk is done (a shadow ray's hit).
    fn test(&self, ray: &Ray, q: Query, id: u32, w: &mut Walk, tr: &mut Trace) -> bool {
        if let Query::Any { skip, .. } = q {
            if id == skip {
                return false;
            }
        }
        tr.tests += 1;
        let Some((t, u, v)) = intersect_triangle(ray, &self.triangles[id as usize]) else {
            return false;
        };
        let hit = Hit {
            t,
            id: id as usize,
            u,
            v,
        };
        match q {
            Query::Any { offset, limit, .. } => {
                let blocks = t > offset && t < limit;
                if blocks {
                    tr.hit = Some(hit);
                }
                blocks
            }
            Query::Closest => {
                if tr
                    .hit
                    .is_none_or(|b| t < b.t || (t == b.t && hit.id < b.id))
                {
                    tr.hit = Some(hit);
                    w.limit = t;
                }
                false
            }
        }
    }
}

/// The closest hit by Listing 4.2 over every triangle (equal t: the lower id): what the walk
/// must find.
pub fn brute_force_closest(triangles: &[[Vec3; 3]], ray: &Ray) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for (id, tri) in triangles.iter().enumerate() {
        if let Some((t, u, v)) = intersect_triangle(ray, tri) {
            if best.is_none_or(|b| t < b.t) {
                best = Some(Hit { t, id, u, v });
            }
        }
    }
    best
}

/// A shaded hit: colour, the normal (turned towards the ray), whether the light reaches it,
/// and the shadow ray's walk (default when none was cast: light behind the surface).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shaded {
    pub color: Vec3,
    pub normal: Vec3,
    pub lit: bool,
    pub shadow: Trace,
}

/// Lambert shading of `hit` with one hard shadow ray, as the kernel's `shade`: ambient · c,
/// plus lightColor · c · N·L where the shadow ray reaches the light.
pub fn shade(bvh: &WagnerBvh, s: &Surface, l: &Lighting, ray: &Ray, hit: &Hit) -> Shaded {
    let p = ray.origin + hit.t * ray.direction;
    let (u, v, k) = (hit.u, hit.v, 3 * hit.id);
    let w = 1.0 - u - v;
    let mut n = (w * s.normals[k] + u * s.normals[k + 1] + v * s.normals[k + 2]).normalize();
    if n.dot(ray.direction) > 0.0 {
        n = -n;
    }
    let c = w * s.colors[k] + u * s.colors[k + 1] + v * s.colors[k + 2];
    let to_light = l.light_position - p;
    let distance = to_light.length();
    let dir = to_light / distance;
    let lambert = n.dot(dir);
    let mut shadow = Trace::default();
    if lambert > 0.0 {
        let shadow_ray = Ray {
            origin: p,
            direction: dir,
        };
        shadow = bvh.occluded(&shadow_ray, l.shadow_offset, distance, hit.id as u32);
    }
    let lit = lambert > 0.0 && shadow.hit.is_none();
    let mut color = l.ambient * c;
    if lit {
        color += l.light_color * c * lambert;
    }
    Shaded {
        color,
        normal: n,
        lit,
        shadow,
    }
}
