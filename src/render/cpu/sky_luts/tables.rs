//! The three tables and their per-texel functions: transmittance
//! (Bruneton's horizon-aware parametrisation), multiple scattering (Ψ_ms)
//! and the sky view, the [`Lut2`] they live in, and their builders.

use std::f32::consts::PI;

use glam::Vec3;
use rayon::prelude::*;

use super::atmosphere::{
    SkyParams, SkyRay, distance_to_boundary, distance_to_ground, distance_to_top,
    fibonacci_direction, horizon_zenith_angle, medium_at, phase_cornette_shanks, phase_rayleigh,
    radius_along, radius_at_altitude, ray_hits_ground, sky_ray_at, step_bounds, step_integral,
    sun_visible_fraction,
};

/// Transmittance table size (cos zenith, altitude).
pub const TRANSMITTANCE_SIZE: (u32, u32) = (256, 64);
/// Multiple-scattering table size (cos sun zenith, altitude).
pub const MULTI_SCATTERING_SIZE: (u32, u32) = (32, 32);
/// Sky-view table size (azimuth from the sun, elevation).
pub const SKY_VIEW_SIZE: (u32, u32) = (192, 108);
/// Midpoint steps of a transmittance texel's optical depth.
pub const TRANSMITTANCE_STEPS: u32 = 40;
/// Directions (spherical Fibonacci) of a multiple-scattering texel.
pub const MULTI_SCATTERING_DIRECTIONS: u32 = 64;
/// Steps of each multiple-scattering direction's march.
pub const MULTI_SCATTERING_STEPS: u32 = 20;
/// Steps of a sky-view texel's march.
pub const SKY_VIEW_STEPS: u32 = 30;

/// `x` in [0, 1] to the texture coordinate that puts 0 and 1 on the first
/// and last texel centres of a `size`-texel axis (Bruneton 2017).
#[inline]
pub fn unit_to_uv(x: f32, size: u32) -> f32 {
    0.5 / size as f32 + x * (1.0 - 1.0 / size as f32)
}

/// The inverse of [`unit_to_uv`].
#[inline]
pub fn uv_to_unit(u: f32, size: u32) -> f32 {
    (u - 0.5 / size as f32) / (1.0 - 1.0 / size as f32)
}

/// Distance (km) from the ground to the top along the ground's horizon.
#[inline]
fn horizon_length(p: &SkyParams) -> f32 {
    let (bottom, top) = (p.ground_radius_km, p.top_radius_km);
    ((top - bottom) * (top + bottom)).sqrt()
}

/// Texture coordinates of (radius km, cos zenith) in the transmittance
/// table: x_μ from the distance to the top between its least (straight up)
/// and largest (the horizon) at that radius, x_r = ρ/H with ρ the distance
/// to the ground's horizon. Rays below the horizon clamp to it.
pub fn transmittance_r_mu_to_uv(r: f32, mu: f32, p: &SkyParams) -> (f32, f32) {
    let (bottom, top) = (p.ground_radius_km, p.top_radius_km);
    let h = horizon_length(p);
    let r = r.clamp(bottom, top);
    let rho = ((r - bottom) * (r + bottom)).max(0.0).sqrt();
    let d = distance_to_top(r, mu, top);
    let (d_min, d_max) = (top - r, rho + h);
    let x_mu = ((d - d_min) / (d_max - d_min)).clamp(0.0, 1.0);
    let (w, hgt) = TRANSMITTANCE_SIZE;
    (unit_to_uv(x_mu, w), unit_to_uv(rho / h, hgt))
}

