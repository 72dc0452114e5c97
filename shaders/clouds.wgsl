// The cloud pass: a full-screen fragment shader that ray-casts the cloud
// height band through P (coverage, normalised height, fill) and the cloud
// map CM. Every function here has a twin of the same name in
// src/render/cpu/ (density.rs, lighting.rs, sky.rs, renderer.rs) or
// src/render/camera.rs; the parity tests render both and compare. Keep
// them in step.
//
// The entry points are appended by src/render/gpu/shaders.rs, one per
// variant (with or without a depth buffer, with or without the TSAA
// distance output), so a variant that a scene does not need is not built.

// Pipeline-overridable constants: features that are off are folded away
// by the shader compiler, so they cost nothing.
override SHADOW_STEPS: u32 = 20u;
override OCTAVES: u32 = 3u;
override DETAIL: bool = true;
// The fine billows near the camera (`[render] fine_detail`), read only
// with DETAIL.
override FINE_DETAIL: bool = true;
override DEBUG_COUNT: bool = false;
// The sea below the horizon (else land), its wind speed (m/s) and the
// direction the wind blows toward (degrees clockwise from north).
override SEA: bool = false;
override SEA_WIND_MPS: f32 = 7.0;
override SEA_WIND_TOWARD_DEG: f32 = 90.0;
// Fade clouds and ground with distance (`[render.atmosphere]
// aerial_perspective`), read by the sky file's `aerial`.
override AERIAL_PERSPECTIVE: bool = true;
// The cloud pass reads the light volume: the light's gains fitted beside
// it (`light_gains`), else those of the renderers without one.
override LIGHT_VOLUME: bool = false;

const PI: f32 = 3.14159265358979;
const BASE_RAMP: f32 = 0.04;
const TOP_ROUNDING: f32 = 0.8;
const P_COVERAGE_MIN: f32 = 1e-3;
const FRINGE_PRESENCE: f32 = 0.005;
const WEATHER_MAX: f32 = 1.4;
const EROSION_BASE: f32 = 0.6;
const SURFACE_RAMP: f32 = 0.08;
const DETAIL_CONTRAST: f32 = 1.23;
const WARP_SCALE_M: f32 = 9000.0;
const WARP_AMPLITUDE_M: f32 = 2000.0;
const WARP_RAMP_INNER: f32 = 0.72;
const WARP_RAMP_OUTER: f32 = 1.3;
const WEATHER_SCALE_M: f32 = 3000.0;
const REFINE: u32 = 4u;
const NEAR_M: f32 = 3000.0;
// A band segment wider than MARCH_LOG_SPAN of ln(t + NEAR_M) takes more
// steps, at most MARCH_STEP_FACTOR_MAX times (march_step_count).
const MARCH_LOG_SPAN: f32 = 0.35;
const MARCH_STEP_FACTOR_MAX: f32 = 4.0;
const DETAIL_TILE: f32 = 4.0;
const BILLOW_FREQUENCY: f32 = 1.618;
const BASE_WEIGHT: f32 = 0.85;
const FINE_FREQUENCY: f32 = 4.0;
const FINE_WEIGHT: f32 = 0.16;
const FINE_SHARP_M: f32 = 3.0;
const GROUND_SHADOW_FOOTPRINT_M: f32 = 6.0;
const NOISE_SIZE: f32 = 64.0;
const NOISE_MAX_LOD: f32 = 5.0;
const BLUE_NOISE_SIZE: u32 = 64u;
const ALBEDO: f32 = 0.99;
const MIN_TRANSMITTANCE: f32 = 0.01;
const SUN_DISK_COS: f32 = 0.999989;
const WATER_F0: f32 = 0.0204;
// The longest shadow ray toward the sun, m.
const SHADOW_RAY_M: f32 = 12000.0;
// SHADOW_STEPS steps per this many metres of shadow ray, at most
// SHADOW_STEP_FACTOR_MAX times SHADOW_STEPS (shadow_step_count).
const SHADOW_STEP_SPAN_M: f32 = 2000.0;
const SHADOW_STEP_FACTOR_MAX: f32 = 3.0;
// Toward the sun a ray's shadow rays take up to FORWARD_STEP_BOOST more
// steps, from FORWARD_COS_MIN to FORWARD_COS_MAX (forward_step_factor).
const FORWARD_STEP_BOOST: f32 = 0.6;
const FORWARD_COS_MIN: f32 = 0.5;
const FORWARD_COS_MAX: f32 = 0.9;
// Multiple scattering and sky light (the CPU's lighting.rs, renderer.rs).
const OCTAVE_SCATTERING: f32 = 0.5;
const OCTAVE_EXTINCTION: f32 = 0.5;
const OCTAVE_ECCENTRICITY: f32 = 0.9;
const MULTIPLE_GAIN: f32 = 0.202;
const MULTIPLE_GAIN_ALONE: f32 = 0.53;
const MULTIPLE_ISOTROPIC_GAIN: f32 = 0.256;
const MULTIPLE_ISOTROPIC_GAIN_ALONE: f32 = 0.46;
const MULTIPLE_SUN_POWER: f32 = 0.2;
const DIFFUSE_GAIN: f32 = 0.019;
const DIFFUSE_GAIN_ALONE: f32 = 0.1;
const DIFFUSE_DEPTH_M: f32 = 100.0;
const FLUENCE_GAIN: f32 = 0.915;
const AMBIENT_GAIN: f32 = 4.355;
const AMBIENT_GAIN_ALONE: f32 = 4.37;
const GROUND_LIGHT_GAIN: f32 = 0.0;
const GROUND_LIGHT_GAIN_ALONE: f32 = 3.82;
// The share of the sun's horizontal irradiance a whole sky of cloud sends
// down onto the land (the CPU's sky.rs).
const GROUND_CLOUD_LIGHT: f32 = 0.53;
// Samples of the clouds' shadow on the ground (the CPU's renderer.rs).
const GROUND_SHADOW_STEPS: u32 = 12u;
// The sea's reflection: reflected rays a pixel, the fewest and most
// uniform steps of each and the step length it takes where it can
// (reflection_step_count), their shadow samples, the lowest elevation the
// waves send one to.
const REFLECTION_RAYS: u32 = 12u;
const REFLECTION_STEPS: u32 = 4u;
const REFLECTION_STEPS_MAX: u32 = 16u;
const REFLECTION_STEP_M: f32 = 300.0;
const REFLECTION_SHADOW_STEPS: u32 = 2u;
const REFLECTION_MIN_ELEVATION: f32 = 0.01;
// The sea's wave trains (the CPU's waves.rs): how many, the octaves of
// wavelength they span, the longest's wavelength (m), their directions' spread about the wind (radians), the
// largest share of Cox and Munk's variance they carry, and the footprint
// over wavelength over which a train fades from a pixel.
const WAVE_COUNT: u32 = 40u;
const WAVE_OCTAVES: f32 = 7.5;
// Strata of the unresolved slopes the mirrored sky averages (the CPU's
// sky.rs).
const SKY_MIRROR_RAYS: u32 = 8u;
const WAVE_LONGEST_M: f32 = 60.0;
const WAVE_SPREAD: f32 = 0.96;
const WAVE_SHARE_MAX: f32 = 0.8;
const WAVE_FADE_START: f32 = 0.1;
const WAVE_FADE_END: f32 = 0.5;
// The most a pixel's footprint on the sea is longer along the line of
// sight than across it, for the waves.
const WAVE_ANISOTROPY_MAX: f32 = 4.0;
// Gravity at the sea's surface, m/s^2 (the CPU's waves.rs).
const GRAVITY: f32 = 9.81;
// The golden ratio's fraction (the CPU's sampling::GOLDEN).
const GOLDEN: f32 = 0.618034;
// The clip depth at which rays are unprojected.
const RAY_DEPTH: f32 = 0.5;

