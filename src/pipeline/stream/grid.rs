//! The static uniform grid of the streaming ray tracer (the streaming tracer, ch. 3 and Fig. 3),
//! built once on the CPU ("precomputed offline on the main processor"): per cell a pointer into the
//! tightly packed reference list, the count of references and the proximity-cloud distance.
//! `glsl/stream/grid.glsl` walks it with the 3D-DDA of Amanatides and Woo; its CPU twin, the
//! same walk in the same f32 arithmetic, is `reference::stream_grid`.
//!
//! Unlike Müller's grids (`accel::grid_frame`), this grid lives in world space: its box is the
//! scene's bounds, slightly enlarged, cut into gx×gy×gz cells that need not be cubes
//! (`--grid 14x16x14`).

use glam::{IVec3, UVec3, Vec3};

use crate::accel::proximity::chebyshev_distances;
use crate::accel::tribox::tri_box_overlap;
use crate::scene::budget;

/// Ray state of the traversal (Fig. 2, `tMax`'s w channel): still walking.
pub const ACTIVE: f32 = 1.0;
/// Ray state: finished (hit found, walk left the grid, or masked out).
pub const DONE: f32 = 2.0;

/// The grid's box and its cells: what `glsl/stream/grid.glsl` gets as uniforms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridBox {
    /// the box's minimum corner (`gridMin`)
    pub min: Vec3,
    /// `gridMin + cellSize · gridSize`, in f32 (`gridMax`)
    pub max: Vec3,
    /// the edge lengths of a cell (`cellSize`)
    pub cell: Vec3,
    /// cells per axis (`gridSize`)
    pub dims: UVec3,
}

impl GridBox {
    /// The box over `lo..hi` (the scene's bounds), enlarged by 10⁻³ of its largest extent on
    /// every side so that no triangle lies on its faces and a flat scene gets a thickness.
    pub fn new(lo: Vec3, hi: Vec3, dims: UVec3) -> GridBox {
        let pad = (hi - lo).max_element().max(1e-6) * 1e-3;
        let (min, max) = (lo - pad, hi + pad);
        let cell = (max - min) / dims.as_vec3();
        GridBox {
            min,
            max: min + cell * dims.as_vec3(),
            cell,
            dims,
        }
    }

    pub fn cell_count(&self) -> usize {
        (self.dims.x * self.dims.y * self.dims.z) as usize
    }

    /// The index of cell `c` (x fastest), `None` outside the grid.
    pub fn index(&self, c: IVec3) -> Option<usize> {
        let d = self.dims.as_ivec3();
        let inside = c.cmpge(IVec3::ZERO).all() && c.cmplt(d).all();
        inside.then(|| ((c.z * d.y + c.y) * d.x + c.x) as usize)
    }

    /// clipToBox: the parameter interval (enter, exit) of o + t·d inside the box; empty when
    /// enter > exit. An axis with d = 0 clips nothing if o lies within its slab.
    pub fn clip(&self, o: Vec3, d: Vec3) -> (f32, f32) {
        let (mut enter, mut exit) = (f32::NEG_INFINITY, f32::INFINITY);
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < self.min[a] || o[a] > self.max[a] {
                    return (f32::INFINITY, f32::NEG_INFINITY);
                }
                continue;
            }
            let t0 = (self.min[a] - o[a]) / d[a];
            let t1 = (self.max[a] - o[a]) / d[a];
            enter = enter.max(t0.min(t1));
            exit = exit.min(t0.max(t1));
        }
        (enter, exit)
    }

    /// planeT: the parameter at which o + t·d leaves cell column `k` of axis `a` (the cell
    /// plane beyond it in the direction of travel); +∞ for d = 0.
    pub fn plane_t(&self, o: Vec3, d: Vec3, a: usize, k: i32) -> f32 {
        if d[a] == 0.0 {
            return f32::INFINITY;
        }
        let up = if d[a] > 0.0 { 1 } else { 0 };
        (self.min[a] + (k + up) as f32 * self.cell[a] - o[a]) / d[a]
    }

    /// cellOf: the cell of point p, clamped into the grid.
    pub fn cell_of(&self, p: Vec3) -> IVec3 {
        let c = ((p - self.min) / self.cell).floor().as_ivec3();
        c.clamp(IVec3::ZERO, self.dims.as_ivec3() - 1)
    }

    /// tMax of cell `c`: per axis the parameter of the next cell plane.
    pub fn t_max(&self, o: Vec3, d: Vec3, c: IVec3) -> Vec3 {
        Vec3::new(
            self.plane_t(o, d, 0, c.x),
            self.plane_t(o, d, 1, c.y),
            self.plane_t(o, d, 2, c.z),
        )
    }
}

