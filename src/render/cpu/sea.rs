//! The sea's mirror image of the clouds: the reflected rays a
//! wind-roughened sea sends up (`reflected_elevation`), each one's coarse
//! march through the band (`reflected_clouds`), their mean per sea pixel
//! (`sea_reflection`) and what it changes in the pixel
//! (`sea_reflection_change`, which the GPU's cloud pass adds to its
//! layer). Twins of the WGSL functions of the same names in
//! `shaders/sea.wgsl`.

use glam::Vec3;

use super::density::{band_segment, density_at};
use super::frame::diffused_light;
use super::frame::{Frame, MIN_TRANSMITTANCE};
use super::lighting::ALBEDO;
use super::lighting::{ambient_light, cloud_shadow};
use super::lighting::{integrate_step, light_gains, sun_scattering};
use super::sky::{
    ground_haze_transmittance, ground_up, mirrored_sky, sea_fresnel, sea_mirror, sky_ambient,
    sun_light_at,
};
use super::waves::{cross_slope, flat_sea, reflected_elevation, reflected_ray, sea_waves};
use crate::render::sampling::GOLDEN;

/// Reflected rays a sea pixel averages (`REFLECTION_RAYS` in WGSL), one
/// per stratum of the waves' slopes ([`reflected_elevation`]). 12, so
/// that BOMEX's CPU picture (four offsets a pixel) shows the mirrored
/// clouds without grain, which 6 leave; the GPU's TSAA averages either
/// over its frames.
pub const REFLECTION_RAYS: u32 = 12;
/// The fewest uniform steps of the march of each reflected ray
/// (`REFLECTION_STEPS` in WGSL); a long one takes more
/// ([`reflection_step_count`]).
pub const REFLECTION_STEPS: u32 = 4;
/// The most steps a reflected ray takes (`REFLECTION_STEPS_MAX`).
pub const REFLECTION_STEPS_MAX: u32 = 16;
/// The step a reflected ray's march takes where it can, m
/// (`REFLECTION_STEP_M`): about a small cumulus's width.
pub const REFLECTION_STEP_M: f32 = 300.0;

/// The steps of a reflected ray's march across `length` m of the band:
/// one per [`REFLECTION_STEP_M`], [`REFLECTION_STEPS`] to
/// [`REFLECTION_STEPS_MAX`]. A step much wider than a cloud lands in
/// it or misses it, and counts it as a slab of the step's depth when it
/// lands: the reflection's mean falls short by the cloud's width over the
/// step. A fixed 4 steps, 1.3 km each across a ray rising at 10° through
/// BOMEX's 900 m band, show the mirrored clouds far dimmer than 16 steps
/// do, as sparse bright grain; over rays rising at 10° through a 1 km
/// band their mean opacity is 0.82 of a fine march's
/// (`a_reflected_rays_march_does_not_step_over_clouds`).
#[inline]
pub fn reflection_step_count(length: f32) -> u32 {
    ((length / REFLECTION_STEP_M).ceil().max(0.0) as u32)
        .clamp(REFLECTION_STEPS, REFLECTION_STEPS_MAX)
}

/// Samples of each of its steps' shadow rays (`REFLECTION_SHADOW_STEPS`).
pub const REFLECTION_SHADOW_STEPS: u32 = 2;