/// The inverse of [`transmittance_r_mu_to_uv`]: (radius km, cos zenith).
pub fn transmittance_uv_to_r_mu(u: f32, v: f32, p: &SkyParams) -> (f32, f32) {
    let (bottom, top) = (p.ground_radius_km, p.top_radius_km);
    let h = horizon_length(p);
    let (w, hgt) = TRANSMITTANCE_SIZE;
    let rho = h * uv_to_unit(v, hgt).clamp(0.0, 1.0);
    let r = (rho * rho + bottom * bottom).sqrt();
    let (d_min, d_max) = (top - r, rho + h);
    let d = d_min + uv_to_unit(u, w).clamp(0.0, 1.0) * (d_max - d_min);
    let mu = if d <= 0.0 {
        1.0
    } else {
        (h * h - rho * rho - d * d) / (2.0 * r * d)
    };
    (r, mu.clamp(-1.0, 1.0))
}

/// Optical depth along `t_max` km from (`r`, `mu`) by the midpoint rule.
pub fn optical_depth(r: f32, mu: f32, t_max: f32, steps: u32, p: &SkyParams) -> Vec3 {
    let dt = t_max / steps as f32;
    let mut depth = Vec3::ZERO;
    for i in 0..steps {
        let r_t = radius_along(r, mu, (i as f32 + 0.5) * dt);
        depth += medium_at(r_t - p.ground_radius_km, p).extinction * dt;
    }
    depth
}

