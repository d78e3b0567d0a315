//! Writing results: the PNG, the NumPy AOVs and the statistics JSON.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use anyhow::{Context as _, Result};
use npyz::WriterBuilder;

use crate::frame::{Aovs, Frame};

/// The colour as an 8-bit PNG (clamped to [0, 1], no gamma, as the thesis displays it).
pub fn write_png(path: &Path, frame: &Frame) -> Result<()> {
    let img = image::RgbImage::from_fn(frame.width, frame.height, |x, y| {
        let c = frame.color[(y * frame.width + x) as usize];
        image::Rgb([0, 1, 2].map(|k| (c[k].clamp(0.0, 1.0) * 255.0).round() as u8))
    });
    img.save(path)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Write one array to `.npy` with the given shape.
pub fn write_npy<T: npyz::AutoSerialize + Copy>(
    path: &Path,
    shape: &[u64],
    data: impl IntoIterator<Item = T>,
) -> Result<()> {
    let file = File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut w = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(BufWriter::new(file))
        .begin_nd()?;
    w.extend(data)?;
    w.finish()?;
    Ok(())
}

/// The AOVs of the GUIDE: ray_origin, ray_direction (f32 `[H,W,3]`), hit_t (f32 `[H,W]`, +inf on
/// a miss), triangle_id (i32 `[H,W]`, -1 on a miss), normal (f32 `[H,W,3]`), and shadow (f32
/// `[H,W]`, the fraction of unblocked shadow rays) where the renderer has it; row 0 = top.
pub fn write_aovs(dir: &Path, width: u32, height: u32, aovs: &Aovs) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let (h, w) = (height as u64, width as u64);
    let flat3 = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
    write_npy(
        &dir.join("ray_origin.npy"),
        &[h, w, 3],
        flat3(&aovs.ray_origin),
    )?;
    write_npy(
        &dir.join("ray_direction.npy"),
        &[h, w, 3],
        flat3(&aovs.ray_direction),
    )?;
    write_npy(&dir.join("hit_t.npy"), &[h, w], aovs.hit_t.iter().copied())?;
    write_npy(
        &dir.join("triangle_id.npy"),
        &[h, w],
        aovs.triangle_id.iter().copied(),
    )?;
    write_npy(&dir.join("normal.npy"), &[h, w, 3], flat3(&aovs.normal))?;
    if let Some(shadow) = &aovs.shadow {
        write_npy(&dir.join("shadow.npy"), &[h, w], shadow.iter().copied())?;
    }
    Ok(())
}