/// `--grid auto`: the paper's heuristic g = ∛n cells per axis (ch. 4), within 1..=1024. The
/// seed's text reads "gx,y,z = 3 √n": the 3 is the radical's index, not a factor — the paper's
/// own arithmetic needs the cube root, since with g³ = n its M = 96·n + 16·g³ is 112 bytes a
/// triangle and 256 MB hold its "2.3 million triangles" (3·∛n would make it 528 bytes and
/// about 0.5 million).
pub fn auto_dims(triangles: usize) -> UVec3 {
    UVec3::splat(((triangles as f64).cbrt().round() as u32).clamp(1, 1024))
}

/// The grid of Fig. 3: per cell (pointer, count, proximity distance), the references tightly
/// packed, and the triangles (v0, edge1, edge2) they point to.
pub struct StreamGrid {
    pub bx: GridBox,
    /// per cell: index of its first reference in `refs`, and their count
    pub cells: Vec<(u32, u32)>,
    /// triangle ids, per cell ascending, cells in index order
    pub refs: Vec<u32>,
    /// per cell: the Chebyshev distance in cells to the nearest non-empty cell (0: non-empty)
    pub proximity: Vec<u32>,
    /// world-space triangles in id order
    pub triangles: Vec<[Vec3; 3]>,
}

/// Per cell (first, count), and the triangle ids of `pairs` (cell, id) packed by cell — a
/// counting sort, stable, so each cell's ids stay ascending as the pairs came in id order.
fn pack_by_cell(cells: usize, pairs: &[(u32, u32)]) -> (Vec<(u32, u32)>, Vec<u32>) {
    let mut packed = vec![(0u32, 0u32); cells];
    for &(c, _) in pairs {
        packed[c as usize].1 += 1;
    }
    let mut first = 0u32;
    for cell in &mut packed {
        let count = cell.1;
        *cell = (first, 0);
        first += count;
    }
    let mut refs = vec![0u32; pairs.len()];
    for &(c, id) in pairs {
        let cell = &mut packed[c as usize];
        refs[(cell.0 + cell.1) as usize] = id;
        cell.1 += 1;
    }
    (packed, refs)
}

/// The cells a triangle overlaps (triangle/box separating axes, boxes enlarged by 10⁻⁴ of a
/// cell so that nothing on a cell face is lost), in index order.
/// (An iterator, not a list: a triangle across a fine grid overlaps millions of cells.)
fn overlapped_cells<'a>(bx: &'a GridBox, t: &'a [Vec3; 3]) -> impl Iterator<Item = usize> + 'a {
    let margin = bx.cell * 1e-4;
    let lo = bx.cell_of(t[0].min(t[1]).min(t[2]) - margin);
    let hi = bx.cell_of(t[0].max(t[1]).max(t[2]) + margin);
    let half = bx.cell * 0.5 + margin;
    (lo.z..=hi.z)
        .flat_map(move |z| {
            (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| IVec3::new(x, y, z)))
        })
        .filter(move |&c| tri_box_overlap(bx.min + (c.as_vec3() + 0.5) * bx.cell, half, *t))
        .map(|c| bx.index(c).expect("clamped"))
}

/// References the grid may hold: Fig. 3 stores pointers and triangle ids as floats (RGB32F,
/// R32F), exact below 2^24.
pub const MAX_REFERENCES: usize = 1 << 24;

/// Host bytes per cell while the grid is built: (pointer, count) 8, the filled flag 1, the
/// proximity distance 4.
pub const CELL_BUILD_BYTES: u64 = 8 + 1 + 4;
/// Host bytes per cell while the grid is built and uploaded: [`CELL_BUILD_BYTES`], the cell's
/// RGB32F texel for the upload 12 and the driver's copy of it, padded to four channels, 16 (a
/// software driver's GPU memory is the host's).
pub const CELL_BYTES: u64 = CELL_BUILD_BYTES + 12 + 16;

