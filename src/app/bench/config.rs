//! What a protocol configures: the sizes at each scale, and the configurations it measures
//! (scene, tracer, image size, reflection depth, rotation angles, warm-up frames).

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
}

impl TracerSpec {
    pub fn name(&self) -> &'static str {
        match self {
            TracerSpec::Base => "base",
            TracerSpec::Grid { .. } => "grid",
        }
    }
    /// The grid's variant and resolution; `None` for the base tracer.
    pub fn grid(&self) -> Option<(GridVariant, u32)> {
        match *self {
            TracerSpec::Base => None,
            TracerSpec::Grid {
                variant,
                resolution,
            } => Some((variant, resolution)),
        }
    }
    pub fn variant(&self) -> Option<GridVariant> {
        self.grid().map(|g| g.0)
    }
    pub fn resolution(&self) -> Option<u32> {
        self.grid().map(|g| g.1)
    }
    /// "base", "grid thesis 24³".
    pub fn label(&self) -> String {
        match self.grid() {
            None => "base".into(),
            Some((v, r)) => format!("grid {} {r}³", variant_name(v)),
        }
    }
    /// A file-name friendly form: "base", "grid-thesis-24".
    pub fn slug(&self) -> String {
        match self.grid() {
            None => "base".into(),
            Some((v, r)) => format!("grid-{}-{r}", variant_name(v)),
        }
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
    pub tracer: TracerSpec,
    /// REFL_DEPTH: reflection passes after the primary pass.
    pub refl_depth: u32,
    pub width: u32,
    pub height: u32,
    /// Rotation angles in degrees, one measured frame each.
    pub angles: Vec<f64>,
    /// Frames rendered first at the first angle and not counted.
    pub warmup: u32,
}

impl Config {
    /// `tracer` on `scene` at the size of `s`, over `s.angles` angles of a full rotation.
    pub fn new(scene: &str, tracer: TracerSpec, refl_depth: u32, s: Sizing) -> Config {
        Config {
            scene: scene.into(),
            tracer,
            refl_depth,
            width: s.width,
            height: s.height,
            angles: rotation_angles(s.angles),
            warmup: s.warmup,
        }
    }
    /// "bunny", the scene file's stem.
    pub fn scene_name(&self) -> &str {
        self.scene.strip_suffix(".toml").unwrap_or(&self.scene)
    }
    /// "bunny, grid exact 24³".
    pub fn label(&self) -> String {
        format!("{}, {}", self.scene_name(), self.tracer.label())
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
    }
}
