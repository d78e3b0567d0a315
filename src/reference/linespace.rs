//! The CPU implementation of Klee 2016's soft shadows (ch. 4.3, Algorithms 1–4, Listings
//! 1–3): the same N-tree, line spaces and traversals as `glsl/klee2016/linespace_shadow.comp`, in plain
//! Rust, step by step like the kernel — the oracle of the tests and the CPU side of the
//! thesis' CPU/GPU comparison (Fig. 12, Table 3).
//!
//! * [`ShadowMode::Linespace`]: all shadow rays of a pixel as one packet, coherent grid
//!   traversal (CGT) slice by slice with the explicit stack of Listing 1 and the shaft of
//!   Listing 2; at the last stack depth with line spaces, a set line-space bit deactivates the
//!   ray (a hit, without triangle tests — the thesis' approximation).
//! * [`ShadowMode::LinespaceDda`]: every ray alone through the same N-tree with a hierarchical
//!   3D-DDA \[AW87\] and the same line-space termination (Table 3's DDA).
//! * [`ShadowMode::Exact`]: the packet traversal of `Linespace` with the line spaces used only
//!   to skip empty shafts, down to the leaves, where the rays are tested against the leaves'
//!   triangles (Table 2's "Schnitttests mit Dreiecken"); the reference.
//! * [`ShadowMode::Variant1`], [`ShadowMode::Variant2`]: Table 2's "Variante 1" and "Variante
//!   2" as the thesis defines them: `Exact` and `Linespace` without the near-origin rule below.
//! * [`ShadowMode::LinespaceFast`] (ours): `Linespace`'s values for less work — the nodes away
//!   from the origin walked first, the near ones after for the rays still unblocked, and a
//!   leaf's triangle skipped for the packet when the origin and the light's corners lie on one
//!   side of its plane ([`packet_misses`]).
//!
//! Where the thesis is silent we do this (and the kernel the same): the node that contains the
//! rays' common origin has no entry side, so no line-space entry; it is always descended, and
//! inside it the leaves are tested exactly (otherwise every surface would shadow itself); the
//! same for a node whose box, grown by one child cell, holds the origin ([`NEAR_MARGIN`]).

use glam::{IVec3, Vec3};

use crate::pipeline::klee2016::ntree::{
    entry_index, face_axes, NTree, PackedLinespaces, CHILDREN_BIT, GEOMETRY_BIT,
};
use crate::reference::intersect_triangle;
use crate::scene::AreaLight;
use crate::scene::ShadowMode;

/// Exact event counts of one pixel or frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ShadowCounts {
    pub triangle_tests: u64,
    pub linespace_lookups: u64,
    pub nodes_visited: u64,
    /// Pixels whose light corners do not all lie on one side of an axis (no packet): lit.
    pub packet_failures: u64,
    /// Triangles skipped for a whole packet by [`packet_misses`] (`LinespaceFast`).
    pub triangles_culled: u64,
    /// Line-space lookups per stack depth (0: the root's children, as the thesis counts
    /// "Tiefe null"): the cascade shows as lookups at more than one depth.
    pub lookups_by_depth: [u64; 3],
}

impl std::ops::AddAssign for ShadowCounts {
    fn add_assign(&mut self, o: Self) {
        self.triangle_tests += o.triangle_tests;
        self.linespace_lookups += o.linespace_lookups;
        self.nodes_visited += o.nodes_visited;
        self.packet_failures += o.packet_failures;
        self.triangles_culled += o.triangles_culled;
        for (a, b) in self.lookups_by_depth.iter_mut().zip(o.lookups_by_depth) {
            *a += b;
        }
    }
}

/// The uniformly spaced sample points of the light: sample r = i·SAMPLES_V + j lies at
/// corner + (i + ½)/SAMPLES_U · edge_u + (j + ½)/SAMPLES_V · edge_v.
pub fn light_samples(light: &AreaLight, su: u32, sv: u32) -> Vec<Vec3> {
    let mut v = Vec::with_capacity((su * sv) as usize);
    for i in 0..su {
        for j in 0..sv {
            v.push(
                light.corner
                    + (i as f32 + 0.5) / su as f32 * light.edge_u
                    + (j as f32 + 0.5) / sv as f32 * light.edge_v,
            );
        }
    }
    v
}

/// The light's corners in the order of Listing 2's corner_dir, equation (1):
/// (u_min, v_min), (u_min, v_max), (u_max, v_min), (u_max, v_max).
pub fn light_corners(light: &AreaLight) -> [Vec3; 4] {
    let c = light.corner;
    [
        c,
        c + light.edge_v,
        c + light.edge_u,
        c + light.edge_u + light.edge_v,
    ]
}

/// The soft-shadow computation on the CPU.
pub struct LinespaceShadows<'a> {
    pub tree: &'a NTree,
    pub packed: &'a PackedLinespaces,
    pub triangles: &'a [[Vec3; 3]],
    pub light: AreaLight,
    pub samples_u: u32,
    pub samples_v: u32,
    /// The shadow-ray origin is moved this far along the normal (world units).
    pub offset: f32,
}

