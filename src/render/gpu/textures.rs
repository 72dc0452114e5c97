//! Texture helpers: creation with labels, uploads of P, the cloud map, the
//! coverage mask and the heightfield.

use half::f16;

use crate::render::cloud_map::CloudMap;
use crate::render::coverage_mask::CoverageMask;
use crate::render::terrain::Heightfield;
use crate::sim::ProjectedField;

/// Format of P (coverage, height, fill, unused) and of the cloud map:
/// half floats, filterable everywhere (hardware bilinear, repeat).
pub const FIELD_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the cloud layer and the TSAA history (premultiplied
/// radiance, opacity).
pub const CLOUD_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the cloud distance (TSAA only).
pub const DISTANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Format of the terrain's depth buffer.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Usage of the passes' size-dependent targets (drawn into, read by a
/// later pass, read back by tests).
pub const TARGET_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

/// A 2D texture with one mip level.
pub fn create_2d(
    device: &wgpu::Device,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: width.max(1),
            height: height.max(1),
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Writes `data` (tightly packed rows of `bytes_per_texel`) to all of `texture`.
pub fn write_all(queue: &wgpu::Queue, texture: &wgpu::Texture, data: &[u8], bytes_per_texel: u32) {
    let size = texture.size();
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        data,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size.width * bytes_per_texel),
            rows_per_image: Some(size.height),
        },
        size,
    );
}

fn halves(texels: impl Iterator<Item = [f32; 4]>) -> Vec<f16> {
    texels.flat_map(|t| t.map(f16::from_f32)).collect()
}

/// P as `FIELD_FORMAT` texels.
pub fn field_texels(p: &ProjectedField) -> Vec<f16> {
    halves(p.texels().iter().map(|t| [t[0], t[1], t[2], 0.0]))
}

/// The cloud map as `FIELD_FORMAT` texels.
pub fn cloud_map_texels(cm: &CloudMap) -> Vec<f16> {
    let n = cm.size();
    halves((0..n * n).map(|k| {
        let [a, b] = cm.texel(k % n, k / n);
        [a, b, 0.0, 0.0]
    }))
}

/// Uploads a texture of `FIELD_FORMAT` from `texels` (`width x height`).
pub fn upload_field(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    width: u32,
    height: u32,
    texels: &[f16],
) -> wgpu::Texture {
    let t = create_2d(
        device,
        label,
        width,
        height,
        FIELD_FORMAT,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    write_all(queue, &t, bytemuck::cast_slice(texels), 8);
    t
}

/// Uploads the coverage mask (`R8Uint`).
pub fn upload_mask(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mask: &CoverageMask,
) -> wgpu::Texture {
    let t = create_2d(
        device,
        "clouds.coverage_mask",
        mask.width as u32,
        mask.height as u32,
        wgpu::TextureFormat::R8Uint,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    write_all(queue, &t, &mask.cells, 1);
    t
}

/// Uploads the heightfield (`R32Float`, metres).
pub fn upload_heights(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    h: &Heightfield,
) -> wgpu::Texture {
    let n = h.size() as u32;
    let t = create_2d(
        device,
        "terrain.heights",
        n,
        n,
        wgpu::TextureFormat::R32Float,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    write_all(queue, &t, bytemuck::cast_slice(h.heights()), 4);
    t
}
