// The per-primitive renderer (after Jimenez de Parga & Gomez Palomo 2018):
// every cloudy parcel is a pseudo-spheroid, a flattened ellipsoid whose
// surface the fBm pushes in and out (their Eq. 2), marched only where the
// ray crosses a spheroid, with the sun's optical depth read from a light
// grid the CPU precomputes. `cumulus bench` compares it with the cloud map;
// `[render] renderer = "spheroids"` draws a scene with it. The CPU twin is
// src/render/cpu/spheroids.rs. The sky, haze and tone map are the cloud
// pass's own functions. Appended to CLOUDS and COMPOSITE (shaders.rs).

// Keep in sync with src/render/cpu/spheroids.rs: Spheroid.
struct Spheroid {
    centre_radius: vec4f, // world centre (m), horizontal semi-axis (m)
    shape: vec4f,         // fill 0..1, vertical / horizontal axis, unused x2
}

// Keep in sync with src/render/cpu/spheroids.rs: LightGrid::to_words.
struct LightGrid {
    origin: vec4f,        // the box's lowest corner (m)
    extent: vec4f,        // the box's size (m)
    dims: vec4u,          // voxels along x, y, z
    depth: array<f32>,    // the sun's optical depth at each voxel centre
}

@group(1) @binding(0) var<storage, read> spheroids: array<Spheroid>;
@group(1) @binding(1) var<storage, read> light_grid: LightGrid;

// How far the fBm moves a spheroid's surface (κ of their Eq. 2).
const SPHEROID_KAPPA: f32 = 0.35;
// The spheroids a ray keeps (the nearest, by entry distance).
const MAX_CANDIDATES: u32 = 16u;
// Octaves of the fBm.
const FBM_OCTAVES: u32 = 4u;
// The fBm's spread about 0.5 is widened by this (clamped to 0..1).
const FBM_CONTRAST: f32 = 3.0;

fn spheroid_hash(x: i32, y: i32, z: i32) -> f32 {
    var h = (bitcast<u32>(x) * 0x8da6b343u) ^ (bitcast<u32>(y) * 0xd8163841u)
        ^ (bitcast<u32>(z) * 0xcb1ab31fu);
    h ^= h >> 13u;
    h *= 0x5bd1e995u;
    h ^= h >> 15u;
    return f32(h & 0x00ffffffu) / 16777216.0;
}

fn spheroid_value_noise(q: vec3f) -> f32 {
    let f = floor(q);
    let t = q - f;
    let w = t * t * (vec3f(3.0) - 2.0 * t);
    let x = i32(f.x);
    let y = i32(f.y);
    let z = i32(f.z);
    let x00 = mix(spheroid_hash(x, y, z), spheroid_hash(x + 1, y, z), w.x);
    let x10 = mix(spheroid_hash(x, y + 1, z), spheroid_hash(x + 1, y + 1, z), w.x);
    let x01 = mix(spheroid_hash(x, y, z + 1), spheroid_hash(x + 1, y, z + 1), w.x);
    let x11 = mix(spheroid_hash(x, y + 1, z + 1), spheroid_hash(x + 1, y + 1, z + 1), w.x);
    return mix(mix(x00, x10, w.y), mix(x01, x11, w.y), w.z);
}

// Fractal Brownian motion in 0..1: octaves of value noise, each twice the
// frequency and half the weight of the last, normalised by the weights,
// its spread widened by FBM_CONTRAST.
fn spheroid_fbm(p: vec3f, scale_m: f32) -> f32 {
    var q = p / scale_m;
    var sum = 0.0;
    var weight = 0.5;
    var total = 0.0;
    for (var i = 0u; i < FBM_OCTAVES; i++) {
        sum += weight * spheroid_value_noise(q + vec3f(f32(i) * 17.31));
        total += weight;
        weight *= 0.5;
        q = q * 2.03;
    }
    return clamp(0.5 + (sum / total - 0.5) * FBM_CONTRAST, 0.0, 1.0);
}