/// One transmittance texel: transmittance to the top of the atmosphere.
pub fn transmittance_texel(x: u32, y: u32, p: &SkyParams) -> Vec3 {
    let (w, h) = TRANSMITTANCE_SIZE;
    let (u, v) = ((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
    let (r, mu) = transmittance_uv_to_r_mu(u, v, p);
    let t_max = distance_to_top(r, mu, p.top_radius_km);
    (-optical_depth(r, mu, t_max, TRANSMITTANCE_STEPS, p)).exp()
}

/// Transmittance from radius `r` km along cos zenith `mu` to the top
/// (the table; directions below the horizon read the horizon's).
#[inline]
pub fn transmittance_to_top(lut: &Lut2, r: f32, mu: f32, p: &SkyParams) -> Vec3 {
    let (u, v) = transmittance_r_mu_to_uv(r, mu, p);
    lut.sample(u, v)
}

/// Transmittance toward the sun at cos zenith `mu_s`, planet shadow included.
#[inline]
pub fn transmittance_to_sun(lut: &Lut2, r: f32, mu_s: f32, p: &SkyParams) -> Vec3 {
    transmittance_to_top(lut, r, mu_s, p) * sun_visible_fraction(r, mu_s, p)
}

/// Texture coordinates of (radius km, cos sun zenith) in the
/// multiple-scattering table: both linear, on the texel centres.
#[inline]
pub fn multi_scattering_r_mu_s_to_uv(r: f32, mu_s: f32, p: &SkyParams) -> (f32, f32) {
    let x_h = (r - p.ground_radius_km) / (p.top_radius_km - p.ground_radius_km);
    let (w, h) = MULTI_SCATTERING_SIZE;
    (
        unit_to_uv(0.5 * mu_s + 0.5, w),
        unit_to_uv(x_h.clamp(0.0, 1.0), h),
    )
}

/// Ψ_ms at (radius km, cos sun zenith), per unit sun irradiance.
#[inline]
pub fn multi_scattering_lookup(lut: &Lut2, r: f32, mu_s: f32, p: &SkyParams) -> Vec3 {
    let (u, v) = multi_scattering_r_mu_s_to_uv(r, mu_s, p);
    lut.sample(u, v)
}

/// Second-order light and transfer along one direction of a
/// multiple-scattering texel (Hillaire's L' and L_f, Eqs. 6 and 8, unit
/// irradiance, isotropic phase): (L', f).
pub fn second_order_along(ray: SkyRay, p: &SkyParams, transmittance: &Lut2) -> (Vec3, Vec3) {
    let t_max = distance_to_boundary(ray.r, ray.mu, p);
    let (mut light, mut transfer, mut throughput) = (Vec3::ZERO, Vec3::ZERO, Vec3::ONE);
    for k in 0..MULTI_SCATTERING_STEPS {
        let (t0, t1) = step_bounds(k, MULTI_SCATTERING_STEPS, t_max);
        let (r_t, mu_s_t) = sky_ray_at(ray, 0.5 * (t0 + t1));
        let m = medium_at(r_t - p.ground_radius_km, p);
        let sun = transmittance_to_sun(transmittance, r_t, mu_s_t, p);
        let weight = throughput * m.scattering() * step_integral(m.extinction, t1 - t0);
        light += weight * sun / (4.0 * PI);
        transfer += weight;
        throughput *= (-m.extinction * (t1 - t0)).exp();
    }
    if ray_hits_ground(ray.r, ray.mu, p.ground_radius_km) {
        let (r_g, mu_s_g) = sky_ray_at(ray, t_max);
        let sun = transmittance_to_sun(transmittance, r_g, mu_s_g, p);
        light += throughput * sun * mu_s_g.max(0.0) * p.ground_albedo / PI;
    }
    (light, transfer)
}

/// One multiple-scattering texel: Ψ_ms = L₂ / (1 - f_ms) per unit sun
/// irradiance, both averaged over [`MULTI_SCATTERING_DIRECTIONS`].
pub fn multi_scattering_texel(x: u32, y: u32, p: &SkyParams, transmittance: &Lut2) -> Vec3 {
    let (w, h) = MULTI_SCATTERING_SIZE;
    let mu_s = 2.0 * (x as f32 / (w - 1) as f32) - 1.0;
    let r =
        p.ground_radius_km + (y as f32 / (h - 1) as f32) * (p.top_radius_km - p.ground_radius_km);
    let sun = Vec3::new((1.0 - mu_s * mu_s).max(0.0).sqrt(), mu_s, 0.0);
    let (mut light, mut transfer) = (Vec3::ZERO, Vec3::ZERO);
    for i in 0..MULTI_SCATTERING_DIRECTIONS {
        let dir = fibonacci_direction(i, MULTI_SCATTERING_DIRECTIONS);
        let ray = SkyRay {
            r,
            mu: dir.y,
            mu_s,
            nu: dir.dot(sun),
        };
        let (l, f) = second_order_along(ray, p, transmittance);
        light += l;
        transfer += f;
    }
    let n = MULTI_SCATTERING_DIRECTIONS as f32;
    (light / n) / (Vec3::ONE - transfer / n).max(Vec3::splat(1e-3))
}

/// Light scattered toward the ray's origin over its first `t_max` km, per
/// unit sun irradiance (single scattering with both phases, plus Ψ_ms times
/// the scattering), and the transmittance over them: (inscatter, T).
pub fn integrate_scattering(
    ray: SkyRay,
    t_max: f32,
    steps: u32,
    p: &SkyParams,
    transmittance: &Lut2,
    multi_scattering: &Lut2,
) -> (Vec3, Vec3) {
    let phase_r = phase_rayleigh(ray.nu);
    let phase_m = phase_cornette_shanks(ray.nu, p.mie_g);
    let (mut inscatter, mut throughput) = (Vec3::ZERO, Vec3::ONE);
    for k in 0..steps {
        let (t0, t1) = step_bounds(k, steps, t_max);
        let (r_t, mu_s_t) = sky_ray_at(ray, 0.5 * (t0 + t1));
        let m = medium_at(r_t - p.ground_radius_km, p);
        let sun = transmittance_to_sun(transmittance, r_t, mu_s_t, p);
        let single =
            (m.rayleigh_scattering * phase_r + Vec3::splat(m.mie_scattering * phase_m)) * sun;
        let multiple = multi_scattering_lookup(multi_scattering, r_t, mu_s_t, p) * m.scattering();
        inscatter += throughput * (single + multiple) * step_integral(m.extinction, t1 - t0);
        throughput *= (-m.extinction * (t1 - t0)).exp();
    }
    (inscatter, throughput)
}

/// Half the sky-view rows: rows `SKY_VIEW_HALF..` look above the horizon.
pub const SKY_VIEW_HALF: u32 = SKY_VIEW_SIZE.1 / 2;

/// Direction of a sky-view texel seen from radius `r`: (cos zenith,
/// azimuth from the sun in [0, π], mirrored). Columns: azimuth = π s², s
/// from 0 to 1 over the texel centres. Rows, each half on its own texel
/// centres: the upper half from the horizon (s = 0) to the zenith (s = 1)
/// at elevation-above-horizon fraction s², the lower from the horizon to
/// the nadir the same way (Hillaire's v = 0.5 ± 0.5·sqrt(|l|/(π/2))).
pub fn sky_view_texel_direction(x: u32, y: u32, r: f32, p: &SkyParams) -> (f32, f32) {
    let s_x = x as f32 / (SKY_VIEW_SIZE.0 - 1) as f32;
    let theta_h = horizon_zenith_angle(r, p);
    let last = (SKY_VIEW_HALF - 1) as f32;
    let theta = if y >= SKY_VIEW_HALF {
        let s = (y - SKY_VIEW_HALF) as f32 / last;
        theta_h * (1.0 - s * s)
    } else {
        let s = (SKY_VIEW_HALF - 1 - y) as f32 / last;
        theta_h + (PI - theta_h) * s * s
    };
    (theta.cos(), PI * s_x * s_x)
}

/// The inverse of [`sky_view_texel_direction`]: fractional texel
/// coordinates and the rows of the half the direction falls in (below the
/// horizon when the ray meets the ground, as in the march: rows never mix
/// across the horizon).
pub fn sky_view_texel_coords(mu: f32, azimuth: f32, r: f32, p: &SkyParams) -> (f32, f32, u32, u32) {
    let fx = (azimuth / PI).clamp(0.0, 1.0).sqrt() * (SKY_VIEW_SIZE.0 - 1) as f32;
    let theta_h = horizon_zenith_angle(r, p);
    let theta = mu.clamp(-1.0, 1.0).acos();
    let last = (SKY_VIEW_HALF - 1) as f32;
    if !ray_hits_ground(r, mu, p.ground_radius_km) {
        let s = (1.0 - theta / theta_h).max(0.0).sqrt();
        (
            fx,
            SKY_VIEW_HALF as f32 + last * s,
            SKY_VIEW_HALF,
            SKY_VIEW_SIZE.1 - 1,
        )
    } else {
        let s = ((theta - theta_h) / (PI - theta_h)).clamp(0.0, 1.0).sqrt();
        (fx, last * (1.0 - s), 0, SKY_VIEW_HALF - 1)
    }
}

/// One sky-view texel: the sky's radiance (sun irradiance included, no sun
/// disk, the ground adds nothing) from radius `r_cam` under a sun at cos
/// zenith `mu_sun`, marched to the top (upper rows) or the ground (lower
/// rows; the lower half's horizon row grazes it at the horizon distance).
pub fn sky_view_texel(
    x: u32,
    y: u32,
    r_cam: f32,
    mu_sun: f32,
    p: &SkyParams,
    transmittance: &Lut2,
    multi_scattering: &Lut2,
) -> Vec3 {
    let (mu, azimuth) = sky_view_texel_direction(x, y, r_cam, p);
    let sin_view = (1.0 - mu * mu).max(0.0).sqrt();
    let sin_sun = (1.0 - mu_sun * mu_sun).max(0.0).sqrt();
    let ray = SkyRay {
        r: r_cam,
        mu,
        mu_s: mu_sun,
        nu: mu * mu_sun + sin_view * sin_sun * azimuth.cos(),
    };
    let t_max = if y < SKY_VIEW_HALF {
        distance_to_ground(r_cam, mu, p.ground_radius_km)
    } else {
        distance_to_top(r_cam, mu, p.top_radius_km)
    };
    let (inscatter, _) = integrate_scattering(
        ray,
        t_max,
        SKY_VIEW_STEPS,
        p,
        transmittance,
        multi_scattering,
    );
    inscatter * p.sun_irradiance
}

/// The sky-ambient quadrature: rows of cos zenith, uniform in (0, 1)
/// (uniform in solid angle over the upper hemisphere), and columns of
/// azimuth from the sun, uniform in (0, π) (the sky is mirror-symmetric
/// about the sun's vertical).
pub const SKY_AMBIENT_SAMPLES: (u32, u32) = (16, 32);
/// The sky-ambient table's size: one texel.
pub const SKY_AMBIENT_SIZE: (u32, u32) = (1, 1);

/// The sky-ambient texel: the sky's irradiance of level ground over π
/// (its radiance over the upper hemisphere weighted by the cosine from
/// the zenith, `∫ L μ dω / π`) seen from radius `r`, read from the
/// sky-view table on the [`SKY_AMBIENT_SAMPLES`] grid (cell centres).
/// What lights the ground, and a cloud through its top, from the whole
/// sky, including the bright aureole around the sun at its true (small)
/// solid angle, which a handful of fixed directions would over- or
/// under-weight. The cosine matters under a low sun: a uniform mean
/// weights the red glow around the sun at the horizon as much as the
/// blue zenith, and the path tracer's cloud bases are as blue as the
/// cosine-weighted sky (docs/ground_truth/compare.py).
pub fn sky_ambient_texel(sky_view: &Lut2, r: f32, p: &SkyParams) -> Vec3 {
    let (rows, columns) = SKY_AMBIENT_SAMPLES;
    let mut sum = Vec3::ZERO;
    for i in 0..rows {
        let mu = (i as f32 + 0.5) / rows as f32;
        for j in 0..columns {
            let azimuth = (j as f32 + 0.5) / columns as f32 * PI;
            let (fx, fy, lo, hi) = sky_view_texel_coords(mu, azimuth, r, p);
            sum += sky_view.sample_texels(fx, fy, lo, hi) * mu;
        }
    }
    // Σ μ over the rows' centres is rows / 2.
    sum * 2.0 / (rows * columns) as f32
}

/// A 2D table of RGB texels, row-major, ready to upload as `Rgba32Float`
/// (alpha 1, unused).
#[derive(Debug, Clone, PartialEq)]
pub struct Lut2 {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 4]>,
}

impl Lut2 {
    /// The table of `texel(x, y)`, rows in parallel.
    pub fn from_fn(width: u32, height: u32, texel: impl Fn(u32, u32) -> Vec3 + Sync) -> Self {
        let mut texels = vec![[0.0; 4]; (width * height) as usize];
        texels
            .par_chunks_mut(width as usize)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, out) in row.iter_mut().enumerate() {
                    *out = texel(x as u32, y as u32).extend(1.0).to_array();
                }
            });
        Self {
            width,
            height,
            texels,
        }
    }

    /// The texel at (x, y) (`textureLoad`).
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        let t = self.texels[(y * self.width + x) as usize];
        Vec3::new(t[0], t[1], t[2])
    }

    /// Bilinear between texel centres at fractional texel coordinates
    /// (texel centre (x, y) at (x, y)), clamped to the columns and to the
    /// rows `row_min..=row_max`.
    #[inline]
    pub fn sample_texels(&self, fx: f32, fy: f32, row_min: u32, row_max: u32) -> Vec3 {
        let fx = fx.clamp(0.0, (self.width - 1) as f32);
        let fy = fy.clamp(row_min as f32, row_max as f32);
        let (x0, y0) = (fx.floor() as u32, fy.floor() as u32);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(row_max));
        let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
        let low = self.texel(x0, y0).lerp(self.texel(x1, y0), tx);
        let high = self.texel(x0, y1).lerp(self.texel(x1, y1), tx);
        low.lerp(high, ty)
    }

    /// Bilinear at texture coordinates (u, v) in [0, 1], clamp to edge.
    #[inline]
    pub fn sample(&self, u: f32, v: f32) -> Vec3 {
        let (fx, fy) = (u * self.width as f32 - 0.5, v * self.height as f32 - 0.5);
        self.sample_texels(fx, fy, 0, self.height - 1)
    }
}

