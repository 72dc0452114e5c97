//! The sea's waves a pixel resolves: a sum of wave trains whose slopes
//! tilt the sea's normal where a pixel is smaller than them (near the
//! camera), and whose slopes a pixel cannot resolve stay in the glint's
//! statistical roughness (far away), so the two together always hold
//! Cox and Munk's (1954) slope variance. Twins of the WGSL functions of
//! the same names in `shaders/waves.wgsl`.
//!
//! Each train travels along its direction at deep water's phase speed,
//! on the sea's clock (`Quality::sea_time_s`).

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::density::smoothstep;
use crate::render::sampling::GOLDEN;

/// Wave trains summed (`WAVE_COUNT` in WGSL), their wavelengths evenly
/// spread in ratio over [`WAVE_OCTAVES`] below [`WAVE_LONGEST_M`], about
/// five an octave. With two an octave (15 trains) the few a pixel
/// resolves from 300 m up make a lattice of diamonds, and seen at a
/// grazing angle the long crests across the line of sight run to the
/// vanishing point as straight lines: more trains in more directions
/// make short crests.
pub const WAVE_COUNT: u32 = 40;
/// The octaves of wavelength the trains span (`WAVE_OCTAVES`): 60 m down
/// to 0.38 m.
pub const WAVE_OCTAVES: f32 = 7.5;
/// The longest train's wavelength, m (`WAVE_LONGEST_M`): about the
/// dominant wave of a 7 m/s wind's sea (its peak wavelength,
/// `2π (1.2 U)² / g`, is 45 m).
pub const WAVE_LONGEST_M: f32 = 60.0;
/// How far the trains' directions spread to either side of the wind,
/// radians (`WAVE_SPREAD`, about 55°): wind seas are short-crested.
pub const WAVE_SPREAD: f32 = 0.96;
/// The largest share of Cox and Munk's variance the trains carry
/// (`WAVE_SHARE_MAX`): in a calm their slick-sea fit exceeds the clean
/// one, and the capillaries always keep some.
pub const WAVE_SHARE_MAX: f32 = 0.8;
/// A train fades from a pixel between this and [`WAVE_FADE_END`] of its
/// wavelength across the pixel's footprint along it
/// (`WAVE_FADE_START`): past half a wavelength it would alias.
pub const WAVE_FADE_START: f32 = 0.1;
/// See [`WAVE_FADE_START`] (`WAVE_FADE_END`).
pub const WAVE_FADE_END: f32 = 0.5;

/// The most a pixel's footprint on the sea may be longer along the line
/// of sight than across it, for the waves (`WAVE_ANISOTROPY_MAX`): seen
/// at a grazing angle (20:1 at 3°) the trains whose crests run along the
/// line of sight stayed resolved long after those across it faded, and
/// their long straight crests ran to the vanishing point like a zoom
/// blur. The waves across the line of sight fade sooner instead.
pub const WAVE_ANISOTROPY_MAX: f32 = 4.0;

/// A pixel's length on the sea along the line of sight, m: of cone angle
/// `spread` at distance `t`, its ray falling at sine `sin_down`,
/// `spread · t / sin_down` (`sin_down` at least 1e-3). The land's
/// `ground_footprint` stops growing at 20 times the width, 3° down; the
/// waves' trains would alias beyond it (rows on the sea 98 m apart 1° down
/// from 30 m, the footprint taken as 34 m).
#[inline]
pub fn wave_footprint(spread: f32, t: f32, sin_down: f32) -> f32 {
    spread * t / sin_down.abs().max(1e-3)
}

/// Gravity at the sea's surface, m/s² (`GRAVITY` in WGSL).
pub const GRAVITY: f32 = 9.81;

/// The frequency of a deep-water wave of `wavelength` m, Hz: its
/// dispersion `ω² = g k`, so `f = √(g / (2π λ))` (a 60 m wave has a
/// period of 6.2 s, a 1 m wave of 0.8 s).
#[inline]
pub fn wave_frequency(wavelength: f32) -> f32 {
    (GRAVITY / (2.0 * PI * wavelength)).sqrt()
}

/// Cox and Munk's (1954) mean square slope of a clean sea in a wind of
/// `wind_mps` (both directions together): `0.003 + 0.00512 U`.
#[inline]
pub fn slope_variance(wind_mps: f32) -> f32 {
    0.003 + 0.00512 * wind_mps.max(0.0)
}

