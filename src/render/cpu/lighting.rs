//! Light: phase functions, sun transmittance by a secondary march,
//! multiple-scattering octaves and the energy-conserving step
//! (docs/renderer.md, "Light").
//!
//! Over 600 lines: the shadow march (`ShadowSteps` to
//! `near_sun_optical_depth`) is a module of its own in waiting; it stays
//! here because `shaders/lighting.wgsl` mirrors this file function for
//! function (`tests/shader_twins.rs`), and splitting both is a change of
//! its own.

use std::f32::consts::PI;

use glam::Vec3;

use super::density::{
    DensityParams, FINE_SHARP_M, Fields, band_segment, density_at, height_fraction, smoothstep,
};
use crate::render::sampling::GOLDEN;

/// Henyey-Greenstein phase function, 1/sr; integrates to 1 over the sphere.
#[inline]
pub fn phase_hg(cos_theta: f32, g: f32) -> f32 {
    let g2 = g * g;
    (1.0 - g2) / (4.0 * PI * (1.0 + g2 - 2.0 * g * cos_theta).max(1e-6).powf(1.5))
}

/// Dual-lobe HG: a strong forward lobe (silver lining) and a weak back lobe.
#[inline]
pub fn phase_dual(cos_theta: f32, eccentricity: f32) -> f32 {
    0.75 * phase_hg(cos_theta, 0.8 * eccentricity) + 0.25 * phase_hg(cos_theta, -0.3 * eccentricity)
}

/// The longest shadow ray toward the sun, m (`SHADOW_RAY_M` in WGSL): a
/// sun 8° up crosses a 1.5 km band in 11 km, and the clouds that far
/// toward it shade a low sun's light (capped at 2 km, the low sun's
/// single scattering is 3 times the path tracer's; docs/ground_truth).
pub const SHADOW_RAY_M: f32 = 12_000.0;

/// The shadow ray's length over which it takes `render.shadow_steps`
/// steps (`SHADOW_STEP_SPAN_M` in WGSL); a longer one, toward a lower sun,
/// takes proportionally more ([`shadow_step_count`]).
pub const SHADOW_STEP_SPAN_M: f32 = 2_000.0;

/// The most steps a long shadow ray takes, as a multiple of
/// `render.shadow_steps` (`SHADOW_STEP_FACTOR_MAX` in WGSL): however low
/// the sun, a shadow ray costs at most this many times a high sun's.
pub const SHADOW_STEP_FACTOR_MAX: f32 = 3.0;

/// The length of the shadow ray from `p` toward the sun: to the band's
/// top, at most [`SHADOW_RAY_M`] (along a sun at or below the horizon,
/// that).
#[inline]
pub fn shadow_ray_length(p: Vec3, sun_dir: Vec3, d: &DensityParams) -> f32 {
    let to_top = if sun_dir.y > 1e-3 {
        (d.band_top_m - p.y).max(0.0) / sun_dir.y
    } else {
        SHADOW_RAY_M
    };
    to_top.min(SHADOW_RAY_M)
}

/// The number of steps of a shadow ray of `length` m: `steps` over
/// [`SHADOW_STEP_SPAN_M`] or less, in proportion beyond it, times
/// `forward` ([`forward_step_factor`]), at most
/// [`SHADOW_STEP_FACTOR_MAX`] times `steps` in all (rounded up). A fixed
/// count over a long ray takes long far steps, which step over the
/// clouds between a low sun and the sample: 20 steps over the low sun's
/// 11 km leak nearly as much as a 2 km cap.
#[inline]
pub fn shadow_step_count(steps: u32, length: f32, forward: f32) -> u32 {
    let along = (length / SHADOW_STEP_SPAN_M).clamp(1.0, SHADOW_STEP_FACTOR_MAX);
    (steps as f32 * (along * forward).min(SHADOW_STEP_FACTOR_MAX)).ceil() as u32
}

/// The most extra shadow steps a view toward the sun takes, as a
/// fraction of its count ([`forward_step_factor`]; `FORWARD_STEP_BOOST`
/// in WGSL): 0.6, 20 steps become 32.
pub const FORWARD_STEP_BOOST: f32 = 0.6;
/// The cosine between a ray and the sun from which its shadow rays take
/// more steps (`FORWARD_COS_MIN`), and at which they take all of
/// [`FORWARD_STEP_BOOST`] (`FORWARD_COS_MAX`), smoothly between.
pub const FORWARD_COS_MIN: f32 = 0.5;
pub const FORWARD_COS_MAX: f32 = 0.9;