/// The transmittance table of `p`.
pub fn build_transmittance(p: &SkyParams) -> Lut2 {
    let (w, h) = TRANSMITTANCE_SIZE;
    Lut2::from_fn(w, h, |x, y| transmittance_texel(x, y, p))
}

/// The multiple-scattering table of `p`.
pub fn build_multi_scattering(p: &SkyParams, transmittance: &Lut2) -> Lut2 {
    let (w, h) = MULTI_SCATTERING_SIZE;
    Lut2::from_fn(w, h, |x, y| multi_scattering_texel(x, y, p, transmittance))
}

/// The sky-view table for a camera at `camera_altitude_m` and the sun at
/// `sun_dir` (only its elevation matters).
pub fn build_sky_view(
    p: &SkyParams,
    transmittance: &Lut2,
    multi_scattering: &Lut2,
    sun_dir: Vec3,
    camera_altitude_m: f32,
) -> Lut2 {
    let (w, h) = SKY_VIEW_SIZE;
    let r = radius_at_altitude(camera_altitude_m, p);
    Lut2::from_fn(w, h, |x, y| {
        sky_view_texel(x, y, r, sun_dir.y, p, transmittance, multi_scattering)
    })
}

/// The sky-ambient table (one texel) of a sky view built for a camera at
/// `camera_altitude_m`.
pub fn build_sky_ambient(p: &SkyParams, sky_view: &Lut2, camera_altitude_m: f32) -> Lut2 {
    let r = radius_at_altitude(camera_altitude_m, p);
    Lut2::from_fn(1, 1, |_, _| sky_ambient_texel(sky_view, r, p))
}

