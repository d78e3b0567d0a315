//! What a protocol configures: the sizes at each scale, and the configurations it measures
//! (scene, tracer, image size, reflection depth, rotation angles, warm-up frames).

use gpgpu_rt::design::Row;
pub use gpgpu_rt::scene::Overrides;

/// Default image size at `--scale quick`: small enough for Mesa llvmpipe.
pub const QUICK_SIZE: (u32, u32) = (64, 64);
/// Default image size at `--scale full`. The thesis does not state its image size.
pub const FULL_SIZE: (u32, u32) = (512, 512);

/// Image size, number of angles and warm-up frames of a protocol at one scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sizing {
    pub width: u32,
    pub height: u32,
    pub angles: u32,
    pub warmup: u32,
}

impl Sizing {
    /// `angles` measured frames after `warmup` frames at the quick image size.
    pub const fn quick(angles: u32, warmup: u32) -> Sizing {
        Sizing::sized(QUICK_SIZE, angles, warmup)
    }

    /// `angles` measured frames after `warmup` frames at the full image size.
    pub const fn full(angles: u32, warmup: u32) -> Sizing {
        Sizing::sized(FULL_SIZE, angles, warmup)
    }

    const fn sized((width, height): (u32, u32), angles: u32, warmup: u32) -> Sizing {
        Sizing {
            width,
            height,
            angles,
            warmup,
        }
    }

    /// "64×64".
    pub fn size(&self) -> String {
        format!("{}×{}", self.width, self.height)
    }
}

/// The two uniform-grid designs (Müller 2015, ch. 3.2, 4.2); `--variants`.
pub use gpgpu_rt::accel::GridVariant;

/// The two BVH designs after Wagner 2018 (`--bvh-variants`): which of them this build
/// measures is [`super::adapter::BVH_VARIANTS`].
pub use gpgpu_rt::accel::BvhVariant;

/// Which tracer a configuration measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TracerSpec {
    /// The base tracer: every ray against every triangle.
    Base,
    /// The uniform-grid tracer with a fixed resolution (N³ voxels).
    Grid {
        variant: GridVariant,
        resolution: u32,
    },
    /// A BVH tracer (`--tracer bvh`) of one variant.
    Bvh { variant: BvhVariant },
    /// The SAH BVH as a tree per object under instances (`--tracer bvh --bvh-instances`): a
    /// moving object rewrites its instance, where the one tree is refitted.
    BvhInstances,
    /// The streaming tracer (`--tracer stream`) on a gx×gy×gz grid, with or without
    /// proximity clouds: the paper's columns pc and g.
    /// With `naive_shadows`, the naive shadow rays the paper's optimisation is measured
    /// against (`--stream-naive-shadows`); with `no_mask`, without the masking kernel's
    /// optimisation (`--stream-no-mask`).
    Stream {
        axes: [u32; 3],
        proximity_clouds: bool,
        naive_shadows: bool,
        no_mask: bool,
    },
    /// The compute exact grid (`--tracer grid`) of N³ voxels with proximity clouds
    /// (`--tracer grid --proximity-clouds`, issue 12 §3).
    GridPc { resolution: u32 },
}

