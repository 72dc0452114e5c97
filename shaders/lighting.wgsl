// The light a cloud sample scatters toward the eye: phase functions, the
// shadow march's steps, the multiple-scattering octaves and the light
// gains; the twins of src/render/cpu/lighting.rs.

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

// Multiple scattering (the CPU's lighting.rs).
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
// The sky's and the ground's light in cloud (the CPU's lighting.rs).
const AMBIENT_GAIN: f32 = 4.355;
const AMBIENT_GAIN_ALONE: f32 = 4.37;
const GROUND_LIGHT_GAIN: f32 = 0.0;
const GROUND_LIGHT_GAIN_ALONE: f32 = 3.82;
// Single-scattering albedo of cloud droplets.
const ALBEDO: f32 = 0.99;

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
    return 1.0 + FORWARD_STEP_BOOST * toward_sun(cos_theta);
}

// How much of a primary ray's view is toward the sun, 0 to 1 (the CPU's
// `toward_sun`).
fn toward_sun(cos_theta: f32) -> f32 {
    return smoothstep(FORWARD_COS_MIN, FORWARD_COS_MAX, cos_theta);
}

// The steps of a shadow ray of `length` m: `steps` over SHADOW_STEP_SPAN_M
// or less, in proportion beyond, times `forward`, at most
// SHADOW_STEP_FACTOR_MAX times `steps` in all (the CPU's
// `shadow_step_count`).
fn shadow_step_count(steps: u32, length: f32, forward: f32) -> u32 {
    let along = clamp(length / SHADOW_STEP_SPAN_M, 1.0, SHADOW_STEP_FACTOR_MAX);
    return u32(ceil(f32(steps) * min(along * forward, SHADOW_STEP_FACTOR_MAX)));
}

// With a light volume, the shadow ray's near part: NEAR_SHADOW_STEPS (at
// most `steps`, times `forward`) over NEAR_SHADOW_M; the volume's
// precomputed depth beyond (the CPU's `near_sun_optical_depth`).
const NEAR_SHADOW_M: f32 = 200.0;
const NEAR_SHADOW_STEPS: u32 = 6u;

fn near_step_count(steps: u32, forward: f32) -> u32 {
    return u32(ceil(f32(min(steps, NEAR_SHADOW_STEPS)) * forward));
}

// The part of the shadow ray from p the march reads density along with
// a light volume: its length, steps, and whether any of the ray is left
// beyond for the volume's depth; up to the whole ray toward the sun (the
// CPU's `near_shadow_ray`).
struct NearShadowRay {
    length: f32,
    count: u32,
    rest: bool,
}

fn near_shadow_ray(p: vec3f, sun_dir: vec3f, steps: u32, forward: f32, toward: f32) -> NearShadowRay {
    let full = shadow_ray_length(p, sun_dir);
    let near = min(full, NEAR_SHADOW_M);
    let near_count = near_step_count(steps, forward);
    let full_count = max(shadow_step_count(steps, full, forward), near_count);
    var r: NearShadowRay;
    r.length = near + (full - near) * toward;
    r.count = near_count + u32(floor(f32(full_count - near_count) * toward + 0.5));
    r.rest = toward < 1.0 && full > NEAR_SHADOW_M;
    return r;
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

fn integrate_step(s: vec3f, sigma_t: f32, dt: f32) -> vec3f {
    if sigma_t * dt < 1e-5 {
        return s * dt;
    }
    return (s - s * exp(-sigma_t * dt)) / sigma_t;
}

// The sky's and the ground's light scattered at height fraction `eta`
// (the CPU's `ambient_light`): the sky's from 0.35 at the band's bottom
// to all at its top, the ground's from all at the bottom to none at the top.
fn ambient_light(sky_top: vec3f, ground: vec3f, eta: f32) -> vec3f {
    let gains = light_gains();
    return sky_top * ((0.35 + 0.65 * eta) * gains.ambient) + ground * ((1.0 - eta) * gains.ground);
}

const GROUND_SHADOW_FOOTPRINT_M: f32 = 6.0;

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
