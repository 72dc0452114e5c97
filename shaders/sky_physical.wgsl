// The physical sky (appended after CLOUDS and SKY_LUTS, shaders.rs, when the
// scene's `[render.atmosphere] model` is "physical"): the twins of the
// physical arms of src/render/cpu/sky.rs, reading Hillaire 2020's tables
// that src/render/gpu/sky_luts_pass.rs builds (bindings 7 to 11 of group
// 0 exist only in this variant). The sky view is built for the camera's
// altitude, frame.cam_pos.y.

@group(0) @binding(7) var<uniform> sky_params: SkyParams;
@group(0) @binding(8) var transmittance_lut: texture_2d<f32>;
@group(0) @binding(9) var multi_scattering_lut: texture_2d<f32>;
@group(0) @binding(10) var sky_view_lut: texture_2d<f32>;
@group(0) @binding(11) var sky_ambient_lut: texture_2d<f32>;

fn sun_light_at(altitude_m: f32, sun_dir: vec3f) -> vec3f {
    return sun_radiance_at(transmittance_lut, sky_params, max(altitude_m, 0.0), sun_dir);
}

fn sky_above(dir: vec3f, sun_dir: vec3f) -> vec3f {
    return sky_view_radiance(sky_view_lut, frame.cam_pos.y, sky_params, dir, sun_dir);
}

// The sky-ambient table's one texel.
fn sky_ambient(sun_dir: vec3f) -> vec3f {
    return textureLoad(sky_ambient_lut, vec2u(0u, 0u), 0).rgb;
}

fn aerial(dir: vec3f, distance_m: f32, sun_dir: vec3f) -> Aerial {
    if !AERIAL_PERSPECTIVE {
        return Aerial(vec3f(0.0), vec3f(1.0));
    }
    let s = aerial_perspective(
        transmittance_lut,
        multi_scattering_lut,
        sky_params,
        frame.cam_pos.y,
        dir,
        distance_m,
        sun_dir,
    );
    return Aerial(s.inscatter, s.transmittance);
}

// The factor on the ground's own light in ground_haze (the CPU's
// `ground_haze_transmittance`).
fn ground_haze_transmittance(dir: vec3f, sun_dir: vec3f) -> vec3f {
    let mu = max(-dir.y, 1e-4);
    return aerial(dir, max(frame.cam_pos.y, 1.0) / mu, sun_dir).transmittance;
}

// The air from the camera down to the ground.
fn ground_haze(surface: vec3f, dir: vec3f, sun_dir: vec3f) -> vec3f {
    let mu = max(-dir.y, 1e-4);
    let a = aerial(dir, max(frame.cam_pos.y, 1.0) / mu, sun_dir);
    return surface * a.transmittance + a.inscatter;
}

fn sun_disk(dir: vec3f, sun_dir: vec3f) -> vec3f {
    return sun_disk_radiance(
        dir,
        sun_dir,
        sun_light_at(frame.cam_pos.y, sun_dir),
        radians(sky_params.sun_angular_radius_deg),
    );
}

// The sun disk's irradiance at the camera (the CPU's `sun_disk_irradiance`).
fn sun_disk_irradiance(sun_dir: vec3f) -> vec3f {
    return sun_light_at(frame.cam_pos.y, sun_dir);
}

