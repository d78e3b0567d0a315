//! The scene on the GPU, as Müller 2015 ch. 3.1.2 keeps it: the object-space vertex
//! attributes in VBOs (uploaded once), and the SSBOs the kernels read, filled by
//! the transform pass (`glsl/mueller2015/transform.vert`, rasterizer discarded) from the VBOs and each
//! object's model and normal matrices. Materials, lights and textures live beside them.
//!
//! Deviation (ours): the thesis runs the transform pass over every object every frame; here a
//! frame draws only the objects whose model matrix changed since their vertices were last
//! written (the lights once), since the SSBOs keep what the pass wrote and the kernels only read
//! them — the same buffers, without re-transforming a static scene every frame
//! (`docs/design/frame.md`). And once the first frame's pass has written every attribute, a
//! moved object's vertices and normals — all a model matrix changes — are rewritten by a compute
//! kernel (`glsl/mueller2015/transform_moved.comp`, [`MovedTransform`]): llvmpipe runs a draw's
//! vertex shader on the calling thread, a dispatch on all its threads (`docs/design/bvh.md`,
//! "Moving objects").

use std::sync::Arc;

use anyhow::{anyhow, bail, Context as _, Result};
use glam::{Mat3, Mat4};
use glow::HasContext;

use crate::gl::resources::{bind_image_unit, buffer_view, GpuTimers, Owned, Ssbo};
use crate::gl::slots;
use crate::gl::{Defines, Gl, GlInfo, Kernel, ShaderSource};
use crate::scene::{budget, Scene};

/// SSBO binding points of the scene, shared with `glsl/common/scene.glsl`.
pub use crate::gl::slots::ssbo as binding;

pub struct GpuScene {
    vao: Owned<glow::VertexArray>,
    light_vao: Owned<glow::VertexArray>,
    /// held for the VAOs, which read them
    _vbos: Vec<Owned<glow::Buffer>>,
    /// (first vertex, vertex count) of every object in the VBOs and SSBOs.
    ranges: Vec<(i32, i32)>,
    light_count: i32,
    ssbos: Vec<(u32, Ssbo)>,
    transform: Kernel,
    /// An FBO with a 1×1 renderbuffer: a surfaceless context has no default framebuffer to
    /// draw the (discarded) points into.
    fbo: Owned<glow::Framebuffer>,
    _rbo: Owned<glow::Renderbuffer>,
    textures: Owned<glow::Texture>,
    /// The normals, colours, lights and vertex SSBOs viewed as RGBA32F buffer textures (image
    /// unit, view), where the GL has the image units: [`vertex_images`](GpuScene::vertex_images).
    vertex_views: Vec<(u32, Owned<glow::Texture>)>,
    pub triangles: usize,
    /// The model matrices the SSBOs were last written with (none before the first pass).
    written: Option<Vec<Mat4>>,
    /// The moved objects' compute pass, where the VBOs fit storage buffers.
    moved: Option<MovedTransform>,
}

/// The transform of the objects that moved once the SSBOs are written (ours,
/// `glsl/mueller2015/transform_moved.comp`): their vertices and normals only, in a compute
/// kernel that reads the transform pass' position and normal VBOs as storage buffers.
struct MovedTransform {
    kernel: Kernel,
    positions: glow::Buffer,
    normals: glow::Buffer,
    /// the same as R32F image buffers (`TRANSFORM_VIEWS`), where the GL has the units
    views: Option<[Owned<glow::Texture>; 2]>,
}

/// Invocations of a work group of `transform_moved.comp` (`TRANSFORM_GROUP`).
const TRANSFORM_GROUP: u32 = 64;