/// The factor on the shadow steps of a ray at `cos_theta` to the sun
/// (`forward_step_factor` in WGSL), 1 to `1 +` [`FORWARD_STEP_BOOST`]:
/// more toward the sun, where the forward lobe makes the sunlight
/// scattered once most of a pixel's light, so the shadow ray's estimate
/// is what the pixel shows. Few steps err toward bright there (the
/// estimate `e^{-Σ σ Δt}` is convex in its samples): against the path
/// tracer's backlit view, 20 steps everywhere measured 16.6 % per pixel
/// where this measured 14.7 % (docs/ground_truth/compare.py). Away from
/// the sun a ray keeps its steps and its cost, and [`shadow_step_count`]
/// keeps the longest rays' bound.
#[inline]
pub fn forward_step_factor(cos_theta: f32) -> f32 {
    1.0 + FORWARD_STEP_BOOST * toward_sun(cos_theta)
}

/// The sum of the shadow ray's step weights, `Σ_{k=1..steps} √k`: step
/// `i` (from 0) is `√(i + 1) / shadow_parts(steps)` of the ray.
#[inline]
pub fn shadow_parts(steps: u32) -> f32 {
    let mut parts = 0.0;
    for k in 1..=steps {
        parts += (k as f32).sqrt();
    }
    parts
}

/// Where each of a pixel's shadow samples sits in its step, in `[0, 1)`
/// (`shadow_offset` in WGSL): the pixel's march dither shifted by the
/// golden ratio, off the march's own placement; the same for every step
/// of the ray. Samples at the steps' centres would give every ray
/// through a cloud the same aliasing: whole clouds too bright or too
/// dark, and streaks across backlit clouds' shaded sides. Placed by the
/// dither, whose per-frame offsets TSAA averages (and the CPU's
/// `cpu_offsets`), the aliasing becomes a fine grain that averages out:
/// at 20 shadow steps the backlit view's single scattering measured
/// 12.4 % off the path tracer's per pixel, 14.5 % with centred samples.
/// One offset for the whole ray keeps its samples evenly spread; an
/// offset rotated by the golden ratio from step to step measured 19.2 %
/// (docs/ground_truth/single_scattering.sh).
#[inline]
pub fn shadow_offset(dither: f32) -> f32 {
    (dither + GOLDEN).fract()
}

/// How a shadow ray places its samples ([`sun_optical_depth`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowSteps {
    /// `render.shadow_steps`: the steps over a ray of up to
    /// [`SHADOW_STEP_SPAN_M`] ([`shadow_step_count`]).
    pub steps: u32,
    /// The factor on them toward the sun, [`forward_step_factor`] of the
    /// primary ray.
    pub forward: f32,
    /// Where each sample sits in its step, `[0, 1)` ([`shadow_offset`];
    /// 0.5: the steps' centres).
    pub offset: f32,
}

/// Optical depth (dimensionless) from `p` toward the sun through the band,
/// by [`shadow_step_count`] samples (`ray.steps` over a ray of up to
/// [`SHADOW_STEP_SPAN_M`], times `ray.forward`), each at `ray.offset` of
/// its step, whose lengths grow as `√1, √2, √3, ...` parts
/// ([`shadow_parts`]) over the ray to the band's top, at most
/// [`SHADOW_RAY_M`] ([`shadow_ray_length`]): fine near `p`, where a
/// cloud's own edge decides its light, without the long far steps of a
/// linear growth, which step over small wisps. Reading the density as the
/// primary march does (the detail noise included, at the level of detail
/// of `footprint_m`, the primary sample's). Without the detail its mean
/// stands in for the noise, small eroded wisps vanish from the shadow,
/// and backlit clouds glow 7 times too bright against the path tracer
/// (docs/ground_truth/compare.py). Few long steps leak the same way (they
/// step over the wisps): the default is 20 (`render.shadow_steps`).
#[inline]
pub fn sun_optical_depth(
    p: Vec3,
    sun_dir: Vec3,
    ray: ShadowSteps,
    footprint_m: f32,
    f: &Fields,
    d: &DensityParams,
) -> f32 {
    if ray.steps == 0 {
        return 0.0;
    }
    let length = shadow_ray_length(p, sun_dir, d);
    let count = shadow_step_count(ray.steps, length, ray.forward);
    shadow_march(p, sun_dir, length, count, ray.offset, footprint_m, f, d).tau
}