/// The mean square slope the wave trains carry: Cox and Munk's fit for a
/// sea whose capillaries and short waves an oil slick has damped,
/// `0.008 + 0.00156 U` (about half of the clean sea's at 7 m/s, waves
/// longer than some decimetres), at most [`WAVE_SHARE_MAX`] of
/// [`slope_variance`].
#[inline]
pub fn wave_variance(wind_mps: f32) -> f32 {
    let u = wind_mps.max(0.0);
    (0.008 + 0.00156 * u).min(WAVE_SHARE_MAX * slope_variance(u))
}

/// The wave slope `(∂h/∂x, ∂h/∂z)` a pixel resolves at `(x, z)` on the
/// sea and the slope variance it does not (the glint's roughness), as
/// `(slope x, slope z, variance)`, for a wind of `wind_mps` blowing
/// toward `toward_deg` (clockwise from north, +z), seen along `dir` (down)
/// by a pixel of cone angle `spread` at distance `t`, at `time_s` on the
/// sea's clock.
///
/// Train `i` has wavelength `WAVE_LONGEST_M · 2^{-WAVE_OCTAVES · i /
/// WAVE_COUNT}`, a direction spread about the wind's by the golden-ratio
/// sequence and a phase the same, travels along that direction at its
/// [`wave_frequency`], and carries an equal share of [`wave_variance`] (a
/// saturated sea's slopes spread evenly over the wavenumbers' octaves).
/// Its weight in the pixel fades with the pixel's footprint along it (its
/// width across the line of sight, `spread · t` but at least
/// [`WAVE_ANISOTROPY_MAX`]-th of its length, and along it,
/// [`wave_footprint`]); the variance it loses, and all of
/// [`slope_variance`] that the trains do not carry, is the unresolved
/// variance. Far away that is the whole of [`slope_variance`] and the
/// slope 0: the flat, rough sea.
#[allow(clippy::too_many_arguments)]
pub fn sea_waves(
    x: f32,
    z: f32,
    dir: Vec3,
    spread: f32,
    t: f32,
    wind_mps: f32,
    toward_deg: f32,
    time_s: f32,
) -> Vec3 {
    let total = slope_variance(wind_mps);
    let share = wave_variance(wind_mps) / WAVE_COUNT as f32;
    let amplitude = (2.0 * share).sqrt();
    let along = Vec2::new(dir.x, dir.z).normalize_or(Vec2::Y);
    let along_m = wave_footprint(spread, t, dir.y);
    let across_m = (spread * t).max(along_m / WAVE_ANISOTROPY_MAX);
    let wind = toward_deg.to_radians();
    let mut slope = Vec2::ZERO;
    let mut resolved = 0.0;
    for i in 0..WAVE_COUNT {
        let fi = i as f32;
        let wavelength = WAVE_LONGEST_M * (-WAVE_OCTAVES * fi / WAVE_COUNT as f32).exp2();
        let turn = WAVE_SPREAD * (2.0 * ((fi + 1.0) * GOLDEN).fract() - 1.0);
        let k = Vec2::new((wind + turn).sin(), (wind + turn).cos());
        let cos_a = k.dot(along);
        let sin_a = k.perp_dot(along);
        let footprint = ((along_m * cos_a).powi(2) + (across_m * sin_a).powi(2)).sqrt();
        let w = 1.0 - smoothstep(WAVE_FADE_START, WAVE_FADE_END, footprint / wavelength);
        if w <= 0.0 {
            continue;
        }
        let travelled = (time_s * wave_frequency(wavelength)).fract();
        // In cycles, reduced to one before the cosine (a GPU's cosine of
        // thousands of radians is not its twin's).
        let cycles =
            (x * k.x + z * k.y) / wavelength + ((fi + 1.0) * GOLDEN * GOLDEN).fract() - travelled;
        let phase = 2.0 * PI * cycles.rem_euclid(1.0);
        slope += k * (w * amplitude * phase.cos());
        resolved += w * w * share;
    }
    Vec3::new(slope.x, slope.y, (total - resolved).max(1e-4))
}

/// The sea's normal under the resolved `waves` ([`sea_waves`]).
#[inline]
pub fn wave_normal(waves: Vec3) -> Vec3 {
    Vec3::new(-waves.x, 1.0, -waves.y).normalize()
}

/// The flat, rough sea: no resolved slope, all of Cox and Munk's variance
/// in a wind of `wind_mps` ([`slope_variance`]).
#[inline]
pub fn flat_sea(wind_mps: f32) -> Vec3 {
    Vec3::new(0.0, 0.0, slope_variance(wind_mps))
}

/// The lowest elevation (radians, about 0.6°) a wave sends a reflected
/// ray to; the facets that would send it lower are hidden behind the
/// next wave at the grazing angles where that happens.
pub const REFLECTION_MIN_ELEVATION: f32 = 0.01;

