//! What [`super::CloudRenderer::render`] and `render_clouds` check of an
//! application's target and depth buffer before recording anything: a
//! mismatch returns a [`RenderError`] naming it, where wgpu's validation
//! would otherwise panic inside the caller's frame (a multisampled or
//! unbindable depth buffer) or the picture would be silently wrong (a
//! target of another size than the renderer's, whose cloud layer the
//! composite reads pixel for pixel).

/// Errors of [`super::CloudRenderer::render`] and `render_clouds`: what
/// the checks below find wrong with the target or the depth buffer.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RenderError {
    #[error(transparent)]
    Unsupported(#[from] super::requirements::Unsupported),
    #[error(
        "the depth buffer is {depth_w}x{depth_h} but the renderer is {width}x{height}: call resize() with the target's size"
    )]
    DepthSizeMismatch {
        depth_w: u32,
        depth_h: u32,
        width: u32,
        height: u32,
    },
    #[error("the depth buffer's format {0:?} is not a depth format")]
    NotADepthFormat(wgpu::TextureFormat),
    #[error(
        "the depth buffer has {0} samples: resolve a multisampled depth buffer to one sample first"
    )]
    DepthMultisampled(u32),
    #[error(
        "the depth buffer's usage {0:?} lacks TEXTURE_BINDING, which the cloud pass reads it with"
    )]
    DepthNotBindable(wgpu::TextureUsages),
    #[error(
        "the target's format {0:?} cannot be blended into on this device, and the clouds are blended over the application's colour where a depth buffer is given: use Rgba16Float, or request wgpu's FLOAT32_BLENDABLE feature"
    )]
    TargetNotBlendable(wgpu::TextureFormat),
    #[error(
        "the target is {target_w}x{target_h} but the renderer is {width}x{height}: call resize() with the target's size"
    )]
    TargetSizeMismatch {
        target_w: u32,
        target_h: u32,
        width: u32,
        height: u32,
    },
    #[error(
        "the target's format {target:?} is not the format {expected:?} the renderer was created for"
    )]
    TargetFormat {
        target: wgpu::TextureFormat,
        expected: wgpu::TextureFormat,
    },
}

/// The target: the renderer's format and size, and, where the composite
/// blends the clouds over the application's colour (`blended`: its depth
/// buffer given, no terrain of the scene's own), a format the device
/// blends into (`Rgba32Float` only with `FLOAT32_BLENDABLE` in
/// `features`).
pub(super) fn check_target(
    target: &wgpu::TextureView,
    format: wgpu::TextureFormat,
    size: (u32, u32),
    blended: bool,
    features: wgpu::Features,
) -> Result<(), RenderError> {
    let t = target.texture();
    if t.format() != format {
        return Err(RenderError::TargetFormat {
            target: t.format(),
            expected: format,
        });
    }
    if blended && !blendable(t.format(), features) {
        return Err(RenderError::TargetNotBlendable(t.format()));
    }
    if (t.width(), t.height()) != size {
        return Err(RenderError::TargetSizeMismatch {
            target_w: t.width(),
            target_h: t.height(),
            width: size.0,
            height: size.1,
        });
    }
    Ok(())
}

/// Whether a device with `features` blends into `format`.
fn blendable(format: wgpu::TextureFormat, features: wgpu::Features) -> bool {
    format
        .guaranteed_format_features(features)
        .flags
        .contains(wgpu::TextureFormatFeatureFlags::BLENDABLE)
}

/// The depth buffer: a depth format, the renderer's size, one sample,
/// `TEXTURE_BINDING` usage. For a depth-stencil format the passes bind a
/// view of its depth alone, returned here (a shader's `texture_depth_2d`
/// cannot bind both aspects, and a default view of such a texture has
/// both).
pub(super) fn check_depth(
    depth: Option<&wgpu::TextureView>,
    size: (u32, u32),
) -> Result<Option<wgpu::TextureView>, RenderError> {
    let Some(d) = depth else { return Ok(None) };
    let t = d.texture();
    let format = t.format();
    if !format.is_depth_stencil_format() {
        return Err(RenderError::NotADepthFormat(format));
    }
    if (t.width(), t.height()) != size {
        return Err(RenderError::DepthSizeMismatch {
            depth_w: t.width(),
            depth_h: t.height(),
            width: size.0,
            height: size.1,
        });
    }
    if t.sample_count() != 1 {
        return Err(RenderError::DepthMultisampled(t.sample_count()));
    }
    if !t.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(RenderError::DepthNotBindable(t.usage()));
    }
    Ok(format.has_stencil_aspect().then(|| {
        t.create_view(&wgpu::TextureViewDescriptor {
            label: Some("cumulus.depth_only"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        })
    }))
}

/// The renderer can move to or be shared with another thread (its wgpu
/// handles are); checked when the crate compiles.
const _: () = {
    const fn send_and_sync<T: Send + Sync>() {}
    send_and_sync::<super::CloudRenderer>();
};