/// The length of a shadow ray's near part, m (`NEAR_SHADOW_M` in WGSL):
/// with a light volume the march reads the density only this far toward
/// the sun and the sun's optical depth beyond it from the volume
/// ([`near_sun_optical_depth`]). Two light cells across: what a cell's
/// one extinction cannot show (a cloud's own eroded edge, the crevice
/// beside a turret) lies nearer than that.
pub const NEAR_SHADOW_M: f32 = 200.0;

/// The near part's steps (`NEAR_SHADOW_STEPS` in WGSL), at most
/// `render.shadow_steps`, times [`forward_step_factor`], growing as
/// [`sun_optical_depth`]'s do.
pub const NEAR_SHADOW_STEPS: u32 = 6;

/// What a shadow ray's march found ([`shadow_march`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowMarch {
    /// The optical depth over the steps taken.
    pub tau: f32,
    /// The length of the steps taken, m.
    pub travelled: f32,
    /// Whether a sample left the band through its top (the rest of the
    /// ray is clear).
    pub left_band: bool,
    /// Density reads.
    pub reads: u32,
}

/// `count` steps over `length` m of the ray from `p` toward the sun, the
/// steps growing as `√1, √2, ...` parts ([`shadow_parts`]), each sample
/// at `offset` of its step; stops at the band's top.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn shadow_march(
    p: Vec3,
    sun_dir: Vec3,
    length: f32,
    count: u32,
    offset: f32,
    footprint_m: f32,
    f: &Fields,
    d: &DensityParams,
) -> ShadowMarch {
    let parts = shadow_parts(count);
    let mut out = ShadowMarch {
        tau: 0.0,
        travelled: 0.0,
        left_band: false,
        reads: 0,
    };
    for i in 0..count {
        let dt = length * ((i + 1) as f32).sqrt() / parts;
        let q = p + sun_dir * (out.travelled + offset * dt);
        if height_fraction(q.y, d) > 1.0 {
            out.left_band = true;
            break;
        }
        out.tau += density_at(q, f, d, true, footprint_m) * dt;
        out.reads += 1;
        out.travelled += dt;
    }
    out
}

/// The steps of a shadow ray's near part (`near_step_count` in WGSL):
/// [`NEAR_SHADOW_STEPS`], at most `steps`, times `forward`.
#[inline]
pub fn near_step_count(steps: u32, forward: f32) -> u32 {
    (steps.min(NEAR_SHADOW_STEPS) as f32 * forward).ceil() as u32
}

/// How much of a primary ray's view is toward the sun, 0 to 1
/// (`toward_sun` in WGSL): 0 below [`FORWARD_COS_MIN`], 1 from
/// [`FORWARD_COS_MAX`], smoothly between; [`forward_step_factor`] is
/// `1 + FORWARD_STEP_BOOST · toward_sun`.
#[inline]
pub fn toward_sun(cos_theta: f32) -> f32 {
    smoothstep(FORWARD_COS_MIN, FORWARD_COS_MAX, cos_theta)
}

/// The part of the shadow ray from `p` the march reads density along
/// when a light volume gives the optical depth beyond it
/// (`near_shadow_ray` in WGSL): its length, its steps, and whether any of
/// the ray is left beyond. Away from the sun, [`near_step_count`] steps
/// over [`NEAR_SHADOW_M`] (less where the band's top is nearer); toward
/// it (`toward`, [`toward_sun`]), up to the whole ray that
/// [`sun_optical_depth`] marches, smoothly. Toward the sun the light
/// scattered once in the forward lobe is most of a pixel's, and it
/// depends on the fine shadow that the volume's cells average away
/// (against the path tracer's backlit view the volume alone beyond 200 m
/// measured 13.2 % per pixel, the whole ray 10.5 %; docs/ground_truth).
#[inline]
pub fn near_shadow_ray(
    p: Vec3,
    sun_dir: Vec3,
    ray: ShadowSteps,
    toward: f32,
    d: &DensityParams,
) -> (f32, u32, bool) {
    let full = shadow_ray_length(p, sun_dir, d);
    let near = full.min(NEAR_SHADOW_M);
    let near_count = near_step_count(ray.steps, ray.forward);
    let full_count = shadow_step_count(ray.steps, full, ray.forward).max(near_count);
    let length = near + (full - near) * toward;
    let count = near_count + ((full_count - near_count) as f32 * toward + 0.5).floor() as u32;
    (length, count, toward < 1.0 && full > NEAR_SHADOW_M)
}

