//! The published evaluation of Müller 2015, ch. 5, typed in as data with the figure each number
//! belongs to. Only numbers the text states are here: Figures 19–22 are plots whose values the
//! text does not give, so for them only the stated setup and the qualitative findings are kept.

use crate::bench::common::format::table;

/// The thesis' test system (ch. 5, first paragraph), and its parts.
pub const GPU: &str = "NVIDIA GeForce GTX 780 (2304 shader units, 3 GB)";
pub const CPU: &str = "Intel Core i7-4770, 3.4 GHz";
pub const OS: &str = "Windows 8.1 64-bit";
pub const HARDWARE: &str =
    "Windows 8.1 64-bit, Intel Core i7-4770 (3.4 GHz), NVIDIA GeForce GTX 780 \
                            (2304 shader units, 3 GB)";

/// What the thesis measured (ch. 5): frames per second and triangle tests per frame.
pub const MEASURES: &str = "frames per second (FPS) and ray–triangle intersection tests per frame";

/// A number the text states.
#[derive(Debug, Clone, Copy)]
pub struct Published {
    /// Where: "Fig. 23", "ch. 5.1", ...
    pub figure: &'static str,
    /// What the number is (the source's words), for a reader of the report's tables.
    pub what: &'static str,
    /// The number as printed, German separators translated ("1 137 720 816" → "1,137,720,816").
    pub printed: &'static str,
}

impl Published {
    const fn new(figure: &'static str, what: &'static str, printed: &'static str) -> Published {
        Published {
            figure,
            what,
            printed,
        }
    }

    /// The number.
    pub fn value(&self) -> f64 {
        let digits = self.printed.replace(',', "");
        digits
            .parse()
            .unwrap_or_else(|_| panic!("published number {:?}", self.printed))
    }

    /// "0.8804 (Fig. 23)".
    pub fn cited(&self) -> String {
        format!("{} ({})", self.printed, self.figure)
    }
}

/// ch. 5.1: the three teapot scenes (a floor is included in each count).
pub const TEAPOT_TRIANGLES: [(&str, u64); 3] =
    [("teapot1", 14592), ("teapot3", 27392), ("teapot6", 46592)];

/// ch. 5.1 setup: one light, reflection depth one, every teapot reflective, the scene rotated
/// through 360° with one frame per viewing angle.
pub const SEC51_SETUP: &str =
    "one light, reflection depth 1, every teapot reflective; the scene rotated \
                               through 360°, one frame per viewing angle";

/// ch. 5.1 findings (Fig. 19, 20 are plots; no values are given in the text).
pub const SEC51_FINDINGS: [&str; 4] = [
    "Fig. 19: FPS is inversely proportional (\"antiproportional\") to the number of triangles.",
    "Fig. 19: with more triangles the FPS fluctuates considerably over the rotation.",
    "Fig. 20: with more triangles there are phases with clearly more tests; local minima correlate with \
     the shadowed area (shadow feelers stop at the first hit).",
    "Fig. 20: smaller local maxima come from multiple reflections, mostly in the six-teapot scene.",
];

/// ch. 5.2 setup and findings (Fig. 21, 22 are plots; no values are given in the text).
pub const SEC52_SETUP: &str =
    "the six-teapot scene of ch. 5.1 rendered with the uniform grid at several \
                               resolutions";
pub const SEC52_OPTIMUM: (u32, u32) = (12, 20);
pub const SEC52_FINDINGS: [&str; 3] = [
    "Fig. 21: the best grid resolution for this scene lies between 12³ and 20³ voxels.",
    "Fig. 22: the (mean) number of tests per frame falls as the grid gets finer, yet FPS falls too past the \
     optimum: building the grid and traversing it every frame costs more.",
    "ch. 5.2: the voxel lists (32 bit per entry × list length × voxels) grow cubically with the resolution \
     and limit it.",
];

/// The thesis' findings about `figures` (given as plots only) beside ours, as a table.
pub fn beside_findings(figures: &str, rows: Vec<(&str, String)>) -> String {
    let rows: Vec<Vec<String>> = rows
        .into_iter()
        .map(|(finding, ours)| vec![finding.to_string(), ours])
        .collect();
    format!(
        "\nThe thesis gives {figures} as plots only; its text states these findings, set here beside \
         ours:\n\n{}",
        table(&["Müller 2015", "ours"], &rows)
    )
}

/// ch. 5.3: the bunny, one light, no reflections.
pub const BUNNY_TRIANGLES: u64 = 69451;
pub const BUNNY_GRID_RESOLUTION: u32 = 24;
pub const BUNNY_BASE_FPS: Published =
    Published::new("Fig. 23", "bunny, base tracer, mean FPS", "0.8804");
pub const BUNNY_GRID_FPS: Published =
    Published::new("Fig. 23", "bunny, grid 24³, mean FPS", "4.8339");
/// The speed-up as the text states it ("Beschleunigung um den Faktor 5.5").
pub const BUNNY_SPEEDUP_STATED: Published =
    Published::new("ch. 5.3", "bunny, speed-up grid 24³ over base", "5.5");
pub const BUNNY_BASE_TESTS: Published = Published::new(
    "Fig. 24",
    "bunny, base tracer, mean triangle tests per frame",
    "1,137,720,816",
);
pub const BUNNY_GRID_TESTS: Published = Published::new(
    "Fig. 24",
    "bunny, grid 24³, mean triangle tests per frame",
    "287,728,727.1",
);

/// ch. 5.3: the dragon, in a scene with one light and a reflective floor.
pub const DRAGON_TRIANGLES: u64 = 204088;
pub const DRAGON_GRID_RESOLUTION: u32 = 28;
pub const DRAGON_GRID_FPS: Published = Published::new(
    "ch. 5.3",
    "dragon (204088 triangles), grid 28³, mean FPS",
    "1.396",
);
pub const DRAGON_BASE: &str =
    "the base tracer could not render it: the operating system's driver watchdog \
                               ended the long dispatches (\"time out\")";
/// The published speed-up computed from the two FPS values (4.8339 / 0.8804 = 5.49).
pub fn bunny_speedup() -> f64 {
    BUNNY_GRID_FPS.value() / BUNNY_BASE_FPS.value()
}

/// The published test reduction (1,137,720,816 / 287,728,727.1 = 3.95; "only a quarter").
pub fn bunny_test_reduction() -> f64 {
    BUNNY_BASE_TESTS.value() / BUNNY_GRID_TESTS.value()
}

/// The published base count divided by the bunny's triangles: the number of rays that would
/// have tested every triangle, had the count been a full 64-bit count (16381.6, just below
/// 128² = 16384, though shadow feelers add tests too).
pub fn bunny_base_tests_per_triangle() -> f64 {
    BUNNY_BASE_TESTS.value() / BUNNY_TRIANGLES as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_ratios_match_the_text() {
        // "einer Beschleunigung um den Faktor 5.5"
        assert!((bunny_speedup() - 5.5).abs() < 0.05, "{}", bunny_speedup());
        // "nur ein Viertel der Tests"
        assert!((bunny_test_reduction() - 4.0).abs() < 0.1);
        assert!((bunny_base_tests_per_triangle() - 16381.6).abs() < 0.1);
        assert_eq!(BUNNY_GRID_TESTS.value(), 287_728_727.1);
        assert_eq!(DRAGON_GRID_FPS.value(), 1.396);
        assert_eq!(
            TEAPOT_TRIANGLES.iter().map(|t| t.1).sum::<u64>(),
            14592 + 27392 + 46592
        );
    }
}