/// The elevation (radians) of a ray the wind-roughened sea reflects,
/// where the mirror ray of the waves the pixel resolves rises at `mirror`
/// radians, at the quantile `u` in `(0, 1)` of the slopes it does not,
/// of mean square `variance` (both directions together;
/// [`super::waves::sea_waves`]).
///
/// A facet tilted by a slope `s` toward or away from the viewer turns
/// the reflected ray up or down by `2 s` (sideways tilts turn it in
/// azimuth: [`cross_slope`], [`reflected_ray`]). The mean square slope
/// (far away all of Cox and Munk's 1954 `0.003 + 0.00512 U` for a wind
/// of `U` m/s) is split between the two directions, so the
/// elevation spreads with a standard deviation of `√(2 · variance)`: 0.28
/// rad (16°) far out at 7 m/s, 0.08 rad on a calm sea. The spread is a logistic
/// distribution of that deviation (its quantile in closed form; its
/// cumulative distribution within 0.02 of a Gaussian's), cut off below
/// [`REFLECTION_MIN_ELEVATION`]: the waves draw a mirrored cloud out
/// into a vertical smear, near the horizon only upward.
#[inline]
pub fn reflected_elevation(mirror: f32, variance: f32, u: f32) -> f32 {
    let deviation = (2.0 * variance.max(0.0)).sqrt();
    // A logistic of scale s has the deviation s·π/√3.
    let s = deviation * 3f32.sqrt() / PI;
    let lowest = 1.0 / (1.0 + ((mirror - REFLECTION_MIN_ELEVATION) / s).exp());
    let q = (lowest + (1.0 - lowest) * u).clamp(1e-6, 1.0 - 1e-6);
    mirror + s * (q / (1.0 - q)).ln()
}

/// A wave's slope across the line of sight at the quantile `u` in `(0,
/// 1)`, of the slopes of mean square `variance` a pixel does not resolve:
/// a logistic of their deviation in one direction, `√(variance / 2)`
/// (far out 0.14 at 7 m/s), as [`reflected_elevation`]'s slopes along it.
#[inline]
pub fn cross_slope(variance: f32, u: f32) -> f32 {
    let deviation = (0.5 * variance.max(0.0)).sqrt();
    let s = deviation * 3f32.sqrt() / PI;
    let q = u.clamp(1e-6, 1.0 - 1e-6);
    s * (q / (1.0 - q)).ln()
}