/// The near part of the shadow ray from `p` ([`near_shadow_ray`]), read
/// as [`sun_optical_depth`] reads; `rest` is whether the caller adds the
/// optical depth beyond `travelled` from the light volume (unless the
/// ray `left_band`).
#[inline]
pub fn near_sun_optical_depth(
    p: Vec3,
    sun_dir: Vec3,
    ray: ShadowSteps,
    toward: f32,
    footprint_m: f32,
    f: &Fields,
    d: &DensityParams,
) -> (ShadowMarch, bool) {
    let (length, count, rest) = near_shadow_ray(p, sun_dir, ray, toward, d);
    let m = shadow_march(p, sun_dir, length, count, ray.offset, footprint_m, f, d);
    (m, rest)
}

/// Transmittance toward the sun, in `[0, 1]`.
#[inline]
pub fn sun_transmittance(
    p: Vec3,
    sun_dir: Vec3,
    ray: ShadowSteps,
    footprint_m: f32,
    f: &Fields,
    d: &DensityParams,
) -> f32 {
    (-sun_optical_depth(p, sun_dir, ray, footprint_m, f, d)).exp()
}

/// Per octave of multiple scattering, the factor on the scattered light
/// (Wrenninge 2013's `a`, his value; `OCTAVE_SCATTERING` in WGSL).
pub const OCTAVE_SCATTERING: f32 = 0.5;
/// Per octave, the factor on the optical depth toward the sun (`b`,
/// Wrenninge's value): the light of later octaves has diffused around
/// what blocks the direct beam.
pub const OCTAVE_EXTINCTION: f32 = 0.5;
/// Per octave, the factor on the phase function's eccentricity (`c`).
/// Light scattered `n` times by a Henyey-Greenstein lobe of asymmetry
/// `g` keeps `g^n` of it, and the forward lobe's `g` is 0.8, so 0.8 is
/// the physical choice; with the gains fitted at each value against the
/// path tracer, 0.9 scores best over the four views
/// (docs/ground_truth/fit_gains.py). The octaves keep more of the
/// forward peak than one lobe's `g^n`: a cloud's light has few orders of
/// scattering near its sunlit skin, where the octaves matter.
pub const OCTAVE_ECCENTRICITY: f32 = 0.9;
/// The gain on the octaves' forward-scattered light (the phase
/// function's lobes at the octave's eccentricity) at a sun in the zenith
/// (fitted, as [`MULTIPLE_ISOTROPIC_GAIN`], [`DIFFUSE_GAIN`],
/// [`FLUENCE_GAIN`] and the sky's and the ground's gains are, by
/// docs/ground_truth/fit_tops.py on fit_gains.py's part renders, four
/// views, the tops held within 9.5 %; figures in
/// docs/ground_truth/README.md).
pub const MULTIPLE_GAIN: f32 = 0.202;
/// [`MULTIPLE_GAIN`] where no light volume is built ([`LightGains::ALONE`]).
pub const MULTIPLE_GAIN_ALONE: f32 = 0.53;
/// The gain on the octaves' isotropic light: light scattered many times
/// leaves a cloud in every direction, not only in the phase's lobes. The
/// light volume carries most of that light ([`FLUENCE_GAIN`]); beside it
/// the fit keeps this much, for the light near the sunlit skin that the
/// cells blur.
pub const MULTIPLE_ISOTROPIC_GAIN: f32 = 0.256;
/// [`MULTIPLE_ISOTROPIC_GAIN`] where no light volume is built.
pub const MULTIPLE_ISOTROPIC_GAIN_ALONE: f32 = 0.46;
/// The octaves scale with the sun's height as
/// `sin(elevation)^MULTIPLE_SUN_POWER`, a weak power: the light a whole
/// layer takes in, which falls with the sun's flux through it, is the
/// light volume's and the diffused sunlight's, and the octaves carry the
/// light near each cloud's sunlit skin, which a low sun lights side-on
/// as well. With the gains refitted at each power (four views, the tops
/// held), 0.2 is the one that keeps both the high and the low sun at
/// about 10 % per pixel or under (docs/ground_truth/fit_tops.py).
pub const MULTIPLE_SUN_POWER: f32 = 0.2;
/// The gain on the diffused sunlight ([`diffused_sun`]) at a sun in the
/// zenith, as the fit beside the transported light gives it. The
/// renderers that build no light volume (the spheroids' and the
/// volume's) have only this term to fill deep cloud, which this little
/// leaves too dark: they take [`DIFFUSE_GAIN_ALONE`] ([`LightGains`]).
pub const DIFFUSE_GAIN: f32 = 0.019;
/// [`DIFFUSE_GAIN`] where no light volume is built, held at 0.1 in the
/// fit of [`LightGains::ALONE`] so that the term fills deep cloud.
pub const DIFFUSE_GAIN_ALONE: f32 = 0.1;
/// A sample carries the diffused sunlight in proportion to its opacity
/// over this many metres, `1 - e^{-σ_t · DIFFUSE_DEPTH_M}`: it fills
/// cloud, not the thin haze and wisps between clouds, which have little
/// cloud around them to diffuse the light.
pub const DIFFUSE_DEPTH_M: f32 = 100.0;

