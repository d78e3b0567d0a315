//! The upper bound of every count a user gives, on the command line or in a scene file: what is
//! meaningful for the designs, well below what would exhaust memory or run for days. The
//! command line states each in `--help` and refuses more with the option's name; scene files
//! are checked when they are loaded (with file and line).

use std::ops::RangeInclusive;

/// Reflection passes after the primary pass (REFL_DEPTH of Fig. 8 in Müller 2015; the thesis
/// measures 0 to 2; each pass halves what is left of the weight of a mirror's colour at best).
pub const REFL_DEPTH: RangeInclusive<u32> = 0..=16;
/// Image width and height in pixels (GL's own texture limit is checked as well).
pub const IMAGE_SIDE: RangeInclusive<u32> = 1..=16384;
/// Frames of one `render` (warm-up and the reported one) or `view --frames`.
pub const FRAMES: RangeInclusive<u32> = 1..=100_000;
/// Camera or object angles per bench configuration (one per degree is 360).
pub const ANGLES: RangeInclusive<u32> = 1..=3600;
/// Warm-up frames per bench configuration.
pub const WARMUP: RangeInclusive<u32> = 0..=1000;
/// Voxels per axis of a uniform grid (N of N³; Müller 2015 measures 8 to 64).
pub const GRID_RES: RangeInclusive<u32> = 1..=1024;
/// Steps (triangle tests or cell moves) per call of the streaming tracer's traverse kernel
/// (the streaming tracer's bounded work per call; llvmpipe ends a loop after 65535 iterations).
pub const STREAM_STEPS: RangeInclusive<u32> = 1..=4096;
/// Calls of the streaming tracer's traverse kernel per traversal, at most.
pub const STREAM_CALLS: RangeInclusive<u32> = 1..=1_000_000;
/// Triangle ids per voxel list of the thesis grid (Listing 17: 512).
pub const VOXEL_ARRAY_LENGTH: RangeInclusive<u32> = 1..=65536;
/// Voxel ids per ray list of the thesis grid (Listing 17: 3·N).
pub const RAY_ARRAY_LENGTH: RangeInclusive<u32> = 1..=65536;
/// Width and height of a decoded texture in texels.
pub const TEXTURE_SIDE: u32 = 16384;
/// Bytes a texture may take while it is decoded (the image crate's allocation limit).
pub const TEXTURE_BYTES: u64 = 1 << 30;

/// `value` if it lies in `range`, else a message naming `what` and the range.
pub fn check(what: &str, value: u32, range: &RangeInclusive<u32>) -> Result<u32, String> {
    if range.contains(&value) {
        Ok(value)
    } else {
        Err(format!(
            "{what} is {value}, outside {} to {}",
            range.start(),
            range.end()
        ))
    }
}

/// A clap value parser for a `u32` in `range` (its message names the range).
pub fn parser(range: RangeInclusive<u32>) -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(*range.start() as i64..=*range.end() as i64)
}

/// The defaults of the design options where the command line gives none, which
/// `design::Design::plain` and the pipelines' option constructors take too.
pub mod defaults {
    /// `--tile`: dispatches of at most 256×256 pixels.
    pub const TILE: u32 = 256;
    /// `--light-samples`: U×V samples of the area light.
    pub const LIGHT_SAMPLES: (u32, u32) = (4, 4);
    /// `--ntree-n`: cells per axis of every N-tree node (the thesis' 10).
    pub const NTREE_N: u32 = 10;
    /// `--ntree-depth`: levels of the N-tree counting the root (reading A).
    pub const NTREE_DEPTH: u32 = 3;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_names_the_value_and_the_range() {
        assert_eq!(check("refl_depth", 16, &REFL_DEPTH), Ok(16));
        let e = check("refl_depth", 17, &REFL_DEPTH).unwrap_err();
        assert!(e.contains("17") && e.contains("0 to 16"), "{e}");
    }

    #[test]
    fn the_byte_limit_admits_the_largest_texture() {
        // a texture of the largest allowed side, RGBA8, must decode within the byte limit
        let largest = (TEXTURE_SIDE as u64).pow(2) * 4;
        assert!(TEXTURE_BYTES >= largest, "{TEXTURE_BYTES} < {largest}");
    }
}