// Their Eq. 2: γ = exp(-d / ((1 - κ) + 2κ fbm)) at ellipsoidal distance d
// (1 on the spheroid's nominal surface), mapped so that it is 0 where γ
// falls to e^-1 (the surface the fBm has moved) and 1 at the centre.
fn spheroid_profile(d: f32, fbm: f32) -> f32 {
    let gamma = exp(-d / ((1.0 - SPHEROID_KAPPA) + 2.0 * SPHEROID_KAPPA * fbm));
    let edge = exp(-1.0);
    return clamp((gamma - edge) / (1.0 - edge), 0.0, 1.0);
}

// The ellipsoidal distance of p from spheroid s (1 on its nominal surface).
fn spheroid_distance(p: vec3f, s: Spheroid) -> f32 {
    let d = p - s.centre_radius.xyz;
    let q = vec3f(d.x, d.y / s.shape.y, d.z) / s.centre_radius.w;
    return length(q);
}

// The entry and exit distances of the ray through spheroid s grown by
// 1 + κ (the farthest the fBm moves its surface); x > y: missed.
fn spheroid_hit(origin: vec3f, dir: vec3f, s: Spheroid) -> vec2f {
    let scale = vec3f(1.0, 1.0 / s.shape.y, 1.0) / (s.centre_radius.w * (1.0 + SPHEROID_KAPPA));
    let o = (origin - s.centre_radius.xyz) * scale;
    let d = dir * scale;
    let a = dot(d, d);
    let b = dot(o, d);
    let c = dot(o, o) - 1.0;
    let h = b * b - a * c;
    if h <= 0.0 {
        return vec2f(1.0, 0.0);
    }
    let r = sqrt(h);
    return vec2f((-b - r) / a, (-b + r) / a);
}

// Extinction (1/m) at p from the candidates `ids[0..n]`: each spheroid's
// profile weighted by its fill, summed and capped at the densest cloud.
fn spheroid_density(p: vec3f, ids: ptr<function, array<u32, 16>>, n: u32, fbm: f32) -> f32 {
    var sum = 0.0;
    for (var i = 0u; i < n; i++) {
        let s = spheroids[(*ids)[i]];
        sum += (0.3 + 0.7 * s.shape.x) * spheroid_profile(spheroid_distance(p, s), fbm);
    }
    return frame.band.w * min(sum, 1.0);
}

// The sun's optical depth at p, read trilinearly from the light grid
// (0 outside its box).
fn light_grid_depth(p: vec3f) -> f32 {
    let dims = light_grid.dims.xyz;
    let g = (p - light_grid.origin.xyz) / light_grid.extent.xyz * vec3f(dims) - vec3f(0.5);
    if any(g < vec3f(-0.5)) || any(g > vec3f(dims) - vec3f(0.5)) {
        return 0.0;
    }
    let hi = vec3i(dims) - vec3i(1);
    let f = clamp(g, vec3f(0.0), vec3f(hi));
    let i0 = vec3i(floor(f));
    let i1 = min(i0 + vec3i(1), hi);
    let t = f - floor(f);
    let nx = i32(dims.x);
    let ny = i32(dims.y);
    let c000 = light_grid.depth[(i0.z * ny + i0.y) * nx + i0.x];
    let c100 = light_grid.depth[(i0.z * ny + i0.y) * nx + i1.x];
    let c010 = light_grid.depth[(i0.z * ny + i1.y) * nx + i0.x];
    let c110 = light_grid.depth[(i0.z * ny + i1.y) * nx + i1.x];
    let c001 = light_grid.depth[(i1.z * ny + i0.y) * nx + i0.x];
    let c101 = light_grid.depth[(i1.z * ny + i0.y) * nx + i1.x];
    let c011 = light_grid.depth[(i1.z * ny + i1.y) * nx + i0.x];
    let c111 = light_grid.depth[(i1.z * ny + i1.y) * nx + i1.x];
    let x00 = mix(c000, c100, t.x);
    let x10 = mix(c010, c110, t.x);
    let x01 = mix(c001, c101, t.x);
    let x11 = mix(c011, c111, t.x);
    return mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z);
}