/// The sunlight diffused through the cloud layer, per unit scattering
/// coefficient and per unit sun irradiance, in cloud of extinction
/// `sigma_t`, under a sun of height `mu_sun` (`sin` of its elevation),
/// times the `gains`' `diffuse`.
///
/// Sunlight that enters a deep layer of cloud is scattered hundreds of
/// times and spreads through it, in every direction: what the layer
/// takes in, and so what fills it, is the sun's flux through its
/// horizontal extent, `E · sin(elevation)`, scattered isotropically. It
/// does not depend on the sun's shadow ray: the path tracer's light in
/// deep cloud rises with the depth the camera sees, and a term of the
/// shadow ray alone, as the octaves are, falls with it (docs/ground_truth).
#[inline]
pub fn diffused_sun(mu_sun: f32, sigma_t: f32, gains: &LightGains) -> f32 {
    gains.diffuse * mu_sun.max(0.0) * (1.0 - (-sigma_t * DIFFUSE_DEPTH_M).exp()) / (4.0 * PI)
}

/// The gain on the light volume's transported sunlight
/// ([`super::light_volume::LightVolume::light_toward`]; `FLUENCE_GAIN` in
/// WGSL), fitted with the others: 0.915, where exact transport would need
/// 1 and the octaves took nothing from it. The cells blur a cloud's
/// sunlit skin into its shaded inside, where the light is weaker: the
/// octaves carry the skin's light, and the volume gives some of that back.
/// The value belongs to the light volume's cells (with cells 80 m tall
/// the fit gives 0.766): a change to their size asks for a refit.
pub const FLUENCE_GAIN: f32 = 0.915;

/// The six fitted gains of the light (`light_gains` in WGSL, which picks
/// them by its `LIGHT_VOLUME` override): the octaves' forward and
/// isotropic parts, the diffused sunlight, the transported light, the
/// sky's and the ground's light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightGains {
    pub multiple: f32,
    pub multiple_isotropic: f32,
    pub diffuse: f32,
    pub fluence: f32,
    pub ambient: f32,
    pub ground: f32,
}

impl LightGains {
    /// Beside the transported light volume (fitted to the path tracer
    /// with it, docs/ground_truth/fit_tops.py): the cloud map's renderer
    /// with multiple scattering on.
    pub const TRANSPORT: Self = Self {
        multiple: MULTIPLE_GAIN,
        multiple_isotropic: MULTIPLE_ISOTROPIC_GAIN,
        diffuse: DIFFUSE_GAIN,
        fluence: FLUENCE_GAIN,
        ambient: AMBIENT_GAIN,
        ground: GROUND_LIGHT_GAIN,
    };
    /// Where no light volume is built (the spheroids' and the volumes'
    /// renderers; the cloud map's with `render.light_photons = 0`): the
    /// gains of the fit in which a diffusion on the light grid stood for
    /// the transported light (docs/ground_truth/README.md). The
    /// transport's own gains give the ground's light nothing and the
    /// octaves half as much, which leaves a renderer without the volume's
    /// light navy in its shade.
    pub const ALONE: Self = Self {
        multiple: MULTIPLE_GAIN_ALONE,
        multiple_isotropic: MULTIPLE_ISOTROPIC_GAIN_ALONE,
        diffuse: DIFFUSE_GAIN_ALONE,
        fluence: 0.0,
        ambient: AMBIENT_GAIN_ALONE,
        ground: GROUND_LIGHT_GAIN_ALONE,
    };
}

