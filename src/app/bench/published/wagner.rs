//! The published evaluation of Wagner 2018 (B.Sc. thesis, *Potenzialanalyse der
//! GPU-Beschleunigung beim Raytracing*), ch. 5 and appendix A, typed in as data with the table
//! each number belongs to: Table A.1 (the square, Fig. 5.1), Table A.2 (sphere and cow,
//! Fig. 5.4) and Table 5.1 (a rounded selection of A.2 with the "Kamera" column).

/// The thesis' test system (ch. 5): "eine NVIDIA GTX 1060 mit 6 GB Speicher", which was also
/// the display GPU. CPU and OS are not stated.
pub const GPU: &str = "NVIDIA GeForce GTX 1060, 6 GB (also driving the display)";

/// The five image sizes of Tables A.1 and A.2, in their order.
pub const SIZES: [(u32, u32); 5] = [
    (320, 240),
    (640, 480),
    (800, 600),
    (1024, 768),
    (1680, 1050),
];
/// The sizes Fig. 5.1 draws ("nur eine Auswahl").
pub const FIG_5_1_SIZES: [(u32, u32); 3] = [(320, 240), (640, 480), (1024, 768)];
/// The reference of the resolution ratios: the smallest size.
pub const REFERENCE_SIZE: (u32, u32) = SIZES[0];

/// Table A.1 "Auswirkung von Anzahl an Dreiecken auf FPS": triangles of the square, and the
/// average FPS at each of [`SIZES`]; `None` where the table has "–" (32768 triangles were
/// measured at 320×240 only).
pub const TABLE_A1: [(u32, [Option<f64>; 5]); 7] = [
    (
        8,
        [
            Some(162.99),
            Some(45.09),
            Some(30.02),
            Some(17.96),
            Some(9.41),
        ],
    ),
    (
        32,
        [
            Some(113.79),
            Some(30.86),
            Some(20.56),
            Some(12.30),
            Some(6.59),
        ],
    ),
    (
        128,
        [
            Some(86.76),
            Some(23.46),
            Some(15.45),
            Some(9.39),
            Some(5.05),
        ],
    ),
    (
        512,
        [
            Some(70.32),
            Some(18.81),
            Some(12.27),
            Some(7.53),
            Some(4.08),
        ],
    ),
    (
        2048,
        [
            Some(58.78),
            Some(15.93),
            Some(10.33),
            Some(6.36),
            Some(3.42),
        ],
    ),
    (
        8192,
        [Some(50.66), Some(13.76), Some(8.94), Some(5.51), Some(2.94)],
    ),
    (32768, [Some(45.07), None, None, None, None]),
];

/// The test objects of ch. 5.2 with their triangle counts.
pub const SPHERE_TRIANGLES: usize = 720;
pub const COW_TRIANGLES: usize = 5804;

/// Table A.2 "Performance verschiedener Objekte": size, pixels (as printed), sphere FPS, cow
/// ("Kuh") FPS.
pub const TABLE_A2: [((u32, u32), u32, f64, f64); 5] = [
    ((320, 240), 76800, 20.12, 11.91),
    ((640, 480), 307200, 7.17, 4.32),
    ((800, 600), 480000, 5.00, 2.95),
    ((1024, 768), 786432, 3.39, 2.11),
    ((1680, 1050), 1764000, 2.00, 1.33),
];

/// Table 5.1 "Performance Objekte und Kamera": size, FPS and "Kamera" of the sphere, FPS and
/// "Kamera" of the cow, as printed (whole numbers). The thesis does not say what the "Kamera"
/// numbers measure (ch. 5.2 only says the usability of the interactive camera was tested, and
/// that below 10 FPS it can hardly be steered smoothly).
pub const TABLE_5_1: [Table51Row; 3] = [
    Table51Row::new((320, 240), [18, 3], [12, 3]),
    Table51Row::new((640, 480), [6, 7], [3, 7]),
    Table51Row::new((1024, 768), [2, 7], [1, 7]),
];

/// A row of Table 5.1: the size; FPS and "Kamera" of the sphere, of the cow.
#[derive(Debug, Clone, Copy)]
pub struct Table51Row {
    pub size: (u32, u32),
    pub sphere: [u32; 2],
    pub cow: [u32; 2],
}

impl Table51Row {
    const fn new(size: (u32, u32), sphere: [u32; 2], cow: [u32; 2]) -> Table51Row {
        Table51Row { size, sphere, cow }
    }
}

/// ch. 5.1 on the BVH build, beside our `bvh_build_ms` of the 210,712-triangle dragon scene.
pub const BUILD_REMARK: &str = "with more than 100k triangles, building the BVH took about five \
                                minutes and the transfer to the GPU was refused (ch. 5.1)";

/// ch. 5.1's findings about Fig. 5.1.
pub const FINDINGS_A1: [&str; 3] = [
    "From 8 to 128 triangles the BVH can hardly counter the extra cost per triangle.",
    "From 512 triangles on, more triangles have only a small effect on the FPS.",
    "At 320×240 even more than 32k triangles still gave about 45 FPS.",
];

/// ch. 5.2's findings about Table 5.1 and Fig. 5.4.
pub const FINDINGS_A2: [&str; 2] = [
    "The FPS fall alike for the simple sphere and the complex cow.",
    "Above 1024×768 the drops are no longer as drastic.",
];

/// The column of `size` in [`SIZES`].
pub fn size_index(size: (u32, u32)) -> Option<usize> {
    SIZES.iter().position(|s| *s == size)
}

/// Table A.1's FPS for the square of `triangles` at `size`.
pub fn a1_fps(triangles: usize, size: (u32, u32)) -> Option<f64> {
    let row = TABLE_A1.iter().find(|r| r.0 as usize == triangles)?;
    row.1[size_index(size)?]
}

/// Table A.2's FPS for `object` ("sphere" or "cow") at `size`.
pub fn a2_fps(object: &str, size: (u32, u32)) -> Option<f64> {
    let row = TABLE_A2.iter().find(|r| r.0 == size)?;
    match object {
        "sphere" => Some(row.2),
        "cow" => Some(row.3),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tables_agree_with_themselves_and_the_text() {
        // the printed pixel counts are W·H
        for ((w, h), pixels, ..) in TABLE_A2 {
            assert_eq!(w * h, pixels);
        }
        // each step quadruples the triangles, from the 8 of four quads
        for (k, (t, _)) in TABLE_A1.iter().enumerate() {
            assert_eq!(*t, 8 * 4u32.pow(k as u32));
        }
        // "selbst mit über 32k Dreiecken lieferte der Raytracer noch ~45FPS"
        assert_eq!(a1_fps(32768, (320, 240)), Some(45.07));
        assert_eq!(a1_fps(32768, (640, 480)), None);
        assert_eq!(a1_fps(8, (1680, 1050)), Some(9.41));
        assert_eq!(a2_fps("cow", (1680, 1050)), Some(1.33));
        assert_eq!(a2_fps("sphere", (800, 600)), Some(5.00));
        // FPS fall with the size everywhere in both tables
        for (_, fps) in TABLE_A1 {
            let f: Vec<f64> = fps.iter().flatten().copied().collect();
            assert!(f.windows(2).all(|w| w[0] > w[1]));
        }
        // Table 5.1 is A.2 rounded only roughly (18 vs 20.12): a separate run
        assert!((TABLE_5_1[0].sphere[0] as f64 - TABLE_A2[0].2).abs() > 1.0);
    }
}