impl MovedTransform {
    /// The pass over the VBOs `vbos[0]` (positions) and `vbos[1]` (normals), unless they exceed
    /// `GL_MAX_SHADER_STORAGE_BLOCK_SIZE` (then the vertex-shader pass does it all).
    fn new(
        gl: &Arc<Gl>,
        info: &GlInfo,
        shaders: &ShaderSource,
        vbos: &[Owned<glow::Buffer>],
        bytes: usize,
    ) -> Result<Option<MovedTransform>> {
        if bytes as i64 > info.max_ssbo_block_size {
            return Ok(None);
        }
        let floats = bytes / 4;
        let view = |vbo: &Owned<glow::Buffer>, unit| {
            buffer_view(
                gl,
                vbo.raw(),
                floats,
                info.profile.image_units,
                unit,
                glow::R32F,
            )
        };
        let views = match (
            view(&vbos[0], slots::image::TRANSFORM_POSITIONS)?,
            view(&vbos[1], slots::image::TRANSFORM_NORMALS)?,
        ) {
            (Some(p), Some(n)) => Some([p, n]),
            _ => None,
        };
        let defines = Defines::new()
            .set("TRANSFORM_GROUP", TRANSFORM_GROUP)
            .set("TRANSFORM_VIEWS", views.is_some() as i32);
        let kernel = Kernel::compute(
            gl,
            shaders,
            "mueller2015/transform_moved.comp",
            &defines,
            "transform",
        )?;
        Ok(Some(MovedTransform {
            kernel,
            positions: vbos[0].raw(),
            normals: vbos[1].raw(),
            views,
        }))
    }

    /// One dispatch per moved object, with its model and normal matrices.
    fn run(
        &self,
        gl: &Gl,
        timers: &mut GpuTimers,
        moved: &[usize],
        ranges: &[(i32, i32)],
        models: &[Mat4],
    ) {
        use crate::gl::slots::ssbo;
        let k = &self.kernel;
        k.use_program();
        // SAFETY: binding our own buffers to storage-buffer binding points.
        unsafe {
            gl.bind_buffer_base(
                glow::SHADER_STORAGE_BUFFER,
                ssbo::TRANSFORM_POSITIONS,
                Some(self.positions),
            );
            gl.bind_buffer_base(
                glow::SHADER_STORAGE_BUFFER,
                ssbo::TRANSFORM_NORMALS,
                Some(self.normals),
            );
        }
        if let Some([p, n]) = &self.views {
            let (access, format) = (glow::READ_ONLY, glow::R32F);
            bind_image_unit(
                gl,
                slots::image::TRANSFORM_POSITIONS,
                p.raw(),
                access,
                format,
            );
            bind_image_unit(gl, slots::image::TRANSFORM_NORMALS, n.raw(), access, format);
        }
        for &i in moved {
            let (first, count) = ranges[i];
            let normal = Mat3::from_mat4(models[i]).inverse().transpose();
            k.set_mat4("modelMatrix", &models[i].to_cols_array());
            k.set_mat3("normalMatrix", &normal.to_cols_array());
            k.set_i32("first", first);
            k.set_i32("count", count);
            k.dispatch_1d(timers, (count as u32).div_ceil(TRANSFORM_GROUP));
        }
    }
}

fn upload_vbo(gl: &Arc<Gl>, data: &[u8]) -> Result<Owned<glow::Buffer>> {
    // SAFETY: buffer creation with data on a current context.
    unsafe {
        let b = Owned::new(gl, gl.create_buffer().map_err(|e| anyhow!(e))?);
        gl.bind_buffer(glow::ARRAY_BUFFER, Some(b.raw()));
        gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, data, glow::STATIC_DRAW);
        crate::gl::check_alloc(gl, "a vertex buffer of the scene", data.len() as u64)?;
        Ok(b)
    }
}

/// A VBO of `size`-component float vectors as vertex attribute `loc` of the bound VAO.
fn float_attribute(gl: &Arc<Gl>, loc: u32, data: &[u8], size: i32) -> Result<Owned<glow::Buffer>> {
    let b = upload_vbo(gl, data)?;
    // SAFETY: attribute setup of the bound VAO from the bound buffer `b`.
    unsafe {
        gl.enable_vertex_attrib_array(loc);
        gl.vertex_attrib_pointer_f32(loc, size, glow::FLOAT, false, 0, 0);
    }
    Ok(b)
}