/// Kay–Kajiya [KK86] on the node [0, N]³ (Algorithm 3): the entry and exit sides and cells
/// of the ray, or `None` when it misses the node before `t_end`.
fn node_intersection(
    n: u32,
    start: Vec3,
    dir: Vec3,
    t_end: f32,
) -> Option<(usize, u32, u32, usize, u32, u32)> {
    let nf = n as f32;
    let (mut tnear, mut tfar) = (f32::NEG_INFINITY, f32::INFINITY);
    let (mut near_axis, mut far_axis) = (0usize, 0usize);
    for a in 0..3 {
        if dir[a] == 0.0 {
            if start[a] < 0.0 || start[a] > nf {
                return None;
            }
            continue;
        }
        let inv = 1.0 / dir[a];
        let mut t0 = (0.0 - start[a]) * inv;
        let mut t1 = (nf - start[a]) * inv;
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        if t0 > tnear {
            tnear = t0;
            near_axis = a;
        }
        if t1 < tfar {
            tfar = t1;
            far_axis = a;
        }
    }
    if tnear > tfar || tfar < 0.0 || tnear > t_end {
        return None;
    }
    let start_vec = start + tnear * dir;
    let end_vec = start + tfar * dir;
    let start_face = 2 * near_axis + if dir[near_axis] > 0.0 { 0 } else { 1 };
    let end_face = 2 * far_axis + if dir[far_axis] > 0.0 { 1 } else { 0 };
    let cell = |v: Vec3, face: usize| {
        let (ua, va) = face_axes(face / 2);
        let c = |x: f32| (x.floor() as i32).clamp(0, n as i32 - 1) as u32;
        (c(v[ua]), c(v[va]))
    };
    let (su, sv) = cell(start_vec, start_face);
    let (eu, ev) = cell(end_vec, end_face);
    Some((start_face, su, sv, end_face, eu, ev))
}

/// `LinespaceFast`: the packet's rays lie in the pyramid from the origin to the (convex)
/// light; its four side planes' unit normals, pointing out (the kernel's `initPyramid`).
pub fn pyramid_sides(origin: Vec3, corners: &[Vec3; 4]) -> [Vec3; 4] {
    // the corners in cyclic order (Listing 2's order is (0, 0), (0, 1), (1, 0), (1, 1))
    let ring = [corners[0], corners[1], corners[3], corners[2]];
    let centre = 0.25 * (ring[0] + ring[1] + ring[2] + ring[3]);
    std::array::from_fn(|e| {
        let n = (ring[e] - origin)
            .cross(ring[(e + 1) & 3] - origin)
            .normalize();
        if n.dot(centre - origin) > 0.0 {
            -n
        } else {
            n
        }
    })
}

/// `LinespaceFast`: no segment from `origin` to a point of the light (given by its `corners`
/// and the pyramid's `sides`, [`pyramid_sides`]) can cross triangle `tri` when the origin and
/// the four corners lie on one side of its plane, or the triangle lies outside a side plane.
/// The margins (1e-5 world units, against Möller–Trumbore's rounding) keep the skip
/// conservative. The kernel's `packetMisses`.
pub fn packet_misses(
    tri: &[Vec3; 3],
    origin: Vec3,
    corners: &[Vec3; 4],
    sides: &[Vec3; 4],
) -> bool {
    if sides
        .iter()
        .any(|n| tri.iter().all(|v| n.dot(*v - origin) > 1e-5))
    {
        return true;
    }
    let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    let eps = 1e-5 * n.length();
    let side = n.dot(origin - tri[0]);
    if side.abs() <= eps {
        return false;
    }
    let s = side.signum();
    corners.iter().all(|c| s * n.dot(*c - tri[0]) > eps)
}

/// Margin, in child cells, around a node within which the rays' origin counts as "in the
/// node": such a node is descended (and its leaves tested exactly) instead of asking its line
/// space. Without it, rays that start just beside a node boundary enter the neighbour through
/// the side cell next to the surface they start on, whose shaft holds that surface: thin dark
/// lines along every node boundary.
pub const NEAR_MARGIN: f32 = 1.0;

/// Does the origin (at `child_start` in the node's coordinates) lie in the node or within
/// [`NEAR_MARGIN`] child cells of it?
pub fn near_origin(child_start: Vec3, nf: f32) -> bool {
    child_start.cmpge(Vec3::splat(-NEAR_MARGIN)).all()
        && child_start.cmple(Vec3::splat(nf + NEAR_MARGIN)).all()
}

/// Algorithm 4: the line-space entry of a ray through a node (true: geometry in the shaft).
/// Entry and exit on the same side (a grazing ray) has no shaft: true, conservatively.
fn get_entry(
    n: u32,
    packed: &PackedLinespaces,
    ls_index: u32,
    hit: (usize, u32, u32, usize, u32, u32),
) -> bool {
    let (s, su, sv, e, eu, ev) = hit;
    match entry_index(n, s, su, sv, e, eu, ev) {
        Some(entry) => packed.get_entry(ls_index, entry),
        None => true,
    }
}

