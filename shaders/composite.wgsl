// The composite pass: the resolved clouds (premultiplied radiance and
// opacity) over the background (the analytic sky and sun disk, or the
// terrain), tone-mapped into the target; its functions are the twins of
// src/render/cpu/tone_map.rs. Appended to the shared functions, with
// glare.wgsl after it (shaders.rs `COMPOSITE`).
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

// On for an 8-bit target: the encoded value is dithered before the
// target rounds it (the CPU's to_srgb8).
override DITHER: bool = false;

fn srgb_decode(e: f32) -> f32 {
    if e <= 0.04045 {
        return e / 12.92;
    }
    return pow((e + 0.055) / 1.055, 2.4);
}

// The twins of src/render/cpu/tone_map.rs's functions of the same names.
fn hash_u32(v: u32) -> u32 {
    var x = v;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

fn output_dither(index: u32) -> f32 {
    let h = hash_u32(index);
    let a = (f32(h & 0xffffu) + 0.5) / 65536.0;
    let b = (f32(h >> 16u) + 0.5) / 65536.0;
    return a + b - 1.0;
}

fn dither_encoded(e: f32, noise: f32) -> f32 {
    let room = clamp(min(e, 1.0 - e) * 255.0, 0.0, 1.0);
    return e + noise * room / 255.0;
}

// Tone map (the CPU `tone_map`), sRGB-encode and, into an 8-bit target,
// dither by the pixel's row-major index (the CPU's to_srgb8); an sRGB
// target gets the dithered value decoded, which it encodes again in
// hardware. An HDR target gets the linear radiance.
fn display(c: vec3f, pos: vec2f) -> vec3f {
    if !TONE_MAP {
        return max(c, vec3f(0.0));
    }
    let m = tone_map(c, frame.exposure.x);
    var e = vec3f(srgb_encode(clamp(m.x, 0.0, 1.0)), srgb_encode(clamp(m.y, 0.0, 1.0)), srgb_encode(clamp(m.z, 0.0, 1.0)));
    if DITHER {
        let noise = output_dither(u32(pos.y) * u32(frame.screen.x) + u32(pos.x));
        e = vec3f(dither_encoded(e.x, noise), dither_encoded(e.y, noise), dither_encoded(e.z, noise));
    }
    if ENCODE_SRGB {
        return e;
    }
    return vec3f(srgb_decode(e.x), srgb_decode(e.y), srgb_decode(e.z));
}

fn sky_background(pos: vec2f) -> vec3f {
    let dir = camera_ray(pos);
    let sun_dir = frame.sun_dir.xyz;
    let eye = frame.cam_pos.xyz;
    // The clouds the sea mirrors are in the cloud layer (the cloud pass's
    // sea_reflection_change, accumulated by TSAA): the sea here is bare.
    let land = flat_ground_albedo(eye, dir, frame.cam_pos.w);
    let bg = background_radiance(dir, sun_dir, sea_waves_at(eye, dir), flat_ground_shadow(eye, dir, sun_dir), land, vec4f(0.0, 0.0, 0.0, 1.0));
    return cirrus_over(eye, dir, sun_dir, frame.cam_pos.w, bg);
}