// Mirrors `FrameUniforms` in src/render/gpu/uniforms.rs (432 bytes). The
// camera is `View`'s (src/render/camera.rs): any perspective projection,
// standard or reversed depth.
struct Frame {
    cam_pos: vec4f,      // eye xyz (m), pixel spread (rad)
    screen: vec4f,       // width, height (px), depth of an empty pixel (1, or 0 reversed), 1 if the depth read is stored flipped
    sun_dir: vec4f,      // xyz, haze distance (m)
    sun_light: vec4f,    // sun colour * SUN_INTENSITY, max distance (m)
    exposure: vec4f,     // exposure before the tone map, 1 when the cloud layer carries the sea's mirrored clouds (else 0), the share of the ground under cloud, the sun glare's strength (render.sun_glare)
    band: vec4f,         // bottom (m), top (m), coverage, extinction (1/m)
    map: vec4f,          // extent (m), detail strength, detail scale (m), map texel (m)
    jitter: vec4f,       // sub-pixel offset x, y (px), dither offset, TSAA blend
    terrain: vec4f,      // extent (m), highest point (m), the sea's clock (s), mesh stride
    counts: vec4u,       // steps, P width, P height, frame index
    mask: vec4u,         // mask width, height, P texels per mask cell, unused
    view_proj: mat4x4f,
    prev_view_proj: mat4x4f,
    inverse_projection: mat4x4f,
    view_to_world: mat4x4f,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var p_tex: texture_2d<f32>;
@group(0) @binding(2) var cm_tex: texture_2d<f32>;
@group(0) @binding(3) var mask_tex: texture_2d<u32>;
@group(0) @binding(4) var wrap_linear: sampler;
@group(0) @binding(5) var noise_tex: texture_3d<f32>;
@group(0) @binding(6) var blue_tex: texture_2d<f32>;

fn height_fraction(y: f32) -> f32 {
    return (y - frame.band.x) / (frame.band.y - frame.band.x);
}

// The part [t0, t1] of the ray inside the slab bottom <= y <= top (camera
// below, inside or above alike); t1 <= t0 where the ray misses it.
fn band_segment(origin: vec3f, dir: vec3f, bottom: f32, top: f32, max_t: f32) -> vec2f {
    if abs(dir.y) < 1e-8 {
        if origin.y < bottom || origin.y > top {
            return vec2f(0.0, -1.0);
        }
        return vec2f(0.0, max_t);
    }
    let ta = (bottom - origin.y) / dir.y;
    let tb = (top - origin.y) / dir.y;
    return vec2f(max(min(ta, tb), 0.0), min(max(ta, tb), max_t));
}

fn wrap_i(a: i32, period: i32) -> i32 {
    return ((a % period) + period) % period;
}

fn lod_of(footprint_m: f32, texel_m: f32) -> f32 {
    return round(log2(max(footprint_m / texel_m, 1.0)));
}

// The gain restoring a mip level's spread (the CPU's `noise_gain`).
fn noise_gain(lod: f32) -> f32 {
    if lod < 0.5 {
        return 1.0;
    } else if lod < 1.5 {
        return 1.05;
    } else if lod < 2.5 {
        return 1.14;
    } else if lod < 3.5 {
        return 1.4;
    } else if lod < 4.5 {
        return 1.82;
    }
    return 2.56;
}

fn gained(value: f32, lod: f32) -> f32 {
    return clamp(0.5 + (value - 0.5) * noise_gain(lod), 0.0, 1.0);
}

// The detail volume's base channel (the CPU's `detail_base`).
fn detail_base(p: vec3f, scale_m: f32, footprint_m: f32) -> f32 {
    let tile_m = DETAIL_TILE * scale_m;
    let texel_m = tile_m / NOISE_SIZE;
    let lod = min(lod_of(footprint_m, texel_m), NOISE_MAX_LOD);
    return gained(textureSampleLevel(noise_tex, wrap_linear, p / tile_m, lod).r, lod);
}

// The detail volume's billows channel (the CPU's `detail_billows`).
fn detail_billows(p: vec3f, scale_m: f32, footprint_m: f32) -> f32 {
    return billows_channel(p, scale_m, footprint_m, BILLOW_FREQUENCY, vec3f(0.31, 0.17, 0.73));
}

// The billows channel at a multiple of the base's frequency (the CPU's
// `billows_channel`).
fn billows_channel(p: vec3f, scale_m: f32, footprint_m: f32, frequency: f32, offset: vec3f) -> f32 {
    let tile_m = DETAIL_TILE * scale_m;
    let texel_m = tile_m / NOISE_SIZE;
    let lod = min(lod_of(footprint_m * frequency, texel_m), NOISE_MAX_LOD);
    let q = p * (frequency / tile_m) + offset;
    return gained(textureSampleLevel(noise_tex, wrap_linear, q, lod).g, lod);
}

// The fine billows' weight at a footprint (the CPU's `fine_weight`).
fn fine_weight(footprint_m: f32) -> f32 {
    if !FINE_DETAIL {
        return 0.0;
    }
    return FINE_WEIGHT * clamp(2.0 - footprint_m / FINE_SHARP_M, 0.0, 1.0);
}

// The fine billows near the camera, about 0 (the CPU's `detail_fine`).
fn detail_fine(p: vec3f, scale_m: f32, footprint_m: f32) -> f32 {
    let w = fine_weight(footprint_m);
    if w <= 0.0 {
        return 0.0;
    }
    return w * (billows_channel(p, scale_m, footprint_m, FINE_FREQUENCY, vec3f(0.57, 0.11, 0.29)) - 0.5);
}

// True where the coarse max-coverage mask says no P texel near map
// coordinate `(u, v)` has coverage: the density there is zero, so the
// texture reads are skipped.
fn coarse_empty(u: f32, v: f32) -> bool {
    let pw = f32(frame.counts.y);
    let ph = f32(frame.counts.z);
    let cell = f32(frame.mask.z);
    let mx = i32(floor((u - floor(u)) * pw / cell));
    let my = i32(floor((v - floor(v)) * ph / cell));
    let c = vec2i(clamp(mx, 0, i32(frame.mask.x) - 1), clamp(my, 0, i32(frame.mask.y) - 1));
    return textureLoad(mask_tex, c, 0).r == 0u;
}

// (cover, local top, fill, map value) at map coordinate uv, the map at
// mip level map_lod (the CPU's `footprint`).
fn footprint(u: f32, v: f32, map_lod: f32, eta: f32) -> vec4f {
    let pf = textureSampleLevel(p_tex, wrap_linear, vec2f(u, v), 0.0);
    let highest = clamp(0.2 + 0.8 * pf.g, 0.0, 1.0);
    if pf.r <= P_COVERAGE_MIN || eta >= highest {
        return vec4f(0.0);
    }
    let cm = textureSampleLevel(cm_tex, wrap_linear, vec2f(u, v), map_lod);
    let cover = clamp(frame.band.z * pf.r, 0.0, 1.0);
    let top = highest * (0.7 + 0.3 * cm.g);
    return vec4f(cover, top, pf.b, cm.r);
}

// The smooth, non-repeating displacement of the P and map lookups at
// world (x, z), map units (the CPU's `domain_warp`).
fn domain_warp(x: f32, z: f32) -> vec2f {
    let a = x / WARP_SCALE_M;
    let b = z / WARP_SCALE_M;
    return WARP_AMPLITUDE_M / frame.map.x * vec2f(
        sin(b + 1.3) + sin((0.8 * a + 0.6 * b) * 0.91 + 4.1) + sin((0.3 * a - 0.95 * b) * 0.73 + 0.5),
        sin(a * 1.13 + 0.7) + sin((0.6 * a - 0.8 * b) * 0.83 + 2.3) + sin((0.95 * a + 0.3 * b) * 0.67 + 5.2),
    );
}

// The warp's weight: 0 over the simulated domain, growing to 1 with the
// distance from its centre (the CPU's `warp_weight`).
fn warp_weight(x: f32, z: f32) -> f32 {
    let a = x / frame.map.x - 0.5;
    let b = z / frame.map.x - 0.5;
    return smoothstep(WARP_RAMP_INNER, WARP_RAMP_OUTER, sqrt(a * a + b * b));
}

// The weather modulation of the cover (the CPU's `weather`).
fn weather(x: f32, z: f32) -> f32 {
    let a = x / WEATHER_SCALE_M;
    let b = z / WEATHER_SCALE_M;
    let g = 0.5 + 0.25 * (sin(a + 0.4) * sin(b * 0.81 + 1.9) + sin((0.6 * a + 0.8 * b) * 1.37 + 2.7));
    return WEATHER_MAX * smoothstep(0.25, 0.75, g);
}

// Where world (x, z) reads P and the map: (u, v) through the weighted
// domain warp, and the weight (the CPU's `warped_lookup`).
fn warped_lookup(x: f32, z: f32) -> vec3f {
    let k = warp_weight(x, z);
    if k <= 0.0 {
        return vec3f(x / frame.map.x, z / frame.map.x, 0.0);
    }
    let w = domain_warp(x, z) * k;
    return vec3f(x / frame.map.x + w.x, z / frame.map.x + w.y, k);
}

// The footprint at world (x, z) through the domain warp, the cover
// modulated by the weather, the map at the footprint's level of detail
// (the CPU's `world_footprint`).
fn world_footprint(x: f32, z: f32, l: vec3f, footprint_m: f32, eta: f32) -> vec4f {
    let u = l.x;
    let v = l.y;
    let k = l.z;
    if coarse_empty(u, v) {
        return vec4f(0.0);
    }
    let fp = footprint(u, v, lod_of(footprint_m, frame.map.w), eta);
    if fp.x <= 0.0 {
        return vec4f(0.0);
    }
    if k <= 0.0 {
        return fp;
    }
    return vec4f(fp.x * mix(1.0, weather(x, z), k), fp.y, fp.z, fp.w);
}

// The highest value of the mixed field (the CPU's `field_max`).
fn field_max(s: f32) -> f32 {
    return cloud_field(1.0, 1.0, s);
}

// The threshold the cloud field must exceed (the CPU's
// `cumulus_threshold`): lowest just above the flat base, a dome rising to
// 1 at the local top, and over the top fifth on to the field's highest
// value, so no core is cut off flat at the top; the same climb where the
// presence (P's spread coverage times the weather) falls under
// FRINGE_PRESENCE, so clouds end before P's coverage does.
fn cumulus_threshold(eta: f32, top: f32, cover: f32, presence: f32, s: f32) -> f32 {
    let t = eta / top;
    let fringe = 1.0 - smoothstep(P_COVERAGE_MIN * WEATHER_MAX, FRINGE_PRESENCE, presence);
    let climb = max(smoothstep(TOP_ROUNDING, 1.0, t), fringe);
    return 1.0 - cover * smoothstep(0.0, BASE_RAMP, eta) * max(1.0 - t * t, 0.0)
        + (field_max(s) - 1.0) * climb;
}

// The detail noise's weight, growing with height (the CPU's
// `erosion_strength`).
fn erosion_strength(s: f32, eta: f32, top: f32) -> f32 {
    return s * (EROSION_BASE + (1.0 - EROSION_BASE) * clamp(eta / top, 0.0, 1.0));
}

// The map value and the 3D noise mixed by `s`, the noise's contrast
// widened, the mix's spread restored (the CPU's `cloud_field`).
fn cloud_field(m: f32, n: f32, s: f32) -> f32 {
    let nn = clamp(0.5 + (n - 0.5) * DETAIL_CONTRAST, 0.0, 1.0);
    let norm = max(sqrt((1.0 - s) * (1.0 - s) + s * s), 1e-3);
    return 0.5 + ((1.0 - s) * (m - 0.5) + s * (nn - 0.5)) / norm;
}

// The density profile where the field meets the threshold (the CPU's
// `surface_profile`).
fn surface_profile(m: f32, n: f32, s: f32, threshold: f32) -> f32 {
    return clamp((cloud_field(m, n, s) - threshold) / SURFACE_RAMP, 0.0, 1.0);
}

// surface_profile of the detail noise (the CPU's `detail_noise`: base and
// billows weighted by BASE_WEIGHT, and the fine billows near the camera),
// reading the volume only where it can change the result (the CPU's
// `detail_profile`).
fn detail_profile(p: vec3f, m: f32, threshold: f32, s: f32, scale_m: f32, footprint_m: f32) -> f32 {
    let fine = 0.5 * fine_weight(footprint_m);
    if surface_profile(m, -fine, s, threshold) >= 1.0 {
        return 1.0;
    }
    let low = BASE_WEIGHT * detail_base(p, scale_m, footprint_m);
    if surface_profile(m, low + (1.0 - BASE_WEIGHT) + fine, s, threshold) <= 0.0 {
        return 0.0;
    }
    if surface_profile(m, low - fine, s, threshold) >= 1.0 {
        return 1.0;
    }
    let n = low + (1.0 - BASE_WEIGHT) * detail_billows(p, scale_m, footprint_m);
    if fine > 0.0 {
        if surface_profile(m, n + fine, s, threshold) <= 0.0 {
            return 0.0;
        }
        if surface_profile(m, n - fine, s, threshold) >= 1.0 {
            return 1.0;
        }
    }
    return surface_profile(m, n + detail_fine(p, scale_m, footprint_m), s, threshold);
}

// Where p reads the detail volume: warped outside the simulated domain
// (the CPU's `noise_point`).
fn noise_point(p: vec3f, l: vec3f) -> vec3f {
    if l.z <= 0.0 {
        return p;
    }
    return vec3f(l.x * frame.map.x, p.y, l.y * frame.map.x);
}

// Extinction sigma_t (1/m) at p; `detail` false puts the detail noise's
// mean in its place (shadow rays); the textures are read at the level of
// detail of a pixel footprint `footprint_m` wide.
fn density_at(p: vec3f, detail: bool, footprint_m: f32) -> f32 {
    let eta = height_fraction(p.y);
    if eta < 0.0 || eta > 1.0 {
        return 0.0;
    }
    let lookup = warped_lookup(p.x, p.z);
    let fp = world_footprint(p.x, p.z, lookup, footprint_m, eta);
    if fp.x <= 0.0 || eta >= fp.y {
        return 0.0;
    }
    let s = erosion_strength(frame.map.y, eta, fp.y);
    let presence = fp.x / max(frame.band.z, 1e-6);
    let threshold = cumulus_threshold(eta, fp.y, fp.x, presence, s);
    if cloud_field(fp.w, 1.0, s) < threshold {
        return 0.0;
    }
    var profile = 0.0;
    if DETAIL && detail {
        let q = noise_point(p, lookup);
        profile = detail_profile(q, fp.w, threshold, s, frame.map.z, footprint_m);
    } else {
        profile = surface_profile(fp.w, 0.5, s, threshold);
    }
    return frame.band.w * (0.3 + 0.7 * fp.z) * profile;
}

fn phase_hg(cos_theta: f32, g: f32) -> f32 {
    let g2 = g * g;
    return (1.0 - g2) / (4.0 * PI * pow(max(1.0 + g2 - 2.0 * g * cos_theta, 1e-6), 1.5));
}

fn phase_dual(cos_theta: f32, eccentricity: f32) -> f32 {
    return 0.75 * phase_hg(cos_theta, 0.8 * eccentricity)
        + 0.25 * phase_hg(cos_theta, -0.3 * eccentricity);
}

// The sum of the shadow ray's step weights, √1 + √2 + ... + √steps (the
// CPU's `shadow_parts`).
fn shadow_parts(steps: u32) -> f32 {
    var parts = 0.0;
    for (var k = 1u; k <= steps; k++) {
        parts += sqrt(f32(k));
    }
    return parts;
}

// Where each of a pixel's shadow samples sits in its step: the pixel's
// dither shifted off the march's own, so TSAA's frames average the shadow
// ray's error over its samples' placements (the CPU's `shadow_offset`).
fn shadow_offset(dither: f32) -> f32 {
    return fract(dither + GOLDEN);
}

// The length of the shadow ray from p toward the sun: to the band's top,
// at most SHADOW_RAY_M (the CPU's `shadow_ray_length`). The march takes
// its shadow_step_count steps of growing length (√1, √2, √3, ... parts of
// shadow_parts) itself, as the CPU's `sun_optical_depth` does.
fn shadow_ray_length(p: vec3f, sun_dir: vec3f) -> f32 {
    var to_top = SHADOW_RAY_M;
    if sun_dir.y > 1e-3 {
        to_top = max(frame.band.y - p.y, 0.0) / sun_dir.y;
    }
    return min(to_top, SHADOW_RAY_M);
}

// The factor on the shadow steps of a ray at cos_theta to the sun (the
// CPU's `forward_step_factor`): up to 1 + FORWARD_STEP_BOOST toward the
// sun, where the sunlight scattered once is most of a pixel's light.
fn forward_step_factor(cos_theta: f32) -> f32 {
    return 1.0 + FORWARD_STEP_BOOST * smoothstep(FORWARD_COS_MIN, FORWARD_COS_MAX, cos_theta);
}

// The steps of a shadow ray of `length` m: `steps` over SHADOW_STEP_SPAN_M
// or less, in proportion beyond, times `forward`, at most
// SHADOW_STEP_FACTOR_MAX times `steps` in all (the CPU's
// `shadow_step_count`).
fn shadow_step_count(steps: u32, length: f32, forward: f32) -> u32 {
    let along = clamp(length / SHADOW_STEP_SPAN_M, 1.0, SHADOW_STEP_FACTOR_MAX);
    return u32(ceil(f32(steps) * min(along * forward, SHADOW_STEP_FACTOR_MAX)));
}

// The light's six fitted gains (the CPU's `LightGains`).
struct LightGains {
    multiple: f32,
    multiple_isotropic: f32,
    diffuse: f32,
    fluence: f32,
    ambient: f32,
    ground: f32,
}

// The gains fitted beside the light volume when the pass reads one
// (LIGHT_VOLUME), else the renderers' without one (the CPU's
// `light_gains`).
fn light_gains() -> LightGains {
    if LIGHT_VOLUME {
        return LightGains(MULTIPLE_GAIN, MULTIPLE_ISOTROPIC_GAIN, DIFFUSE_GAIN, FLUENCE_GAIN, AMBIENT_GAIN, GROUND_LIGHT_GAIN);
    }
    return LightGains(MULTIPLE_GAIN_ALONE, MULTIPLE_ISOTROPIC_GAIN_ALONE, DIFFUSE_GAIN_ALONE, 0.0, AMBIENT_GAIN_ALONE, GROUND_LIGHT_GAIN_ALONE);
}

// The sunlight diffused through the cloud layer, per unit scattering
// coefficient, in cloud of extinction `sigma_t` (the CPU's `diffused_sun`).
fn diffused_sun(mu_sun: f32, sigma_t: f32) -> f32 {
    return light_gains().diffuse * max(mu_sun, 0.0) * (1.0 - exp(-sigma_t * DIFFUSE_DEPTH_M)) / (4.0 * PI);
}

// The real spherical harmonics to l = 2 at unit `d` (the CPU's `sh9`):
// (l, m) = (0, 0), (1, -1), (1, 0), (1, 1), (2, -2) ... (2, 2), z the
// polar axis. The light volume holds the transported sunlight in them
// (`light_toward` is its read, or 0 without one).
fn sh9(d: vec3f) -> array<f32, 9> {
    return array<f32, 9>(
        0.2820948,
        0.4886025 * d.y,
        0.4886025 * d.z,
        0.4886025 * d.x,
        1.0925484 * d.x * d.y,
        1.0925484 * d.y * d.z,
        0.31539157 * (3.0 * d.z * d.z - 1.0),
        1.0925484 * d.x * d.z,
        0.5462742 * (d.x * d.x - d.y * d.y),
    );
}

// Single scattering and, when OCTAVES > 0, OCTAVES octaves of multiple
// scattering (forward and isotropic parts) and the diffused sunlight
// (the CPU's `sun_scattering`; gains fitted to the path tracer,
// docs/ground_truth).
fn sun_scattering(tau_sun: f32, cos_theta: f32, mu_sun: f32, sigma_t: f32) -> f32 {
    var sum = phase_dual(cos_theta, 1.0) * exp(-tau_sun);
    if OCTAVES == 0u {
        return sum;
    }
    let height = pow(max(mu_sun, 0.0), MULTIPLE_SUN_POWER);
    let gains = light_gains();
    let isotropic = gains.multiple_isotropic / (4.0 * PI);
    var a = 1.0;
    var b = 1.0;
    var c = 1.0;
    for (var i = 0u; i < OCTAVES; i++) {
        a *= OCTAVE_SCATTERING;
        b *= OCTAVE_EXTINCTION;
        c *= OCTAVE_ECCENTRICITY;
        let phase = gains.multiple * phase_dual(cos_theta, c) + isotropic;
        sum += height * a * phase * exp(-b * tau_sun);
    }
    return sum + diffused_sun(mu_sun, sigma_t);
}

// The sky's and the ground's light scattered at height fraction `eta`
// (the CPU's `ambient_light`): the sky's from 0.35 at the band's bottom
// to all at its top, the ground's from all at the bottom to none at the top.
fn ambient_light(sky_top: vec3f, ground: vec3f, eta: f32) -> vec3f {
    let gains = light_gains();
    return sky_top * ((0.35 + 0.65 * eta) * gains.ambient) + ground * ((1.0 - eta) * gains.ground);
}

fn integrate_step(s: vec3f, sigma_t: f32, dt: f32) -> vec3f {
    if sigma_t * dt < 1e-5 {
        return s * dt;
    }
    return (s - s * exp(-sigma_t * dt)) / sigma_t;
}

fn normalize_or(v: vec3f, fallback: vec3f) -> vec3f {
    let l = length(v);
    if l > 0.0 && l < 3.4e38 {
        return v / l;
    }
    return fallback;
}

// (inscattered light, transmittance) of the air in front of something
// (the CPU's `aerial`, a tuple there).
struct Aerial {
    inscatter: vec3f,
    transmittance: vec3f,
}

// The sky file appended after this one (sky_analytic.wgsl or
// sky_physical.wgsl) defines sun_light_at, sky_above, aerial, ground_haze
// and sun_disk, the twins of src/render/cpu/sky.rs.

// The flat land's albedo (the CPU's sky.rs).
const LAND_ALBEDO: vec3f = vec3f(0.08, 0.1, 0.06);

// The flat land's own light (the CPU's `land_surface`).
fn land_surface(sun_dir: vec3f, shadow: f32, albedo: vec3f) -> vec3f {
    let sun = sun_light_at(0.0, sun_dir);
    let lit = sun * (max(sun_dir.y, 0.0) * shadow / PI) + sky_ambient(sun_dir);
    return albedo * lit;
}

// The flat land through the air, its sunlit part dimmed by the clouds'
// shadow, with the sunlight the clouds scatter down onto it (the CPU's
// `land_radiance`).
fn land_radiance(dir: vec3f, sun_dir: vec3f, shadow: f32, albedo: vec3f) -> vec3f {
    let surface = land_surface(sun_dir, shadow, albedo) + albedo * ground_cloud_light(sun_dir);
    return ground_haze(surface, dir, sun_dir);
}

// The sunlight the clouds scatter down onto the land, its irradiance over
// π per unit albedo, for the share frame.exposure.z of the ground under
// cloud (the CPU's `ground_cloud_light`).
fn ground_cloud_light(sun_dir: vec3f) -> vec3f {
    let cover = clamp(frame.exposure.z, 0.0, 1.0);
    return sun_light_at(0.5 * (frame.band.x + frame.band.y), sun_dir) * (GROUND_CLOUD_LIGHT * cover * max(sun_dir.y, 0.0) / PI);
}

fn cloud_shadow(p: vec3f, sun_dir: vec3f, steps: u32) -> f32 {
    let seg = band_segment(p, sun_dir, frame.band.x, frame.band.y, 20000.0);
    if seg.y <= seg.x {
        return 1.0;
    }
    let n = max(steps, 1u);
    let dt = (seg.y - seg.x) / f32(n);
    var tau = 0.0;
    for (var i = 0u; i < n; i++) {
        tau += density_at(p + sun_dir * (seg.x + (f32(i) + 0.5) * dt), true, GROUND_SHADOW_FOOTPRINT_M) * dt;
    }
    return exp(-tau);
}

// The clouds' shadow where a ray that meets no terrain reaches the flat
// ground (the CPU's `flat_ground_shadow`).
fn flat_ground_shadow(origin: vec3f, dir: vec3f, sun_dir: vec3f) -> f32 {
    if dir.y >= 0.0 || origin.y <= 0.0 || SHADOW_STEPS == 0u || sun_dir.y <= 0.0 {
        return 1.0;
    }
    let t = origin.y / -dir.y;
    if t > frame.sun_light.w {
        return 1.0;
    }
    let p = vec3f(origin.x + dir.x * t, 0.0, origin.z + dir.z * t);
    return cloud_shadow(p, sun_dir, GROUND_SHADOW_STEPS);
}

// Schlick's Fresnel reflectance of water (the CPU's `fresnel_water`).
fn fresnel_water(cos_i: f32) -> f32 {
    let c = 1.0 - clamp(cos_i, 0.0, 1.0);
    return WATER_F0 + (1.0 - WATER_F0) * c * c * c * c * c;
}

// The water's own light (the CPU's `water_light`).
fn water_light(sun: vec3f, sun_dir: vec3f) -> vec3f {
    return vec3f(0.004, 0.012, 0.02)
        * (sun * (max(sun_dir.y, 0.0) / PI) + sky_ambient(sun_dir));
}

// A pixel's length on the sea along the line of sight (the CPU's
// `wave_footprint`).
fn wave_footprint(spread: f32, t: f32, sin_down: f32) -> f32 {
    return spread * t / max(abs(sin_down), 1e-3);
}

// A deep-water wave's frequency, Hz: sqrt(g / (2 pi wavelength)) (the
// CPU's `wave_frequency`).
fn wave_frequency(wavelength: f32) -> f32 {
    return sqrt(GRAVITY / (2.0 * PI * wavelength));
}

// Cox and Munk's mean square slope of a clean sea (the CPU's
// `slope_variance`).
fn slope_variance(wind_mps: f32) -> f32 {
    return 0.003 + 0.00512 * max(wind_mps, 0.0);
}

// The mean square slope the wave trains carry: Cox and Munk's slick sea,
// at most WAVE_SHARE_MAX of the clean one's (the CPU's `wave_variance`).
fn wave_variance(wind_mps: f32) -> f32 {
    let u = max(wind_mps, 0.0);
    return min(0.008 + 0.00156 * u, WAVE_SHARE_MAX * slope_variance(u));
}

// The wave slope a pixel resolves at (x, z) and the slope variance it
// does not: WAVE_COUNT trains over WAVE_OCTAVES of wavelength, each faded by the
// pixel's footprint along it (the CPU's `sea_waves`).
fn sea_waves(x: f32, z: f32, dir: vec3f, spread: f32, t: f32, wind_mps: f32, toward_deg: f32, time_s: f32) -> vec3f {
    let total = slope_variance(wind_mps);
    let share = wave_variance(wind_mps) / f32(WAVE_COUNT);
    let amplitude = sqrt(2.0 * share);
    var along = vec2f(0.0, 1.0);
    if dot(dir.xz, dir.xz) > 0.0 {
        along = normalize(dir.xz);
    }
    let along_m = wave_footprint(spread, t, dir.y);
    let across_m = max(spread * t, along_m / WAVE_ANISOTROPY_MAX);
    let wind = radians(toward_deg);
    var slope = vec2f(0.0);
    var resolved = 0.0;
    for (var i = 0u; i < WAVE_COUNT; i++) {
        let fi = f32(i);
        let wavelength = WAVE_LONGEST_M * exp2(-WAVE_OCTAVES * fi / f32(WAVE_COUNT));
        let turn = WAVE_SPREAD * (2.0 * fract((fi + 1.0) * GOLDEN) - 1.0);
        let k = vec2f(sin(wind + turn), cos(wind + turn));
        let cos_a = dot(k, along);
        let sin_a = k.x * along.y - k.y * along.x;
        let footprint = sqrt((along_m * cos_a) * (along_m * cos_a) + (across_m * sin_a) * (across_m * sin_a));
        let w = 1.0 - smoothstep(WAVE_FADE_START, WAVE_FADE_END, footprint / wavelength);
        if w <= 0.0 {
            continue;
        }
        let travelled = fract(time_s * wave_frequency(wavelength));
        // In cycles, reduced to one before the cosine (a GPU's cosine of
        // thousands of radians is not its twin's).
        let phase = 2.0 * PI * fract((x * k.x + z * k.y) / wavelength + fract((fi + 1.0) * GOLDEN * GOLDEN) - travelled);
        slope += k * (w * amplitude * cos(phase));
        resolved += w * w * share;
    }
    return vec3f(slope, max(total - resolved, 1e-4));
}

// The waves where the ray meets the sea; the flat sea where it looks up,
// the eye is under the sea or the sea lies beyond the rays' reach (the
// CPU's `sea_waves_at`; only with SEA).
fn sea_waves_at(origin: vec3f, dir: vec3f) -> vec3f {
    if !SEA || dir.y >= 0.0 || origin.y <= 0.0 {
        return flat_sea(SEA_WIND_MPS);
    }
    let t = origin.y / -dir.y;
    if t > frame.sun_light.w {
        return flat_sea(SEA_WIND_MPS);
    }
    return sea_waves(origin.x + dir.x * t, origin.z + dir.z * t, dir, frame.cam_pos.w, t, SEA_WIND_MPS, SEA_WIND_TOWARD_DEG, frame.terrain.z);
}

// No resolved slope, all of Cox and Munk's variance (the CPU's
// `flat_sea`).
fn flat_sea(wind_mps: f32) -> vec3f {
    return vec3f(0.0, 0.0, slope_variance(wind_mps));
}

// The sea's normal under the resolved waves (the CPU's `wave_normal`).
fn wave_normal(waves: vec3f) -> vec3f {
    return normalize(vec3f(-waves.x, 1.0, -waves.y));
}

// The ray the sea sends up along `dir` under the resolved waves, at least
// 1e-3 up (the CPU's `sea_mirror`).
fn sea_mirror(dir: vec3f, waves: vec3f) -> vec3f {
    let n = wave_normal(waves);
    let r = dir - n * (2.0 * dot(dir, n));
    return normalize_or(vec3f(r.x, max(r.y, 1e-3), r.z), vec3f(0.0, 1.0, 0.0));
}

// The sea's Fresnel reflectance under the resolved waves (the CPU's
// `sea_fresnel`).
fn sea_fresnel(dir: vec3f, waves: vec3f) -> f32 {
    return fresnel_water(max(-dot(dir, wave_normal(waves)), 1e-3));
}

// The wind-roughened sea along `dir` (pointing down) under `waves`: the
// sky mirrored by the resolved waves, the sun's glint (the unresolved
// slopes about the resolved one, Beckmann), the water's own blue, the air
// in front (the CPU's `sea_radiance`).
fn sea_radiance(dir: vec3f, sun_dir: vec3f, waves: vec3f, shadow: f32, reflection: vec4f) -> vec3f {
    let mu = max(-dir.y, 1e-3);
    let f = sea_fresnel(dir, waves);
    let reflected = reflection.rgb + mirrored_sky(dir, waves, sun_dir) * reflection.a;
    let sun = sun_light_at(0.0, sun_dir) * shadow;
    let variance = waves.z;
    let h = normalize_or(sun_dir - dir, vec3f(0.0, 1.0, 0.0));
    let cos_b = max(h.y, 1e-3);
    let tan2 = (h.x / cos_b + waves.x) * (h.x / cos_b + waves.x) + (h.z / cos_b + waves.y) * (h.z / cos_b + waves.y);
    let cos2 = cos_b * cos_b;
    let d = exp(-tan2 / variance) / (PI * variance * cos2 * cos2);
    var glint = vec3f(0.0);
    if sun_dir.y > 0.0 {
        glint = sun * (fresnel_water(dot(h, sun_dir)) * d / (4.0 * mu));
    }
    let surface = reflected * f + glint + water_light(sun, sun_dir) * (1.0 - f);
    return ground_haze(surface, dir, sun_dir);
}

// The elevation (radians) of a ray the wind-roughened sea reflects where
// the resolved waves' mirror ray rises at `mirror`, at the quantile `u` of
// the unresolved slopes (mean square `variance`): a logistic of their
// deviation, cut off below REFLECTION_MIN_ELEVATION (the CPU's
// `reflected_elevation`).
fn reflected_elevation(mirror: f32, variance: f32, u: f32) -> f32 {
    let deviation = sqrt(2.0 * max(variance, 0.0));
    let s = deviation * sqrt(3.0) / PI;
    let lowest = 1.0 / (1.0 + exp((mirror - REFLECTION_MIN_ELEVATION) / s));
    let q = clamp(lowest + (1.0 - lowest) * u, 1e-6, 1.0 - 1e-6);
    return mirror + s * log(q / (1.0 - q));
}

// A wave's slope across the line of sight at the quantile `u`: a logistic
// of the unresolved slopes' deviation in one direction (the CPU's
// `cross_slope`).
fn cross_slope(variance: f32, u: f32) -> f32 {
    let deviation = sqrt(0.5 * max(variance, 0.0));
    let s = deviation * sqrt(3.0) / PI;
    let q = clamp(u, 1e-6, 1.0 - 1e-6);
    return s * log(q / (1.0 - q));
}

// The ray a wave sends up from the sea, seen along a ray falling at
// `mirror` radians along `across`: rising at elevation `e`, turned
// sideways by `slope (sin(mirror) + sin(e))` (the CPU's `reflected_ray`).
fn reflected_ray(across: vec3f, mirror: f32, e: f32, slope: f32) -> vec3f {
    let side = vec3f(-across.z, 0.0, across.x);
    let sideways = slope * (sin(mirror) + sin(e));
    return normalize(across * cos(e) + side * sideways + vec3f(0.0, sin(e), 0.0));
}

// The sky the sea mirrors along `dir` under the waves: the mean over
// SKY_MIRROR_RAYS strata of the unresolved slopes about the resolved
// waves' mirror ray (the CPU's `mirrored_sky`).
fn mirrored_sky(dir: vec3f, waves: vec3f, sun_dir: vec3f) -> vec3f {
    let r0 = sea_mirror(dir, waves);
    let across = normalize_or(vec3f(r0.x, 0.0, r0.z), vec3f(0.0, 0.0, 1.0));
    let mirror = asin(clamp(r0.y, -1.0, 1.0));
    var sum = vec3f(0.0);
    for (var k = 0u; k < SKY_MIRROR_RAYS; k++) {
        let u = (f32(k) + 0.5) / f32(SKY_MIRROR_RAYS);
        let e = reflected_elevation(mirror, waves.z, u);
        sum += sky_above(reflected_ray(across, mirror, e, 0.0), sun_dir);
    }
    return sum / f32(SKY_MIRROR_RAYS);
}

// What the clouds the sea mirrors change in a sea pixel's radiance: the sea
// with them less without them, under the flat sea's mirror and Fresnel
// factor (the CPU's `sea_reflection_change`). The cloud pass adds it to
// the cloud layer, so TSAA accumulates it.
fn sea_reflection_change(origin: vec3f, dir: vec3f, dither: f32, sun_dir: vec3f) -> vec3f {
    let r = sea_reflection(origin, dir, dither, sun_dir);
    if r.a >= 1.0 && all(r.rgb == vec3f(0.0)) {
        return vec3f(0.0);
    }
    let waves = flat_sea(SEA_WIND_MPS);
    return (r.rgb - mirrored_sky(dir, waves, sun_dir) * (1.0 - r.a)) * sea_fresnel(dir, waves) * ground_haze_transmittance(dir, sun_dir);
}

// The clouds the sea mirrors (rgb, premultiplied) and the reflected rays'
// transmittance (a) where a ray that meets no terrain reaches it: the
// mean of REFLECTION_RAYS reflected rays, one per stratum of the waves'
// slopes shifted by the pixel's dither (the CPU's `sea_reflection`).
fn sea_reflection(origin: vec3f, dir: vec3f, dither: f32, sun_dir: vec3f) -> vec4f {
    if !SEA || dir.y >= 0.0 || origin.y <= 0.0 {
        return vec4f(0.0, 0.0, 0.0, 1.0);
    }
    let t_sea = origin.y / -dir.y;
    if t_sea > frame.sun_light.w {
        return vec4f(0.0, 0.0, 0.0, 1.0);
    }
    let p = vec3f(origin.x + dir.x * t_sea, 0.0, origin.z + dir.z * t_sea);
    // The resolved waves' mirror ray; the slopes the pixel does not
    // resolve spread the reflected rays about it.
    let waves = sea_waves_at(origin, dir);
    let r0 = sea_mirror(dir, waves);
    let across = normalize_or(vec3f(r0.x, 0.0, r0.z), vec3f(0.0, 0.0, 1.0));
    let mirror = asin(clamp(r0.y, -1.0, 1.0));
    let step_dither = fract(dither + GOLDEN);
    // What lights the mirrored clouds, the same for every reflected ray
    // (the CPU's ReflectionLight).
    let sun = sun_light_at(0.5 * (frame.band.x + frame.band.y), sun_dir);
    let sky_top = sky_ambient(sun_dir) * 0.25;
    let ground = ground_up(sun_dir, true) * 0.25;
    let blur = 2.0 * sqrt(0.003 + 0.00512 * max(SEA_WIND_MPS, 0.0));
    var sum = vec4f(0.0);
    for (var k = 0u; k < REFLECTION_RAYS; k++) {
        let u = (f32(k) + dither) / f32(REFLECTION_RAYS);
        let e = reflected_elevation(mirror, waves.z, u);
        let slope = cross_slope(waves.z, fract((f32(k) + 0.5) * GOLDEN + step_dither));
        let r = reflected_ray(across, mirror, e, slope);
        sum += reflected_clouds(p, r, t_sea, step_dither, sun_dir, sun, sky_top, ground, blur);
    }
    return sum / f32(REFLECTION_RAYS);
}

// The steps of a reflected ray's march across `length` m of the band: one
// per REFLECTION_STEP_M, REFLECTION_STEPS to REFLECTION_STEPS_MAX (the
// CPU's `reflection_step_count`).
fn reflection_step_count(length: f32) -> u32 {
    return clamp(u32(max(ceil(length / REFLECTION_STEP_M), 0.0)), REFLECTION_STEPS, REFLECTION_STEPS_MAX);
}

// The clouds along one ray `r` the sea reflects from `p`, `t_sea` from the
// eye (rgb premultiplied, a its transmittance through the band): a
// coarser twin of march_ray (the CPU's `reflected_clouds`).
fn reflected_clouds(p: vec3f, r: vec3f, t_sea: f32, dither: f32, sun_dir: vec3f, sun: vec3f, sky_top: vec3f, ground: vec3f, blur: f32) -> vec4f {
    let seg = band_segment(p, r, frame.band.x, frame.band.y, frame.sun_light.w);
    if seg.y <= seg.x {
        return vec4f(0.0, 0.0, 0.0, 1.0);
    }
    let spread = frame.cam_pos.w;
    let cos_theta = dot(r, sun_dir);
    let steps = reflection_step_count(seg.y - seg.x);
    let h = (seg.y - seg.x) / f32(steps);
    var transmittance = 1.0;
    var light = vec3f(0.0);
    for (var i = 0u; i < steps; i++) {
        let t = seg.x + (f32(i) + dither) * h;
        let x = p + r * t;
        let sigma_t = density_at(x, true, (spread + blur) * (t_sea + t));
        if sigma_t <= 0.0 {
            continue;
        }
        let shadow = cloud_shadow(x, sun_dir, REFLECTION_SHADOW_STEPS);
        let tau_sun = -log(max(shadow, 1e-30));
        let eta = clamp((x.y - frame.band.x) / (frame.band.y - frame.band.x), 0.0, 1.0);
        let diffused = light_gains().fluence * light_toward(x, -r);
        let scatter = sun * (sun_scattering(tau_sun, cos_theta, sun_dir.y, sigma_t) + diffused) + ambient_light(sky_top, ground, eta);
        light += integrate_step(scatter * (sigma_t * ALBEDO), sigma_t, h) * transmittance;
        transmittance *= exp(-sigma_t * h);
        if transmittance < MIN_TRANSMITTANCE {
            break;
        }
    }
    return vec4f(light, transmittance);
}

// The light rising from the flat ground, unshadowed (the CPU's
// `ground_up`).
fn ground_up(sun_dir: vec3f, sea: bool) -> vec3f {
    if sea {
        let sun = sun_light_at(0.0, sun_dir);
        return sky_above(vec3f(0.0, 1.0, 0.0), sun_dir) * WATER_F0 + water_light(sun, sun_dir) * (1.0 - WATER_F0);
    }
    return land_surface(sun_dir, 1.0, LAND_ALBEDO);
}

// The sky and the sun disk, or below the horizon the land (of albedo
// `land`) or the sea in the clouds' shadow (the CPU's
// `background_radiance`).
fn background_radiance(dir: vec3f, sun_dir: vec3f, waves: vec3f, shadow: f32, land: vec3f, reflection: vec4f) -> vec3f {
    if dir.y >= 0.0 {
        return sky_above(dir, sun_dir) + sun_disk(dir, sun_dir);
    }
    if SEA {
        return sea_radiance(dir, sun_dir, waves, shadow, reflection);
    }
    return land_radiance(dir, sun_dir, shadow, land);
}

// The blue-noise tile's offset of pixel (x, y) (the CPU's `pixel_dither`).
fn pixel_dither(x: u32, y: u32) -> f32 {
    return textureLoad(blue_tex, vec2u(x % BLUE_NOISE_SIZE, y % BLUE_NOISE_SIZE), 0).r;
}

// The distance at march parameter s (the CPU's `march_distance`).
fn march_distance(t0: f32, log_ratio: f32, s: f32) -> f32 {
    return (t0 + NEAR_M) * exp(s * log_ratio) - NEAR_M;
}

// The coarse steps of a band segment that spans log_ratio of
// ln(t + NEAR_M): more where it is wider than MARCH_LOG_SPAN (the CPU's
// `march_step_count`).
fn march_step_count(steps: u32, log_ratio: f32) -> u32 {
    let factor = clamp(log_ratio / MARCH_LOG_SPAN, 1.0, MARCH_STEP_FACTOR_MAX);
    return u32(ceil(f32(max(steps, 1u)) * factor));
}

// The fitted ACES curve (the CPU's `aces_curve`).
fn aces_curve(v: vec3f) -> vec3f {
    let a = v * (v + 0.0245786) - 0.000090537;
    let b = v * (0.983729 * v + 0.432951) + 0.238081;
    return a / b;
}

// ACES filmic tone map of the radiance times `exposure`, to display-linear
// 0..1 (the CPU's `tone_map`). The matrices are the CPU's ACES_INPUT and
// ACES_OUTPUT, written column by column.
fn tone_map(c: vec3f, exposure: f32) -> vec3f {
    let to_working = mat3x3f(
        vec3f(0.59719, 0.07600, 0.02840),
        vec3f(0.35458, 0.90834, 0.13383),
        vec3f(0.04823, 0.01566, 0.83777),
    );
    let to_srgb = mat3x3f(
        vec3f(1.60475, -0.10208, -0.00327),
        vec3f(-0.53108, 1.10813, -0.07276),
        vec3f(-0.07367, -0.00605, 1.07602),
    );
    let v = to_working * (max(c, vec3f(0.0)) * exposure);
    return clamp(to_srgb * aces_curve(v), vec3f(0.0), vec3f(1.0));
}

// Normalised device coordinates of a pixel position (y up; 0.5 = a
// pixel's centre).
fn pixel_ndc(px: vec2f) -> vec2f {
    return vec2f(2.0 * px.x / frame.screen.x - 1.0, 1.0 - 2.0 * px.y / frame.screen.y);
}

// The unit world ray through pixel position `px` (unprojected at depth
// RAY_DEPTH, finite for every perspective projection).
fn camera_ray(px: vec2f) -> vec3f {
    let q = frame.inverse_projection * vec4f(pixel_ndc(px), RAY_DEPTH, 1.0);
    return normalize((frame.view_to_world * vec4f(q.xyz / q.w, 0.0)).xyz);
}

// The result of one ray: premultiplied cloud radiance (the light of the
// clouds plus the haze in front of them) and opacity, the transmittance-
// weighted cloud distance (for TSAA), and the density samples taken.
struct CloudSample {
    premultiplied: vec4f,
    distance: f32,
    samples: u32,
}

// Marches the band segment of one ray up to `max_t` (the twin of
// `march_ray` less the background, which the composite pass adds).
//
// The CPU's march nests three loops: coarse intervals, the REFINE
// sub-samples of those that touch cloud, and the shadow ray of each lit
// sub-sample. Here they are one loop that reads the density once per
// iteration, the same reads in the same order with the same arithmetic:
// neighbouring pixels that run in lockstep on a GPU (a SIMD group) then
// each go on with their own next read, instead of all waiting while one
// of them refines an interval or marches a shadow ray.
fn march_ray(origin: vec3f, dir: vec3f, dither: f32, max_t: f32) -> CloudSample {
    var out: CloudSample;
    out.premultiplied = vec4f(0.0);
    out.distance = frame.sun_light.w;
    out.samples = 0u;
    let seg = band_segment(origin, dir, frame.band.x, frame.band.y, max_t);
    if seg.y <= seg.x {
        return out;
    }
    let t0 = seg.x;
    let t1 = seg.y;
    let sun_dir = frame.sun_dir.xyz;
    let log_ratio = log((t1 + NEAR_M) / (t0 + NEAR_M));
    let steps = march_step_count(frame.counts.x, log_ratio);
    let spread = frame.cam_pos.w;
    let sun = sun_light_at(0.5 * (frame.band.x + frame.band.y), sun_dir);
    let sky_top = sky_ambient(sun_dir) * 0.25;
    let ground = ground_up(sun_dir, SEA) * 0.25;
    let cos_theta = dot(dir, sun_dir);
    let forward = forward_step_factor(cos_theta);
    let offset = shadow_offset(dither);
    var transmittance = 1.0;
    var light = vec3f(0.0);
    var depth_weighted = 0.0;
    var samples = 1u;
    var sigma_a = density_at(origin + dir * t0, true, spread * t0);
    // Coarse intervals begun; the current one's sub-samples taken and
    // planned (planned = taken: probe the next interval's far end), its
    // start and sub-step.
    var i = 0u;
    var j = 0u;
    var n = 0u;
    var start = t0;
    var h = 0.0;
    var ta = t0;
    var tb = t0;
    // The lit sub-sample whose light is still to be added, and its shadow
    // ray: steps taken and to take (equal: done), the steps' weights'
    // sum, length, distance, optical depth so far (the whole ray's once
    // it is done, when the light is added).
    var lit = false;
    var lit_t = 0.0;
    var lit_p = vec3f(0.0);
    var lit_footprint = 0.0;
    var lit_sigma = 0.0;
    var k = 0u;
    var shadow_count = 0u;
    var parts = 0.0;
    var shadow_length = 0.0;
    var shadow_t = 0.0;
    var tau = 0.0;
    loop {
        // What this iteration reads: the lit sample's next shadow step,
        // else (its light added first) the next sub-sample or interval end.
        var q = vec3f(0.0);
        var q_footprint = 0.0;
        var dt = 0.0;
        var kind = 0u; // 0: interval end, 1: sub-sample, 2: shadow step
        var t = 0.0;
        if k < shadow_count {
            dt = shadow_length * sqrt(f32(k + 1u)) / parts;
            q = lit_p + sun_dir * (shadow_t + offset * dt);
            if height_fraction(q.y) > 1.0 {
                k = shadow_count;
            } else {
                kind = 2u;
                q_footprint = lit_footprint;
            }
        }
        if kind != 2u {
            if lit {
                lit = false;
                let eta = clamp((lit_p.y - frame.band.x) / (frame.band.y - frame.band.x), 0.0, 1.0);
                let ambient = ambient_light(sky_top, ground, eta);
                let diffused = light_gains().fluence * light_toward(lit_p, -dir);
                let scatter = sun * (sun_scattering(tau, cos_theta, sun_dir.y, lit_sigma) + diffused) + ambient;
                let s = scatter * (lit_sigma * ALBEDO);
                let step_t = exp(-lit_sigma * h);
                light += integrate_step(s, lit_sigma, h) * transmittance;
                depth_weighted += lit_t * transmittance * (1.0 - step_t);
                transmittance *= step_t;
                if transmittance < MIN_TRANSMITTANCE {
                    break;
                }
            }
            if j == n {
                if i == steps {
                    break;
                }
                tb = march_distance(t0, log_ratio, f32(i + 1u) / f32(steps));
                q = origin + dir * tb;
                q_footprint = spread * tb;
            } else {
                kind = 1u;
                t = start + (f32(j) + dither) * h;
                q = origin + dir * t;
                q_footprint = spread * t;
            }
        }
        let sigma = density_at(q, true, q_footprint);
        samples += 1u;
        if kind == 2u {
            tau += sigma * dt;
            shadow_t += dt;
            k += 1u;
        } else if kind == 0u {
            let touched = sigma_a > 0.0 || sigma > 0.0;
            sigma_a = sigma;
            n = 1u;
            h = tb - ta;
            if touched {
                n = REFINE;
                h = (tb - ta) / f32(REFINE);
            }
            start = ta;
            ta = tb;
            j = 0u;
            i += 1u;
        } else {
            j += 1u;
            if sigma > 0.0 {
                lit = true;
                lit_t = t;
                lit_p = q;
                lit_footprint = q_footprint;
                lit_sigma = sigma;
                tau = 0.0;
                shadow_t = 0.0;
                shadow_length = shadow_ray_length(q, sun_dir);
                shadow_count = shadow_step_count(SHADOW_STEPS, shadow_length, forward);
                parts = shadow_parts(shadow_count);
                k = 0u;
            }
        }
    }
    let opacity = 1.0 - transmittance;
    var cloud_distance = 0.0;
    if opacity > 0.0 {
        cloud_distance = depth_weighted / opacity;
        out.distance = cloud_distance;
    }
    let a = aerial(dir, cloud_distance, sun_dir);
    out.premultiplied = vec4f(light * a.transmittance + a.inscatter * opacity, opacity);
    out.samples = samples;
    return out;
}

// The view's depth of a depth-buffer value: the terrain's buffer under a
// reversed-depth view stores it flipped (1 - d).
fn view_depth(d: f32) -> f32 {
    return mix(d, 1.0 - d, frame.screen.w);
}

// Distance from the eye to the surface at the view's depth `z` at pixel
// position `px` (any perspective projection; infinite at an infinite far
// plane).
fn depth_to_distance(z: f32, px: vec2f) -> f32 {
    let q = frame.inverse_projection * vec4f(pixel_ndc(px), z, 1.0);
    if abs(q.w) <= 1e-30 * length(q.xyz) || q.w == 0.0 {
        return 3.0e38;
    }
    return length(q.xyz / q.w);
}

// Whether the view's depth `z` is geometry (not the far value a depth
// buffer is cleared to).
fn is_geometry(z: f32) -> bool {
    return z != frame.screen.z;
}

// The march of one pixel at fragment position `pos` up to `max_t`; with
// `sea`, the change the clouds the sea mirrors make to the sea behind,
// under the clouds' transmittance.
fn cloud_pixel(pos: vec2f, max_t: f32, sea: bool) -> CloudSample {
    let px = vec2u(pos);
    let dir = camera_ray(pos + frame.jitter.xy);
    let dither = fract(pixel_dither(px.x, px.y) + frame.jitter.z);
    var s = march_ray(frame.cam_pos.xyz, dir, dither, max_t);
    if SEA && sea && frame.exposure.y > 0.5 {
        let change = sea_reflection_change(frame.cam_pos.xyz, dir, dither, frame.sun_dir.xyz);
        s.premultiplied = vec4f(s.premultiplied.rgb + (1.0 - s.premultiplied.a) * change, s.premultiplied.a);
    }
    if DEBUG_COUNT {
        s.premultiplied = vec4f(f32(s.samples), 0.0, 0.0, 0.0);
    }
    return s;
}

struct FullScreen {
    @builtin(position) position: vec4f,
}

@vertex
fn vs_full_screen(@builtin(vertex_index) i: u32) -> FullScreen {
    // One triangle that covers the screen.
    let uv = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    var out: FullScreen;
    out.position = vec4f(uv * 2.0 - 1.0, 0.0, 1.0);
    return out;
}