/// A ray's direction in N-tree cell units with its 3D-DDA constants [AW87].
struct DdaRay {
    dir: Vec3,
    step: IVec3,
    t_delta: Vec3,
}

impl DdaRay {
    fn new(dir: Vec3) -> DdaRay {
        let sign = |x: f32| if x > 0.0 { 1 } else { -1 };
        DdaRay {
            dir,
            step: IVec3::new(sign(dir.x), sign(dir.y), sign(dir.z)),
            t_delta: Vec3::ONE / dir.abs(),
        }
    }
}

/// One level of the hierarchical 3D-DDA: the N×N×N cells of one node group, in that node's
/// cell units (`start` is the ray origin there, `t` runs along the ray's direction in them).
#[derive(Clone, Copy, Default)]
struct Dda {
    group: u32,
    start: Vec3,
    cell: IVec3,
    t_max: Vec3,
    t: f32,
    t_end: f32,
}

impl Dda {
    /// Enters the node group `group` whose local ray origin is `start`: None when the ray
    /// misses the node's [0,N)³ before `t_end`.
    fn enter(ray: &DdaRay, n: i32, group: u32, start: Vec3, t_end: f32) -> Option<Dda> {
        let nf = n as f32;
        let dir = ray.dir;
        let inside = start.cmpge(Vec3::ZERO).all() && start.cmplt(Vec3::splat(nf)).all();
        let t0 = if inside {
            0.0
        } else {
            let (mut tnear, mut tfar) = (0.0f32, f32::INFINITY);
            for a in 0..3 {
                if dir[a] == 0.0 {
                    if start[a] < 0.0 || start[a] > nf {
                        return None;
                    }
                    continue;
                }
                let mut t0 = -start[a] / dir[a];
                let mut t1 = (nf - start[a]) / dir[a];
                if t0 > t1 {
                    std::mem::swap(&mut t0, &mut t1);
                }
                tnear = tnear.max(t0);
                tfar = tfar.min(t1);
            }
            if tnear > tfar || tnear > t_end {
                return None;
            }
            tnear
        };
        let p = start + t0 * dir;
        let cell = p.floor().as_ivec3().clamp(IVec3::ZERO, IVec3::splat(n - 1));
        let mut t_max = Vec3::INFINITY;
        for a in 0..3 {
            if dir[a] > 0.0 {
                t_max[a] = (cell[a] as f32 + 1.0 - start[a]) / dir[a];
            } else if dir[a] < 0.0 {
                t_max[a] = (cell[a] as f32 - start[a]) / dir[a];
            }
        }
        Some(Dda {
            group,
            start,
            cell,
            t_max,
            t: t0,
            t_end,
        })
    }

    /// Steps to the next cell along the axis whose boundary comes first.
    fn advance(&mut self, ray: &DdaRay) {
        let tm = self.t_max;
        let a = if tm.x <= tm.y && tm.x <= tm.z {
            0
        } else if tm.y <= tm.z {
            1
        } else {
            2
        };
        self.t = tm[a];
        self.cell[a] += ray.step[a];
        self.t_max[a] += ray.t_delta[a];
    }
}

/// One level of Listing 1's stack.
#[derive(Clone)]
struct StackLevel {
    parent_group: u32,
    nodelist: Vec<([u32; 2], IVec3)>,
    nodelist_index: usize,
    traverse_childs: bool,
    current_slice: i32,
    last_slice: i32,
}

/// Listing 2's shaft (ray_start per depth, the ray directions and the active flags).
struct Shaft {
    origin_world: Vec3,
    corner_dir: [Vec3; 4],
    k: usize,
    u: usize,
    v: usize,
    dir: i32,
    ray_start: Vec<Vec3>,
    ray_direction: Vec<Vec3>,
    light_points: Vec<Vec3>,
    active_rays: Vec<bool>,
    active_count: usize,
    /// `LinespaceFast`: two walks, packet tests of the leaves
    fast: bool,
    /// `LinespaceFast`: the light's corners and the side planes of the pyramid from the origin
    /// to them ([`pyramid_sides`]), the same for every leaf of the packet
    corners: [Vec3; 4],
    sides: [Vec3; 4],
    /// `LinespaceFast`'s walk: 0 the nodes away from the origin, 1 those near it.
    phase: u8,
}

impl<'a> LinespaceShadows<'a> {
    fn nn(&self) -> usize {
        (self.tree.n as usize).pow(3)
    }

    fn node(&self, group: u32, c: IVec3) -> [u32; 2] {
        let n = self.tree.n as i32;
        self.tree.nodes[group as usize * self.nn() + (c.x + n * (c.y + n * c.z)) as usize]
    }

    /// `t` of the light in a node's coordinates at level `level` (1 in the root's).
    fn t_end(&self, level: usize) -> f32 {
        (self.tree.n as f32).powi(level as i32)
    }

