//! The wgpu wiring every pass shares: bind-group layout entries, layouts
//! and groups, the frame's uniform buffer, full-screen pipelines, and the
//! recorder that begins each labelled, timed render pass.

use super::uniforms::FrameUniforms;

/// A filterable float texture.
pub const FILTERABLE: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: true };
/// A float texture read with `textureLoad` only.
pub const UNFILTERABLE: wgpu::TextureSampleType =
    wgpu::TextureSampleType::Float { filterable: false };

fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

fn texture_of(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
    )
}

/// A binding of the compute stage.
pub fn compute_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

/// A 2D texture binding.
pub fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayoutEntry {
    texture_of(binding, sample_type, wgpu::TextureViewDimension::D2)
}

/// A 3D texture binding.
pub fn texture_3d_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayoutEntry {
    texture_of(binding, sample_type, wgpu::TextureViewDimension::D3)
}

/// The repeating, trilinear sampler the WGSL's `wrap_linear` (group 0,
/// binding 4) is: the cloud pass's and the stand-alone passes'.
pub fn wrap_linear_sampler(device: &wgpu::Device, label: &str) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(label),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        address_mode_w: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}

/// A filtering sampler binding.
pub fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
    )
}

/// A uniform buffer binding.
pub fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

/// A read-only storage buffer binding, for the fragment stage only (vertex
/// storage buffers are a downlevel feature).
pub fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        visibility: wgpu::ShaderStages::FRAGMENT,
        ..entry(
            binding,
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
        )
    }
}

/// A labelled bind-group layout.
pub fn layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries,
    })
}

/// A bind group whose `resources` take bindings 0, 1, 2, ... in order.
pub fn bind(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// The default view of a texture.
pub fn view(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor::default())
}

/// A buffer for one [`FrameUniforms`] block, written each frame.
pub fn uniform_buffer(device: &wgpu::Device, label: &str) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size_of::<FrameUniforms>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A shader module from WGSL source.
pub fn module(device: &wgpu::Device, label: &str, source: String) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}

/// A pipeline layout over `groups` (group 0, 1, ...).
pub fn pipeline_layout(
    device: &wgpu::Device,
    label: &str,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::PipelineLayout {
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|g| Some(*g)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    })
}

/// A full-screen pass: `vs_full_screen` (one triangle), then the
/// fragment entry point `fragment` (`None`: the module's only one) with the
/// pipeline-overridable `constants`, into `targets`.
pub fn full_screen_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    groups: &[&wgpu::BindGroupLayout],
    targets: &[Option<wgpu::ColorTargetState>],
    fragment: Option<&str>,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    let layout = pipeline_layout(device, label, groups);
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_full_screen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: fragment,
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                zero_initialize_workgroup_memory: false,
            },
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A colour attachment cleared to transparent black (`Some(colour)`) or
/// loaded (`None`), and stored.
pub fn color_attachment(
    view: &wgpu::TextureView,
    clear: Option<wgpu::Color>,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: clear.map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
            store: wgpu::StoreOp::Store,
        },
    })
}

/// Begins the render passes of one frame: each labelled with its name,
/// each writing its start and end timestamps (queries `2k`, `2k + 1` for
/// the `k`-th pass) when a query set is given, and each named in
/// [`Self::passes`] in the order it ran.
pub struct Recorder<'a> {
    pub encoder: &'a mut wgpu::CommandEncoder,
    timestamps: Option<&'a wgpu::QuerySet>,
    passes: Vec<&'static str>,
}

impl<'a> Recorder<'a> {
    /// A recorder into `encoder`.
    pub fn new(
        encoder: &'a mut wgpu::CommandEncoder,
        timestamps: Option<&'a wgpu::QuerySet>,
    ) -> Self {
        Self {
            encoder,
            timestamps,
            passes: Vec::new(),
        }
    }

    /// Begins the pass `name`.
    pub fn begin(
        &mut self,
        name: &'static str,
        colors: &[Option<wgpu::RenderPassColorAttachment>],
        depth: Option<wgpu::RenderPassDepthStencilAttachment>,
    ) -> wgpu::RenderPass<'_> {
        let k = self.passes.len() as u32;
        self.passes.push(name);
        self.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: colors,
            depth_stencil_attachment: depth,
            timestamp_writes: self.timestamps.map(|q| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: Some(2 * k),
                end_of_pass_write_index: Some(2 * k + 1),
            }),
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// The passes begun, in order.
    pub fn passes(self) -> Vec<&'static str> {
        self.passes
    }
}
