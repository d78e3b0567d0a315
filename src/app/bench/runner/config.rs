//! What a protocol configures: the sizes at each scale, and the configurations it measures
//! (scene, tracer, image size, reflection depth, rotation angles, warm-up frames).

use gpgpu_rt::accel::{self, Accel, BvhLevels, BvhOptions, BvhPasses, ExactGridOptions};
use gpgpu_rt::design::{Design, Row};
use gpgpu_rt::pipeline::mueller2015::RenderOptions;
use gpgpu_rt::pipeline::stream::StreamOptions;
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

/// Which tracer a configuration measures: the library's design, the same value `render`
/// parses from its command line, with each protocol's configuration pinned in it (the SAH BVH
/// in Müller 2015's four kernels, the thesis' pipeline the protocols compare in). Its size,
/// reflection depth, tile and AOVs are the configuration's, set when it runs
/// (`adapter::design`).
#[derive(Debug, Clone)]
pub struct Tracer(pub Design);

/// Two tracers are one configuration where their labels are: the label names every option a
/// protocol varies, and the reports and CSVs know a configuration by it.
impl PartialEq for Tracer {
    fn eq(&self, other: &Tracer) -> bool {
        self.label() == other.label()
    }
}

impl Tracer {
    /// Müller 2015's pipeline with `accel` (a placeholder size until it runs).
    fn mueller(accel: Accel) -> Tracer {
        Tracer(Design::Mueller2015(RenderOptions::new(accel, 1, 1, 0)))
    }

    /// The base tracer: every ray against every triangle.
    pub fn base() -> Tracer {
        Tracer::mueller(Accel::Base)
    }

    /// The uniform grid `variant` with a fixed resolution (N³ voxels; the thesis grid with
    /// Listing 17's list lengths unless the command line says otherwise).
    pub fn uniform_grid(variant: GridVariant, resolution: u32) -> Tracer {
        let accel = match variant {
            GridVariant::Thesis => accel::thesis_grid::ENTRY.plain,
            GridVariant::Exact => accel::exact_grid::ENTRY.plain,
        };
        Tracer::mueller(accel.with_grid_resolution(resolution))
    }

    /// The exact grid of N³ voxels with proximity clouds (`--tracer grid --proximity-clouds`).
    pub fn grid_pc(resolution: u32) -> Tracer {
        Tracer::mueller(Accel::ExactGrid(ExactGridOptions {
            resolution: Some(resolution),
            proximity_clouds: true,
        }))
    }

    /// A BVH of one variant: ours in Müller 2015's four kernels, or Wagner 2018's kernel.
    pub fn bvh(variant: BvhVariant) -> Tracer {
        match variant {
            BvhVariant::Sah => Tracer::sah(BvhLevels::One),
            BvhVariant::Wagner => Tracer(Design::plain(Tracer::row_named("bvh-wagner"), 1, 1, 0)),
        }
    }

    /// The SAH BVH as a tree per object under instances (`--bvh-instances`), in the four
    /// kernels: a moving object rewrites its instance, where the one tree is refitted.
    pub fn bvh_instances() -> Tracer {
        Tracer::sah(BvhLevels::Two)
    }

    fn sah(levels: BvhLevels) -> Tracer {
        Tracer::mueller(Accel::Bvh(BvhOptions {
            passes: BvhPasses::FourKernels,
            levels,
        }))
    }

    /// The streaming tracer on a gx×gy×gz grid, with or without proximity clouds (the
    /// paper's columns pc and g); with `naive_shadows`, the naive shadow rays the paper's
    /// optimisation is measured against; with `no_mask`, without the masking kernel's.
    pub fn stream(
        axes: [u32; 3],
        proximity_clouds: bool,
        naive_shadows: bool,
        no_mask: bool,
    ) -> Tracer {
        Tracer(Design::Stream(StreamOptions {
            dims: Some(axes),
            proximity_clouds,
            naive_shadows,
            no_mask,
            ..StreamOptions::new(1, 1, 0)
        }))
    }