/// The three tables: transmittance and multiple scattering depend on
/// `params` only, the sky view also on the sun and the camera's altitude.
#[derive(Debug, Clone, PartialEq)]
pub struct SkyLuts {
    pub params: SkyParams,
    pub transmittance: Lut2,
    pub multi_scattering: Lut2,
    pub sky_view: Lut2,
    /// The sky's mean radiance over the upper hemisphere (1x1,
    /// [`sky_ambient_texel`]), built with the sky view.
    pub sky_ambient: Lut2,
    /// Camera altitude above the ground, m.
    pub camera_altitude_m: f32,
    /// Unit vector toward the sun, world frame.
    pub sun_dir: Vec3,
}

impl SkyLuts {
    /// All three tables.
    pub fn build(params: SkyParams, sun_dir: Vec3, camera_altitude_m: f32) -> Self {
        let transmittance = build_transmittance(&params);
        let multi_scattering = build_multi_scattering(&params, &transmittance);
        let sky_view = build_sky_view(
            &params,
            &transmittance,
            &multi_scattering,
            sun_dir,
            camera_altitude_m,
        );
        Self {
            sky_ambient: build_sky_ambient(&params, &sky_view, camera_altitude_m),
            params,
            transmittance,
            multi_scattering,
            sky_view,
            camera_altitude_m,
            sun_dir,
        }
    }

    /// Rebuilds the sky view alone, for a new sun or camera altitude.
    pub fn rebuild_sky_view(&mut self, sun_dir: Vec3, camera_altitude_m: f32) {
        let (t, ms) = (&self.transmittance, &self.multi_scattering);
        self.sky_view = build_sky_view(&self.params, t, ms, sun_dir, camera_altitude_m);
        self.sky_ambient = build_sky_ambient(&self.params, &self.sky_view, camera_altitude_m);
        (self.sun_dir, self.camera_altitude_m) = (sun_dir, camera_altitude_m);
    }
}
