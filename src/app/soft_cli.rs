//! `render --shadows exact|linespace|linespace-dda --light-samples UxV [--ntree-n N]
//! [--ntree-depth D]`: the soft-shadow pipeline of Klee 2016 on the command line.

use std::path::Path;

use anyhow::{Context as _, Result};
use serde_json::json;

use gpgpu_rt::gl::{GlContext, ShaderSource};
use gpgpu_rt::output;
use gpgpu_rt::scene::{RenderSettings, Scene};
use gpgpu_rt::tracer::linespace::{
    parse_samples, ShadowMode, SoftShadowFrame, SoftShadowOptions, SoftShadowRenderer,
};
use gpgpu_rt::tracer::Frame;

/// The soft-shadow options of `render` and `view`.
#[derive(clap::Args, Debug, Clone)]
pub struct SoftShadowArgs {
    /// Soft shadows from the scene's `[[area_light]]` with the Cascaded Line Space (Klee 2016):
    /// G-buffer, shadow compute pass, screen-filling quad. `exact`: triangle tests (the
    /// reference); `linespace`: packet traversal, the line-space bit decides a hit;
    /// `linespace-dda`: one 3D-DDA per ray with the same line-space termination.
    /// [default: the scene's render.shadows, else the point-light ray tracer]
    #[arg(long, value_enum)]
    pub shadows: Option<ShadowMode>,
    /// Uniform samples of the area light, UxV (2x2 … 10x10 in the thesis) [default: the
    /// scene's render.light_samples, else 4x4].
    #[arg(long, value_parser = parse_samples, value_name = "UxV")]
    pub light_samples: Option<(u32, u32)>,
    /// Cells per axis of every N-tree node (N; 10 in the thesis).
    #[arg(long, default_value_t = 10, value_name = "N")]
    pub ntree_n: u32,
    /// Levels of the N-tree including the root (3 in the thesis; 3 or 4).
    #[arg(long, default_value_t = 3, value_name = "D")]
    pub ntree_depth: u32,
}

impl SoftShadowArgs {
    /// The scene file's `render.shadows` and `render.light_samples` where the command line
    /// gives none.
    pub fn with_scene_defaults(mut self, settings: &RenderSettings) -> SoftShadowArgs {
        self.shadows = self.shadows.or(settings.shadows);
        self.light_samples = self.light_samples.or(settings.light_samples);
        self
    }

    /// The light samples: the option, else 4x4.
    pub fn samples(&self) -> (u32, u32) {
        self.light_samples.unwrap_or((4, 4))
    }

    pub fn options(
        &self,
        mode: ShadowMode,
        width: u32,
        height: u32,
        tile: u32,
    ) -> SoftShadowOptions {
        SoftShadowOptions {
            mode,
            samples_u: self.samples().0,
            samples_v: self.samples().1,
            ntree_n: self.ntree_n,
            ntree_depth: self.ntree_depth,
            width,
            height,
            tile,
        }
    }
}

/// The statistics document of a soft-shadow frame (the keys of `render --stats`).
pub fn stats_json(
    ctx: &GlContext,
    scene: &Scene,
    r: &SoftShadowRenderer,
    f: &SoftShadowFrame,
) -> serde_json::Value {
    let s = &f.stats;
    let mut doc = json!({
        "scene": scene.path,
        "renderer": ctx.info.renderer,
        "gl_version": ctx.info.version,
        "vendor": ctx.info.vendor,
        "tracer": "linespace",
        "width": f.width,
        "height": f.height,
        "triangles": scene.triangle_count(),
        "area_lights": scene.area_lights.len(),
        "tile": r.options.tile,
        "triangle_tests": s.triangle_tests,
        "triangle_tests_total": s.total_triangle_tests(),
        "events": s.events,
        "truncated_rays": s.truncated_rays,
        "gpu_ms": s.gpu_ms,
        "gpu_ms_total": s.total_gpu_ms(),
        "wall_ms": s.wall_ms,
    });
    for (k, v) in &s.facts {
        doc[k] = v.clone();
    }
    for (k, v) in &s.events {
        doc[k] = json!(v);
    }
    doc
}

/// Render `scene` with the soft-shadow pipeline and write the PNG, the AOVs (the base
/// tracer's plus `shadow.npy`) and the statistics of the last of `frames` frames.
#[allow(clippy::too_many_arguments)]
pub fn render(
    ctx: &GlContext,
    scene: &Scene,
    shaders: &ShaderSource,
    options: SoftShadowOptions,
    frames: u32,
    out: &Path,
    aov_dir: Option<&Path>,
    stats: Option<&Path>,
) -> Result<()> {
    let mut r = SoftShadowRenderer::new(ctx.gl.clone(), &ctx.info, scene, shaders, options)?;
    // `--frames N`: N − 1 warm-up frames (shader compilation on first use), the last reported
    for _ in 1..frames {
        r.draw(&scene.camera)?;
    }
    let f = r.render(&scene.camera)?;
    let frame = Frame {
        width: f.width,
        height: f.height,
        color: f.color.clone(),
        aovs: None,
        stats: f.stats.clone(),
    };
    output::write_png(out, &frame)?;
    if let Some(dir) = aov_dir {
        output::write_aovs(dir, f.width, f.height, &f.aovs)?;
        output::write_npy(
            &dir.join("shadow.npy"),
            &[f.height as u64, f.width as u64],
            f.shadow.iter().copied(),
        )?;
    }
    if let Some(path) = stats {
        let doc = stats_json(ctx, scene, &r, &f);
        std::fs::write(path, serde_json::to_string_pretty(&doc)? + "\n")
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    eprintln!(
        "{}: {}x{}, {} triangles, soft shadows `{}` with {}x{} samples on {}: {:.1} GPU ms ({:.1} shadow pass), \
         {} triangle tests, {} line-space lookups -> {}",
        scene.path.display(),
        f.width,
        f.height,
        scene.triangle_count(),
        r.options.mode.name(),
        r.options.samples_u,
        r.options.samples_v,
        ctx.info.renderer,
        f.stats.total_gpu_ms(),
        f.stats.gpu_ms.iter().filter(|(k, _)| k.starts_with("shadow")).map(|(_, v)| v).sum::<f64>(),
        f.stats.total_triangle_tests(),
        f.stats.events.get("linespace_lookups").copied().unwrap_or(0),
        out.display()
    );
    Ok(())
}