/// Object-space vertex attributes of all objects, one array per VBO, as the thesis' RTObject
/// keeps them.
struct VertexData {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    colors: Vec<[f32; 3]>,
    texcoords: Vec<[f32; 2]>,
    /// The material id of each vertex's triangle.
    materials: Vec<i32>,
    /// (first vertex, vertex count) of every object.
    ranges: Vec<(i32, i32)>,
}

impl VertexData {
    fn of(scene: &Scene) -> VertexData {
        let vertices = scene.vertex_count();
        let mut d = VertexData {
            positions: Vec::with_capacity(vertices),
            normals: Vec::with_capacity(vertices),
            colors: Vec::with_capacity(vertices),
            texcoords: Vec::with_capacity(vertices),
            materials: Vec::with_capacity(vertices),
            ranges: Vec::new(),
        };
        for o in &scene.objects {
            let m = &o.mesh;
            d.ranges
                .push((d.positions.len() as i32, m.positions.len() as i32));
            d.positions.extend(m.positions.iter().map(|v| v.to_array()));
            d.normals.extend(m.normals.iter().map(|v| v.to_array()));
            d.colors.extend(m.colors.iter().map(|v| v.to_array()));
            d.texcoords.extend(m.texcoords.iter().map(|v| v.to_array()));
            d.materials
                .extend(m.triangle_material.iter().flat_map(|m| [*m as i32; 3]));
        }
        d
    }
}

/// What the transform pass needs of the device, and a warning for a scene without lights.
fn check_device(info: &GlInfo, scene: &Scene) -> Result<()> {
    if scene.lights.is_empty() && scene.area_lights.is_empty() {
        log::warn!(
            "{}: the scene has no lights; only ambient light",
            scene.path.display()
        );
    }
    if info.max_vertex_shader_storage_blocks < 8 {
        bail!(
            "the transform pass writes 7 shader storage blocks from a vertex shader, \
             GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS is {}",
            info.max_vertex_shader_storage_blocks
        );
    }
    Ok(())
}

/// The transform pass' VAOs, objects and lights, and all their VBOs.
type VertexArrays = (
    Owned<glow::VertexArray>,
    Owned<glow::VertexArray>,
    Vec<Owned<glow::Buffer>>,
);

/// The transform pass' VAOs, objects and lights, and all their VBOs.
fn vertex_arrays(gl: &Arc<Gl>, scene: &Scene, data: &VertexData) -> Result<VertexArrays> {
    let mut vbos = Vec::new();
    // SAFETY: VAO/VBO setup on a current context.
    unsafe {
        let vao = Owned::new(gl, gl.create_vertex_array().map_err(|e| anyhow!(e))?);
        gl.bind_vertex_array(Some(vao.raw()));
        for (loc, bytes, n) in [
            (0u32, bytemuck::cast_slice::<_, u8>(&data.positions), 3),
            (1, bytemuck::cast_slice(&data.normals), 3),
            (2, bytemuck::cast_slice(&data.colors), 3),
            (3, bytemuck::cast_slice(&data.texcoords), 2),
        ] {
            vbos.push(float_attribute(gl, loc, bytes, n)?);
        }
        let b = upload_vbo(gl, bytemuck::cast_slice(&data.materials))?;
        gl.enable_vertex_attrib_array(4);
        gl.vertex_attrib_pointer_i32(4, 1, glow::INT, 0, 0);
        vbos.push(b);

        let light_vao = Owned::new(gl, gl.create_vertex_array().map_err(|e| anyhow!(e))?);
        gl.bind_vertex_array(Some(light_vao.raw()));
        let lp: Vec<[f32; 3]> = scene.lights.iter().map(|l| l.position.to_array()).collect();
        let lc: Vec<[f32; 3]> = scene.lights.iter().map(|l| l.color.to_array()).collect();
        for (loc, v) in [(0u32, lp), (2, lc)] {
            vbos.push(float_attribute(gl, loc, bytemuck::cast_slice(&v), 3)?);
        }
        gl.bind_vertex_array(None);
        gl.bind_buffer(glow::ARRAY_BUFFER, None);
        Ok((vao, light_vao, vbos))
    }
}