    /// The pixel's shadow value (fraction of unblocked samples) for a surface point `p` with
    /// normal `normal` (facing the viewer), and the counts.
    pub fn shadow(&self, mode: ShadowMode, p: Vec3, normal: Vec3) -> (f32, ShadowCounts) {
        self.shadow_in_batches(mode, p, normal, 1)
    }

    /// [`Self::shadow`] with the rays split into `batches` packets as the GPU's shadow pass
    /// splits them (`rayBegin..rayEnd`, `shadow_pass::ShadowPass::run`): the same value, and
    /// the counts of the smaller packets' traversals.
    pub fn shadow_in_batches(
        &self,
        mode: ShadowMode,
        p: Vec3,
        normal: Vec3,
        batches: usize,
    ) -> (f32, ShadowCounts) {
        let rays = (self.samples_u * self.samples_v) as usize;
        let per_batch = rays.div_ceil(batches.clamp(1, rays));
        let starts: Vec<usize> = (0..rays).step_by(per_batch).collect();
        self.shadow_in_ranges(mode, p, normal, &starts)
    }

    /// [`Self::shadow`] with the rays split into packets at `starts` (ascending, from 0): the
    /// packets `starts[i]..starts[i + 1]` and the last one to the last ray, as the GPU's shadow
    /// pass traced a pixel whose batches hit llvmpipe's loop limit (its batch starts,
    /// `SoftShadowRenderer::read_batch_starts`).
    pub fn shadow_in_ranges(
        &self,
        mode: ShadowMode,
        p: Vec3,
        normal: Vec3,
        starts: &[usize],
    ) -> (f32, ShadowCounts) {
        let rays = (self.samples_u * self.samples_v) as usize;
        // every ray in exactly one packet
        assert!(
            starts.first() == Some(&0)
                && starts.windows(2).all(|w| w[0] < w[1])
                && starts.last().is_some_and(|&l| l < rays),
            "batch starts {starts:?} do not split {rays} rays"
        );
        let mut counts = ShadowCounts::default();
        let mut lit = 0;
        let ends = starts.iter().skip(1).copied().chain([rays]);
        for (&begin, end) in starts.iter().zip(ends) {
            let (l, c) = self.lit_rays(mode, p, normal, begin..end);
            lit += l;
            counts += c;
        }
        (lit as f32 / rays as f32, counts)
    }

    /// How many of the rays `batch` (of the light samples, in order) reach the light: one
    /// packet, as one dispatch of the GPU's shadow pass traces it.
    fn lit_rays(
        &self,
        mode: ShadowMode,
        p: Vec3,
        normal: Vec3,
        batch: std::ops::Range<usize>,
    ) -> (usize, ShadowCounts) {
        let mut counts = ShadowCounts::default();
        let origin = p + normal * self.offset;
        let light_points = light_samples(&self.light, self.samples_u, self.samples_v);
        let num_rays = light_points.len();
        // samples behind the surface are blocked by it (N·L <= 0, as Listing 15)
        let active_rays: Vec<bool> = light_points
            .iter()
            .enumerate()
            .map(|(r, l)| batch.contains(&r) && normal.dot(*l - p) > 0.0)
            .collect();
        let active_count = active_rays.iter().filter(|a| **a).count();
        if active_count == 0 {
            return (0, counts);
        }
        let inv = self.tree.inv_node_size();
        let o = self.tree.to_ntree(origin);
        let ray_direction: Vec<Vec3> = light_points.iter().map(|l| (*l - origin) * inv).collect();
        let lit = match mode {
            ShadowMode::LinespaceDda => (0..num_rays)
                .filter(|&r| {
                    active_rays[r]
                        && !self.dda_blocked(
                            o,
                            ray_direction[r],
                            origin,
                            light_points[r],
                            &mut counts,
                        )
                })
                .count(),
            _ => {
                let corners = light_corners(&self.light);
                let corner_dir = corners.map(|c| (c - origin) * inv);
                let Some(k) = traversal_axis(&corner_dir, self.light.center() - origin) else {
                    // no packet: lit, counted once per pixel
                    counts.packet_failures += (batch.start == 0) as u64;
                    return (batch.len(), counts);
                };
                let (u, v) = face_axes(k);
                let mut shaft = Shaft {
                    origin_world: origin,
                    corner_dir,
                    k,
                    u,
                    v,
                    dir: if corner_dir[0][k] > 0.0 { 1 } else { -1 },
                    ray_start: vec![Vec3::ZERO; self.tree.depth as usize],
                    ray_direction,
                    light_points,
                    active_rays,
                    active_count,
                    fast: mode.fast_path(),
                    corners,
                    sides: if mode.fast_path() {
                        pyramid_sides(origin, &corners)
                    } else {
                        [Vec3::ZERO; 4]
                    },
                    phase: 0,
                };
                shaft.ray_start[0] = o;
                // LinespaceFast: the walk away from the origin first, then the near one for
                // the rays it left unblocked
                if shaft.fast && self.cgt(mode, &mut shaft, &mut counts) == 0 {
                    return (0, counts);
                }
                shaft.phase = 1;
                self.cgt(mode, &mut shaft, &mut counts)
            }
        };
        (lit, counts)
    }

