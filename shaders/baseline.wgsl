// The per-parcel baseline renderer, after Goswami & Neyret (2017): every
// cloudy parcel is a noisy sphere, and every march sample tests every
// parcel, so the cost per pixel grows with the parcel count. It is only
// here to be compared with the cloud-map method (`cumulus bench`). The
// lighting, sky, haze and tone map are the cloud pass's own functions.
// Appended to clouds.wgsl and composite.wgsl.

// Keep in sync with src/render/gpu/baseline.rs: Sphere.
struct Sphere {
    centre_radius: vec4f, // world centre (m), radius (m)
    fill: vec4f,          // fill density 0..1, unused x3
}

@group(1) @binding(0) var<storage, read> spheres: array<Sphere>;

// The baseline's own procedural detail noise (the value noise the cloud
// pass used before its 3D volume), so the baseline needs no textures.
fn sphere_hash(x: i32, y: i32, z: i32) -> f32 {
    var h = (bitcast<u32>(x) * 0x8da6b343u) ^ (bitcast<u32>(y) * 0xd8163841u)
        ^ (bitcast<u32>(z) * 0xcb1ab31fu);
    h ^= h >> 13u;
    h *= 0x5bd1e995u;
    h ^= h >> 15u;
    return f32(h & 0x00ffffffu) / 16777216.0;
}

fn sphere_value_noise(q: vec3f) -> f32 {
    let f = floor(q);
    let t = q - f;
    let w = t * t * (vec3f(3.0) - 2.0 * t);
    let x = i32(f.x);
    let y = i32(f.y);
    let z = i32(f.z);
    let x00 = mix(sphere_hash(x, y, z), sphere_hash(x + 1, y, z), w.x);
    let x10 = mix(sphere_hash(x, y + 1, z), sphere_hash(x + 1, y + 1, z), w.x);
    let x01 = mix(sphere_hash(x, y, z + 1), sphere_hash(x + 1, y, z + 1), w.x);
    let x11 = mix(sphere_hash(x, y + 1, z + 1), sphere_hash(x + 1, y + 1, z + 1), w.x);
    return mix(mix(x00, x10, w.y), mix(x01, x11, w.y), w.z);
}

fn sphere_noise(p: vec3f, scale_m: f32) -> f32 {
    let q = p / scale_m;
    return 0.5 * sphere_value_noise(q) + 0.3 * sphere_value_noise(q * 2.0 + vec3f(17.3))
        + 0.2 * sphere_value_noise(q * 4.0 + vec3f(5.9));
}

// The baseline's per-pixel dither (interleaved gradient noise, Jimenez
// 2014), so it needs no blue-noise texture.
fn sphere_dither(x: u32, y: u32) -> f32 {
    return fract(52.982918 * fract(0.06711056 * f32(x) + 0.00583715 * f32(y)));
}

// Extinction (1/m) at p: the sum of every sphere's parabolic profile,
// eroded by the detail noise when it is on. O(parcels).
fn sphere_density(p: vec3f, detail: bool) -> f32 {
    var sum = 0.0;
    let n = arrayLength(&spheres);
    for (var i = 0u; i < n; i++) {
        let s = spheres[i];
        let d = p - s.centre_radius.xyz;
        let r2 = s.centre_radius.w * s.centre_radius.w;
        let q = dot(d, d) / r2;
        if q < 1.0 {
            sum += (0.3 + 0.7 * s.fill.x) * min((1.0 - q) * 3.0, 1.0);
        }
    }
    var profile = min(sum, 1.0);
    if profile <= 0.0 {
        return 0.0;
    }
    if DETAIL && detail {
        let n = sphere_noise(p, frame.map.z);
        profile = max(profile - frame.map.y * n * (1.0 - profile), 0.0);
    }
    return frame.band.w * profile;
}

