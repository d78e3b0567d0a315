//! The GPU side of Wagner 2018's pipeline: the BVH in the three textures of Fig. 4.3 and the
//! triangles in three more (texture buffers, bound to the samplers of [`crate::gl::slots`]),
//! the images the kernel writes, and its uniforms.

use std::sync::Arc;

use anyhow::Result;
use glam::Vec3;

use super::uniforms::{Lighting, WagnerCamera};
use crate::gl::resources::{Image2d, TexelData, TextureBuffers};
use crate::gl::slots::{image, sampler};
use crate::gl::{Gl, Kernel};
use crate::pipeline::wagner2018::bvh::WagnerBvh;

/// RGBA32F texels of `v` (w = 0): CUDA's float4 textures held float3 too (Wagner 2018, ch. 6).
fn float4(v: &[Vec3]) -> Vec<[f32; 4]> {
    v.iter().map(|p| p.extend(0.0).to_array()).collect()
}

/// The six texture buffers: the BVH (Fig. 4.3) and the triangles.
pub struct SceneTextures {
    /// bounds, node integers, triangle ids; vertices, normals, colours
    textures: TextureBuffers,
}

/// The texels of the six textures.
fn texture_data(bvh: &WagnerBvh, normals: &[Vec3], colors: &[Vec3]) -> [TexelData<'static>; 6] {
    let vertices: Vec<Vec3> = bvh.triangles.iter().flatten().copied().collect();
    let data = |name, format, texel_bytes, bytes: &[u8], unit| {
        TexelData::new(name, format, texel_bytes, bytes, unit).into_owned()
    };
    let float4 = |name, v: &[Vec3], unit| {
        let texels = float4(v);
        data(name, glow::RGBA32F, 16, bytemuck::cast_slice(&texels), unit)
    };
    [
        data(
            "bvhBounds",
            glow::RGBA32F,
            16,
            bytemuck::cast_slice(&bvh.bounds_texels()),
            sampler::WAGNER_BVH_BOUNDS,
        ),
        data(
            "bvhNodes",
            glow::RGBA32I,
            16,
            bytemuck::cast_slice(&bvh.node_texels()),
            sampler::WAGNER_BVH_NODES,
        ),
        data(
            "bvhTriangles",
            glow::R32I,
            4,
            bytemuck::cast_slice(&bvh.triangle_texels()),
            sampler::WAGNER_BVH_TRIANGLES,
        ),
        float4("triVertices", &vertices, sampler::WAGNER_VERTICES),
        float4("triNormals", normals, sampler::WAGNER_NORMALS),
        float4("triColors", colors, sampler::WAGNER_COLORS),
    ]
}

impl SceneTextures {
    /// Upload `bvh` and the triangles' per-vertex `normals` and `colors` (3 per triangle).
    pub fn upload(
        gl: &Arc<Gl>,
        bvh: &WagnerBvh,
        normals: &[Vec3],
        colors: &[Vec3],
    ) -> Result<SceneTextures> {
        Ok(SceneTextures {
            textures: TextureBuffers::upload(gl, texture_data(bvh, normals, colors))?,
        })
    }

    /// Bytes of the three BVH textures and of the three triangle textures.
    pub fn bytes(&self) -> (usize, usize) {
        (self.textures.bytes(0..3), self.textures.bytes(3..6))
    }

    pub fn bind(&self, gl: &Gl) {
        self.textures.bind(gl);
    }
}

/// The images the kernel writes (RGBA32F, GL row order).
pub struct Images {
    /// ch. 4.3: the rendered image (rgb, 1)
    pub output: Image2d,
    /// (t, triangle id as bits, u, v) of the first hit
    pub hit: Image2d,
    /// the primary ray's direction (AOVs only)
    pub ray: Image2d,
    /// the normal at the first hit, w: 1 lit, 0 in shadow (AOVs only)
    pub normal: Image2d,
}

impl Images {
    pub fn new(gl: &Arc<Gl>, w: u32, h: u32) -> Result<Images> {
        let f = glow::RGBA32F;
        Ok(Images {
            output: Image2d::new(gl, w, h, f)?,
            hit: Image2d::new(gl, w, h, f)?,
            ray: Image2d::new(gl, w, h, f)?,
            normal: Image2d::new(gl, w, h, f)?,
        })
    }

    fn all(&self) -> [(&Image2d, u32); 4] {
        [
            (&self.output, image::WAGNER_OUTPUT),
            (&self.hit, image::WAGNER_HIT),
            (&self.ray, image::WAGNER_RAY),
            (&self.normal, image::WAGNER_NORMAL),
        ]
    }

    pub fn bind(&self, gl: &Gl) {
        self.all()
            .iter()
            .for_each(|(i, unit)| i.bind_image(gl, *unit));
    }
}

/// The kernel's uniforms for a frame: Listing 4.1's camera, the light, the image.
pub fn set_uniforms(k: &Kernel, cam: &WagnerCamera, l: &Lighting, size: (u32, u32), aovs: bool) {
    k.set_vec3("camera.position", cam.position.to_array());
    k.set_vec3("camera.direction", cam.direction.to_array());
    k.set_vec3("camera.xDirection", cam.x_direction.to_array());
    k.set_vec3("camera.yDirection", cam.y_direction.to_array());
    k.set_f32("camera.xScale", cam.x_scale);
    k.set_f32("camera.yScale", cam.y_scale);
    k.set_ivec2("imageSize2", [size.0 as i32, size.1 as i32]);
    k.set_vec3("lightPosition", l.light_position.to_array());
    k.set_vec3("lightColor", l.light_color.to_array());
    k.set_vec3("ambientColor", l.ambient.to_array());
    k.set_vec3("backgroundColor", l.background.to_array());
    k.set_i32("storeAovs", aovs as i32);
}
