// The atmosphere of Hillaire 2020's sky tables: its media, phase functions,
// ray geometry and step integrals, the twins of
// src/render/cpu/sky_luts/atmosphere.rs (same names, same arguments in the
// same order; a Rust tuple is a vec2f or a small struct here). Lengths in
// km, coefficients 1/km, as on the CPU. The sky tables are a library
// without bindings or `PI`: this file, tables.wgsl and lookups.wgsl are
// assembled as `SKY_LUTS` by src/render/gpu/shaders.rs; sky_luts_build.wgsl
// appends the three compute entry points that write the tables
// (rgba32float, alpha 1), and the physical sky (sky_physical.wgsl) reads
// them with the lookups.

const GOLDEN_ANGLE: f32 = 2.399963;
const TRANSMITTANCE_WIDTH: u32 = 256u;
const TRANSMITTANCE_HEIGHT: u32 = 64u;
const MULTI_SCATTERING_WIDTH: u32 = 32u;
const MULTI_SCATTERING_HEIGHT: u32 = 32u;
const SKY_VIEW_WIDTH: u32 = 192u;
const SKY_VIEW_HEIGHT: u32 = 108u;
const SKY_VIEW_HALF: u32 = 54u;
const TRANSMITTANCE_STEPS: u32 = 40u;
const MULTI_SCATTERING_DIRECTIONS: u32 = 64u;
const MULTI_SCATTERING_STEPS: u32 = 20u;
const SKY_VIEW_STEPS: u32 = 30u;
const AERIAL_PERSPECTIVE_STEPS: u32 = 10u;
const SKY_AMBIENT_ROWS: u32 = 16u;
const SKY_AMBIENT_COLUMNS: u32 = 32u;
const LIMB_DARKENING_U: f32 = 0.6;

// Keep in sync with src/render/gpu/uniforms.rs: SkyParamsUniforms (96
// bytes; each vec3f shares its 16 bytes with the f32 after it).
struct SkyParams {
    rayleigh_scattering: vec3f,
    ground_radius_km: f32,
    ozone_absorption: vec3f,
    top_radius_km: f32,
    ground_albedo: vec3f,
    rayleigh_scale_height_km: f32,
    sun_irradiance: vec3f,
    mie_scattering: f32,
    mie_extinction: f32,
    mie_scale_height_km: f32,
    mie_g: f32,
    ozone_center_km: f32,
    ozone_width_km: f32,
    sun_angular_radius_deg: f32,
}

// Keep in sync with src/render/gpu/uniforms.rs: SkyViewUniforms (8 bytes):
// the sky view's camera radius (km) and the sun's cos zenith.
struct SkyView {
    camera_radius_km: f32,
    sun_cos_zenith: f32,
}

struct Medium {
    rayleigh_scattering: vec3f,
    mie_scattering: f32,
    extinction: vec3f,
}

struct SkyRay {
    r: f32,
    mu: f32,
    mu_s: f32,
    nu: f32,
}

// (L', f) of second_order_along.
struct SecondOrder {
    light: vec3f,
    transfer: vec3f,
}

// (inscatter, T) of integrate_scattering.
struct Scattering {
    inscatter: vec3f,
    transmittance: vec3f,
}

// (fx, fy, row_min, row_max) of sky_view_texel_coords.
struct SkyViewCoords {
    fx: f32,
    fy: f32,
    row_min: u32,
    row_max: u32,
}

fn scattering(m: Medium) -> vec3f {
    return m.rayleigh_scattering + vec3f(m.mie_scattering);
}

fn medium_at(altitude_km: f32, p: SkyParams) -> Medium {
    let h = max(altitude_km, 0.0);
    let rayleigh = exp(-h / p.rayleigh_scale_height_km);
    let mie = exp(-h / p.mie_scale_height_km);
    let ozone = max(1.0 - abs(h - p.ozone_center_km) / (0.5 * p.ozone_width_km), 0.0);
    let rayleigh_scattering = p.rayleigh_scattering * rayleigh;
    return Medium(
        rayleigh_scattering,
        p.mie_scattering * mie,
        rayleigh_scattering + vec3f(p.mie_extinction * mie) + p.ozone_absorption * ozone,
    );
}

fn phase_rayleigh(cos_theta: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + cos_theta * cos_theta);
}