/// The gains for a renderer with a light volume (`volume`) or without.
#[inline]
pub fn light_gains(volume: bool) -> LightGains {
    if volume {
        LightGains::TRANSPORT
    } else {
        LightGains::ALONE
    }
}

/// Sun light scattered toward the eye per unit scattering coefficient in
/// cloud of extinction `sigma_t`: single scattering (`phase_dual`
/// through the optical depth `tau_sun`) and, when `octaves > 0`, multiple
/// scattering: `octaves` octaves (Wrenninge 2013: octave `i` scatters
/// `a^i` of the light through `b^i` of the optical depth), each as a
/// forward part (the phase with `c^i` of the eccentricity, times
/// [`MULTIPLE_GAIN`]) and an isotropic part ([`MULTIPLE_ISOTROPIC_GAIN`]),
/// scaled by the sun's height `mu_sun` (`sin` of its elevation) to the
/// power [`MULTIPLE_SUN_POWER`]; and the sunlight diffused through the
/// layer ([`diffused_sun`]).
///
/// The light volume's term
/// ([`super::light_volume::LightVolume::light_toward`]) is added beside
/// this one (`renderer::diffused_light`). The six gains (the octaves' two,
/// the two diffused lights', the sky's [`super::lighting::AMBIENT_GAIN`]
/// and the ground's [`super::lighting::GROUND_LIGHT_GAIN`]) were fitted to Mitsuba
/// 3's volumetric path tracer (all orders of scattering) on four views: a
/// high sun, a low sun, a backlit view and a side view (docs/ground_truth:
/// the model chosen with `surrogate.py`, the gains fitted on the
/// renderer's own parts). Forward octaves alone, however fitted, leave
/// 18-21 % per pixel: they dim deep cloud, where the path tracer's light
/// stays.
#[inline]
pub fn sun_scattering(
    tau_sun: f32,
    cos_theta: f32,
    mu_sun: f32,
    sigma_t: f32,
    octaves: u32,
    gains: &LightGains,
) -> f32 {
    let mut sum = phase_dual(cos_theta, 1.0) * (-tau_sun).exp();
    if octaves == 0 {
        return sum;
    }
    let height = mu_sun.max(0.0).powf(MULTIPLE_SUN_POWER);
    let isotropic = gains.multiple_isotropic / (4.0 * PI);
    let (mut a, mut b, mut c) = (1.0, 1.0, 1.0);
    for _ in 0..octaves {
        a *= OCTAVE_SCATTERING;
        b *= OCTAVE_EXTINCTION;
        c *= OCTAVE_ECCENTRICITY;
        let phase = gains.multiple * phase_dual(cos_theta, c) + isotropic;
        sum += height * a * phase * (-b * tau_sun).exp();
    }
    sum + diffused_sun(mu_sun, sigma_t, gains)
}

/// Energy-conserving integral of in-scattered light `s` over a step of
/// length `dt` with extinction `sigma_t` (Hillaire 2016):
/// `(s - s e^{-σ Δ}) / σ`; tends to `s Δ` as σ -> 0.
#[inline]
pub fn integrate_step(s: Vec3, sigma_t: f32, dt: f32) -> Vec3 {
    if sigma_t * dt < 1e-5 {
        return s * dt;
    }
    (s - s * (-sigma_t * dt).exp()) / sigma_t
}

/// Single-scattering albedo of cloud droplets.
pub const ALBEDO: f32 = 0.99;

/// The gain on the sky's light in cloud (`AMBIENT_GAIN` in WGSL):
/// isotropic scattering of the upper sky's irradiance (`sky_above(up) /
/// 4`), 0.35 of it at the band's bottom and all of it at its top
/// ([`super::lighting::ambient_light`]), times this, which stands for that light's own
/// multiple scattering; fitted with the octaves and the transported
/// sunlight ([`sun_scattering`], [`FLUENCE_GAIN`]) and
/// [`GROUND_LIGHT_GAIN`] (docs/ground_truth/fit_tops.py).
pub const AMBIENT_GAIN: f32 = 4.355;
/// [`AMBIENT_GAIN`] where no light volume is built
/// ([`LightGains::ALONE`]).
pub const AMBIENT_GAIN_ALONE: f32 = 4.37;

