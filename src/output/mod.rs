//! Writing results: the colour image, the NumPy AOVs, the statistics JSON, and every other file
//! a command writes (the bench's CSVs, plots and report, the viewer's screenshots).
//!
//! Every command that writes files goes through this module:
//!
//! 1. [`check`] its output paths before any GPU work ([`Target`]: a format the command writes,
//!    a folder that exists and takes new files, no two outputs at the same file) and
//!    [`refuse_inputs`] (no output at the scene file, a model or a texture it reads:
//!    [`scene_inputs`]);
//! 2. write each file to a temporary file beside it, flushed to disk ([`Staging::file`]);
//! 3. rename them all over their targets only when all were written ([`Staging::commit`]): a
//!    failure leaves the old files as they were and no temporary file behind (a rename that
//!    fails after others puts their old files back).
//!
//! Errors name the file. A device or pipe (`/dev/stdout`) is written in place, after every
//! regular file was written and before any is renamed.

mod check;
pub mod console;
mod inputs;
pub mod interrupt;
mod stage;

use std::path::Path;

use anyhow::Result;
use npyz::WriterBuilder;

use crate::frame::{Aovs, Frame};

pub use check::{check, check_folder, parent_of, refuse_inputs, same_file, Format, Input, Target};
pub use inputs::scene_inputs;
pub use stage::{write_file, Batch, Staging, WriteSeek};

/// The files of `--aov-dir` (`shadow.npy` only where the renderer has it).
pub const AOV_FILES: [&str; 6] = [
    "ray_origin.npy",
    "ray_direction.npy",
    "hit_t.npy",
    "triangle_id.npy",
    "normal.npy",
    "shadow.npy",
];

/// The colour as 8-bit RGB (clamped to [0, 1], no gamma, as the thesis displays it).
pub fn frame_image(frame: &Frame) -> image::RgbImage {
    image::RgbImage::from_fn(frame.width, frame.height, |x, y| {
        let c = frame.color[(y * frame.width + x) as usize];
        image::Rgb([0, 1, 2].map(|k| (c[k].clamp(0.0, 1.0) * 255.0).round() as u8))
    })
}

/// Is `path` an OpenEXR file by its extension?
pub fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// The frame's colour for `path`: linear float RGB in OpenEXR for `.exr` (the values as the
/// kernels computed them, not clamped), else 8-bit PNG or JPEG ([`encode_image`]).
pub fn encode_color(frame: &Frame, path: &Path, w: &mut dyn WriteSeek) -> Result<()> {
    if !is_exr(path) {
        return encode_image(&frame_image(frame), path, w);
    }
    let channel = |name: &str, k: usize| {
        let v: Vec<f32> = frame.color.iter().map(|c| c[k]).collect();
        exr::prelude::AnyChannel::new(name, exr::prelude::FlatSamples::F32(v))
    };
    let channels = vec![channel("R", 0), channel("G", 1), channel("B", 2)];
    encode_exr(w, (frame.width, frame.height), "color", channels)
}

/// One OpenEXR image of one layer named `layer` with `channels` (each `width`·`height`
/// samples, row 0 = top), ZIP-compressed (lossless), to `w`.
fn encode_exr(
    w: &mut dyn WriteSeek,
    (width, height): (u32, u32),
    layer: &str,
    channels: Vec<exr::prelude::AnyChannel<exr::prelude::FlatSamples>>,
) -> Result<()> {
    use exr::prelude::*;
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::named(layer),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    Image::from_layer(layer)
        .write()
        .to_buffered(w)
        .map_err(|e| anyhow::anyhow!("OpenEXR: {e}"))
}

/// The AOVs as one OpenEXR file: a channel per npy array and component, named as the files
/// are (`hit_t`, `triangle_id`, `normal.X`/`.Y`/`.Z`, `ray_origin.X`…, `ray_direction.X`…,
/// `shadow` where the renderer has it), the same values: f32, and `triangle_id` as a 32-bit
/// unsigned channel holding the npy's i32 bits (a miss, −1, is 4294967295).
pub fn encode_aovs_exr(w: &mut dyn WriteSeek, width: u32, height: u32, a: &Aovs) -> Result<()> {
    use exr::prelude::{AnyChannel, FlatSamples};
    let f32s = |name: String, v: Vec<f32>| AnyChannel::new(name.as_str(), FlatSamples::F32(v));
    let vec3 = |name: &str, v: &[[f32; 3]]| {
        ["X", "Y", "Z"]
            .into_iter()
            .enumerate()
            .map(|(k, axis)| f32s(format!("{name}.{axis}"), v.iter().map(|p| p[k]).collect()))
            .collect::<Vec<_>>()
    };
    let mut channels = vec![
        f32s("hit_t".into(), a.hit_t.clone()),
        AnyChannel::new(
            "triangle_id",
            FlatSamples::U32(a.triangle_id.iter().map(|&id| id as u32).collect()),
        ),
    ];
    channels.extend(vec3("normal", &a.normal));
    channels.extend(vec3("ray_origin", &a.ray_origin));
    channels.extend(vec3("ray_direction", &a.ray_direction));
    if let Some(s) = &a.shadow {
        channels.push(f32s("shadow".into(), s.clone()));
    }
    encode_exr(w, (width, height), "aovs", channels)
}

