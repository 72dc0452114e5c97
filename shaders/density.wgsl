// The clouds' density: P (coverage, normalised height, fill), the cloud
// map CM and the 3D detail noise, combined as in src/render/cpu/density.rs,
// whose functions and constants these are, name for name.

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
const DETAIL_TILE: f32 = 4.0;
const BILLOW_FREQUENCY: f32 = 1.618;
const BASE_WEIGHT: f32 = 0.85;
const FINE_FREQUENCY: f32 = 4.0;
const FINE_WEIGHT: f32 = 0.16;
const FINE_SHARP_M: f32 = 3.0;
const NOISE_SIZE: f32 = 64.0;
const NOISE_MAX_LOD: f32 = 5.0;

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
