// The sky tables of Hillaire 2020 (transmittance, multiple scattering, sky
// view, sky ambient) and their texel reads, the twins of
// src/render/cpu/sky_luts/tables.rs (a `&Lut2` there is a
// `texture_2d<f32>` read with textureLoad here).

// ---- Lut2 (texel centres, clamp to edge) ----

fn texel(lut: texture_2d<f32>, x: u32, y: u32) -> vec3f {
    return textureLoad(lut, vec2u(x, y), 0).rgb;
}

// glam's Vec3::lerp: a + (b - a) t.
fn lerp(a: vec3f, b: vec3f, t: f32) -> vec3f {
    return a + (b - a) * t;
}

fn sample_texels(lut: texture_2d<f32>, fx: f32, fy: f32, row_min: u32, row_max: u32) -> vec3f {
    let width = textureDimensions(lut).x;
    let cx = clamp(fx, 0.0, f32(width - 1u));
    let cy = clamp(fy, f32(row_min), f32(row_max));
    let x0 = u32(floor(cx));
    let y0 = u32(floor(cy));
    let x1 = min(x0 + 1u, width - 1u);
    let y1 = min(y0 + 1u, row_max);
    let tx = cx - f32(x0);
    let ty = cy - f32(y0);
    let low = lerp(texel(lut, x0, y0), texel(lut, x1, y0), tx);
    let high = lerp(texel(lut, x0, y1), texel(lut, x1, y1), tx);
    return lerp(low, high, ty);
}

fn sample(lut: texture_2d<f32>, u: f32, v: f32) -> vec3f {
    let size = textureDimensions(lut);
    let fx = u * f32(size.x) - 0.5;
    let fy = v * f32(size.y) - 0.5;
    return sample_texels(lut, fx, fy, 0u, size.y - 1u);
}

// ---- Transmittance ----

fn unit_to_uv(x: f32, size: u32) -> f32 {
    return 0.5 / f32(size) + x * (1.0 - 1.0 / f32(size));
}

fn uv_to_unit(u: f32, size: u32) -> f32 {
    return (u - 0.5 / f32(size)) / (1.0 - 1.0 / f32(size));
}

fn horizon_length(p: SkyParams) -> f32 {
    let bottom = p.ground_radius_km;
    let top = p.top_radius_km;
    return sqrt((top - bottom) * (top + bottom));
}

fn transmittance_r_mu_to_uv(r_in: f32, mu: f32, p: SkyParams) -> vec2f {
    let bottom = p.ground_radius_km;
    let top = p.top_radius_km;
    let h = horizon_length(p);
    let r = clamp(r_in, bottom, top);
    let rho = sqrt(max((r - bottom) * (r + bottom), 0.0));
    let d = distance_to_top(r, mu, top);
    let d_min = top - r;
    let d_max = rho + h;
    let x_mu = clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
    return vec2f(unit_to_uv(x_mu, TRANSMITTANCE_WIDTH), unit_to_uv(rho / h, TRANSMITTANCE_HEIGHT));
}

// (radius km, cos zenith).
fn transmittance_uv_to_r_mu(u: f32, v: f32, p: SkyParams) -> vec2f {
    let bottom = p.ground_radius_km;
    let top = p.top_radius_km;
    let h = horizon_length(p);
    let rho = h * clamp(uv_to_unit(v, TRANSMITTANCE_HEIGHT), 0.0, 1.0);
    let r = sqrt(rho * rho + bottom * bottom);
    let d_min = top - r;
    let d_max = rho + h;
    let d = d_min + clamp(uv_to_unit(u, TRANSMITTANCE_WIDTH), 0.0, 1.0) * (d_max - d_min);
    var mu = 1.0;
    if d > 0.0 {
        mu = (h * h - rho * rho - d * d) / (2.0 * r * d);
    }
    return vec2f(r, clamp(mu, -1.0, 1.0));
}

fn optical_depth(r: f32, mu: f32, t_max: f32, steps: u32, p: SkyParams) -> vec3f {
    let dt = t_max / f32(steps);
    var depth = vec3f(0.0);
    for (var i = 0u; i < steps; i++) {
        let r_t = radius_along(r, mu, (f32(i) + 0.5) * dt);
        depth += medium_at(r_t - p.ground_radius_km, p).extinction * dt;
    }
    return depth;
}

fn transmittance_texel(x: u32, y: u32, p: SkyParams) -> vec3f {
    let u = (f32(x) + 0.5) / f32(TRANSMITTANCE_WIDTH);
    let v = (f32(y) + 0.5) / f32(TRANSMITTANCE_HEIGHT);
    let r_mu = transmittance_uv_to_r_mu(u, v, p);
    let t_max = distance_to_top(r_mu.x, r_mu.y, p.top_radius_km);
    return exp(-optical_depth(r_mu.x, r_mu.y, t_max, TRANSMITTANCE_STEPS, p));
}