/// The SSBOs the kernels read: per vertex and per light, filled by the transform pass, and the
/// materials (reflection, specular, shininess, texture layer or -1), uploaded here.
fn scene_ssbos(gl: &Arc<Gl>, scene: &Scene, max: i64) -> Result<Vec<(u32, Ssbo)>> {
    let materials: Vec<[f32; 4]> = scene
        .materials
        .iter()
        .map(|m| {
            let texture = m.texture.map(|t| t as f32).unwrap_or(-1.0);
            [m.reflection, m.specular, m.shininess, texture]
        })
        .collect();
    let material_bytes: &[u8] = bytemuck::cast_slice(&materials);
    ssbo_sizes(scene)
        .into_iter()
        .map(|(b, name, bytes)| {
            let data = (b == binding::MATERIAL).then_some(material_bytes);
            Ok((b, Ssbo::new(gl, name, bytes, data, max)?))
        })
        .collect()
}

/// The normals, colours, lights and vertex SSBOs as RGBA32F buffer textures over the same storage (no
/// copy: the transform pass' stores show through them after its barrier), for the hit
/// evaluation and shading:
/// llvmpipe loads a storage-buffer vector lane by lane and component by component, an image
/// texel for all lanes at once (docs/design/frame.md). None where the GL lacks the image units
/// (GL 4.5 guarantees 8, which the ray-state images and the BVH take) or the texels.
fn vertex_views(
    gl: &Arc<Gl>,
    info: &GlInfo,
    ssbos: &[(u32, Ssbo)],
) -> Result<Vec<(u32, Owned<glow::Texture>)>> {
    use crate::gl::slots::image;
    let views = [
        (binding::NORMAL, image::SCENE_NORMAL),
        (binding::COLOR, image::SCENE_COLOR),
        (binding::LIGHT_POS, image::SCENE_LIGHT_POS),
        (binding::LIGHT_COLOR, image::SCENE_LIGHT_COLOR),
        (binding::VERTEX, image::SCENE_VERTEX),
    ];
    let ssbo = |b: u32| {
        &ssbos
            .iter()
            .find(|(sb, _)| *sb == b)
            .expect("a scene SSBO")
            .1
    };
    let mut made = Vec::new();
    for (b, unit) in views {
        match ssbo(b).texel_view(gl, info.profile.image_units, unit, glow::RGBA32F)? {
            Some(t) => made.push((unit, t)),
            // all four or none: the kernels read all of them one way
            None => return Ok(Vec::new()),
        }
    }
    Ok(made)
}

