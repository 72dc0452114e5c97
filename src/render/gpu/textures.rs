//! Texture helpers: creation with labels, uploads of P, the cloud map (with
//! its mip chain), the 3D detail volume (with its mips), the blue-noise
//! tile, the coverage mask and the heightfield.

use half::f16;

use crate::render::cloud_map::CloudMap;
use crate::render::coverage_mask::CoverageMask;
use crate::render::noise_volume::{NoiseVolume, SIZE as NOISE_SIZE};
use crate::render::sampling;
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
/// Format of the physical sky's three tables (RGB, alpha 1), written by
/// a compute pass.
pub const LUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the light volume's planes: filterable, and writable by a
/// compute pass without extra features.
pub const PLANE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
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
    write_level(queue, texture, 0, data, bytes_per_texel);
}

/// Writes `data` (tightly packed) to all of mip level `level` of `texture`.
fn write_level(
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    level: u32,
    data: &[u8],
    bytes_per_texel: u32,
) {
    let size = texture.size().mip_level_size(level, texture.dimension());
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: level,
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

/// A sampled texture, written by uploads, of `size` (width, height,
/// depth) with `levels` mip levels.
fn create_sampled(
    device: &wgpu::Device,
    label: &str,
    size: [u32; 3],
    levels: u32,
    dimension: wgpu::TextureDimension,
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: size[2],
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Uploads the cloud map and its mip chain (`FIELD_FORMAT`): the GPU
/// samples the levels the CPU twin computed, not ones it filters itself.
pub fn upload_cloud_map(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    cm: &CloudMap,
) -> wgpu::Texture {
    let n = cm.size() as u32;
    let t = create_sampled(
        device,
        "clouds.cloud_map",
        [n, n, 1],
        cm.levels() as u32,
        wgpu::TextureDimension::D2,
        FIELD_FORMAT,
    );
    for k in 0..cm.levels() {
        let (_, texels) = cm.level(k);
        let h = halves(texels.iter().map(|&[a, b]| [a, b, 0.0, 0.0]));
        write_level(queue, &t, k as u32, bytemuck::cast_slice(&h), 8);
    }
    t
}

/// Uploads the 3D detail volume and its mips (`Rg8Unorm`, filterable),
/// or, without `v` (neither the detail noise nor the land's woods read
/// it, `GpuSettings::noise_volume`), a 1³ stand-in that no shader
/// variant reads, so the binding exists but the volume does not.
pub fn upload_noise_volume(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    v: Option<&NoiseVolume>,
) -> wgpu::Texture {
    let volume = |label: &str, n: u32, levels: u32| {
        create_sampled(
            device,
            label,
            [n, n, n],
            levels,
            wgpu::TextureDimension::D3,
            wgpu::TextureFormat::Rg8Unorm,
        )
    };
    let Some(v) = v else {
        let t = volume("clouds.detail_volume_off", 1, 1);
        write_level(queue, &t, 0, &[128, 128], 2);
        return t;
    };
    let t = volume(
        "clouds.detail_volume",
        NOISE_SIZE as u32,
        v.level_count() as u32,
    );
    for k in 0..v.level_count() {
        write_level(queue, &t, k as u32, bytemuck::cast_slice(v.level(k)), 2);
    }
    t
}

/// Uploads the blue-noise tile (`R32Float`, read with `textureLoad`).
pub fn upload_blue_noise(device: &wgpu::Device, queue: &wgpu::Queue) -> wgpu::Texture {
    let n = sampling::SIZE as u32;
    let t = create_2d(
        device,
        "clouds.blue_noise",
        n,
        n,
        wgpu::TextureFormat::R32Float,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    write_all(queue, &t, bytemuck::cast_slice(sampling::tile()), 4);
    t
}

fn halves(texels: impl Iterator<Item = [f32; 4]>) -> Vec<f16> {
    texels.flat_map(|t| t.map(f16::from_f32)).collect()
}

/// P as `FIELD_FORMAT` texels.
pub fn field_texels(p: &ProjectedField) -> Vec<f16> {
    halves(p.texels().iter().map(|t| [t[0], t[1], t[2], 0.0]))
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