/// Encode `img` for `path`: JPEG for `.jpg`/`.jpeg`, else PNG.
pub fn encode_image(img: &image::RgbImage, path: &Path, mut w: &mut dyn WriteSeek) -> Result<()> {
    let format = match image::ImageFormat::from_path(path) {
        Ok(image::ImageFormat::Jpeg) => image::ImageFormat::Jpeg,
        _ => image::ImageFormat::Png,
    };
    img.write_to(&mut w, format)?;
    Ok(())
}

/// The frame's colour to `path` (PNG or JPEG by the extension), replacing it only when
/// complete.
pub fn write_image(path: &Path, frame: &Frame) -> Result<()> {
    write_file(path, |w| encode_color(frame, path, w))
}

/// Encode one array as `.npy` with the given shape.
pub fn encode_npy<T: npyz::AutoSerialize + Copy>(
    w: &mut dyn WriteSeek,
    shape: &[u64],
    data: impl IntoIterator<Item = T>,
) -> Result<()> {
    let mut npy = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(w)
        .begin_nd()?;
    npy.extend(data)?;
    npy.finish()?;
    Ok(())
}

/// Write one array to the `.npy` file `path`, replacing it only when complete.
pub fn write_npy<T: npyz::AutoSerialize + Copy>(
    path: &Path,
    shape: &[u64],
    data: impl IntoIterator<Item = T>,
) -> Result<()> {
    write_file(path, |w| encode_npy(w, shape, data))
}

/// Stage the text `text` as `path`.
pub fn stage_text(s: &mut Staging, path: &Path, text: &str) -> Result<()> {
    s.file(path, |w| Ok(w.write_all(text.as_bytes())?))
}

/// The one file of `--aov-format exr`.
pub const AOV_EXR: &str = "aovs.exr";

/// How `--aov-dir` writes the AOVs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum AovFormat {
    /// A NumPy `.npy` file per AOV.
    #[default]
    Npy,
    /// One multi-channel OpenEXR file, `aovs.exr`.
    Exr,
}

/// Stage the AOVs in `dir` (made if missing) as `format` says.
pub fn stage_aovs_as(
    s: &mut Staging,
    format: AovFormat,
    dir: &Path,
    (width, height): (u32, u32),
    a: &Aovs,
) -> Result<()> {
    match format {
        AovFormat::Npy => stage_aovs(s, dir, width, height, a),
        AovFormat::Exr => {
            s.create_folder(dir)?;
            s.file(&dir.join(AOV_EXR), |w| encode_aovs_exr(w, width, height, a))
        }
    }
}

/// Stage the AOVs of the GUIDE in `dir` (made if missing): ray_origin, ray_direction (f32
/// `[H,W,3]`), hit_t (f32 `[H,W]`, +inf on a miss), triangle_id (i32 `[H,W]`, -1 on a miss),
/// normal (f32 `[H,W,3]`), and shadow (f32 `[H,W]`, the fraction of unblocked shadow rays)
/// where the renderer has it; row 0 = top.
pub fn stage_aovs(s: &mut Staging, dir: &Path, width: u32, height: u32, a: &Aovs) -> Result<()> {
    s.create_folder(dir)?;
    let (h, w) = (height as u64, width as u64);
    let flat3 = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
    let [origin, direction, hit_t, triangle_id, normal, shadow] = AOV_FILES.map(|f| dir.join(f));
    s.file(&origin, |o| encode_npy(o, &[h, w, 3], flat3(&a.ray_origin)))?;
    s.file(&direction, |o| {
        encode_npy(o, &[h, w, 3], flat3(&a.ray_direction))
    })?;
    s.file(&hit_t, |o| encode_npy(o, &[h, w], a.hit_t.iter().copied()))?;
    let ids = a.triangle_id.iter().copied();
    s.file(&triangle_id, |o| encode_npy(o, &[h, w], ids))?;
    s.file(&normal, |o| encode_npy(o, &[h, w, 3], flat3(&a.normal)))?;
    if let Some(v) = &a.shadow {
        s.file(&shadow, |o| encode_npy(o, &[h, w], v.iter().copied()))?;
    }
    Ok(())
}
