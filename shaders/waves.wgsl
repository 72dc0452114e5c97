// The sea's wave trains and the rays they reflect; the twins of
// src/render/cpu/waves.rs.

// The sea's wave trains (the CPU's waves.rs): how many, the octaves of
// wavelength they span, the longest's wavelength (m), their directions' spread about the wind (radians), the
// largest share of Cox and Munk's variance they carry, and the footprint
// over wavelength over which a train fades from a pixel.
const WAVE_COUNT: u32 = 40u;
const WAVE_OCTAVES: f32 = 7.5;
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

// No resolved slope, all of Cox and Munk's variance (the CPU's
// `flat_sea`).
fn flat_sea(wind_mps: f32) -> vec3f {
    return vec3f(0.0, 0.0, slope_variance(wind_mps));
}

// The sea's normal under the resolved waves (the CPU's `wave_normal`).
fn wave_normal(waves: vec3f) -> vec3f {
    return normalize(vec3f(-waves.x, 1.0, -waves.y));
}

// The lowest elevation (radians) a wave sends a reflected ray to (the
// CPU's waves.rs).
const REFLECTION_MIN_ELEVATION: f32 = 0.01;

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