// The span [t0, t1] of the ray that crosses any sphere (t1 <= t0: none).
fn sphere_span(origin: vec3f, dir: vec3f, max_t: f32) -> vec2f {
    var t0 = max_t;
    var t1 = 0.0;
    let n = arrayLength(&spheres);
    for (var i = 0u; i < n; i++) {
        let s = spheres[i];
        let oc = origin - s.centre_radius.xyz;
        let b = dot(oc, dir);
        let c = dot(oc, oc) - s.centre_radius.w * s.centre_radius.w;
        let h = b * b - c;
        if h > 0.0 {
            let r = sqrt(h);
            t0 = min(t0, max(-b - r, 0.0));
            t1 = max(t1, min(-b + r, max_t));
        }
    }
    return vec2f(t0, t1);
}

fn sphere_optical_depth(p: vec3f, sun_dir: vec3f) -> f32 {
    if SHADOW_STEPS == 0u {
        return 0.0;
    }
    let parts = f32(SHADOW_STEPS * (SHADOW_STEPS + 1u) / 2u);
    var t = 0.0;
    var tau = 0.0;
    for (var i = 0u; i < SHADOW_STEPS; i++) {
        let dt = SHADOW_RAY_M * f32(i + 1u) / parts;
        tau += sphere_density(p + sun_dir * (t + 0.5 * dt), false) * dt;
        t += dt;
    }
    return tau;
}

// `march_ray` with the spheres in place of P and the cloud map.
fn march_spheres(origin: vec3f, dir: vec3f, dither: f32) -> vec4f {
    let seg = sphere_span(origin, dir, frame.sun_light.w);
    if seg.y <= seg.x {
        return vec4f(0.0);
    }
    let sun_dir = frame.sun_dir.xyz;
    let steps = max(frame.counts.x, 1u);
    let dt = (seg.y - seg.x) / f32(steps);
    let cos_theta = dot(dir, sun_dir);
    let sun = sun_light_at(0.5 * (frame.band.x + frame.band.y), sun_dir);
    let sky_top = sky_ambient(sun_dir) * 0.25;
    let ground = ground_up(sun_dir, SEA) * 0.25;
    var transmittance = 1.0;
    var light = vec3f(0.0);
    var depth_weighted = 0.0;
    for (var i = 0u; i < steps; i++) {
        let t = seg.x + (f32(i) + dither) * dt;
        let p = origin + dir * t;
        let sigma_t = sphere_density(p, true);
        if sigma_t <= 0.0 {
            continue;
        }
        let tau_sun = sphere_optical_depth(p, sun_dir);
        let eta = clamp((p.y - frame.band.x) / (frame.band.y - frame.band.x), 0.0, 1.0);
        let ambient = ambient_light(sky_top, ground, eta);
        let s = (sun * sun_scattering(tau_sun, cos_theta, frame.sun_dir.y) + ambient) * (sigma_t * ALBEDO);
        let step_t = exp(-sigma_t * dt);
        light += integrate_step(s, sigma_t, dt) * transmittance;
        depth_weighted += t * transmittance * (1.0 - step_t);
        transmittance *= step_t;
        if transmittance < MIN_TRANSMITTANCE {
            break;
        }
    }
    let opacity = 1.0 - transmittance;
    var distance = 0.0;
    if opacity > 0.0 {
        distance = depth_weighted / opacity;
    }
    let a = aerial(dir, distance, sun_dir);
    return vec4f(light * a.transmittance + a.inscatter * opacity, opacity);
}

@fragment
fn fs_baseline(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let px = vec2u(pos.xy);
    let c = march_spheres(frame.cam_pos.xyz, camera_ray(pos.xy), sphere_dither(px.x, px.y));
    // No cloud shadows on its ground and no clouds in its sea: its bind
    // group has no P or map.
    let bg = background_radiance(camera_ray(pos.xy), frame.sun_dir.xyz, 1.0, vec4f(0.0, 0.0, 0.0, 1.0));
    return vec4f(display(c.rgb + (1.0 - c.a) * bg), 1.0);
}