/// The ray a wave sends up from the sea, about a mirror ray that rises at
/// `mirror` radians, horizontally along `across` (unit; the resolved
/// waves' mirror ray, [`super::sky::sea_mirror`]): rising at
/// elevation `e` ([`reflected_elevation`]) and turned sideways by the
/// wave's slope `slope` across the line of sight ([`cross_slope`]). A
/// facet tilted sideways by `s` adds `s (sin(mirror) + sin(e))` of the
/// ray's length sideways (to first order in `s`, whatever the facet's
/// tilt toward the viewer that sends the ray to `e`): up to `2 s`
/// looking straight down, and near the horizon still some degrees for
/// the steep rays that reach the clouds (2.8° at `s` 0.14, a mirror ray
/// 2° down and a reflected ray 17.6° up). A mirrored cloud's streak is
/// as wide as the cloud, its sides softened.
#[inline]
pub fn reflected_ray(across: Vec3, mirror: f32, e: f32, slope: f32) -> Vec3 {
    let side = Vec3::new(-across.z, 0.0, across.x);
    let sideways = slope * (mirror.sin() + e.sin());
    (across * e.cos() + side * sideways + Vec3::Y * e.sin()).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_waves_keep_cox_and_munks_variance() {
        let wind = 7.0;
        let total = slope_variance(wind);
        let dir = Vec3::new(0.3, -0.4, 0.8).normalize();
        // Far away no train is resolved: the flat sea, all the variance
        // in the glint's roughness.
        let far = sea_waves(123.0, -45.0, dir, 1e-3, 2e5, wind, 90.0, 0.0);
        assert_eq!(far, flat_sea(wind));
        // A tiny pixel resolves them all: their slopes' variance over the
        // sea is the trains' share, the rest stays unresolved.
        let n = 40_000;
        let (mut sum, mut sum2, mut unresolved) = (Vec2::ZERO, 0.0, 0.0);
        for i in 0..n {
            let (x, z) = (
                (i % 200) as f32 * 3.7 + 0.13 * i as f32,
                (i / 200) as f32 * 4.1,
            );
            let w = sea_waves(x, z, dir, 1e-7, 10.0, wind, 90.0, 0.0);
            sum += Vec2::new(w.x, w.y);
            sum2 += w.x * w.x + w.y * w.y;
            unresolved = w.z;
        }
        let mean = sum / n as f32;
        let variance = sum2 / n as f32 - mean.length_squared();
        let trains = wave_variance(wind);
        assert!(mean.length() < 0.02, "mean slope {mean}");
        assert!(
            (variance / trains - 1.0).abs() < 0.1,
            "{variance} vs {trains}"
        );
        assert!((unresolved - (total - trains)).abs() < 1e-5);
        // The trains carry about half of it at 7 m/s (Cox and Munk's
        // slick sea over their clean one).
        assert!((0.4..0.6).contains(&(trains / total)));
    }

    #[test]
    fn each_train_travels_at_deep_waters_phase_speed() {
        // Deep water's dispersion: a 60 m wave's period is √(2πλ/g),
        // 6.20 s; its phase speed λ/T, 9.68 m/s.
        assert!((1.0 / wave_frequency(60.0) - 6.20).abs() < 0.01);
        assert!((60.0 * wave_frequency(60.0) - 9.68).abs() < 0.01);
        // One train alone (a pixel that resolves only the longest, whose
        // footprint is past WAVE_FADE_END of every other's wavelength):
        // its slope at (x, t) returns a phase speed times dt further along
        // its direction at t + dt.
        let dir = Vec3::new(0.0, -1.0, 0.0);
        let second = WAVE_LONGEST_M * (-WAVE_OCTAVES / WAVE_COUNT as f32).exp2();
        let footprint = 0.5 * WAVE_FADE_END * (second + WAVE_LONGEST_M);
        let spread = footprint / 100.0;
        let at = |x: f32, z: f32, time: f32| sea_waves(x, z, dir, spread, 100.0, 7.0, 90.0, time);
        let turn = WAVE_SPREAD * (2.0 * GOLDEN - 1.0);
        let heading = 90f32.to_radians() + turn;
        let k = Vec2::new(heading.sin(), heading.cos());
        let c = WAVE_LONGEST_M * wave_frequency(WAVE_LONGEST_M);
        let (mut moved, mut still) = (0.0, 0.0);
        for i in 0..50 {
            let (x, z) = (3.1 * i as f32, -1.7 * i as f32);
            let a = at(x, z, 0.0);
            let b = at(x + k.x * c * 1.5, z + k.y * c * 1.5, 1.5);
            moved += (a - b).length();
            still += (a - at(x, z, 1.5)).length();
        }
        assert!(still > 1e-4, "the train moves: {still}");
        assert!(moved < 1e-2 * still, "{moved} vs {still}");
    }

    /// The sums of the squared resolved slopes along x and along z over
    /// a grid of 10,000 points, seen along `dir` by a pixel of cone angle
    /// `spread` at `t`, in a 7 m/s wind toward `toward_deg`.
    fn slope_sums(dir: Vec3, spread: f32, t: f32, toward_deg: f32) -> (f32, f32) {
        (0..10_000).fold((0.0, 0.0), |(sx, sz), i| {
            let (x, z) = ((i % 100) as f32 * 1.37, (i / 100) as f32 * 1.91);
            let w = sea_waves(x, z, dir, spread, t, 7.0, toward_deg, 0.0);
            (sx + w.x * w.x, sz + w.y * w.y)
        })
    }

    #[test]
    fn the_waves_run_along_the_wind() {
        // Slopes along the wind (toward the east, +x) outweigh those
        // across it.
        let (along, across) = slope_sums(Vec3::new(0.0, -1.0, 0.0), 1e-7, 10.0, 90.0);
        assert!(along > 1.5 * across, "{along} vs {across}");
    }

    #[test]
    fn a_grazing_pixel_resolves_fewer_waves_along_the_line_of_sight() {
        // Seen 3° down, a pixel 2 mrad wide 1 km out is 38 m along the
        // line of sight and (by WAVE_ANISOTROPY_MAX) 9.6 m across it: the
        // trains that run along it fade first, so the resolved slope's
        // variance across it is larger.
        let dir = Vec3::new(0.0, -(3f32.to_radians().sin()), 3f32.to_radians().cos());
        // Wind toward the north-east: trains both along and across.
        let (x_var, z_var) = slope_sums(dir, 2e-3, 1000.0, 45.0);
        assert!(x_var > 2.0 * z_var, "{x_var} vs {z_var}");
        let w = sea_waves(0.0, 0.0, dir, 2e-3, 1000.0, 7.0, 45.0, 0.0);
        assert!(w.z > 0.5 * slope_variance(7.0) && w.z < slope_variance(7.0));
    }
}
