// The composite pass: the resolved clouds (premultiplied radiance and
// opacity) over the background (the analytic sky and sun disk, or the
// terrain), tone-mapped into the target. Appended to clouds.wgsl.
//
// src/render/gpu/shaders.rs adds the background bindings of the variant:
// none (sky only), the terrain's HDR colour, or an external depth buffer
// (pixels with geometry keep their colour, the clouds in front are blended
// over it with premultiplied alpha).

override ENCODE_SRGB: bool = false;

@group(1) @binding(0) var cloud_tex: texture_2d<f32>;

fn srgb_encode(x: f32) -> f32 {
    if x <= 0.0031308 {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

// Tone map (the CPU `tone_map`), then sRGB-encode when the target is not an
// sRGB format (an sRGB target encodes in hardware).
fn display(c: vec3f) -> vec3f {
    let e = frame.ambient_top.w;
    let m = vec3f(tone_map(c.x, e), tone_map(c.y, e), tone_map(c.z, e));
    if ENCODE_SRGB {
        return vec3f(srgb_encode(m.x), srgb_encode(m.y), srgb_encode(m.z));
    }
    return m;
}

fn sky_background(pos: vec2f) -> vec3f {
    let dir = camera_ray(pos);
    let sun_dir = frame.sun_dir.xyz;
    return sky_radiance(dir, sun_dir) + sun_disk(dir, sun_dir);
}