/// The clouds mirrored by the sea where a ray that meets no terrain
/// reaches it (y = 0; the flat mean surface, as the sky's reflection):
/// (their light, premultiplied; the transmittance of the reflected rays
/// through the band). The waves scatter the mirror image up and down
/// ([`reflected_elevation`]), so the pixel averages [`REFLECTION_RAYS`]
/// reflected rays, one in each stratum of the slopes' distribution along
/// the line of sight (the strata shifted by the pixel's `dither`, so
/// neighbouring pixels and TSAA frames fill in between them), each
/// turned sideways by a slope across it ([`reflected_ray`]), each
/// [`reflected_clouds`]. `(0, 1)`
/// over land, with the camera under the ground, or when the sea lies
/// beyond `max_distance_m`.
pub fn sea_reflection(
    origin: Vec3,
    dir: Vec3,
    dither: f32,
    sun_dir: Vec3,
    spread: f32,
    fr: &Frame,
) -> (Vec3, f32) {
    let q = &fr.quality;
    let Some(wind) = q.sea_wind_mps else {
        return (Vec3::ZERO, 1.0);
    };
    if dir.y >= 0.0 || origin.y <= 0.0 {
        return (Vec3::ZERO, 1.0);
    }
    let t_sea = origin.y / -dir.y;
    if t_sea > q.max_distance_m {
        return (Vec3::ZERO, 1.0);
    }
    let p = Vec3::new(origin.x + dir.x * t_sea, 0.0, origin.z + dir.z * t_sea);
    // The mirror ray of the waves the pixel resolves; the slopes it does
    // not spread the reflected rays about it.
    let waves = sea_waves_at(origin, dir, spread, fr).unwrap_or(flat_sea(wind));
    let r0 = sea_mirror(dir, waves);
    let across = Vec3::new(r0.x, 0.0, r0.z).normalize_or(Vec3::Z);
    let mirror = r0.y.clamp(-1.0, 1.0).asin();
    // The steps' placement within a ray, apart from the strata's shift.
    let step_dither = (dither + GOLDEN).fract();
    let light_in = ReflectionLight::new(fr, sun_dir, wind);
    let mut light = Vec3::ZERO;
    let mut transmittance = 0.0;
    for k in 0..REFLECTION_RAYS {
        let u = (k as f32 + dither) / REFLECTION_RAYS as f32;
        let e = reflected_elevation(mirror, waves.z, u);
        // The sideways slopes in golden-ratio steps, apart from the
        // elevation's strata.
        let slope = cross_slope(waves.z, ((k as f32 + 0.5) * GOLDEN + step_dither).fract());
        let r = reflected_ray(across, mirror, e, slope);
        let (l, t) = reflected_clouds(p, r, t_sea, step_dither, sun_dir, &light_in, spread, fr);
        light += l;
        transmittance += t;
    }
    let n = REFLECTION_RAYS as f32;
    (light / n, transmittance / n)
}

/// What lights the clouds a sea pixel mirrors, the same for each of its
/// reflected rays (computed once in [`sea_reflection`]; arguments of
/// `reflected_clouds` in WGSL): the sun at the band's middle, the
/// sky's and the ground's ambient, and the waves' sideways blur (radians).
#[derive(Debug, Clone, Copy)]
pub struct ReflectionLight {
    /// The sun's light at the band's middle.
    pub sun: Vec3,
    /// The upper sky's ambient ([`ambient_light`]'s `sky_top`).
    pub sky_top: Vec3,
    /// The sea's light from below ([`ambient_light`]'s `ground`).
    pub ground: Vec3,
    /// Twice the Cox-Munk slopes' deviation, radians: the level of
    /// detail the mirrored clouds are read at, per metre of distance
    /// (against aliasing; [`reflected_clouds`]).
    pub blur: f32,
}

impl ReflectionLight {
    /// The light of `fr` under a sun along `sun_dir`, over a sea in a
    /// wind of `wind_mps`.
    pub fn new(fr: &Frame, sun_dir: Vec3, wind_mps: f32) -> Self {
        let sky = &fr.sky_light();
        let d = &fr.density;
        Self {
            sun: sun_light_at(sky, 0.5 * (d.band_bottom_m + d.band_top_m), sun_dir),
            sky_top: sky_ambient(sky, sun_dir) * 0.25,
            ground: ground_up(sky, sun_dir, true) * 0.25,
            blur: 2.0 * (0.003 + 0.00512 * wind_mps.max(0.0)).sqrt(),
        }
    }
}

/// What the clouds the sea mirrors ([`sea_reflection`]) change in the
/// radiance of a sea pixel along `dir`: [`super::sky::sea_radiance`] with them less
/// without them, `(L - S (1 - T)) · F · T_air` for the clouds' light `L`
/// and transmittance `T`, the mirrored sky `S` ([`mirrored_sky`]), the
/// Fresnel factor `F` ([`sea_fresnel`]; both of the flat, rough sea,
/// [`flat_sea`], not of the waves the pixel resolves) and the air's
/// transmittance `T_air` ([`ground_haze_transmittance`]); zero where
/// nothing is mirrored. On the GPU this term is accumulated by TSAA over
/// jittered rays and moving waves while the composite draws the sea at
/// the pixel's centre now: with the resolved waves' `S F` in both, their
/// history and the present would not cancel, and the sky's ripples would
/// show under the mirrored clouds. With the flat sea's, what is left of
/// the waves under a mirrored cloud is their ripple of the sky about its
/// mean (and the cloud's image unrippled by the Fresnel factor), on the
/// CPU and the GPU alike. The sky `S` the clouds hide is the flat sea's mirror's, though the reflected
/// rays that meet them rise higher: near the horizon, where the mirrored
/// sky is brightest, the change is somewhat too dark.
/// The GPU adds it to the cloud layer in the cloud pass (under the
/// clouds' transmittance), so TSAA accumulates the reflection's grain
/// with the clouds', and the composite draws the sea without it.
pub fn sea_reflection_change(
    origin: Vec3,
    dir: Vec3,
    dither: f32,
    sun_dir: Vec3,
    spread: f32,
    fr: &Frame,
) -> Vec3 {
    let (light, transmittance) = sea_reflection(origin, dir, dither, sun_dir, spread, fr);
    if transmittance >= 1.0 && light == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let Some(wind) = fr.quality.sea_wind_mps else {
        return Vec3::ZERO;
    };
    let waves = flat_sea(wind);
    let sky = &fr.sky_light();
    (light - mirrored_sky(sky, dir, waves, sun_dir) * (1.0 - transmittance))
        * sea_fresnel(dir, waves)
        * ground_haze_transmittance(sky, dir, sun_dir)
}

