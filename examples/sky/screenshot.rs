//! `--screenshot`: the last frame, read back before it is presented, saved
//! as a PNG.

use std::path::Path;

use anyhow::{Context, Result};
use cumulus::render::gpu::GpuContext;

/// Reads the surface's `texture` (after the frame was submitted, before it
/// is presented; the surface was configured with `COPY_SRC`) and writes it
/// to `path` as an RGB PNG; the frame's size.
pub fn save(ctx: &GpuContext, texture: &wgpu::Texture, path: &Path) -> Result<(u32, u32)> {
    let rgba = ctx.read_texture(texture, 4)?;
    let bgra = matches!(
        texture.format(),
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    );
    let (w, h) = (texture.width(), texture.height());
    let rgb: Vec<u8> = rgba
        .chunks_exact(4)
        .flat_map(|px| {
            if bgra {
                [px[2], px[1], px[0]]
            } else {
                [px[0], px[1], px[2]]
            }
        })
        .collect();
    let img = image::RgbImage::from_raw(w, h, rgb).context("screenshot size")?;
    cumulus::io::write_png_atomically(path, &img)
        .with_context(|| format!("{}: cannot write", path.display()))?;
    Ok((w, h))
}