impl TracerSpec {
    /// Its design in `design::REGISTRY`.
    pub fn row(&self) -> &'static Row {
        let name = match self {
            TracerSpec::Base => "base",
            TracerSpec::Grid {
                variant: GridVariant::Thesis,
                ..
            } => "grid-thesis",
            TracerSpec::Grid { .. } | TracerSpec::GridPc { .. } => "grid-exact",
            TracerSpec::Bvh {
                variant: BvhVariant::Sah,
            }
            | TracerSpec::BvhInstances => "bvh",
            TracerSpec::Bvh {
                variant: BvhVariant::Wagner,
            } => "bvh-wagner",
            TracerSpec::Stream { .. } => "stream",
        };
        gpgpu_rt::design::row(name).expect("the registry has every tracer of the bench")
    }

    /// Whether it skips empty cells by proximity clouds.
    pub fn proximity_clouds(&self) -> bool {
        match *self {
            TracerSpec::GridPc { .. } => true,
            TracerSpec::Stream {
                proximity_clouds, ..
            } => proximity_clouds,
            _ => false,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            TracerSpec::Base => "base",
            TracerSpec::Grid { .. } => "grid",
            TracerSpec::Bvh { .. } | TracerSpec::BvhInstances => "bvh",
            TracerSpec::Stream { .. } => "stream",
            TracerSpec::GridPc { .. } => "grid",
        }
    }
    /// The grid's variant and resolution; `None` for the other tracers.
    pub fn grid(&self) -> Option<(GridVariant, u32)> {
        match *self {
            TracerSpec::Grid {
                variant,
                resolution,
            } => Some((variant, resolution)),
            _ => None,
        }
    }
    /// The grid's variant; `None` for the other tracers.
    pub fn variant(&self) -> Option<GridVariant> {
        self.grid().map(|g| g.0)
    }
    pub fn resolution(&self) -> Option<u32> {
        self.grid().map(|g| g.1)
    }
    /// The grid's cells per axis, of any grid tracer: "24", "14x16x14"; `None` without a grid.
    pub fn grid_label(&self) -> Option<String> {
        match *self {
            TracerSpec::Grid { resolution, .. } | TracerSpec::GridPc { resolution } => {
                Some(resolution.to_string())
            }
            TracerSpec::Stream {
                axes: [x, y, z], ..
            } if x == y && y == z => Some(x.to_string()),
            TracerSpec::Stream {
                axes: [x, y, z], ..
            } => Some(format!("{x}x{y}x{z}")),
            _ => None,
        }
    }
    /// The variant's name, of the grid or the BVH: "thesis", "sah"; `None` for the base tracer.
    pub fn variant_label(&self) -> Option<&'static str> {
        match *self {
            TracerSpec::Base => None,
            TracerSpec::Grid { variant, .. } => Some(variant_name(variant)),
            TracerSpec::Bvh { variant } => Some(variant.name()),
            TracerSpec::BvhInstances => Some("sah-instances"),
            TracerSpec::Stream {
                proximity_clouds,
                naive_shadows,
                no_mask,
                ..
            } => Some(match (proximity_clouds, naive_shadows, no_mask) {
                (false, false, false) => "g",
                (true, false, false) => "pc",
                (false, true, false) => "g-naive",
                (true, true, false) => "pc-naive",
                (false, false, true) => "g-nomask",
                (true, false, true) => "pc-nomask",
                (false, true, true) => "g-naive-nomask",
                (true, true, true) => "pc-naive-nomask",
            }),
            TracerSpec::GridPc { .. } => Some("exact-pc"),
        }
    }
    /// "base", "grid thesis 24³", "bvh sah", "stream pc 14x16x14".
    pub fn label(&self) -> String {
        match *self {
            TracerSpec::Base => "base".into(),
            TracerSpec::Grid {
                variant,
                resolution,
            } => format!("grid {} {resolution}³", variant_name(variant)),
            TracerSpec::Bvh { variant } => format!("bvh {}", variant.name()),
            TracerSpec::BvhInstances => "bvh sah-instances".into(),
            TracerSpec::Stream { .. } | TracerSpec::GridPc { .. } => format!(
                "{} {} {}",
                self.name(),
                self.variant_label().unwrap_or_default(),
                self.grid_label().unwrap_or_default()
            ),
        }
    }
    /// A file-name friendly form: "base", "grid-thesis-24", "bvh-sah".
    pub fn slug(&self) -> String {
        self.label().replace('³', "").replace(' ', "-")
    }
}

pub fn variant_name(v: GridVariant) -> &'static str {
    match v {
        GridVariant::Thesis => "thesis",
        GridVariant::Exact => "exact",
    }
}

/// One measured configuration: a scene, a tracer, an image size and the angles of the rotation.
#[derive(Debug, Clone)]
pub struct Config {
    /// File name in the scenes folder, e.g. `bunny.toml`.
    pub scene: String,
    /// Procedural sizes that replace the scene file's (the square's `level`).
    pub overrides: Overrides,
    pub tracer: TracerSpec,
    /// REFL_DEPTH: reflection passes after the primary pass.
    pub refl_depth: u32,
    pub width: u32,
    pub height: u32,
    /// Rotation angles in degrees, one measured frame each.
    pub angles: Vec<f64>,
    /// Frames rendered first at the first angle and not counted.
    pub warmup: u32,
    /// Shadow rays towards the scene's lights; `false`: the lights removed, eye rays (and
    /// reflection rays) only, lit by the ambient term: the streaming tracer's Table 1.
    pub shadows: bool,
    /// Compare the first frame's first hits with the CPU reference's (`accel-compare`): the
    /// facts `first_hit_agreement` and `first_hit_judge` of that frame.
    pub judge: bool,
}