/// The gain on the ground's light in cloud (`GROUND_LIGHT_GAIN` in
/// WGSL): isotropic scattering of the ground's upward irradiance
/// (`ground_up / 4`), all of it at the band's bottom and none at its top
/// ([`super::lighting::ambient_light`]), times this. It is 0 beside the
/// transported sunlight, which reaches the bases through the clouds as
/// the path tracer's does: the fit (docs/ground_truth/fit_tops.py) puts
/// it at 0 or within 0.011 of it, where no view's error moves by more
/// than 0.0002. The path-traced references light the clouds from below
/// only through their environment's lower half, so a refit against
/// references with a ground may want it back.
pub const GROUND_LIGHT_GAIN: f32 = 0.0;
/// [`GROUND_LIGHT_GAIN`] where no light volume is built.
pub const GROUND_LIGHT_GAIN_ALONE: f32 = 3.82;

/// The real spherical harmonics to l = 2 at unit `d`, in the order
/// (l, m) = (0, 0), (1, -1), (1, 0), (1, 1), (2, -2) … (2, 2), with `z`
/// as the polar axis (`sh9` in WGSL).
#[inline]
pub fn sh9(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_094_8,
        0.488_602_5 * y,
        0.488_602_5 * z,
        0.488_602_5 * x,
        1.092_548_4 * x * y,
        1.092_548_4 * y * z,
        0.315_391_57 * (3.0 * z * z - 1.0),
        1.092_548_4 * x * z,
        0.546_274_2 * (x * x - y * y),
    ]
}

/// The sky's and the ground's light scattered at height fraction `eta` of
/// the band (0 bottom, 1 top), from the upper sky's `sky_up / 4`, weighted
/// from 0.35 at the bottom to 1 at the top, times the `gains`' `ambient`
/// ([`super::lighting::AMBIENT_GAIN`] beside the light volume), and the ground's `ground /
/// 4`, weighted from 1 at the bottom to 0 at the top, times their
/// `ground` ([`super::lighting::GROUND_LIGHT_GAIN`]).
#[inline]
pub fn ambient_light(sky_top: Vec3, ground: Vec3, eta: f32, gains: &LightGains) -> Vec3 {
    sky_top * ((0.35 + 0.65 * eta) * gains.ambient) + ground * ((1.0 - eta) * gains.ground)
}

/// The footprint the ground's cloud shadows read the density at, m
/// (`GROUND_SHADOW_FOOTPRINT_M` in WGSL): twice
/// [`super::density::FINE_SHARP_M`], so they read no fine billows (12
/// samples across the band would only alias them), and at the default
/// detail scale the finest mip level of everything else.
pub const GROUND_SHADOW_FOOTPRINT_M: f32 = 2.0 * FINE_SHARP_M;