fn transmittance_to_top(lut: texture_2d<f32>, r: f32, mu: f32, p: SkyParams) -> vec3f {
    let uv = transmittance_r_mu_to_uv(r, mu, p);
    return sample(lut, uv.x, uv.y);
}

fn transmittance_to_sun(lut: texture_2d<f32>, r: f32, mu_s: f32, p: SkyParams) -> vec3f {
    return transmittance_to_top(lut, r, mu_s, p) * sun_visible_fraction(r, mu_s, p);
}

// ---- Multiple scattering ----

fn multi_scattering_r_mu_s_to_uv(r: f32, mu_s: f32, p: SkyParams) -> vec2f {
    let x_h = (r - p.ground_radius_km) / (p.top_radius_km - p.ground_radius_km);
    return vec2f(
        unit_to_uv(0.5 * mu_s + 0.5, MULTI_SCATTERING_WIDTH),
        unit_to_uv(clamp(x_h, 0.0, 1.0), MULTI_SCATTERING_HEIGHT),
    );
}

fn multi_scattering_lookup(lut: texture_2d<f32>, r: f32, mu_s: f32, p: SkyParams) -> vec3f {
    let uv = multi_scattering_r_mu_s_to_uv(r, mu_s, p);
    return sample(lut, uv.x, uv.y);
}

fn second_order_along(ray: SkyRay, p: SkyParams, transmittance: texture_2d<f32>) -> SecondOrder {
    let t_max = distance_to_boundary(ray.r, ray.mu, p);
    var light = vec3f(0.0);
    var transfer = vec3f(0.0);
    var throughput = vec3f(1.0);
    for (var k = 0u; k < MULTI_SCATTERING_STEPS; k++) {
        let t = step_bounds(k, MULTI_SCATTERING_STEPS, t_max);
        let at = sky_ray_at(ray, 0.5 * (t.x + t.y));
        let m = medium_at(at.x - p.ground_radius_km, p);
        let sun = transmittance_to_sun(transmittance, at.x, at.y, p);
        let weight = throughput * scattering(m) * step_integral(m.extinction, t.y - t.x);
        light += weight * sun / (4.0 * PI);
        transfer += weight;
        throughput *= exp(-m.extinction * (t.y - t.x));
    }
    if ray_hits_ground(ray.r, ray.mu, p.ground_radius_km) {
        let g = sky_ray_at(ray, t_max);
        let sun = transmittance_to_sun(transmittance, g.x, g.y, p);
        light += throughput * sun * max(g.y, 0.0) * p.ground_albedo / PI;
    }
    return SecondOrder(light, transfer);
}

fn multi_scattering_texel(x: u32, y: u32, p: SkyParams, transmittance: texture_2d<f32>) -> vec3f {
    let mu_s = 2.0 * (f32(x) / f32(MULTI_SCATTERING_WIDTH - 1u)) - 1.0;
    let r = p.ground_radius_km
        + (f32(y) / f32(MULTI_SCATTERING_HEIGHT - 1u)) * (p.top_radius_km - p.ground_radius_km);
    let sun = vec3f(sqrt(max(1.0 - mu_s * mu_s, 0.0)), mu_s, 0.0);
    var light = vec3f(0.0);
    var transfer = vec3f(0.0);
    for (var i = 0u; i < MULTI_SCATTERING_DIRECTIONS; i++) {
        let dir = fibonacci_direction(i, MULTI_SCATTERING_DIRECTIONS);
        let ray = SkyRay(r, dir.y, mu_s, dot(dir, sun));
        let s = second_order_along(ray, p, transmittance);
        light += s.light;
        transfer += s.transfer;
    }
    let n = f32(MULTI_SCATTERING_DIRECTIONS);
    return (light / n) / max(vec3f(1.0) - transfer / n, vec3f(1e-3));
}

// ---- Sky view ----

