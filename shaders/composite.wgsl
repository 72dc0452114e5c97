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
    return background_radiance(dir, sun_dir, sea_waves_at(eye, dir), flat_ground_shadow(eye, dir, sun_dir), land, vec4f(0.0, 0.0, 0.0, 1.0));
}

// The sun's glare (src/render/cpu/glare.rs, the twins of its functions):
// the CIE glare spread's small-angle term around the sun, lit by the sun
// disk's irradiance at the camera times its visibility through the cloud
// layer at GLARE_TAPS pixels across the disk (a tap below the horizon, on
// the flat ground or sea, hidden), times render.sun_glare
// (frame.exposure.w). Only a tone-mapped target gets it. Each variant of
// fs_composite defines terrain_hides(px): whether its background hides
// the sky at pixel px.
const GLARE_CORE: f32 = 10.0;
const GLARE_MIN_DEG: f32 = 0.27;
const GLARE_TAPS: u32 = 5u;
const GLARE_TAP_REACH: f32 = 0.6;

fn glare_spread(cos_theta: f32) -> f32 {
    let chord = sqrt(max(2.0 - 2.0 * clamp(cos_theta, -1.0, 1.0), 0.0));
    let theta = max(degrees(2.0 * asin(min(0.5 * chord, 1.0))), GLARE_MIN_DEG);
    return GLARE_CORE / (theta * theta * theta);
}

fn sun_glare(dir: vec3f, sun_dir: vec3f, source: vec3f) -> vec3f {
    return source * glare_spread(dot(dir, sun_dir));
}

// The sun's centre in pixels (xy) and 1 (z), or z 0 behind the camera.
fn sun_pixel(sun_dir: vec3f) -> vec3f {
    let c = frame.view_proj * vec4f(sun_dir, 0.0);
    if c.w <= 1e-6 {
        return vec3f(0.0);
    }
    return vec3f(
        (c.x / c.w + 1.0) * 0.5 * frame.screen.x,
        (1.0 - c.y / c.w) * 0.5 * frame.screen.y,
        1.0,
    );
}

fn glare_tap(centre: vec2f, radius_px: f32, tap: u32) -> vec2i {
    let r = GLARE_TAP_REACH * radius_px;
    var o = vec2f(0.0);
    switch tap {
        case 1u: { o = vec2f(-r, 0.0); }
        case 2u: { o = vec2f(r, 0.0); }
        case 3u: { o = vec2f(0.0, -r); }
        case 4u: { o = vec2f(0.0, r); }
        default: {}
    }
    let p = floor(centre + o);
    return vec2i(clamp(p, vec2f(0.0), max(frame.screen.xy, vec2f(1.0)) - 1.0));
}

fn sun_radius_px(pixel_spread: f32) -> f32 {
    return radians(GLARE_MIN_DEG) / max(pixel_spread, 1e-9);
}

fn sun_visibility(sun_dir: vec3f) -> f32 {
    let centre = sun_pixel(sun_dir);
    if centre.z < 0.5 {
        return 0.0;
    }
    let radius = sun_radius_px(frame.cam_pos.w);
    var sum = 0.0;
    for (var tap = 0u; tap < GLARE_TAPS; tap++) {
        let p = glare_tap(centre.xy, radius, tap);
        if !terrain_hides(p) && camera_ray(vec2f(p) + 0.5).y >= 0.0 {
            sum += 1.0 - textureLoad(cloud_tex, p, 0).a;
        }
    }
    return sum / f32(GLARE_TAPS);
}

// The glare's radiance at pixel pos: none without a tone map or with
// render.sun_glare 0.
fn glare_at(pos: vec2f) -> vec3f {
    if !TONE_MAP || frame.exposure.w <= 0.0 {
        return vec3f(0.0);
    }
    let sun_dir = frame.sun_dir.xyz;
    let irradiance = sun_disk_irradiance(sun_dir);
    if all(irradiance == vec3f(0.0)) {
        return vec3f(0.0);
    }
    let source = irradiance * (sun_visibility(sun_dir) * frame.exposure.w);
    return sun_glare(camera_ray(pos), sun_dir, source);
}