/// Host bytes of one (cell, triangle) pair of the first pass.
const PAIR_BYTES: u64 = 8;
/// Host bytes per reference while the grid is built: the (cell, triangle) pair of the first
/// pass, three times over while the pairs grow (the old block and the new, twice as large, are
/// both held while they move), and the packed id 4.
pub const REFERENCE_BUILD_BYTES: u64 = 3 * PAIR_BYTES + 4;
/// Host bytes per reference, built and uploaded: its R32F texel 4 and the driver's copy 4 more.
pub const REFERENCE_BYTES: u64 = REFERENCE_BUILD_BYTES + 4 + 4;

impl StreamGrid {
    /// Register every triangle in the cells it overlaps, pack the lists, compute the
    /// proximity distances. The cells' memory is checked before it is allocated and the
    /// references are counted as they are found: a grid past the host's memory or past
    /// [`MAX_REFERENCES`] is refused before it is built, naming `--grid`.
    pub fn build(
        triangles: Vec<[Vec3; 3]>,
        bounds: (Vec3, Vec3),
        dims: UVec3,
    ) -> Result<StreamGrid, String> {
        let bx = GridBox::new(bounds.0, bounds.1, dims);
        let n = bx.cell_count();
        let what = format!(
            "the stream's grid of {}x{}x{} cells",
            dims.x, dims.y, dims.z
        );
        let mut budget = budget::Tracker::new(&what, "--grid");
        budget.add(n as u64 * CELL_BYTES)?;
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (id, t) in triangles.iter().enumerate() {
            for c in overlapped_cells(&bx, t) {
                if pairs.len() == pairs.capacity() {
                    // the pairs grow by doubling, and while they move the old block and the
                    // new one (twice as large) are both held: checked before it is taken
                    let more = pairs.capacity().max(4);
                    budget.add(2 * more as u64 * PAIR_BYTES)?;
                    pairs.reserve_exact(more);
                }
                if pairs.len() + 1 == MAX_REFERENCES {
                    return Err(format!(
                        "{what} would hold 2^24 or more references to the {} triangles (it \
                         passed that at triangle {id}): the float textures of Fig. 3 address at \
                         most 2^24; use a coarser --grid or a smaller scene",
                        triangles.len()
                    ));
                }
                pairs.push((c as u32, id as u32));
            }
        }
        // (the pairs were added as they grew)
        budget.add(pairs.len() as u64 * (REFERENCE_BYTES - 3 * PAIR_BYTES))?;
        let (cells, refs) = pack_by_cell(n, &pairs);
        drop(pairs);
        let filled: Vec<bool> = cells.iter().map(|&(_, count)| count > 0).collect();
        Ok(StreamGrid {
            proximity: chebyshev_distances(dims, &filled),
            bx,
            cells,
            refs,
            triangles,
        })
    }

    /// The paper's storage estimate M = 96·n + 16·gx·gy·gz bytes (ch. 4).
    pub fn paper_bytes(&self) -> u64 {
        96 * self.triangles.len() as u64 + 16 * self.bx.cell_count() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The heuristic against the paper's own figure: with g = ∛n per axis, M = 96·n + 16·g³
    /// bytes for 2.3 million triangles fits the test GPU's 256 MB, which 3·∛n would overflow
    /// about four times.
    #[test]
    fn auto_grid_is_the_cube_root_the_papers_memory_figure_needs() {
        assert_eq!(auto_dims(636), UVec3::splat(9)); // ∛636 ≈ 8.60
        assert_eq!(auto_dims(69451), UVec3::splat(41)); // ∛69451 ≈ 41.11
        assert_eq!(auto_dims(1), UVec3::ONE);
        let n: u64 = 2_300_000;
        let g = auto_dims(n as usize).x as u64;
        let bytes = 96 * n + 16 * g * g * g;
        assert!(bytes <= 256 << 20, "M = {bytes} for g = {g}");
        assert!(96 * n + 16 * (3 * g).pow(3) > 4 * (256 << 20));
    }
}