/// The clouds along one ray `r` the sea reflects from `p`, `t_sea` from
/// the eye: (their light, premultiplied; the ray's transmittance through
/// the band). The ray is marched across the band in
/// [`reflection_step_count`] uniform steps (about 300 m, 4 to 16), each sample placed in its step by
/// `dither` (fine grain, not bands of rows that sample the same depths),
/// each lit sample by the sun through [`cloud_shadow`] with
/// [`REFLECTION_SHADOW_STEPS`] samples (the octaves as in the clouds' own
/// light) and by the sky's and the ground's ambient (`light_in`): a coarser
/// twin of `renderer::march_ray`, for a reflection the Fresnel factor dims to a
/// few percent looking down. The clouds are read at the level of detail
/// of twice the Cox-Munk slopes' deviation times the distance
/// (`light_in.blur`), so that a few samples across the band do not
/// alias. That blurs sideways too, beside the waves' own sideways turn
/// ([`reflected_ray`]): a choice against aliasing.
#[allow(clippy::too_many_arguments)]
pub fn reflected_clouds(
    p: Vec3,
    r: Vec3,
    t_sea: f32,
    dither: f32,
    sun_dir: Vec3,
    light_in: &ReflectionLight,
    spread: f32,
    fr: &Frame,
) -> (Vec3, f32) {
    let q = &fr.quality;
    let d = &fr.density;
    let Some((t0, t1)) = band_segment(p, r, d.band_bottom_m, d.band_top_m, q.max_distance_m) else {
        return (Vec3::ZERO, 1.0);
    };
    let ReflectionLight {
        sun,
        sky_top,
        ground,
        blur,
    } = *light_in;
    let cos = r.dot(sun_dir);
    let gains = light_gains(fr.light.is_some());
    let steps = reflection_step_count(t1 - t0);
    let h = (t1 - t0) / steps as f32;
    let mut transmittance = 1.0_f32;
    let mut light = Vec3::ZERO;
    for i in 0..steps {
        let t = t0 + (i as f32 + dither) * h;
        let x = p + r * t;
        let sigma_t = density_at(x, &fr.fields, d, true, (spread + blur) * (t_sea + t));
        if sigma_t <= 0.0 {
            continue;
        }
        let shadow = cloud_shadow(x, sun_dir, REFLECTION_SHADOW_STEPS, &fr.fields, d);
        let tau_sun = -shadow.max(1e-30).ln();
        let eta = ((x.y - d.band_bottom_m) / (d.band_top_m - d.band_bottom_m)).clamp(0.0, 1.0);
        let scatter = sun
            * (sun_scattering(tau_sun, cos, sun_dir.y, sigma_t, q.octaves, &gains)
                + diffused_light(x, -r, q.octaves, fr))
            + ambient_light(sky_top, ground, eta, &gains);
        light += integrate_step(scatter * (sigma_t * ALBEDO), sigma_t, h) * transmittance;
        transmittance *= (-sigma_t * h).exp();
        if transmittance < MIN_TRANSMITTANCE {
            break;
        }
    }
    (light, transmittance)
}

/// The waves ([`sea_waves`]) where a ray of cone angle `spread` from
/// `origin` along `dir` meets the sea (y = 0) in `fr`; [`flat_sea`] where
/// it looks up, the camera is under the sea or the sea lies beyond
/// `max_distance_m`; `None` over land.
pub fn sea_waves_at(origin: Vec3, dir: Vec3, spread: f32, fr: &Frame) -> Option<Vec3> {
    let q = &fr.quality;
    let wind = q.sea_wind_mps?;
    if dir.y >= 0.0 || origin.y <= 0.0 {
        return Some(flat_sea(wind));
    }
    let t = origin.y / -dir.y;
    if t > q.max_distance_m {
        return Some(flat_sea(wind));
    }
    Some(sea_waves(
        origin.x + dir.x * t,
        origin.z + dir.z * t,
        dir,
        spread,
        t,
        wind,
        q.sea_wind_toward_deg,
        q.sea_time_s,
    ))
}