/// Binding, name and bytes of every scene SSBO.
fn ssbo_sizes(scene: &Scene) -> [(u32, &'static str, usize); 8] {
    let triangles = scene.triangle_count();
    let vertices = 3 * triangles;
    let lights = scene.lights.len().max(1);
    [
        (binding::VERTEX, "vertex", 16 * vertices),
        (binding::NORMAL, "normals", 16 * vertices),
        (binding::COLOR, "colors", 16 * vertices),
        (binding::TEXCOORD, "texcoords", 8 * vertices),
        (binding::TRI_MATERIAL, "triMaterial", 4 * triangles),
        (binding::MATERIAL, "material", 16 * scene.materials.len()),
        (binding::LIGHT_POS, "lightPos", 16 * lights),
        (binding::LIGHT_COLOR, "lightColor", 16 * lights),
    ]
}

/// The most triangles Müller 2015's pipeline renders: their ids travel in float channels.
pub const MAX_TRIANGLES: usize = 1 << 24;

/// The scene file `path`, whose objects will give `triangles` ([`Scene::count_triangles`]),
/// within this pipeline's limits, checked before the scene is loaded: the ids' 2^24 and the
/// per-vertex buffers (16 bytes a vertex) within `GL_MAX_SHADER_STORAGE_BLOCK_SIZE`.
pub fn check_counts(info: &GlInfo, path: &std::path::Path, triangles: u64) -> Result<()> {
    if triangles > MAX_TRIANGLES as u64 {
        bail!(
            "{}: {triangles} triangles, more than the {MAX_TRIANGLES} whose ids the ray-state \
             images carry exactly (a float channel: 2^24)",
            path.display()
        );
    }
    let bytes = 16 * 3 * triangles;
    if bytes > info.max_ssbo_block_size.max(0) as u64 {
        bail!(
            "{}: {triangles} triangles need {} in the scene buffer `vertex` (16 bytes a \
             vertex), more than GL_MAX_SHADER_STORAGE_BLOCK_SIZE = {} of this GL implementation",
            path.display(),
            budget::human(bytes),
            budget::human(info.max_ssbo_block_size.max(0) as u64),
        );
    }
    Ok(())
}

/// Every buffer the upload will make, estimated before any is made: each SSBO within
/// `GL_MAX_SHADER_STORAGE_BLOCK_SIZE`, the vertex arrays (host copy and VBOs) within the host's
/// memory.
pub fn check_sizes(info: &GlInfo, scene: &Scene) -> Result<()> {
    let triangles = scene.triangle_count();
    // the kernels carry a triangle id in a float channel of the ray state (rayDir.w, the
    // colour buffer's carried hit): exact up to 2^24
    check_counts(info, &scene.path, triangles as u64)?;
    for (_, name, bytes) in ssbo_sizes(scene) {
        if bytes as i64 > info.max_ssbo_block_size {
            bail!(
                "{}: {triangles} triangles need {} in the scene buffer `{name}`, more than \
                 GL_MAX_SHADER_STORAGE_BLOCK_SIZE = {} of this GL implementation",
                scene.path.display(),
                budget::human(bytes as u64),
                budget::human(info.max_ssbo_block_size as u64),
            );
        }
    }
    // the vertex data on the host and in the VBOs: 3 positions, normals, colours (12 bytes),
    // texture coordinates (8) and material ids (4) per triangle, twice
    let bytes = 2 * 3 * (12 + 12 + 12 + 8 + 4) * triangles as u64;
    budget::check_host(&format!("uploading {triangles} triangles"), bytes)
        .map_err(|m| anyhow!("{}: {m}", scene.path.display()))
}

/// An FBO with a 1×1 renderbuffer for the transform pass' (discarded) points.
fn point_target(gl: &Arc<Gl>) -> Result<(Owned<glow::Framebuffer>, Owned<glow::Renderbuffer>)> {
    // SAFETY: framebuffer setup on a current context.
    unsafe {
        let fbo = Owned::new(gl, gl.create_framebuffer().map_err(|e| anyhow!(e))?);
        let rbo = Owned::new(gl, gl.create_renderbuffer().map_err(|e| anyhow!(e))?);
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rbo.raw()));
        gl.renderbuffer_storage(glow::RENDERBUFFER, glow::RGBA8, 1, 1);
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo.raw()));
        gl.framebuffer_renderbuffer(
            glow::FRAMEBUFFER,
            glow::COLOR_ATTACHMENT0,
            glow::RENDERBUFFER,
            Some(rbo.raw()),
        );
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        Ok((fbo, rbo))
    }
}

