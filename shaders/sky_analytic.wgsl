// The analytic sky (appended after CLOUDS and land.wgsl when the scene's
// `[render.atmosphere] model` is "analytic"): the twins of the analytic
// arms of src/render/cpu/sky.rs. The same functions, reading the physical
// tables, are in sky_physical.wgsl; a pass has one of the two.

fn sun_color(sun_dir: vec3f) -> vec3f {
    let air_mass = 1.0 / max(sun_dir.y, 0.035);
    return exp(-vec3f(0.018, 0.04, 0.09) * air_mass);
}

// frame.sun_light is sun_color(sun_dir) * SUN_INTENSITY, at any altitude.
fn sun_light_at(altitude_m: f32, sun_dir: vec3f) -> vec3f {
    return frame.sun_light.xyz;
}

fn analytic_sky(dir: vec3f, sun_dir: vec3f) -> vec3f {
    let sun = sun_color(sun_dir);
    let day = max(sqrt(clamp(sun_dir.y, 0.0, 1.0)), 0.15);
    let zenith = vec3f(0.16, 0.32, 0.75);
    let horizon = vec3f(0.62, 0.72, 0.86);
    let f = pow(1.0 - dir.y, 4.0);
    let base = mix(zenith, horizon, f) * day * mix(sun, vec3f(1.0), 0.6);
    let glow = sun * (phase_hg(dot(dir, sun_dir), 0.76) * 0.35);
    return base + glow;
}

fn sky_above(dir: vec3f, sun_dir: vec3f) -> vec3f {
    return analytic_sky(dir, sun_dir);
}

fn sky_ambient(sun_dir: vec3f) -> vec3f {
    return analytic_sky(vec3f(0.0, 1.0, 0.0), sun_dir);
}

fn aerial(dir: vec3f, distance_m: f32, sun_dir: vec3f) -> Aerial {
    if !AERIAL_PERSPECTIVE {
        return Aerial(vec3f(0.0), vec3f(1.0));
    }
    let haze = exp(-distance_m / max(frame.sun_dir.w, 1.0));
    let up = normalize_or(vec3f(dir.x, max(dir.y, 0.0), dir.z), vec3f(0.0, 1.0, 0.0));
    return Aerial(analytic_sky(up, sun_dir) * (1.0 - haze), vec3f(haze));
}

// The factor on the ground's own light in ground_haze (the CPU's
// `ground_haze_transmittance`).
fn ground_haze_transmittance(dir: vec3f, sun_dir: vec3f) -> vec3f {
    let mu = max(-dir.y, 1e-4);
    return vec3f(1.0 - exp(-mu * 40.0));
}

// Faded into the horizon's sky within a few degrees of it.
fn ground_haze(surface: vec3f, dir: vec3f, sun_dir: vec3f) -> vec3f {
    let mu = max(-dir.y, 1e-4);
    let horizon = analytic_sky(normalize_or(vec3f(dir.x, 0.0, dir.z), vec3f(1.0, 0.0, 0.0)), sun_dir);
    return mix(surface, horizon, exp(-mu * 40.0));
}

fn sun_disk(dir: vec3f, sun_dir: vec3f) -> vec3f {
    if dot(dir, sun_dir) > SUN_DISK_COS {
        return sun_color(sun_dir) * 60.0;
    }
    return vec3f(0.0);
}

// The flat disk's radiance over its solid angle (the CPU's
// `sun_disk_irradiance`).
fn sun_disk_irradiance(sun_dir: vec3f) -> vec3f {
    return sun_color(sun_dir) * (60.0 * 2.0 * PI * (1.0 - SUN_DISK_COS));
}