    fn row_named(name: &str) -> &'static Row {
        gpgpu_rt::design::row(name).expect("the registry has every tracer of the bench")
    }

    /// Its design in `design::REGISTRY`.
    pub fn row(&self) -> &'static Row {
        self.0.row()
    }

    /// The accelerator of Müller 2015's pipeline; `None` for the other pipelines.
    fn accel(&self) -> Option<&Accel> {
        match &self.0 {
            Design::Mueller2015(o) => Some(&o.accel),
            _ => None,
        }
    }

    /// The streaming tracer's options; `None` for the other designs.
    pub fn stream_options(&self) -> Option<&StreamOptions> {
        match &self.0 {
            Design::Stream(o) => Some(o),
            _ => None,
        }
    }

    /// Whether it is the base tracer.
    pub fn is_base(&self) -> bool {
        self.accel() == Some(&Accel::Base)
    }

    /// Whether it skips empty cells by proximity clouds.
    pub fn proximity_clouds(&self) -> bool {
        match (self.accel(), self.stream_options()) {
            (Some(a), _) => a.proximity_clouds(),
            (_, Some(o)) => o.proximity_clouds,
            _ => false,
        }
    }

    /// "base", "grid", "bvh", "stream": the `--tracer` value.
    pub fn name(&self) -> &'static str {
        match (&self.0, self.accel()) {
            (_, Some(a)) => a.tracer(),
            (Design::Stream(_), _) => "stream",
            _ => "bvh",
        }
    }

    /// The uniform grid's variant and resolution (without proximity clouds); `None` for the
    /// other tracers.
    pub fn grid(&self) -> Option<(GridVariant, u32)> {
        match *self.accel()? {
            Accel::ThesisGrid(o) => Some((GridVariant::Thesis, o.resolution?)),
            Accel::ExactGrid(o) if !o.proximity_clouds => Some((GridVariant::Exact, o.resolution?)),
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
        if let Some(n) = self.accel().and_then(|a| a.grid_resolution()) {
            return Some(n.to_string());
        }
        match self.stream_options()?.dims? {
            [x, y, z] if x == y && y == z => Some(x.to_string()),
            [x, y, z] => Some(format!("{x}x{y}x{z}")),
        }
    }
    /// The variant's name, of the grid or the BVH: "thesis", "sah"; `None` for the base tracer.
    pub fn variant_label(&self) -> Option<&'static str> {
        if let Some(o) = self.stream_options() {
            return Some(stream_label(o));
        }
        Some(match self.accel() {
            None => "wagner",
            Some(Accel::Base) => return None,
            Some(Accel::ThesisGrid(_)) => "thesis",
            Some(Accel::ExactGrid(o)) if o.proximity_clouds => "exact-pc",
            Some(Accel::ExactGrid(_)) => "exact",
            Some(Accel::Bvh(o)) if o.levels == BvhLevels::Two => "sah-instances",
            Some(Accel::Bvh(_)) => "sah",
        })
    }
    /// "base", "grid thesis 24³", "bvh sah", "stream pc 14x16x14".
    pub fn label(&self) -> String {
        match (self.grid(), self.variant_label()) {
            (_, None) => self.name().into(),
            (Some((v, n)), _) => format!("grid {} {n}³", variant_name(v)),
            (None, Some(v)) if self.name() == "bvh" => format!("bvh {v}"),
            (None, Some(v)) => format!(
                "{} {v} {}",
                self.name(),
                self.grid_label().unwrap_or_default()
            ),
        }
    }
    /// A file-name friendly form: "base", "grid-thesis-24", "bvh-sah".
    pub fn slug(&self) -> String {
        self.label().replace('³', "").replace(' ', "-")
    }
}

/// The streaming tracer's column: "g", "pc", "pc-naive", "g-naive-nomask".
fn stream_label(o: &StreamOptions) -> &'static str {
    match (o.proximity_clouds, o.naive_shadows, o.no_mask) {
        (false, false, false) => "g",
        (true, false, false) => "pc",
        (false, true, false) => "g-naive",
        (true, true, false) => "pc-naive",
        (false, false, true) => "g-nomask",
        (true, false, true) => "pc-nomask",
        (false, true, true) => "g-naive-nomask",
        (true, true, true) => "pc-naive-nomask",
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
    pub tracer: Tracer,
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
    pub fn new(scene: &str, tracer: Tracer, refl_depth: u32, s: Sizing) -> Config {
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
    pub fn fixed(scene: &str, tracer: Tracer, (width, height): (u32, u32), s: Sizing) -> Config {
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
        let spec = Tracer::uniform_grid(GridVariant::Thesis, 24);
        assert_eq!(
            (spec.label(), spec.slug()),
            ("grid thesis 24³".into(), "grid-thesis-24".into())
        );
        let bvh = Tracer::bvh(BvhVariant::Sah);
        assert_eq!(
            (bvh.label(), bvh.slug()),
            ("bvh sah".into(), "bvh-sah".into())
        );
        assert_eq!((bvh.variant_label(), bvh.grid()), (Some("sah"), None));
        let instances = Tracer::bvh_instances();
        assert_eq!(
            (instances.label(), instances.slug(), instances.row().name),
            (
                "bvh sah-instances".into(),
                "bvh-sah-instances".into(),
                "bvh"
            )
        );
        // each protocol pins the thesis' four kernels, whatever `render`'s default
        let four = |t: &Tracer| matches!(&t.0, Design::Mueller2015(o) if !o.accel.fused());
        assert!(four(&bvh) && four(&instances));
        let pc = Tracer::grid_pc(16);
        assert_eq!(pc.label(), "grid exact-pc 16");
        assert_eq!(
            Tracer::stream([14, 16, 14], true, false, false).label(),
            "stream pc 14x16x14"
        );
        assert_eq!(Tracer::bvh(BvhVariant::Wagner).label(), "bvh wagner");
        assert!(Tracer::base().is_base() && Tracer::base().label() == "base");
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