impl GpuScene {
    pub fn new(
        gl: &Arc<Gl>,
        info: &GlInfo,
        scene: &Scene,
        shaders: &ShaderSource,
    ) -> Result<GpuScene> {
        check_device(info, scene)?;
        crate::scene::validate::scene(scene)
            .map_err(|m| anyhow!("{}: {m}", scene.path.display()))?;
        check_sizes(info, scene)?;
        let data = VertexData::of(scene);
        let program = Kernel::program(
            gl,
            shaders,
            &[(glow::VERTEX_SHADER, "mueller2015/transform.vert")],
            &Defines::new().set("SCENE_TRIANGLES", scene.triangle_count()),
            "transform",
        )?;
        let (vao, light_vao, vbos) = vertex_arrays(gl, scene, &data)?;
        let ssbos = scene_ssbos(gl, scene, info.max_ssbo_block_size)?;
        let (fbo, rbo) = point_target(gl)?;
        let textures = upload_textures(gl, info, scene)?;
        let vertex_views = vertex_views(gl, info, &ssbos)?;
        let vbo_bytes = std::mem::size_of_val(data.positions.as_slice());
        let moved = MovedTransform::new(gl, info, shaders, &vbos, vbo_bytes)?;
        crate::gl::check_error(gl, "uploading the scene")?;
        Ok(GpuScene {
            vao,
            light_vao,
            _vbos: vbos,
            ranges: data.ranges,
            light_count: scene.lights.len() as i32,
            ssbos,
            transform: program,
            fbo,
            _rbo: rbo,
            textures,
            vertex_views,
            triangles: scene.triangle_count(),
            written: None,
            moved,
        })
    }

    /// Bytes of GPU memory in the scene SSBOs.
    pub fn ssbo_bytes(&self) -> usize {
        self.ssbos.iter().map(|(_, s)| s.bytes).sum()
    }

    /// Whether the vertex normals and colours and the lights are also bound as image buffers
    /// (`SCENE_IMAGES` of `glsl/bvh/vertex_attributes.glsl` and `glsl/mueller2015/shade.glsl`).
    pub fn vertex_images(&self) -> bool {
        !self.vertex_views.is_empty()
    }

    pub fn bind(&self, gl: &Gl) {
        for (b, s) in &self.ssbos {
            s.bind(gl, *b);
        }
        for (unit, view) in &self.vertex_views {
            // SAFETY: binding our own buffer texture to an image unit, read-only.
            unsafe {
                let (t, f) = (Some(view.raw()), glow::RGBA32F);
                gl.bind_image_texture(*unit, t, 0, false, 0, glow::READ_ONLY, f);
            }
        }
        // SAFETY: binding our texture array to its unit (sampler `textures`).
        unsafe {
            gl.active_texture(glow::TEXTURE0 + crate::gl::slots::sampler::TEXTURES);
            gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(self.textures.raw()));
        }
    }

    /// The transform pass: the vertices of every object whose model matrix changed since the
    /// SSBOs were written (every object the first time) through it into the SSBOs, and the
    /// first time the lights. `models[i]` is object i's model matrix. No pass (and no
    /// `transform` time) when nothing moved.
    pub fn transform(&mut self, gl: &Gl, timers: &mut GpuTimers, models: &[Mat4]) {
        let moved: Vec<usize> = (0..models.len())
            .filter(|&i| self.written.as_ref().is_none_or(|w| w[i] != models[i]))
            .collect();
        let lights = self.written.is_none() && self.light_count > 0;
        if moved.is_empty() && !lights {
            return;
        }
        self.bind(gl);
        if self.written.is_some() {
            if let Some(m) = &self.moved {
                m.run(gl, timers, &moved, &self.ranges, models);
                self.written = Some(models.to_vec());
                return;
            }
        }
        let k = &self.transform;
        k.use_program();
        // a pass whose vertex shader stores into the scene's buffers, which the last frame's
        // kernels read: a pass with the barriers of gl::sync. GL 4.6 §7.12 leaves open how often
        // a vertex shader runs for a vertex; the stores are idempotent, so any count gives the
        // same buffers
        crate::gl::sync::before(gl, crate::gl::sync::SHADER);
        timers.time(gl, k.timer(), || {
            // SAFETY: draws with our program and VAOs; rasterization is discarded.
            unsafe {
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo.raw()));
                gl.enable(glow::RASTERIZER_DISCARD);
                k.set_i32("transformLights", 0);
                gl.bind_vertex_array(Some(self.vao.raw()));
                for &i in &moved {
                    let (first, count) = self.ranges[i];
                    let normal = Mat3::from_mat4(models[i]).inverse().transpose();
                    k.set_mat4("modelMatrix", &models[i].to_cols_array());
                    k.set_mat3("normalMatrix", &normal.to_cols_array());
                    gl.draw_arrays(glow::POINTS, first, count);
                }
                if lights {
                    k.set_i32("transformLights", 1);
                    k.set_mat4("modelMatrix", &Mat4::IDENTITY.to_cols_array());
                    gl.bind_vertex_array(Some(self.light_vao.raw()));
                    gl.draw_arrays(glow::POINTS, 0, self.light_count);
                }
                gl.bind_vertex_array(None);
                gl.disable(glow::RASTERIZER_DISCARD);
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            }
        });
        crate::gl::sync::after_pass(gl);
        self.written = Some(models.to_vec());
    }
}

