// The physical sky (appended after clouds.wgsl and sky_luts.wgsl when the
// scene's `[render.atmosphere] model` is "physical"): the twins of the
// physical arms of src/render/cpu/sky.rs, reading Hillaire 2020's tables
// that src/render/gpu/sky_luts_pass.rs builds (bindings 7 to 10 of group
// 0 exist only in this variant). The sky view is built for the camera's
// altitude, frame.cam_pos.y.

@group(0) @binding(7) var<uniform> sky_params: SkyParams;
@group(0) @binding(8) var transmittance_lut: texture_2d<f32>;
@group(0) @binding(9) var multi_scattering_lut: texture_2d<f32>;
@group(0) @binding(10) var sky_view_lut: texture_2d<f32>;

fn sun_light_at(altitude_m: f32, sun_dir: vec3f) -> vec3f {
    return sun_radiance_at(transmittance_lut, sky_params, max(altitude_m, 0.0), sun_dir);
}

fn sky_above(dir: vec3f, sun_dir: vec3f) -> vec3f {
    return sky_view_radiance(sky_view_lut, frame.cam_pos.y, sky_params, dir, sun_dir);
}

// The mean of the zenith and four azimuths at 20° and at 55° elevation
// (the CPU's SKY_AMBIENT_ELEVATIONS).
fn sky_ambient(sun_dir: vec3f) -> vec3f {
    var sum = sky_above(vec3f(0.0, 1.0, 0.0), sun_dir);
    let elevations = array(vec2f(0.9396926, 0.3420201), vec2f(0.5735764, 0.819152));
    for (var k = 0u; k < 2u; k++) {
        let e = elevations[k];
        for (var i = 0u; i < 4u; i++) {
            let a = (f32(i) + 0.5 * f32(k)) * 0.5 * PI;
            sum += sky_above(vec3f(e.x * sin(a), e.y, e.x * cos(a)), sun_dir);
        }
    }
    return sum / 9.0;
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