    /// The slices [first, last] (in traversal order) the packet crosses in a node at stack
    /// depth `d` (whose local coordinates hold ray_start[d]).
    fn slice_range(&self, s: &Shaft, d: usize) -> Option<(i32, i32)> {
        let nf = self.tree.n as f32;
        let ko = s.ray_start[d][s.k];
        let te = self.t_end(d);
        let ends = s.corner_dir.map(|c| ko + c[s.k] * te);
        if s.dir > 0 {
            let kfar = ends
                .iter()
                .copied()
                .fold(f32::NEG_INFINITY, f32::max)
                .min(nf);
            let knear = ko.max(0.0);
            if knear >= nf || kfar <= 0.0 || knear > kfar {
                return None;
            }
            let first = (knear.floor() as i32).clamp(0, self.tree.n as i32 - 1);
            let last = ((kfar.ceil() as i32) - 1)
                .clamp(0, self.tree.n as i32 - 1)
                .max(first);
            Some((first, last))
        } else {
            let kfar = ends.iter().copied().fold(f32::INFINITY, f32::min).max(0.0);
            let knear = ko.min(nf);
            if knear <= 0.0 || kfar >= nf || knear < kfar {
                return None;
            }
            let first = ((knear.ceil() as i32) - 1).clamp(0, self.tree.n as i32 - 1);
            let last = (kfar.floor() as i32)
                .clamp(0, self.tree.n as i32 - 1)
                .min(first);
            Some((first, last))
        }
    }