fn phase_cornette_shanks(cos_theta: f32, g: f32) -> f32 {
    let g2 = g * g;
    let denom = (2.0 + g2) * pow(max(1.0 + g2 - 2.0 * g * cos_theta, 1e-6), 1.5);
    return 3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + cos_theta * cos_theta) / denom;
}

fn radius_along(r: f32, mu: f32, t: f32) -> f32 {
    return sqrt(max(t * t + 2.0 * r * mu * t + r * r, 0.0));
}

fn distance_to_top(r: f32, mu: f32, top: f32) -> f32 {
    let disc = r * r * mu * mu + (top - r) * (top + r);
    return max(-r * mu + sqrt(max(disc, 0.0)), 0.0);
}

fn ray_hits_ground(r: f32, mu: f32, bottom: f32) -> bool {
    return mu < 0.0 && r * r * mu * mu - (r - bottom) * (r + bottom) >= 0.0;
}

fn distance_to_ground(r: f32, mu: f32, bottom: f32) -> f32 {
    let c = (r - bottom) * (r + bottom);
    let disc = max(r * r * mu * mu - c, 0.0);
    return max(c / max(-r * mu + sqrt(disc), 1e-9), 0.0);
}

fn distance_to_boundary(r: f32, mu: f32, p: SkyParams) -> f32 {
    if ray_hits_ground(r, mu, p.ground_radius_km) {
        return distance_to_ground(r, mu, p.ground_radius_km);
    }
    return distance_to_top(r, mu, p.top_radius_km);
}

fn sun_visible_fraction(r: f32, mu_s: f32, p: SkyParams) -> f32 {
    let sin_h = min(p.ground_radius_km / r, 1.0);
    let cos_h = -sqrt(max(1.0 - sin_h * sin_h, 0.0));
    let half_size = sin_h * radians(p.sun_angular_radius_deg);
    let x = clamp((mu_s - cos_h + half_size) / (2.0 * half_size), 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

fn fibonacci_direction(i: u32, n: u32) -> vec3f {
    let y = 1.0 - (2.0 * f32(i) + 1.0) / f32(n);
    let ring = sqrt(max(1.0 - y * y, 0.0));
    let phi = f32(i) * GOLDEN_ANGLE;
    return vec3f(ring * cos(phi), y, ring * sin(phi));
}

// (radius km, sun cos zenith) at t km along the ray.
fn sky_ray_at(ray: SkyRay, t: f32) -> vec2f {
    let r_t = radius_along(ray.r, ray.mu, t);
    return vec2f(r_t, clamp((ray.r * ray.mu_s + t * ray.nu) / r_t, -1.0, 1.0));
}

// (t0, t1) km.
fn step_bounds(k: u32, steps: u32, t_max: f32) -> vec2f {
    let a = f32(k) / f32(steps);
    let b = f32(k + 1u) / f32(steps);
    return vec2f(t_max * a * a, t_max * b * b);
}

fn step_integral_1(extinction: f32, dt: f32) -> f32 {
    if extinction * dt < 1e-3 {
        return dt * (1.0 - 0.5 * extinction * dt);
    }
    return (1.0 - exp(-extinction * dt)) / extinction;
}

fn step_integral(extinction: vec3f, dt: f32) -> vec3f {
    return vec3f(
        step_integral_1(extinction.x, dt),
        step_integral_1(extinction.y, dt),
        step_integral_1(extinction.z, dt),
    );
}

fn horizon_zenith_angle(r: f32, p: SkyParams) -> f32 {
    let bottom = p.ground_radius_km;
    return PI - acos(sqrt(max((r - bottom) * (r + bottom), 0.0)) / r);
}

fn radius_at_altitude(altitude_m: f32, p: SkyParams) -> f32 {
    return clamp(p.ground_radius_km + altitude_m * 1e-3, p.ground_radius_km, p.top_radius_km);
}

fn azimuth_from_sun(dir: vec3f, sun_dir: vec3f) -> f32 {
    let cross = dir.z * sun_dir.x - dir.x * sun_dir.z;
    let dot = dir.x * sun_dir.x + dir.z * sun_dir.z;
    return atan2(abs(cross), dot);
}

fn sky_ray(altitude_m: f32, dir: vec3f, sun_dir: vec3f, p: SkyParams) -> SkyRay {
    return SkyRay(radius_at_altitude(altitude_m, p), dir.y, sun_dir.y, dot(dir, sun_dir));
}

