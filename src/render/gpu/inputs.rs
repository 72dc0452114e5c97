//! Bind group 0, the inputs every pass reads: the frame's uniform block,
//! P, the cloud map, the coverage mask of P and the wrapping sampler.

use super::bind::{self, FILTERABLE};
use super::textures;
use crate::render::cloud_map::CloudMap;
use crate::render::coverage_mask::CoverageMask;
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
    mask: wgpu::Texture,
    /// The coverage mask: width, height, P texels per cell, 0.
    pub mask_info: [u32; 4],
}

impl Inputs {
    /// The inputs with `cloud_map` uploaded and an empty P (clear sky).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, cloud_map: &CloudMap) -> Self {
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
            ],
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("clouds.wrap_linear"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
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
        let cloud_map = upload_cloud_map(device, queue, cloud_map);
        let mask = CoverageMask::build(&empty);
        let mask_texture = textures::upload_mask(device, queue, &mask);
        let group = group0(
            device,
            &layout,
            &uniforms,
            &p_texture,
            &cloud_map,
            &mask_texture,
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
            mask: mask_texture,
            mask_info: [1, 1, mask.cell as u32, 0],
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
        self.cloud_map = upload_cloud_map(device, queue, cloud_map);
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
            &self.uniforms,
            &self.p_texture,
            &self.cloud_map,
            &self.mask,
            &self.sampler,
        );
    }
}

fn upload_cloud_map(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    cloud_map: &CloudMap,
) -> wgpu::Texture {
    let n = cloud_map.size() as u32;
    textures::upload_field(
        device,
        queue,
        "clouds.cloud_map",
        n,
        n,
        &textures::cloud_map_texels(cloud_map),
    )
}

fn group0(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    uniforms: &wgpu::Buffer,
    p: &wgpu::Texture,
    cloud_map: &wgpu::Texture,
    mask: &wgpu::Texture,
    sampler: &wgpu::Sampler,
) -> wgpu::BindGroup {
    bind::bind(
        device,
        "clouds.group0",
        layout,
        &[
            uniforms.as_entire_binding(),
            wgpu::BindingResource::TextureView(&bind::view(p)),
            wgpu::BindingResource::TextureView(&bind::view(cloud_map)),
            wgpu::BindingResource::TextureView(&bind::view(mask)),
            wgpu::BindingResource::Sampler(sampler),
        ],
    )
}