fn integrate_scattering(
    ray: SkyRay,
    t_max: f32,
    steps: u32,
    p: SkyParams,
    transmittance: texture_2d<f32>,
    multi_scattering: texture_2d<f32>,
) -> Scattering {
    let phase_r = phase_rayleigh(ray.nu);
    let phase_m = phase_cornette_shanks(ray.nu, p.mie_g);
    var inscatter = vec3f(0.0);
    var throughput = vec3f(1.0);
    for (var k = 0u; k < steps; k++) {
        let t = step_bounds(k, steps, t_max);
        let at = sky_ray_at(ray, 0.5 * (t.x + t.y));
        let m = medium_at(at.x - p.ground_radius_km, p);
        let sun = transmittance_to_sun(transmittance, at.x, at.y, p);
        let single = (m.rayleigh_scattering * phase_r + vec3f(m.mie_scattering * phase_m)) * sun;
        let multiple = multi_scattering_lookup(multi_scattering, at.x, at.y, p) * scattering(m);
        inscatter += throughput * (single + multiple) * step_integral(m.extinction, t.y - t.x);
        throughput *= exp(-m.extinction * (t.y - t.x));
    }
    return Scattering(inscatter, throughput);
}

// (cos zenith, azimuth from the sun).
fn sky_view_texel_direction(x: u32, y: u32, r: f32, p: SkyParams) -> vec2f {
    let s_x = f32(x) / f32(SKY_VIEW_WIDTH - 1u);
    let theta_h = horizon_zenith_angle(r, p);
    let last = f32(SKY_VIEW_HALF - 1u);
    var theta: f32;
    if y >= SKY_VIEW_HALF {
        let s = f32(y - SKY_VIEW_HALF) / last;
        theta = theta_h * (1.0 - s * s);
    } else {
        let s = f32(SKY_VIEW_HALF - 1u - y) / last;
        theta = theta_h + (PI - theta_h) * s * s;
    }
    return vec2f(cos(theta), PI * s_x * s_x);
}

fn sky_view_texel_coords(mu: f32, azimuth: f32, r: f32, p: SkyParams) -> SkyViewCoords {
    let fx = sqrt(clamp(azimuth / PI, 0.0, 1.0)) * f32(SKY_VIEW_WIDTH - 1u);
    let theta_h = horizon_zenith_angle(r, p);
    let theta = acos(clamp(mu, -1.0, 1.0));
    let last = f32(SKY_VIEW_HALF - 1u);
    if !ray_hits_ground(r, mu, p.ground_radius_km) {
        let s = sqrt(max(1.0 - theta / theta_h, 0.0));
        return SkyViewCoords(fx, f32(SKY_VIEW_HALF) + last * s, SKY_VIEW_HALF, SKY_VIEW_HEIGHT - 1u);
    }
    let s = sqrt(clamp((theta - theta_h) / (PI - theta_h), 0.0, 1.0));
    return SkyViewCoords(fx, last * (1.0 - s), 0u, SKY_VIEW_HALF - 1u);
}

fn sky_view_texel(
    x: u32,
    y: u32,
    r_cam: f32,
    mu_sun: f32,
    p: SkyParams,
    transmittance: texture_2d<f32>,
    multi_scattering: texture_2d<f32>,
) -> vec3f {
    let dir = sky_view_texel_direction(x, y, r_cam, p);
    let mu = dir.x;
    let sin_view = sqrt(max(1.0 - mu * mu, 0.0));
    let sin_sun = sqrt(max(1.0 - mu_sun * mu_sun, 0.0));
    let ray = SkyRay(r_cam, mu, mu_sun, mu * mu_sun + sin_view * sin_sun * cos(dir.y));
    var t_max: f32;
    if y < SKY_VIEW_HALF {
        t_max = distance_to_ground(r_cam, mu, p.ground_radius_km);
    } else {
        t_max = distance_to_top(r_cam, mu, p.top_radius_km);
    }
    let s = integrate_scattering(
        ray,
        t_max,
        SKY_VIEW_STEPS,
        p,
        transmittance,
        multi_scattering,
    );
    return s.inscatter * p.sun_irradiance;
}

// ---- Sky ambient ----

fn sky_ambient_texel(sky_view: texture_2d<f32>, r: f32, p: SkyParams) -> vec3f {
    var sum = vec3f(0.0);
    for (var i = 0u; i < SKY_AMBIENT_ROWS; i++) {
        let mu = (f32(i) + 0.5) / f32(SKY_AMBIENT_ROWS);
        for (var j = 0u; j < SKY_AMBIENT_COLUMNS; j++) {
            let azimuth = (f32(j) + 0.5) / f32(SKY_AMBIENT_COLUMNS) * PI;
            let c = sky_view_texel_coords(mu, azimuth, r, p);
            sum += sample_texels(sky_view, c.fx, c.fy, c.row_min, c.row_max) * mu;
        }
    }
    // Cosine-weighted (the CPU's `sky_ambient_texel`): Σ μ over the rows is ROWS / 2.
    return sum * 2.0 / f32(SKY_AMBIENT_ROWS * SKY_AMBIENT_COLUMNS);
}
