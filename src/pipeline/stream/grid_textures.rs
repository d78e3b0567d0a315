//! The static grid and the triangles in texture memory, as seed 004's Fig. 3 lays them out
//! (two levels of indirection): the cells in a 3D RGB32F texture (pointer, count, proximity
//! distance), the references tightly packed in an R32F texture buffer, the triangles in two 3D
//! RGB32F textures of 4 depth slices each (v0, edge1, edge2, diffuse colour; n0, n1, n2,
//! reflectivity) — 8 texels, the paper's 96 bytes, per triangle.

use std::sync::Arc;

use anyhow::{bail, Result};
use glam::Vec3;

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

/// Per triangle and slice: the texels of the two triangle textures, slices of width×height.
fn triangle_texels(
    grid: &StreamGrid,
    scene: &Scene,
    width: u32,
    height: u32,
) -> [Vec<[f32; 3]>; 2] {
    let a = scene.world_attributes();
    let reflect: Vec<f32> = scene.materials.iter().map(|m| m.reflection).collect();
    let slice = (width * height) as usize;
    let mut vertex = vec![[0.0; 3]; 4 * slice];
    let mut normal = vec![[0.0; 3]; 4 * slice];
    for (id, t) in grid.triangles.iter().enumerate() {
        let k = 3 * id;
        let refl = reflect[a.triangle_material[id] as usize];
        let v: [Vec3; 4] = [t[0], t[1] - t[0], t[2] - t[0], a.colors[k]];
        let n: [Vec3; 4] = [
            a.normals[k],
            a.normals[k + 1],
            a.normals[k + 2],
            Vec3::new(refl, 0.0, 0.0),
        ];
        for s in 0..4 {
            vertex[s * slice + id] = v[s].to_array();
            normal[s * slice + id] = n[s].to_array();
        }
    }
    [vertex, normal]
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
        let cells: Vec<[f32; 3]> = grid
            .cells
            .iter()
            .zip(&grid.proximity)
            .map(|(&(first, count), &d)| [first as f32, count as f32, d as f32])
            .collect();
        let d = grid.bx.dims;
        let cells = Texture3d::rgb32f(gl, "cells", [d.x, d.y, d.z], &cells)?;
        let refs: Vec<f32> = grid.refs.iter().map(|&r| r as f32).collect();
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
        let [v, nn] = triangle_texels(grid, scene, width, height);
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
