//! `--screenshot`: the presented frame copied back and saved as a PNG.

use std::path::Path;

use anyhow::{Context, Result};
use cumulus::render::gpu::GpuContext;

/// A frame copied into a mappable buffer (rows padded to 256 bytes).
pub struct Readback {
    buffer: wgpu::Buffer,
    row: u32,
    width: u32,
    height: u32,
}

/// Records a copy of `texture` (the surface's frame) into a new buffer.
pub fn copy(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
) -> Readback {
    let (width, height) = (texture.width(), texture.height());
    let row = (4 * width).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
        * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sky.screenshot"),
        size: row as u64 * height as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(height),
            },
        },
        texture.size(),
    );
    Readback {
        buffer,
        row,
        width,
        height,
    }
}

/// Waits for the copy (after the frame was submitted) and writes it to
/// `path` as an RGB PNG; the frame's size.
pub fn save(
    ctx: &GpuContext,
    r: Readback,
    format: wgpu::TextureFormat,
    path: &Path,
) -> Result<(u32, u32)> {
    let data = ctx.map_read(&r.buffer)?;
    let bgra = matches!(
        format,
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    );
    let (w, h) = (r.width, r.height);
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h as usize {
        for px in data[y * r.row as usize..][..4 * w as usize].chunks_exact(4) {
            if bgra {
                rgb.extend([px[2], px[1], px[0]]);
            } else {
                rgb.extend([px[0], px[1], px[2]]);
            }
        }
    }
    let img = image::RgbImage::from_raw(w, h, rgb).context("screenshot size")?;
    cumulus::io::write_png_atomically(path, &img)
        .with_context(|| format!("{}: cannot write", path.display()))?;
    Ok((w, h))
}