/// Transmittance of the cloud band from a ground point `p` toward the sun:
/// `steps` samples across the band segment of the sun ray, reading the
/// detail noise as the clouds' own shadow rays do (without it the field
/// near the base is wider than the cloud, and the shadows were large dark
/// patches), at [`GROUND_SHADOW_FOOTPRINT_M`].
pub fn cloud_shadow(p: Vec3, sun_dir: Vec3, steps: u32, f: &Fields, d: &DensityParams) -> f32 {
    let Some((t0, t1)) = band_segment(p, sun_dir, d.band_bottom_m, d.band_top_m, 20_000.0) else {
        return 1.0;
    };
    let dt = (t1 - t0) / steps.max(1) as f32;
    let tau: f32 = (0..steps.max(1))
        .map(|i| {
            let q = p + sun_dir * (t0 + (i as f32 + 0.5) * dt);
            density_at(q, f, d, true, GROUND_SHADOW_FOOTPRINT_M) * dt
        })
        .sum();
    (-tau).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: LightGains = LightGains::TRANSPORT;

    #[test]
    fn hg_phase_integrates_to_one() {
        for g in [-0.5, 0.0, 0.3, 0.8, 0.95] {
            let n = 200_000;
            // ∫ p(cos θ) 2π d(cos θ) over [-1, 1], midpoint rule.
            let s: f64 = (0..n)
                .map(|i| {
                    let mu = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
                    phase_hg(mu as f32, g) as f64 * 2.0 * std::f64::consts::PI * 2.0 / n as f64
                })
                .sum();
            assert!((s - 1.0).abs() < 2e-3, "g={g}: {s}");
        }
    }

    #[test]
    fn deep_cloud_keeps_the_diffused_sunlight() {
        // Far behind its sunlit skin (tau 200), a point in dense cloud
        // still holds the light diffused through the layer: the octaves
        // are gone (e^{-0.125 * 200}), the diffused light is not.
        let (cos, mu, sigma) = (0.3, 0.8, 0.03);
        let deep = sun_scattering(200.0, cos, mu, sigma, 3, &G);
        let expected = DIFFUSE_GAIN * mu / (4.0 * PI);
        assert!(
            deep > 0.9 * expected && deep < 1.01 * expected,
            "{deep} vs {expected}"
        );
        // It scales with the sun's flux through the layer, sin(elevation),
        // and is the same in every direction.
        let low = sun_scattering(200.0, cos, 0.2, sigma, 3, &G);
        assert!((low / deep - 0.25).abs() < 0.02, "{low} / {deep}");
        assert_eq!(deep, sun_scattering(200.0, -0.9, mu, sigma, 3, &G));
        // Thin haze carries little of it; a sun below the horizon none.
        assert!(diffused_sun(mu, 1e-4, &G) < 0.02 * diffused_sun(mu, sigma, &G));
        assert_eq!(diffused_sun(-0.1, sigma, &G), 0.0);
        // No octaves: single scattering alone, nothing diffused.
        let single = sun_scattering(2.0, cos, mu, sigma, 0, &G);
        assert_eq!(single, phase_dual(cos, 1.0) * (-2.0_f32).exp());
    }

    #[test]
    fn octaves_scatter_sideways_as_well_as_forward() {
        // Near the sunlit skin, multiply scattered light leaves sideways
        // (cos 0) at least the isotropic part's share, not only what the
        // forward lobes send there.
        let (mu, sigma) = (1.0, 0.03);
        let side =
            sun_scattering(0.0, 0.0, mu, sigma, 3, &G) - sun_scattering(0.0, 0.0, mu, sigma, 0, &G);
        let iso: f32 = (1..=3).map(|i| OCTAVE_SCATTERING.powi(i)).sum::<f32>()
            * MULTIPLE_ISOTROPIC_GAIN
            / (4.0 * PI);
        assert!(side > iso + diffused_sun(mu, sigma, &G), "{side} vs {iso}");
        // Toward the sun the forward lobes add far more (an isotropic
        // light alone would add the same).
        let forward = sun_scattering(0.0, 0.99, mu, sigma, 3, &G)
            - sun_scattering(0.0, 0.99, mu, sigma, 0, &G);
        assert!(forward > 2.0 * side, "{forward} vs {side}");
    }

    #[test]
    fn shadow_rays_take_more_steps_toward_the_sun() {
        // Away from the sun (and square to it) a ray keeps its count.
        for cos in [-1.0, 0.0, FORWARD_COS_MIN] {
            assert_eq!(shadow_step_count(20, 1000.0, forward_step_factor(cos)), 20);
        }
        // Toward it, up to FORWARD_STEP_BOOST more: 20 become 32.
        for cos in [FORWARD_COS_MAX, 1.0] {
            assert_eq!(shadow_step_count(20, 1000.0, forward_step_factor(cos)), 32);
        }
        // Growing in between.
        let mut last = 0;
        for i in 0..=50 {
            let n = shadow_step_count(20, 1000.0, forward_step_factor(i as f32 / 50.0));
            assert!(n >= last);
            last = n;
        }
        // A long ray toward a low sun ahead keeps the longest rays' bound:
        // at most SHADOW_STEP_FACTOR_MAX times the steps in all.
        let most = (20.0 * SHADOW_STEP_FACTOR_MAX) as u32;
        assert_eq!(shadow_step_count(20, 5000.0, 1.0), 50);
        assert_eq!(
            shadow_step_count(20, 5000.0, forward_step_factor(1.0)),
            most
        );
        assert_eq!(
            shadow_step_count(20, SHADOW_RAY_M, forward_step_factor(1.0)),
            most
        );
        assert_eq!(shadow_step_count(0, 1000.0, forward_step_factor(1.0)), 0);
    }

    #[test]
    fn integrate_step_conserves_energy() {
        // Emitted light over a thick step saturates at s/σ, never more.
        let s = Vec3::splat(2.0);
        let i = integrate_step(s, 0.5, 1000.0);
        assert!((i.x - 4.0).abs() < 1e-5);
        let small = integrate_step(s, 1e-9, 3.0);
        assert!((small.x - 6.0).abs() < 1e-4);
    }
}
