// The sea's mirrored clouds and the waves seen along a ray; the twins of
// src/render/cpu/sea.rs.

// The sea's reflection: reflected rays a pixel, the fewest and most
// uniform steps of each and the step length it takes where it can
// (reflection_step_count) and their shadow samples.
const REFLECTION_RAYS: u32 = 12u;
const REFLECTION_STEPS: u32 = 4u;
const REFLECTION_STEPS_MAX: u32 = 16u;
const REFLECTION_STEP_M: f32 = 300.0;
const REFLECTION_SHADOW_STEPS: u32 = 2u;

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