impl Config {
    /// `tracer` on `scene` at the size of `s`, over `s.angles` angles of a full rotation.
    pub fn new(scene: &str, tracer: TracerSpec, refl_depth: u32, s: Sizing) -> Config {
        Config {
            scene: scene.into(),
            overrides: Overrides::default(),
            tracer,
            refl_depth,
            width: s.width,
            height: s.height,
            angles: rotation_angles(s.angles),
            warmup: s.warmup,
            shadows: true,
            judge: false,
        }
    }
    /// `tracer` on `scene` at `width`×`height`, `frames` frames after `warmup`, camera and
    /// objects fixed (every frame at angle 0: nothing moves, nothing is rebuilt).
    pub fn fixed(
        scene: &str,
        tracer: TracerSpec,
        (width, height): (u32, u32),
        s: Sizing,
    ) -> Config {
        Config {
            width,
            height,
            angles: vec![0.0; s.angles as usize],
            ..Config::new(scene, tracer, 0, s)
        }
    }
    /// The same configuration with the square's subdivision `level`.
    pub fn with_level(self, level: u32) -> Config {
        Config {
            overrides: Overrides { level: Some(level) },
            ..self
        }
    }
    /// "bunny", the scene file's stem.
    pub fn scene_name(&self) -> &str {
        self.scene.strip_suffix(".toml").unwrap_or(&self.scene)
    }
    /// "bunny", "square level 3": the scene with its overrides.
    pub fn scene_label(&self) -> String {
        match self.overrides.level {
            Some(l) => format!("{} level {l}", self.scene_name()),
            None => self.scene_name().to_string(),
        }
    }
    /// "bunny, grid exact 24³".
    pub fn label(&self) -> String {
        format!("{}, {}", self.scene_label(), self.tracer.label())
    }
    /// "square-level-3_bvh-sah": a file-name friendly label.
    pub fn slug(&self) -> String {
        format!(
            "{}_{}",
            self.scene_label().replace(' ', "-"),
            self.tracer.slug()
        )
    }
    pub fn frames(&self) -> u64 {
        self.warmup as u64 + self.angles.len() as u64
    }
}

/// The angles of a rotation through 360° in `n` equal steps, starting at 0°.
pub fn rotation_angles(n: u32) -> Vec<f64> {
    (0..n).map(|i| 360.0 * i as f64 / n as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_angles_cover_the_circle_once() {
        assert_eq!(rotation_angles(4), vec![0.0, 90.0, 180.0, 270.0]);
        let full = rotation_angles(360);
        assert_eq!(full.len(), 360);
        assert_eq!(full[1], 1.0);
        assert_eq!(full[359], 359.0);
    }

    #[test]
    fn grid_variants_keep_their_command_line_names() {
        use clap::ValueEnum;
        let names: Vec<String> = GridVariant::value_variants()
            .iter()
            .filter_map(|v| Some(v.to_possible_value()?.get_name().to_string()))
            .collect();
        assert_eq!(names, ["thesis", "exact"]);
        assert_eq!(
            GridVariant::from_str("exact", false),
            Ok(GridVariant::Exact)
        );
        let spec = TracerSpec::Grid {
            variant: GridVariant::Thesis,
            resolution: 24,
        };
        assert_eq!(
            (spec.label(), spec.slug()),
            ("grid thesis 24³".into(), "grid-thesis-24".into())
        );
        let bvh = TracerSpec::Bvh {
            variant: BvhVariant::Sah,
        };
        assert_eq!(
            (bvh.label(), bvh.slug()),
            ("bvh sah".into(), "bvh-sah".into())
        );
        assert_eq!((bvh.variant_label(), bvh.grid()), (Some("sah"), None));
        let instances = TracerSpec::BvhInstances;
        assert_eq!(
            (instances.label(), instances.slug(), instances.row().name),
            (
                "bvh sah-instances".into(),
                "bvh-sah-instances".into(),
                "bvh"
            )
        );
        let c = Config::fixed("square.toml", bvh, (320, 240), Sizing::quick(3, 1)).with_level(2);
        assert_eq!(
            (c.label(), c.slug()),
            (
                "square level 2, bvh sah".into(),
                "square-level-2_bvh-sah".into()
            )
        );
        assert_eq!((c.angles, c.refl_depth, c.width), (vec![0.0; 3], 0, 320));
    }
}
