//! What the renderer asks of a wgpu adapter, so that an application can
//! ask before it creates its device ([`check_adapter`]), and
//! [`GpuContext`](super::GpuContext) refuses an adapter that could not
//! draw the clouds with an error that names what is missing.
//!
//! The renderer needs compute shaders (the light volume, the sky's
//! tables), storage textures and floating-point render targets: WebGPU
//! and every Vulkan, Metal and D3D12 adapter have them. Downlevel
//! adapters (OpenGL ES / WebGL2, and wgpu's OpenGL backend, which it
//! treats as GLES) are refused: wgpu does not let them render into
//! `R32Float` (the clouds' distance for TSAA), among others.

use super::textures::{
    CLOUD_FORMAT, DEPTH_FORMAT, DISTANCE_FORMAT, FIELD_FORMAT, LUT_FORMAT, PLANE_FORMAT,
};

/// A texture format the renderer creates, how it uses it, and for what.
#[derive(Debug, Clone, Copy)]
pub struct FormatNeed {
    pub format: wgpu::TextureFormat,
    pub usages: wgpu::TextureUsages,
    /// Whether a filtering sampler reads it.
    pub filterable: bool,
    /// What the renderer keeps in it.
    pub what: &'static str,
}

const SAMPLED: wgpu::TextureUsages =
    wgpu::TextureUsages::TEXTURE_BINDING.union(wgpu::TextureUsages::COPY_DST);
const TARGET: wgpu::TextureUsages =
    wgpu::TextureUsages::RENDER_ATTACHMENT.union(wgpu::TextureUsages::TEXTURE_BINDING);
const STORAGE: wgpu::TextureUsages =
    wgpu::TextureUsages::STORAGE_BINDING.union(wgpu::TextureUsages::TEXTURE_BINDING);

/// The texture formats and usages the renderer needs (the optional
/// passes' included: terrain, TSAA, the light volume, the physical sky).
pub const FORMATS: [FormatNeed; 7] = [
    FormatNeed {
        format: FIELD_FORMAT,
        usages: SAMPLED,
        filterable: true,
        what: "P and the cloud map",
    },
    FormatNeed {
        format: CLOUD_FORMAT,
        usages: TARGET,
        filterable: true,
        what: "the cloud layer and the TSAA history",
    },
    FormatNeed {
        format: DISTANCE_FORMAT,
        usages: TARGET,
        filterable: false,
        what: "the clouds' distance, which TSAA reprojects",
    },
    FormatNeed {
        format: wgpu::TextureFormat::R32Float,
        usages: SAMPLED,
        filterable: false,
        what: "the blue-noise dither and the terrain's heights",
    },
    FormatNeed {
        format: PLANE_FORMAT,
        usages: STORAGE,
        filterable: true,
        what: "the light volume's planes, written by a compute pass",
    },
    FormatNeed {
        format: LUT_FORMAT,
        usages: STORAGE,
        filterable: false,
        what: "the physical sky's tables, written by a compute pass",
    },
    FormatNeed {
        format: DEPTH_FORMAT,
        usages: TARGET,
        filterable: false,
        what: "the terrain's depth",
    },
];

/// The downlevel capabilities the renderer needs: compute shaders.
pub const DOWNLEVEL: wgpu::DownlevelFlags = wgpu::DownlevelFlags::COMPUTE_SHADERS;

/// The limits the renderer needs: wgpu's downlevel defaults (which
/// [`GpuContext`](super::GpuContext) requests, raised to the adapter's
/// texture sizes). It needs no wgpu feature (it uses timestamp queries
/// when the device has them).
pub fn limits() -> wgpu::Limits {
    wgpu::Limits::downlevel_defaults()
}

/// Each of [`limits`] that `has` falls short of, named.
fn missing_limits(has: &wgpu::Limits) -> Vec<String> {
    let mut missing = Vec::new();
    limits().check_limits_with_fail_fn(has, false, |name, want, allowed| {
        missing.push(format!("limit {name}: needs {want}, has {allowed}"));
    });
    missing
}

/// An adapter that cannot draw the clouds, and everything it lacks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the GPU adapter {adapter} cannot draw the clouds: it lacks {}", missing.join("; "))]
pub struct Unsupported {
    pub adapter: String,
    /// Each missing capability, named as wgpu names it, with what the
    /// renderer needs it for.
    pub missing: Vec<String>,
}

