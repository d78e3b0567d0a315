//! The static grid and the triangles in texture memory, as the streaming tracer's Fig. 3 lays them
//! out (two levels of indirection): the cells in a 3D RGB32F texture (pointer, count, proximity
//! distance), the references tightly packed in an R32F texture buffer, the triangles in two 3D
//! RGB32F textures of 4 depth slices each (v0, edge1, edge2, diffuse colour; n0, n1, n2,
//! reflectivity) — 8 texels, the paper's 96 bytes, per triangle. Each texel's layout is a
//! `#[repr(C)]` record here ([`CellTexel`], [`ReferenceTexel`], [`TriangleVertexTexels`],
//! [`TriangleNormalTexels`]), named with its fields in `glsl/stream/grid.glsl`.

use std::sync::Arc;

use anyhow::{bail, Result};
use bytemuck::{Pod, Zeroable};

use super::grid::{StreamGrid, MAX_REFERENCES};
use crate::gl::resources::{TexelData, Texture3d, TextureBuffers};
use crate::gl::slots::sampler;
use crate::gl::{Gl, Kernel};
use crate::scene::Scene;

/// Pointers and triangle ids are stored as floats (RGB32F, R32F, as the paper): exact below
/// 2^24.
const FLOAT_EXACT: usize = MAX_REFERENCES;

pub struct GridTextures {
    cells: Texture3d,
    refs: TextureBuffers,
    tri_vertex: Texture3d,
    tri_normal: Texture3d,
    /// the triangle textures' width (triangle id → x, y)
    tri_width: u32,
}

/// One texel of the `cells` texture (RGB32F, one per grid cell, x fastest; Fig. 3's first
/// level of indirection). Floats, as the paper stores them: exact below 2^24
/// ([`FLOAT_EXACT`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct CellTexel {
    /// R: the index in `references` of the cell's first reference
    pub pointer: f32,
    /// G: how many references the cell holds (they follow `pointer`, ascending ids)
    pub count: f32,
    /// B: the proximity-cloud distance, in cells, to the nearest non-empty cell (Chebyshev;
    /// 0 for a non-empty cell)
    pub proximity: f32,
}
const _: () = assert!(size_of::<CellTexel>() == 12);

/// One texel of the `references` texture buffer (R32F): the lists of all cells, tightly
/// packed, in cell order.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct ReferenceTexel {
    /// R: a triangle id, which places the triangle's texels in `triVertex` and `triNormal`
    pub triangle: f32,
}
const _: () = assert!(size_of::<ReferenceTexel>() == 4);

/// A triangle's four texels of the `triVertex` texture (RGB32F, 4 depth slices): field `k`
/// is its texel in slice `k`, at the (x, y) of its id.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct TriangleVertexTexels {
    /// slice 0: the first vertex, world space
    pub v0: [f32; 3],
    /// slice 1: v1 − v0 ("edge1 and edge2 are stored instead of v1 and v2", ch. 3)
    pub edge1: [f32; 3],
    /// slice 2: v2 − v0
    pub edge2: [f32; 3],
    /// slice 3: the diffuse colour (of the first vertex)
    pub color: [f32; 3],
}
const _: () = assert!(size_of::<TriangleVertexTexels>() == 48);

/// A triangle's four texels of the `triNormal` texture (RGB32F, 4 depth slices): field `k`
/// is its texel in slice `k`, at the (x, y) of its id.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct TriangleNormalTexels {
    /// slices 0–2: the vertex normals, world space
    pub n0: [f32; 3],
    pub n1: [f32; 3],
    pub n2: [f32; 3],
    /// slice 3, R: the material's reflectivity
    pub reflectivity: f32,
    /// slice 3, G and B: 0
    pub unused: [f32; 2],
}
const _: () = assert!(size_of::<TriangleNormalTexels>() == 48);

/// The cells' texels, in cell index order.
fn cell_texels(grid: &StreamGrid) -> Vec<CellTexel> {
    grid.cells
        .iter()
        .zip(&grid.proximity)
        .map(|(&(first, count), &d)| CellTexel {
            pointer: first as f32,
            count: count as f32,
            proximity: d as f32,
        })
        .collect()
}

