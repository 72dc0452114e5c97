//! Bind group 0, the inputs every pass reads: the frame's uniform block,
//! P, the cloud map (with mips), the coverage mask of P, the wrapping
//! sampler, the 3D detail volume (with mips) and the blue-noise tile.

use std::sync::Arc;

use super::bind::{self, FILTERABLE, UNFILTERABLE};
use super::textures;
use crate::render::cloud_map::CloudMap;
use crate::render::coverage_mask::CoverageMask;
use crate::render::noise_volume::NoiseVolume;
use crate::sim::ProjectedField;

/// Group 0 and the textures behind it.
pub struct Inputs {
    pub uniforms: wgpu::Buffer,
    pub layout: wgpu::BindGroupLayout,
    pub group: wgpu::BindGroup,
    sampler: wgpu::Sampler,
    p_texture: wgpu::Texture,
    /// P's size, texels.
    pub p_size: [u32; 2],
    cloud_map: wgpu::Texture,
    noise: wgpu::Texture,
    /// The detail volume, kept to upload when the detail is switched on.
    volume: Arc<NoiseVolume>,
    /// Whether `noise` holds the volume (the detail is on) or a stand-in.
    pub detail: bool,
    blue_noise: wgpu::Texture,
    mask: wgpu::Texture,
    /// The coverage mask: width, height, P texels per cell, 0.
    pub mask_info: [u32; 4],
    /// Texels per side of the cloud map.
    pub map_size: u32,
}

impl Inputs {
    /// The inputs with `cloud_map` uploaded (its detail volume only with
    /// `detail`) and an empty P (clear sky).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        cloud_map: &CloudMap,
        detail: bool,
    ) -> Self {
        let uniforms = bind::uniform_buffer(device, "clouds.frame_uniforms");
        let layout = bind::layout(
            device,
            "clouds.group0",
            &[
                bind::uniform_entry(0),
                bind::texture_entry(1, FILTERABLE),
                bind::texture_entry(2, FILTERABLE),
                bind::texture_entry(3, wgpu::TextureSampleType::Uint),
                bind::sampler_entry(4),
                bind::texture_3d_entry(5, FILTERABLE),
                bind::texture_entry(6, UNFILTERABLE),
            ],
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("clouds.wrap_linear"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            address_mode_w: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let empty = ProjectedField::new(1, 1);
        let p_texture = textures::upload_field(
            device,
            queue,
            "clouds.P",
            1,
            1,
            &textures::field_texels(&empty),
        );
        let volume = cloud_map.noise_shared();
        let noise = textures::upload_noise_volume(device, queue, detail.then_some(&*volume));
        let map_size = cloud_map.size() as u32;
        let cloud_map = textures::upload_cloud_map(device, queue, cloud_map);
        let blue_noise = textures::upload_blue_noise(device, queue);
        let mask = CoverageMask::build(&empty);
        let mask_texture = textures::upload_mask(device, queue, &mask);
        let group = group0(
            device,
            &layout,
            &[&p_texture, &cloud_map, &mask_texture, &noise, &blue_noise],
            &uniforms,
            &sampler,
        );
        Self {
            uniforms,
            layout,
            group,
            sampler,
            p_texture,
            p_size: [1, 1],
            cloud_map,
            noise,
            volume,
            detail,
            blue_noise,
            mask: mask_texture,
            mask_info: [1, 1, mask.cell as u32, 0],
            map_size,
        }
    }

    /// Uploads a new P (it may change size) and its coverage mask.
    pub fn update_field(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        field: &ProjectedField,
    ) {
        let (w, h) = (field.width().max(1) as u32, field.height().max(1) as u32);
        let texels = if field.width() == 0 || field.height() == 0 {
            textures::field_texels(&ProjectedField::new(1, 1))
        } else {
            textures::field_texels(field)
        };
        let mut rebind = false;
        if [w, h] != self.p_size {
            self.p_texture = textures::upload_field(device, queue, "clouds.P", w, h, &texels);
            self.p_size = [w, h];
            rebind = true;
        } else {
            textures::write_all(queue, &self.p_texture, bytemuck::cast_slice(&texels), 8);
        }
        rebind |= self.upload_mask(device, queue, field);
        if rebind {
            self.rebind(device);
        }
    }

    /// Replaces the cloud map.
    pub fn update_cloud_map(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        cloud_map: &CloudMap,
    ) {
        self.cloud_map = textures::upload_cloud_map(device, queue, cloud_map);
        self.map_size = cloud_map.size() as u32;
        self.volume = cloud_map.noise_shared();
        self.noise =
            textures::upload_noise_volume(device, queue, self.detail.then_some(&*self.volume));
        self.rebind(device);
    }

    /// Uploads the detail volume (`on`) or drops it for a stand-in.
    pub fn set_detail(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, on: bool) {
        if on == self.detail {
            return;
        }
        self.detail = on;
        self.noise = textures::upload_noise_volume(device, queue, on.then_some(&*self.volume));
        self.rebind(device);
    }

    /// Writes the mask of `field`; whether its texture was replaced (new
    /// size).
    fn upload_mask(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        field: &ProjectedField,
    ) -> bool {
        let mask = CoverageMask::build(field);
        let info = [mask.width as u32, mask.height as u32, mask.cell as u32, 0];
        if info == self.mask_info {
            textures::write_all(queue, &self.mask, &mask.cells, 1);
            false
        } else {
            self.mask = textures::upload_mask(device, queue, &mask);
            self.mask_info = info;
            true
        }
    }

    fn rebind(&mut self, device: &wgpu::Device) {
        self.group = group0(
            device,
            &self.layout,
            &[
                &self.p_texture,
                &self.cloud_map,
                &self.mask,
                &self.noise,
                &self.blue_noise,
            ],
            &self.uniforms,
            &self.sampler,
        );
    }
}

/// Group 0 over `textures` (P, cloud map, mask, detail volume, blue
/// noise, in binding order around the uniforms and the sampler).
fn group0(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    textures: &[&wgpu::Texture; 5],
    uniforms: &wgpu::Buffer,
    sampler: &wgpu::Sampler,
) -> wgpu::BindGroup {
    let [p, cloud_map, mask, noise, blue] = textures.map(bind::view);
    bind::bind(
        device,
        "clouds.group0",
        layout,
        &[
            uniforms.as_entire_binding(),
            wgpu::BindingResource::TextureView(&p),
            wgpu::BindingResource::TextureView(&cloud_map),
            wgpu::BindingResource::TextureView(&mask),
            wgpu::BindingResource::Sampler(sampler),
            wgpu::BindingResource::TextureView(&noise),
            wgpu::BindingResource::TextureView(&blue),
        ],
    )
}
