// The optional cirrus layer: the twin of `render::cpu::cirrus`. Its
// settings are override constants (set from `[render.cirrus]`); with
// CIRRUS false the layer compiles to nothing.

override CIRRUS: bool = false;
override CIRRUS_COVER: f32 = 0.0;
override CIRRUS_ALTITUDE_M: f32 = 9000.0;
override CIRRUS_DIRECTION_DEG: f32 = 60.0;
override CIRRUS_OPTICAL_DEPTH: f32 = 0.2;

const CIRRUS_ALONG_M: f32 = 9000.0;
const CIRRUS_ACROSS_M: f32 = 1500.0;
const CIRRUS_OCTAVES: u32 = 5u;
const CIRRUS_FIBRE_GROWTH: f32 = 2.8;
const CIRRUS_CONTRAST: f32 = 3.0;
const CIRRUS_EDGE: f32 = 0.35;
const CIRRUS_PHASE_G: f32 = 0.75;
const CIRRUS_MU_MIN: f32 = 0.03;

// An integer hash of the lattice point (ix, iy) to [0, 1) (the CPU's
// `cirrus_hash`: the same bits).
fn cirrus_hash(ix: i32, iy: i32) -> f32 {
    var h = (bitcast<u32>(ix) * 0x8da6b343u) ^ (bitcast<u32>(iy) * 0xd8163841u);
    h = h * 747796405u + 2891336453u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    h = h ^ (h >> 22u);
    return f32(h >> 8u) / 16777216.0;
}

// Value noise at (x, y), lattice units (the CPU's `cirrus_noise`).
fn cirrus_noise(x: f32, y: f32) -> f32 {
    let fx = floor(x);
    let fy = floor(y);
    let ix = i32(fx);
    let iy = i32(fy);
    let u = x - fx;
    let v = y - fy;
    let su = u * u * (3.0 - 2.0 * u);
    let sv = v * v * (3.0 - 2.0 * v);
    let a = cirrus_hash(ix, iy);
    let b = cirrus_hash(ix + 1, iy);
    let c = cirrus_hash(ix, iy + 1);
    let d = cirrus_hash(ix + 1, iy + 1);
    let top = a + (b - a) * su;
    let bottom = c + (d - c) * su;
    return top + (bottom - top) * sv;
}

// The layer's density at world (x, z), 0..=1, the octaves finer than
// twice the footprint faded to their mean (the CPU's `cirrus_density`).
fn cirrus_density(x: f32, z: f32, footprint_m: f32) -> f32 {
    let a = radians(CIRRUS_DIRECTION_DEG);
    let s = sin(a);
    let c = cos(a);
    let along = (x * s + z * c) / CIRRUS_ALONG_M;
    let across = (x * c - z * s) / CIRRUS_ACROSS_M;
    var sum = 0.0;
    var amplitude = 1.0;
    var total = 0.0;
    var f_along = 1.0;
    var f_across = 1.0;
    for (var k = 0u; k < CIRRUS_OCTAVES; k++) {
        let shift = 17.31 * f32(k);
        let resolved = clamp(CIRRUS_ACROSS_M / (f_across * max(footprint_m, 1e-3)) - 1.0, 0.0, 1.0);
        let n = cirrus_noise(along * f_along + shift, across * f_across - shift);
        sum += amplitude * (0.5 + (n - 0.5) * resolved);
        total += amplitude;
        amplitude *= 0.5;
        f_along *= 2.0;
        f_across *= CIRRUS_FIBRE_GROWTH;
    }
    let n = clamp(0.5 + (sum / total - 0.5) * CIRRUS_CONTRAST, 0.0, 1.0);
    let threshold = 1.0 - CIRRUS_COVER;
    return clamp((n - threshold) / CIRRUS_EDGE, 0.0, 1.0);
}

// The background seen along dir from eye behind the cirrus layer, for a
// pixel of cone angle `spread` (the CPU's `cirrus_over`).
fn cirrus_over(eye: vec3f, dir: vec3f, sun_dir: vec3f, spread: f32, background: vec3f) -> vec3f {
    if !CIRRUS || dir.y <= 0.0 || eye.y >= CIRRUS_ALTITUDE_M {
        return background;
    }
    let t = (CIRRUS_ALTITUDE_M - eye.y) / dir.y;
    let p = eye + dir * t;
    let mu = max(dir.y, CIRRUS_MU_MIN);
    let density = cirrus_density(p.x, p.z, spread * t / mu);
    if density <= 0.0 {
        return background;
    }
    let tau = density * CIRRUS_OPTICAL_DEPTH / mu;
    let opacity = 1.0 - exp(-tau);
    let sun = sun_light_at(CIRRUS_ALTITUDE_M, sun_dir);
    let ambient = sky_ambient(sun_dir) * 0.25;
    let light = (sun * phase_hg(dot(dir, sun_dir), CIRRUS_PHASE_G) + ambient) * (ALBEDO * opacity);
    let air = aerial(dir, t, sun_dir);
    return background * (1.0 - opacity) + light * air.transmittance + air.inscatter * opacity;
}
