// What the physical sky reads of its tables at a view ray: the twins of
// src/render/cpu/sky_luts/lookups.rs.

fn sky_view_radiance(
    sky_view: texture_2d<f32>,
    camera_altitude_m: f32,
    p: SkyParams,
    dir: vec3f,
    sun_dir: vec3f,
) -> vec3f {
    let r = radius_at_altitude(camera_altitude_m, p);
    let c = sky_view_texel_coords(dir.y, azimuth_from_sun(dir, sun_dir), r, p);
    return sample_texels(sky_view, c.fx, c.fy, c.row_min, c.row_max);
}

fn aerial_perspective(
    transmittance: texture_2d<f32>,
    multi_scattering: texture_2d<f32>,
    p: SkyParams,
    altitude_m: f32,
    dir: vec3f,
    distance_m: f32,
    sun_dir: vec3f,
) -> Scattering {
    let ray = sky_ray(altitude_m, dir, sun_dir, p);
    let t_max = clamp(distance_m * 1e-3, 0.0, distance_to_boundary(ray.r, ray.mu, p));
    let s = integrate_scattering(
        ray,
        t_max,
        AERIAL_PERSPECTIVE_STEPS,
        p,
        transmittance,
        multi_scattering,
    );
    return Scattering(s.inscatter * p.sun_irradiance, s.transmittance);
}

fn sun_radiance_at(transmittance: texture_2d<f32>, p: SkyParams, altitude_m: f32, sun_dir: vec3f) -> vec3f {
    let r = radius_at_altitude(altitude_m, p);
    return transmittance_to_sun(transmittance, r, sun_dir.y, p) * p.sun_irradiance;
}

fn sun_disk_radiance(dir: vec3f, sun_dir: vec3f, irradiance: vec3f, angular_radius_rad: f32) -> vec3f {
    let d = dir - sun_dir;
    let one_minus_cos = 0.5 * dot(d, d);
    let half = sin(0.5 * angular_radius_rad);
    let cap = 2.0 * half * half;
    if one_minus_cos >= cap {
        return vec3f(0.0);
    }
    let mu = sqrt(1.0 - one_minus_cos / cap);
    let solid_angle = 2.0 * PI * cap;
    return irradiance * (1.0 - LIMB_DARKENING_U * (1.0 - mu))
        / (solid_angle * (1.0 - LIMB_DARKENING_U / 3.0));
}
