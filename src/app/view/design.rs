//! What the window shows: a ray tracer with its options, or the soft shadows with theirs.

use super::renderer::{soft_shadow_support, ShadowMode, Show, Stats, TracerArg, TracerOptions};
pub use crate::args::value_name;
use crate::args::SoftShadowArgs;
use gpgpu_rt::design::Pipeline;
use gpgpu_rt::scene::Scene;

/// The design shown and the options of both kinds: the keys change them, the renderers are
/// made from them.
pub struct Design {
    /// The ray tracer and its options (kept while the soft shadows are shown).
    pub kind: TracerArg,
    pub options: TracerOptions,
    /// Soft shadows shown (`None`: the ray tracer `kind`).
    pub shadows: Option<ShadowMode>,
    /// Light samples U×V of the soft shadows.
    pub samples: (u32, u32),
    /// The soft shadows' command-line options (the N-tree).
    pub soft: SoftShadowArgs,
    /// Why the scene cannot have soft shadows (no or several area lights); `None`: it can.
    pub no_soft: Option<String>,
    /// The grid resolution the grid tracer last reported (for `auto`).
    pub grid_in_use: Option<u32>,
}

impl Design {
    /// The ray tracer `kind` with `options`, or the soft shadows `soft.shadows`, for `scene`.
    pub fn new(
        kind: TracerArg,
        options: TracerOptions,
        soft: SoftShadowArgs,
        scene: &Scene,
    ) -> Design {
        Design {
            kind,
            options,
            shadows: soft.shadows,
            samples: soft.samples(),
            soft,
            no_soft: soft_shadow_support(scene).err().map(|e| format!("{e:#}")),
            grid_in_use: None,
        }
    }

    /// What is shown, for the renderers.
    pub fn shown(&self) -> Show<'_> {
        match self.shadows {
            Some(mode) => self.soft_shadows(mode, self.samples),
            None => Show::Tracer(self.kind, &self.options),
        }
    }

    /// The soft shadows `mode` with `samples`, for the renderers.
    pub fn soft_shadows(&self, mode: ShadowMode, samples: (u32, u32)) -> Show<'_> {
        Show::Soft {
            mode,
            samples,
            args: &self.soft,
            options: &self.options,
        }
    }

    /// The image size.
    pub fn size(&self) -> (u32, u32) {
        (self.options.width, self.options.height)
    }

    /// What the window shows: "base tracer", "bvh wagner tracer", "soft shadows linespace 3x3".
    pub fn name(&self) -> String {
        match self.shadows {
            Some(mode) => format!(
                "soft shadows {} {}x{}",
                mode.name(),
                self.samples.0,
                self.samples.1
            ),
            None if self.kind == TracerArg::Bvh => {
                format!("bvh {} tracer", value_name(self.options.args.bvh_variant))
            }
            None => format!("{} tracer", value_name(self.kind)),
        }
    }

    /// The title's part for the design: "grid exact auto=16³ · 256×256 · refl 1", or for the
    /// soft shadows (`ntree`: the N-tree's N and depth) "soft shadows linespace 4×4 · N-tree
    /// 10/3 · 256×256".
    pub fn title(&self, ntree: Option<(u32, u32)>) -> String {
        let mut t = match (self.shadows, ntree) {
            (Some(mode), Some((n, depth))) => format!(
                "soft shadows {} {}×{} · N-tree {n}/{depth}",
                mode.name(),
                self.samples.0,
                self.samples.1,
            ),
            _ => self.tracer_title(),
        };
        t += &format!(" · {}×{}", self.options.width, self.options.height);
        if self.shadows.is_none() && !self.wagner() {
            t += &format!(" · refl {}", self.options.refl_depth);
        }
        t
    }

    /// Wagner 2018's pipeline (`--tracer bvh --bvh-variant wagner`): no reflection.
    fn wagner(&self) -> bool {
        self.options.row(self.kind).pipeline == Pipeline::Wagner2018
    }

    /// "base", "bvh sah fused", "bvh wagner", "grid exact 16³", "grid thesis auto=12³".
    fn tracer_title(&self) -> String {
        let mut t = value_name(self.kind);
        if self.kind == TracerArg::Bvh {
            t += &format!(" {}", value_name(self.options.args.bvh_variant));
            if !self.wagner() {
                // the configuration that runs: the fused pass unless the thesis' four kernels
                let bvh = &self.options.args.bvh;
                t += if bvh.four_kernels {
                    " four kernels"
                } else {
                    " fused"
                };
                t += if bvh.bvh_instances { " two levels" } else { "" };
            }
        }
        if self.kind == TracerArg::Grid {
            let res = self
                .options
                .resolution()
                .map(|r| r.to_string())
                .or_else(|| self.grid_in_use.map(|r| format!("auto={r}")))
                .unwrap_or_else(|| "auto".into());
            t += &format!(
                " {} {res}³",
                value_name(self.options.args.grid.grid_variant)
            );
        }
        t
    }

    /// Why S and L do nothing in this scene.
    pub fn no_soft_error(&self) -> anyhow::Error {
        anyhow::anyhow!(
            "{} (S and L need a scene with one [[area_light]])",
            self.no_soft.as_deref().unwrap_or("no area light")
        )
    }

    /// Take note of a frame's statistics (the grid resolution `auto` chose).
    pub fn note(&mut self, stats: &Stats) {
        if self.shadows.is_none() {
            if let Some(r) = stats.grid_resolution() {
                self.grid_in_use = Some(r);
            }
        }
    }
}