/// Whether `adapter` has everything the renderer needs: `Err` lists what
/// it lacks (downlevel flags, limits, texture formats and their usages).
pub fn check_adapter(adapter: &wgpu::Adapter) -> Result<(), Unsupported> {
    let info = adapter.get_info();
    let missing = missing_capabilities(
        &adapter.limits(),
        adapter.get_downlevel_capabilities().flags,
        |f| adapter.get_texture_format_features(f),
    );
    if missing.is_empty() {
        Ok(())
    } else {
        Err(Unsupported {
            adapter: format!("{} ({:?})", info.name, info.backend),
            missing,
        })
    }
}

/// Whether `device` can draw the clouds ([`CloudRenderer::new`](super::CloudRenderer::new)
/// asks): its limits against [`limits`], then a one-texel texture of
/// each of [`FORMATS`] with its usages, made inside a validation error
/// scope, so a format the device refuses is named instead of failing a
/// later frame. (A device does not tell its downlevel flags or its
/// formats' filtering; [`check_adapter`] checks those on the adapter.)
pub fn check_device(device: &wgpu::Device) -> Result<(), Unsupported> {
    let mut missing = missing_limits(&device.limits());
    for need in FORMATS {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let probe = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("cumulus.format_probe"),
            size: wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: need.format,
            usage: need.usages,
            view_formats: &[],
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            missing.push(format!(
                "{:?} as {:?} ({}): {e}",
                need.format, need.usages, need.what
            ));
        }
        probe.destroy();
    }
    if missing.is_empty() {
        Ok(())
    } else {
        Err(Unsupported {
            adapter: "the device's adapter".into(),
            missing,
        })
    }
}

/// What an adapter of these capabilities lacks, each named ([`check_adapter`]).
pub fn missing_capabilities(
    has: &wgpu::Limits,
    downlevel: wgpu::DownlevelFlags,
    format_features: impl Fn(wgpu::TextureFormat) -> wgpu::TextureFormatFeatures,
) -> Vec<String> {
    let mut missing = Vec::new();
    if !downlevel.contains(DOWNLEVEL) {
        missing.push(format!(
            "downlevel flags {:?} (the light volume and the sky's tables are compute passes)",
            DOWNLEVEL - downlevel
        ));
    }
    missing.extend(missing_limits(has));
    for need in FORMATS {
        let f = format_features(need.format);
        if !f.allowed_usages.contains(need.usages) {
            missing.push(format!(
                "{:?} as {:?} ({})",
                need.format,
                need.usages - f.allowed_usages,
                need.what
            ));
        }
        if need.filterable
            && !f
                .flags
                .contains(wgpu::TextureFormatFeatureFlags::FILTERABLE)
        {
            missing.push(format!("filtering of {:?} ({})", need.format, need.what));
        }
    }
    missing
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_formats(_: wgpu::TextureFormat) -> wgpu::TextureFormatFeatures {
        wgpu::TextureFormatFeatures {
            allowed_usages: wgpu::TextureUsages::all(),
            flags: wgpu::TextureFormatFeatureFlags::all(),
        }
    }

    /// A full adapter lacks nothing; one without compute, without
    /// `R32Float` render targets or with small limits is told each.
    #[test]
    fn each_missing_capability_is_named() {
        let full = wgpu::Limits::default();
        let all = wgpu::DownlevelFlags::all();
        assert!(missing_capabilities(&full, all, all_formats).is_empty());
        let no_compute = all - wgpu::DownlevelFlags::COMPUTE_SHADERS;
        let m = missing_capabilities(&full, no_compute, all_formats);
        assert_eq!(m.len(), 1);
        assert!(m[0].contains("COMPUTE_SHADERS"), "{m:?}");
        let no_r32_target = |f: wgpu::TextureFormat| {
            let mut x = all_formats(f);
            if f == wgpu::TextureFormat::R32Float {
                x.allowed_usages -= wgpu::TextureUsages::RENDER_ATTACHMENT;
            }
            x
        };
        let m = missing_capabilities(&full, all, no_r32_target);
        assert_eq!(m.len(), 1, "{m:?}");
        assert!(
            m[0].contains("R32Float") && m[0].contains("RENDER_ATTACHMENT"),
            "{m:?}"
        );
        let small = wgpu::Limits {
            max_storage_textures_per_shader_stage: 1,
            ..full
        };
        let m = missing_capabilities(&small, all, all_formats);
        assert!(
            m.iter()
                .any(|s| s.contains("max_storage_textures_per_shader_stage")),
            "{m:?}"
        );
    }
}