// The march: the spheroids the ray crosses (the nearest MAX_CANDIDATES,
// sorted by entry), their spans merged so no stretch is marched twice
// (their "no duplicate tracing"), the steps spread evenly over the merged
// length; each sample reads the fBm once and the light grid once.
fn march_spheroids(origin: vec3f, dir: vec3f, dither: f32) -> vec4f {
    let max_t = frame.sun_light.w;
    var ids: array<u32, 16>;
    var t_in: array<f32, 16>;
    var t_out: array<f32, 16>;
    var n = 0u;
    let count = arrayLength(&spheroids);
    for (var i = 0u; i < count; i++) {
        let h = spheroid_hit(origin, dir, spheroids[i]);
        let a = max(h.x, 0.0);
        let b = min(h.y, max_t);
        if b <= a {
            continue;
        }
        // Insertion by entry distance; a full list drops its farthest.
        var k = min(n, MAX_CANDIDATES - 1u);
        if n == MAX_CANDIDATES && a >= t_in[k] {
            continue;
        }
        while k > 0u && t_in[k - 1u] > a {
            ids[k] = ids[k - 1u];
            t_in[k] = t_in[k - 1u];
            t_out[k] = t_out[k - 1u];
            k -= 1u;
        }
        ids[k] = i;
        t_in[k] = a;
        t_out[k] = b;
        n = min(n + 1u, MAX_CANDIDATES);
    }
    if n == 0u {
        return vec4f(0.0);
    }
    // Merge the sorted spans in place.
    var m = 0u;
    var seg0: array<f32, 16>;
    var seg1: array<f32, 16>;
    seg0[0] = t_in[0];
    seg1[0] = t_out[0];
    for (var i = 1u; i < n; i++) {
        if t_in[i] <= seg1[m] {
            seg1[m] = max(seg1[m], t_out[i]);
        } else {
            m += 1u;
            seg0[m] = t_in[i];
            seg1[m] = t_out[i];
        }
    }
    var total = 0.0;
    for (var i = 0u; i <= m; i++) {
        total += seg1[i] - seg0[i];
    }
    let sun_dir = frame.sun_dir.xyz;
    let steps = max(frame.counts.x, 1u);
    let dt = total / f32(steps);
    let l = standalone_light(dir, sun_dir);
    var march = StandaloneMarch(vec3f(0.0), 1.0, 0.0);
    var seg = 0u;
    var before = 0.0; // merged length before segment `seg`
    for (var i = 0u; i < steps; i++) {
        let s = (f32(i) + dither) * dt;
        while seg < m && s >= before + seg1[seg] - seg0[seg] {
            before += seg1[seg] - seg0[seg];
            seg += 1u;
        }
        let t = seg0[seg] + (s - before);
        let p = origin + dir * t;
        var fbm = 0.5;
        if DETAIL {
            fbm = spheroid_fbm(p, frame.map.z);
        }
        let sigma_t = spheroid_density(p, &ids, n, fbm);
        if sigma_t <= 0.0 {
            continue;
        }
        let tau_sun = light_grid_depth(p);
        if standalone_step(&march, l, p, t, dt, sigma_t, tau_sun) {
            break;
        }
    }
    return hazed_clouds(march, dir, sun_dir);
}

@fragment
fn fs_spheroids(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let px = vec2u(pos.xy);
    let dir = camera_ray(pos.xy);
    let c = march_spheroids(frame.cam_pos.xyz, dir, standalone_dither(px.x, px.y));
    // No cloud shadows on its ground and no clouds in its sea: its bind
    // groups have no P or map.
    let bg = cirrus_over(frame.cam_pos.xyz, dir, frame.sun_dir.xyz, frame.cam_pos.w, background_radiance(dir, frame.sun_dir.xyz, sea_waves_at(frame.cam_pos.xyz, dir), 1.0, flat_ground_albedo(frame.cam_pos.xyz, dir, frame.cam_pos.w), vec4f(0.0, 0.0, 0.0, 1.0)));
    return vec4f(display(c.rgb + (1.0 - c.a) * bg, pos.xy), 1.0);
}
