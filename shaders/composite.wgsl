// The composite pass: the resolved clouds (premultiplied radiance and
// opacity) over the background (the analytic sky and sun disk, or the
// terrain), tone-mapped into the target. Appended to clouds.wgsl.
//
// src/render/gpu/shaders.rs adds the background bindings of the variant:
// none (sky only), the terrain's HDR colour, or an external depth buffer
// (pixels with geometry keep their colour, the clouds in front are blended
// over it with premultiplied alpha).

override ENCODE_SRGB: bool = false;
// Off for a floating-point (HDR) target, which receives the linear
// radiance untouched, for an engine's own exposure and tone map (and the
// CLI's OpenEXR output).
override TONE_MAP: bool = true;

@group(1) @binding(0) var cloud_tex: texture_2d<f32>;

fn srgb_encode(x: f32) -> f32 {
    if x <= 0.0031308 {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

// Tone map (the CPU `tone_map`), then sRGB-encode when the target is not an
// sRGB format (an sRGB target encodes in hardware); an HDR target gets the
// linear radiance.
fn display(c: vec3f) -> vec3f {
    if !TONE_MAP {
        return max(c, vec3f(0.0));
    }
    let m = tone_map(c, frame.exposure.x);
    if ENCODE_SRGB {
        return vec3f(srgb_encode(m.x), srgb_encode(m.y), srgb_encode(m.z));
    }
    return m;
}

fn sky_background(pos: vec2f) -> vec3f {
    let dir = camera_ray(pos);
    let sun_dir = frame.sun_dir.xyz;
    let eye = frame.cam_pos.xyz;
    // The clouds the sea mirrors are in the cloud layer (the cloud pass's
    // sea_reflection_change, accumulated by TSAA): the sea here is bare.
    let land = flat_ground_albedo(eye, dir, frame.cam_pos.w);
    return background_radiance(dir, sun_dir, sea_waves_at(eye, dir), flat_ground_shadow(eye, dir, sun_dir), land, vec4f(0.0, 0.0, 0.0, 1.0));
}
