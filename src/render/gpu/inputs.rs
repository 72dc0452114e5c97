//! Bind group 0, the inputs every pass reads: the frame's uniform block,
//! P, the cloud map (with mips), the coverage mask of P, the wrapping
//! sampler, the 3D detail volume (with mips) and the blue-noise tile; under
//! the physical sky also the atmosphere's params and its three tables
//! (bindings 7 to 11, built by [`SkyLutsPass`]; absent under the analytic
//! sky).

use glam::Vec3;

use std::sync::Arc;

use super::bind::{self, FILTERABLE, UNFILTERABLE};
use super::sky_luts_pass::{SkyLutsPass, SkyTable};
use super::textures;
use crate::render::cloud_map::CloudMap;
use crate::render::coverage_mask::CoverageMask;
use crate::render::cpu::sky_luts::SkyParams;
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
    /// The physical sky's tables (none: the analytic sky).
    pub sky: Option<SkyLutsPass>,
}

impl Inputs {
    /// The inputs with `cloud_map` uploaded (its detail volume only with
    /// `detail`: the detail noise or the land's woods read it), an empty P (clear sky), and with `sky` the physical
    /// sky's tables for the sun at `sun_dir` (the sky view for a camera on
    /// the ground until the first frame).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        cloud_map: &CloudMap,
        detail: bool,
        sky: Option<&SkyParams>,
        sun_dir: Vec3,
    ) -> Self {
        let uniforms = bind::uniform_buffer(device, "clouds.frame_uniforms");
        let sky = sky.map(|p| SkyLutsPass::with_device(device, queue, p, sun_dir, 0.0));
        let layout = group0_layout(device, sky.is_some());
        let sampler = bind::wrap_linear_sampler(device, "clouds.wrap_linear");
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
            sky.as_ref(),
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
            sky,
        }
    }

    /// Switches between the physical sky (`Some`: its tables built, or
    /// rebuilt where the params changed) and the analytic one; whether the
    /// layout changed (the passes' pipelines must then be rebuilt).
    pub fn set_sky(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        sky: Option<&SkyParams>,
        sun_dir: Vec3,
        camera_altitude_m: f32,
    ) -> bool {
        match (sky, &mut self.sky) {
            (Some(p), Some(pass)) => {
                pass.update(device, queue, p, sun_dir, camera_altitude_m);
                false
            }
            (None, None) => false,
            (p, _) => {
                self.sky = p.map(|p| {
                    SkyLutsPass::with_device(device, queue, p, sun_dir, camera_altitude_m)
                });
                self.layout = group0_layout(device, self.sky.is_some());
                self.rebind(device);
                true
            }
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

    /// Uploads the detail volume (`on`: the detail noise or the land's
    /// woods read it) or drops it for a stand-in.
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
            self.sky.as_ref(),
        );
    }
}

/// Group 0's layout, with the physical sky's bindings when `sky`.
fn group0_layout(device: &wgpu::Device, sky: bool) -> wgpu::BindGroupLayout {
    let mut entries = vec![
        bind::uniform_entry(0),
        bind::texture_entry(1, FILTERABLE),
        bind::texture_entry(2, FILTERABLE),
        bind::texture_entry(3, wgpu::TextureSampleType::Uint),
        bind::sampler_entry(4),
        bind::texture_3d_entry(5, FILTERABLE),
        bind::texture_entry(6, UNFILTERABLE),
    ];
    if sky {
        entries.extend([
            bind::uniform_entry(7),
            bind::texture_entry(8, UNFILTERABLE),
            bind::texture_entry(9, UNFILTERABLE),
            bind::texture_entry(10, UNFILTERABLE),
            bind::texture_entry(11, UNFILTERABLE),
        ]);
    }
    bind::layout(device, "clouds.group0", &entries)
}

/// Group 0 over `textures` (P, cloud map, mask, detail volume, blue
/// noise, in binding order around the uniforms and the sampler).
fn group0(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    textures: &[&wgpu::Texture; 5],
    uniforms: &wgpu::Buffer,
    sampler: &wgpu::Sampler,
    sky: Option<&SkyLutsPass>,
) -> wgpu::BindGroup {
    let [p, cloud_map, mask, noise, blue] = textures.map(bind::view);
    let tables = sky.map(|s| SkyTable::ALL.map(|t| bind::view(s.texture(t))));
    let mut resources = vec![
        uniforms.as_entire_binding(),
        wgpu::BindingResource::TextureView(&p),
        wgpu::BindingResource::TextureView(&cloud_map),
        wgpu::BindingResource::TextureView(&mask),
        wgpu::BindingResource::Sampler(sampler),
        wgpu::BindingResource::TextureView(&noise),
        wgpu::BindingResource::TextureView(&blue),
    ];
    if let (Some(s), Some(tables)) = (sky, &tables) {
        resources.push(s.params_buffer().as_entire_binding());
        resources.extend(tables.iter().map(wgpu::BindingResource::TextureView));
    }
    bind::bind(device, "clouds.group0", layout, &resources)
}