/// Four slices of `width`×`height` texels: field `k` of record `id` at texel `id` of slice
/// `k` (the rest 0).
fn slices<T: Pod>(records: &[T], width: u32, height: u32) -> Vec<[f32; 3]> {
    let slice = (width * height) as usize;
    let mut out = vec![[0.0; 3]; 4 * slice];
    for (id, r) in records.iter().enumerate() {
        let fields: &[[f32; 3]] = bytemuck::cast_slice(std::slice::from_ref(r));
        for (k, f) in fields.iter().enumerate() {
            out[k * slice + id] = *f;
        }
    }
    out
}

/// Per triangle its texels of the two triangle textures, in id order.
fn triangle_texels(
    grid: &StreamGrid,
    scene: &Scene,
) -> (Vec<TriangleVertexTexels>, Vec<TriangleNormalTexels>) {
    let a = scene.world_attributes();
    let reflect: Vec<f32> = scene.materials.iter().map(|m| m.reflection).collect();
    grid.triangles
        .iter()
        .enumerate()
        .map(|(id, t)| {
            let k = 3 * id;
            let vertex = TriangleVertexTexels {
                v0: t[0].to_array(),
                edge1: (t[1] - t[0]).to_array(),
                edge2: (t[2] - t[0]).to_array(),
                color: a.colors[k].to_array(),
            };
            let normal = TriangleNormalTexels {
                n0: a.normals[k].to_array(),
                n1: a.normals[k + 1].to_array(),
                n2: a.normals[k + 2].to_array(),
                reflectivity: reflect[a.triangle_material[id] as usize],
                unused: [0.0; 2],
            };
            (vertex, normal)
        })
        .unzip()
}

impl GridTextures {
    /// Upload `grid` (built over `scene`'s world triangles) with the scene's normals, colours
    /// and reflectivities.
    pub fn upload(gl: &Arc<Gl>, grid: &StreamGrid, scene: &Scene) -> Result<GridTextures> {
        let n = grid.triangles.len();
        if grid.refs.len() >= FLOAT_EXACT || n >= FLOAT_EXACT {
            bail!(
                "the grid holds {} references to {n} triangles: the float textures of Fig. 3 \
                 address at most 2^24; use a coarser grid or a smaller scene",
                grid.refs.len()
            );
        }
        let cells = cell_texels(grid);
        let d = grid.bx.dims;
        let cells = Texture3d::rgb32f(gl, "cells", [d.x, d.y, d.z], bytemuck::cast_slice(&cells))?;
        let refs: Vec<ReferenceTexel> = grid
            .refs
            .iter()
            .map(|&r| ReferenceTexel { triangle: r as f32 })
            .collect();
        let refs = TextureBuffers::upload(
            gl,
            [TexelData::new(
                "references",
                glow::R32F,
                4,
                bytemuck::cast_slice(&refs),
                sampler::STREAM_REFS,
            )],
        )?;
        let width = (n as u32).clamp(1, 2048);
        let height = (n as u32).div_ceil(width).max(1);
        let (vertex, normal) = triangle_texels(grid, scene);
        let v = slices(&vertex, width, height);
        let nn = slices(&normal, width, height);
        Ok(GridTextures {
            cells,
            refs,
            tri_vertex: Texture3d::rgb32f(gl, "triVertex", [width, height, 4], &v)?,
            tri_normal: Texture3d::rgb32f(gl, "triNormal", [width, height, 4], &nn)?,
            tri_width: width,
        })
    }

    /// Bytes on the GPU: cells, references, triangles.
    pub fn bytes(&self) -> [usize; 3] {
        [
            self.cells.bytes,
            self.refs.bytes(0..1),
            self.tri_vertex.bytes + self.tri_normal.bytes,
        ]
    }

    pub fn bind(&self, gl: &Gl) {
        self.cells.bind(gl, sampler::STREAM_CELLS);
        self.refs.bind(gl);
        self.tri_vertex.bind(gl, sampler::STREAM_TRI_VERTEX);
        self.tri_normal.bind(gl, sampler::STREAM_TRI_NORMAL);
    }

    /// The uniforms of `glsl/stream/grid.glsl` (the program in use).
    pub fn set_uniforms(&self, k: &Kernel, grid: &StreamGrid) {
        let b = &grid.bx;
        k.set_vec3("gridMin", b.min.to_array());
        k.set_vec3("gridMax", b.max.to_array());
        k.set_vec3("cellSize", b.cell.to_array());
        k.set_ivec3("gridSize", b.dims.as_ivec3().to_array());
        k.set_i32("triTextureWidth", self.tri_width as i32);
    }
}