    /// u_min/u_max/v_min/v_max of the packet within slice `j` at depth `d` (Fig. 10(b)–(c)):
    /// the corner rays where they enter and leave the slice.
    fn slice_uv(&self, s: &Shaft, d: usize, j: i32) -> [f32; 4] {
        let ko = s.ray_start[d][s.k];
        let te = self.t_end(d);
        let (a, b) = (j as f32, j as f32 + 1.0);
        let mut r = [
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for c in &s.corner_dir {
            let kend = ko + c[s.k] * te;
            let (lo, hi) = if s.dir > 0 { (ko, kend) } else { (kend, ko) };
            for kk in [a.clamp(lo, hi), b.clamp(lo, hi)] {
                let lambda = (kk - ko) / c[s.k];
                let pu = s.ray_start[d][s.u] + lambda * c[s.u];
                let pv = s.ray_start[d][s.v] + lambda * c[s.v];
                r[0] = r[0].min(pu);
                r[1] = r[1].max(pu);
                r[2] = r[2].min(pv);
                r[3] = r[3].max(pv);
            }
        }
        r
    }

    fn init_level(&self, s: &Shaft, d: usize, group: u32) -> Option<StackLevel> {
        let (first, last) = self.slice_range(s, d)?;
        Some(StackLevel {
            parent_group: group,
            nodelist: Vec::with_capacity((self.tree.n * self.tree.n) as usize),
            nodelist_index: 0,
            traverse_childs: false,
            current_slice: first,
            last_slice: last,
        })
    }

    /// Algorithm 2: the line-space check of a node for all active rays. `deactivate`: at the
    /// last depth with line spaces a set bit is a hit and deactivates the ray; elsewhere the
    /// first set bit returns true (the node must be descended).
    fn is_intersection(
        &self,
        s: &mut Shaft,
        node: [u32; 2],
        child_start: Vec3,
        level: usize,
        deactivate: bool,
        counts: &mut ShadowCounts,
    ) -> bool {
        let mut found = false;
        let te = self.t_end(level);
        for r in 0..s.ray_direction.len() {
            if !s.active_rays[r] {
                continue;
            }
            let Some(hit) = node_intersection(self.tree.n, child_start, s.ray_direction[r], te)
            else {
                continue;
            };
            counts.linespace_lookups += 1;
            counts.lookups_by_depth[level - 1] += 1;
            if get_entry(self.tree.n, self.packed, node[1], hit) {
                found = true;
                if deactivate {
                    s.active_rays[r] = false;
                    s.active_count -= 1;
                } else {
                    return true;
                }
            }
        }
        found
    }

    /// Exact triangle tests of a leaf for all active rays that cross it.
    fn leaf_tests(
        &self,
        s: &mut Shaft,
        node: [u32; 2],
        child_start: Vec3,
        level: usize,
        counts: &mut ShadowCounts,
    ) {
        if s.fast {
            return self.leaf_tests_packet(s, node, child_start, level, counts);
        }
        let te = self.t_end(level);
        let off = (node[0] >> 2) as usize;
        let tris = &self.tree.leaf_triangles[off..off + node[1] as usize];
        for r in 0..s.ray_direction.len() {
            if !s.active_rays[r]
                || node_intersection(self.tree.n, child_start, s.ray_direction[r], te).is_none()
            {
                continue;
            }
            let rd = s.light_points[r] - s.origin_world;
            for &t in tris {
                counts.triangle_tests += 1;
                let tri = &self.triangles[t as usize];
                if let Some((tt, _, _)) =
                    intersect_triangle(s.origin_world, rd, tri[0], tri[1], tri[2])
                {
                    if tt < 1.0 {
                        s.active_rays[r] = false;
                        s.active_count -= 1;
                        break;
                    }
                }
            }
        }
    }

    /// `LinespaceFast`: a leaf's triangles one by one, each first against the whole packet
    /// ([`packet_misses`]), then for the active rays that cross the leaf (found at the first
    /// triangle not skipped); a ray meets the triangles in [`Self::leaf_tests`]' order and stops
    /// at the same one (the kernel's `leafTestsPacket`).
    fn leaf_tests_packet(
        &self,
        s: &mut Shaft,
        node: [u32; 2],
        child_start: Vec3,
        level: usize,
        counts: &mut ShadowCounts,
    ) {
        let te = self.t_end(level);
        let mut crossing: Option<Vec<usize>> = None;
        let off = (node[0] >> 2) as usize;
        for &t in &self.tree.leaf_triangles[off..off + node[1] as usize] {
            if crossing.as_ref().is_some_and(|c| c.is_empty()) {
                break;
            }
            let tri = &self.triangles[t as usize];
            if packet_misses(tri, s.origin_world, &s.corners, &s.sides) {
                counts.triangles_culled += 1;
                continue;
            }
            let rays = crossing.get_or_insert_with(|| {
                (0..s.ray_direction.len())
                    .filter(|&r| {
                        s.active_rays[r]
                            && node_intersection(self.tree.n, child_start, s.ray_direction[r], te)
                                .is_some()
                    })
                    .collect()
            });
            rays.retain(|&r| {
                counts.triangle_tests += 1;
                let rd = s.light_points[r] - s.origin_world;
                let hit = intersect_triangle(s.origin_world, rd, tri[0], tri[1], tri[2])
                    .is_some_and(|(tt, _, _)| tt < 1.0);
                if hit {
                    s.active_rays[r] = false;
                    s.active_count -= 1;
                }
                !hit
            });
        }
    }

    /// `LinespaceFast`: does the cell `c` at stack depth `d` belong to the other walk? Near
    /// the origin ([`near_origin`]) is walk 1's, the rest walk 0's; deeper cells follow their
    /// parent (the kernel's `phaseSkips`).
    fn phase_skips(&self, s: &Shaft, d: usize, c: IVec3) -> bool {
        let nf = self.tree.n as f32;
        s.fast && d == 0 && near_origin((s.ray_start[0] - c.as_vec3()) * nf, nf) != (s.phase == 1)
    }

    /// `LinespaceFast`, walk 1: the slices at depth 0 past the origin's neighbourhood hold no
    /// near cell (the kernel's `phaseEnds`).
    fn phase_ends(&self, s: &Shaft, d: usize, slice: i32) -> bool {
        let nf = self.tree.n as f32;
        let kc = (s.ray_start[0][s.k] - slice as f32) * nf;
        s.fast && d == 0 && s.phase == 1 && (kc < -NEAR_MARGIN || kc > nf + NEAR_MARGIN)
    }

    /// Examine slice `slice` of the node at stack depth `d`: its children with geometry inside
    /// the packet's u/v_min/max into the level's node list.
    fn examine_slice(
        &self,
        s: &Shaft,
        d: usize,
        slice: i32,
        lvl: &mut StackLevel,
        counts: &mut ShadowCounts,
    ) {
        let n = self.tree.n as i32;
        let uv = self.slice_uv(s, d, slice);
        let cu0 = (uv[0].floor() as i32).max(0);
        let cu1 = (uv[1].floor() as i32).min(n - 1);
        let cv0 = (uv[2].floor() as i32).max(0);
        let cv1 = (uv[3].floor() as i32).min(n - 1);
        lvl.nodelist.clear();
        for cu in cu0..=cu1 {
            for cv in cv0..=cv1 {
                let mut c = IVec3::ZERO;
                c[s.k] = slice;
                c[s.u] = cu;
                c[s.v] = cv;
                // LinespaceFast: the other walk's cell
                if self.phase_skips(s, d, c) {
                    continue;
                }
                counts.nodes_visited += 1;
                let node = self.node(lvl.parent_group, c);
                if node[0] & GEOMETRY_BIT != 0 {
                    lvl.nodelist.push((node, c));
                }
            }
        }
        lvl.nodelist_index = lvl.nodelist.len();
    }

    /// Whether the packet descends into inner node `node`, a child of the node at stack depth
    /// `d` (its rays from `child_start`, in the node's units): ours, a node near the origin is
    /// descended; else its line space decides (at the last line-space depth, `bit_is_hit`
    /// variants take a set bit as a hit and never descend).
    fn descends(
        &self,
        mode: ShadowMode,
        s: &mut Shaft,
        node: [u32; 2],
        child_start: Vec3,
        d: usize,
        counts: &mut ShadowCounts,
    ) -> bool {
        let level_of_node = d + 1;
        if mode.near_origin_rule() && near_origin(child_start, self.tree.n as f32) {
            return true;
        }
        if mode.bit_is_hit() && d as i32 == self.tree.last_linespace_depth() {
            self.is_intersection(s, node, child_start, level_of_node, true, counts);
            return false;
        }
        self.is_intersection(s, node, child_start, level_of_node, false, counts)
    }

    /// Algorithm 1 (continuation): the slice-by-slice traversal with the explicit stack.
    /// Returns the number of rays still active (lit).
    fn cgt(&self, mode: ShadowMode, s: &mut Shaft, counts: &mut ShadowCounts) -> usize {
        let nf = self.tree.n as f32;
        let max_depth = self.tree.depth as usize - 1;
        let mut stack: Vec<Option<StackLevel>> = vec![None; max_depth];
        stack[0] = self.init_level(s, 0, 0);
        if stack[0].is_none() {
            return s.active_count;
        }
        let mut depth: i32 = 0;
        while depth >= 0 {
            let d = depth as usize;
            let mut next_depth = false;
            let Some(level) = stack[d].clone() else {
                depth -= 1;
                continue;
            };
            let mut lvl = level;
            let mut slice = lvl.current_slice;
            loop {
                if self.phase_ends(s, d, slice) {
                    break;
                }
                if !lvl.traverse_childs {
                    self.examine_slice(s, d, slice, &mut lvl, counts);
                }
                while lvl.nodelist_index > 0 {
                    lvl.nodelist_index -= 1;
                    let (node, offset) = lvl.nodelist[lvl.nodelist_index];
                    let child_start = (s.ray_start[d] - offset.as_vec3()) * nf;
                    let level_of_node = d + 1;
                    if node[0] & CHILDREN_BIT == 0 {
                        self.leaf_tests(s, node, child_start, level_of_node, counts);
                    } else {
                        if self.descends(mode, s, node, child_start, d, counts) {
                            s.ray_start[d + 1] = child_start;
                            if let Some(next) = self.init_level(s, d + 1, node[0] >> 2) {
                                lvl.traverse_childs = true;
                                lvl.current_slice = slice;
                                stack[d + 1] = Some(next);
                                next_depth = true;
                            }
                        }
                    }
                    if s.active_count == 0 {
                        return 0;
                    }
                    if next_depth {
                        break;
                    }
                }
                if next_depth {
                    break;
                }
                lvl.traverse_childs = false;
                if slice == lvl.last_slice {
                    break;
                }
                slice += s.dir;
            }
            if next_depth {
                stack[d] = Some(lvl);
                depth += 1;
            } else {
                stack[d] = None;
                depth -= 1;
            }
        }
        s.active_count
    }

    /// One ray with a hierarchical 3D-DDA [AW87] through the N-tree, the same line-space
    /// termination as the packet traversal (Table 3's DDA). True: blocked.
    fn dda_blocked(
        &self,
        o: Vec3,
        dir: Vec3,
        origin_world: Vec3,
        light_point: Vec3,
        counts: &mut ShadowCounts,
    ) -> bool {
        let n = self.tree.n as i32;
        let nf = n as f32;
        let last_ls_depth = self.tree.last_linespace_depth();
        let max_depth = self.tree.depth as usize - 1;
        let ray = DdaRay::new(dir);
        let init = |group: u32, start: Vec3, t_end: f32| Dda::enter(&ray, n, group, start, t_end);
        let mut stack = vec![Dda::default(); max_depth];
        let Some(root) = init(0, o, 1.0) else {
            return false;
        };
        stack[0] = root;
        let mut depth: i32 = 0;
        let rd = light_point - origin_world;
        while depth >= 0 {
            let d = depth as usize;
            let st = stack[d];
            if st.cell.cmplt(IVec3::ZERO).any()
                || st.cell.cmpge(IVec3::splat(n)).any()
                || st.t > st.t_end
            {
                depth -= 1;
                continue;
            }
            // advance this level past the current cell before looking into it
            stack[d].advance(&ray);
            counts.nodes_visited += 1;
            let node = self.node(st.group, st.cell);
            if node[0] & GEOMETRY_BIT == 0 {
                continue;
            }
            let child_start = (st.start - st.cell.as_vec3()) * nf;
            let level_of_node = d + 1;
            let te = self.t_end(level_of_node);
            if node[0] & CHILDREN_BIT == 0 {
                let off = (node[0] >> 2) as usize;
                for &t in &self.tree.leaf_triangles[off..off + node[1] as usize] {
                    counts.triangle_tests += 1;
                    let tri = &self.triangles[t as usize];
                    if let Some((tt, _, _)) =
                        intersect_triangle(origin_world, rd, tri[0], tri[1], tri[2])
                    {
                        if tt < 1.0 {
                            return true;
                        }
                    }
                }
                continue;
            }
            let inside = near_origin(child_start, nf);
            let descend = if inside {
                true
            } else if let Some(hit) = node_intersection(self.tree.n, child_start, dir, te) {
                counts.linespace_lookups += 1;
                counts.lookups_by_depth[d] += 1;
                if get_entry(self.tree.n, self.packed, node[1], hit) {
                    if d as i32 == last_ls_depth {
                        return true;
                    }
                    true
                } else {
                    false
                }
            } else {
                false
            };
            if descend {
                if let Some(next) = init(node[0] >> 2, child_start, te) {
                    stack[d + 1] = next;
                    depth += 1;
                }
            }
        }
        false
    }

    /// Primary-ray casting on the CPU (Table 1's "CPU": the thesis ray traces the initial image
    /// on the CPU): the closest hit (world t along the normalised `d`, triangle id) by a
    /// hierarchical 3D-DDA through the N-tree, front to back, testing the leaves' triangles
    /// and stopping once the closest hit lies before the current leaf's exit.
    pub fn closest_hit(
        &self,
        o_world: Vec3,
        d_world: Vec3,
        counts: &mut ShadowCounts,
    ) -> Option<(f32, u32)> {
        let n = self.tree.n as i32;
        let nf = n as f32;
        let max_depth = self.tree.depth as usize - 1;
        let o = self.tree.to_ntree(o_world);
        let dir = d_world * self.tree.inv_node_size();
        let ray = DdaRay::new(dir);
        let init = |group: u32, start: Vec3, t_end: f32| Dda::enter(&ray, n, group, start, t_end);
        let mut stack = vec![Dda::default(); max_depth];
        stack[0] = init(0, o, f32::INFINITY)?;
        let mut depth: i32 = 0;
        let mut best: Option<(f32, u32)> = None;
        while depth >= 0 {
            let d = depth as usize;
            let st = stack[d];
            if st.cell.cmplt(IVec3::ZERO).any() || st.cell.cmpge(IVec3::splat(n)).any() {
                depth -= 1;
                continue;
            }
            stack[d].advance(&ray);
            counts.nodes_visited += 1;
            let node = self.node(st.group, st.cell);
            if node[0] & GEOMETRY_BIT == 0 {
                continue;
            }
            if node[0] & CHILDREN_BIT == 0 {
                let off = (node[0] >> 2) as usize;
                for &t in &self.tree.leaf_triangles[off..off + node[1] as usize] {
                    counts.triangle_tests += 1;
                    let tri = &self.triangles[t as usize];
                    if let Some((tt, _, _)) =
                        intersect_triangle(o_world, d_world, tri[0], tri[1], tri[2])
                    {
                        if best.is_none_or(|b| tt < b.0) {
                            best = Some((tt, t));
                        }
                    }
                }
                // the leaf's exit in world units (t of depth d is N^d times the root's)
                let exit = stack[d].t / self.t_end(d);
                if let Some(b) = best {
                    if b.0 <= exit {
                        return best;
                    }
                }
                continue;
            }
            let child_start = (st.start - st.cell.as_vec3()) * nf;
            if let Some(next) = init(node[0] >> 2, child_start, f32::INFINITY) {
                stack[d + 1] = next;
                depth += 1;
            }
        }
        best
    }

    /// The exact shadow value by brute force: every sample ray against every triangle (the
    /// oracle for `Exact`).
    pub fn brute_force(&self, p: Vec3, normal: Vec3) -> f32 {
        let origin = p + normal * self.offset;
        let pts = light_samples(&self.light, self.samples_u, self.samples_v);
        let lit = pts
            .iter()
            .filter(|l| {
                normal.dot(**l - p) > 0.0
                    && !self.triangles.iter().any(|t| {
                        matches!(intersect_triangle(origin, **l - origin, t[0], t[1], t[2]), Some((tt, _, _)) if tt < 1.0)
                    })
            })
            .count();
        lit as f32 / pts.len() as f32
    }
}

/// Algorithm 1: the traversal axis k, the dominant axis of the light vector `centre` (from the
/// origin to the light's centre) — valid when all four corner rays `corner_dir` go the same way
/// along it; else the valid axis along which the corner rays go fastest; none if no axis is valid.
fn traversal_axis(corner_dir: &[Vec3; 4], centre: Vec3) -> Option<usize> {
    let valid =
        |a: usize| corner_dir.iter().all(|c| c[a] > 0.0) || corner_dir.iter().all(|c| c[a] < 0.0);
    let lv = centre.abs();
    let dominant = if lv.x >= lv.y && lv.x >= lv.z {
        0
    } else if lv.y >= lv.z {
        1
    } else {
        2
    };
    if valid(dominant) {
        return Some(dominant);
    }
    let slowest = |a: usize| {
        corner_dir
            .iter()
            .map(|c| c[a].abs())
            .fold(f32::INFINITY, f32::min)
    };
    (0..3)
        .filter(|&a| valid(a))
        .max_by(|&a, &b| slowest(a).total_cmp(&slowest(b)))
}