/// The texture layers (every texture resized to the largest sides, at most
/// GL_MAX_TEXTURE_SIZE) and their upload copy within the host's memory, before they are made.
fn check_texture_memory(info: &GlInfo, scene: &Scene) -> Result<()> {
    let max = info.max_texture_size.max(1) as u64;
    let side = |f: fn(&image::RgbaImage) -> u32| {
        let most = scene.textures.iter().map(|(_, t)| f(t) as u64).max();
        most.unwrap_or(1).min(max)
    };
    let layers = scene.textures.len().max(1) as u64;
    let bytes = 2 * 4 * layers * side(|t| t.width()) * side(|t| t.height());
    budget::check_host(&format!("{layers} texture layers"), bytes)
        .map_err(|m| anyhow!("{}: {m}", scene.path.display()))
}

/// All textures as layers of one RGBA8 2D array texture (bilinear, repeat), sampled by
/// intersect1 with the material's layer. A scene without textures gets one white texel.
fn upload_textures(gl: &Arc<Gl>, info: &GlInfo, scene: &Scene) -> Result<Owned<glow::Texture>> {
    check_texture_memory(info, scene)?;
    let (w, h, layers) = scene.texture_layers(info.max_texture_size as u32);
    if layers.len() > info.max_array_texture_layers.max(1) as usize {
        bail!(
            "{} textures, more than GL_MAX_ARRAY_TEXTURE_LAYERS = {}",
            layers.len(),
            info.max_array_texture_layers
        );
    }
    let mut data = Vec::with_capacity((w * h * 4) as usize * layers.len());
    for l in &layers {
        data.extend_from_slice(l.as_raw());
    }
    // SAFETY: texture upload of w·h·layers RGBA8 texels.
    unsafe {
        let t = Owned::new(gl, gl.create_texture().map_err(|e| anyhow!(e))?);
        gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(t.raw()));
        gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
        gl.tex_image_3d(
            glow::TEXTURE_2D_ARRAY,
            0,
            glow::RGBA8 as i32,
            w as i32,
            h as i32,
            layers.len() as i32,
            0,
            glow::RGBA,
            glow::UNSIGNED_BYTE,
            glow::PixelUnpackData::Slice(Some(&data)),
        );
        let what = format!("{} texture layers of {w}x{h}", layers.len());
        crate::gl::check_alloc(gl, &what, data.len() as u64)?;
        for (p, v) in [
            (glow::TEXTURE_MIN_FILTER, glow::LINEAR),
            (glow::TEXTURE_MAG_FILTER, glow::LINEAR),
            (glow::TEXTURE_WRAP_S, glow::REPEAT),
            (glow::TEXTURE_WRAP_T, glow::REPEAT),
        ] {
            gl.tex_parameter_i32(glow::TEXTURE_2D_ARRAY, p, v as i32);
        }
        gl.bind_texture(glow::TEXTURE_2D_ARRAY, None);
        crate::gl::check_error(gl, "uploading the textures").context("texture upload")?;
        Ok(t)
    }
}
