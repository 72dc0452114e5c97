//! The optional cirrus layer (`[render.cirrus]`): a thin sheet of ice
//! cloud high above the cumulus band, drawn in the sky behind them.
//!
//! It is two-dimensional: streaks of a value-noise fBm stretched along the
//! layer's direction ([`cirrus_density`]), with an optical depth of at
//! most `optical_depth` straight up and `1/μ` times that along a slanted
//! ray. The sun's light is scattered once with an ice crystal's forward
//! peak ([`CIRRUS_PHASE_G`]) and the sky's light as the cumulus scatter it;
//! the air between the camera and the layer hazes it as it hazes the
//! clouds ([`cirrus_over`]). It reads no texture and no density, so it
//! costs a few hashes per sky pixel and nothing where it is off. The layer
//! does not dim the sun on the clouds or the ground below it (at the
//! default optical depth, 0.2 at the thickest streaks, the sun would lose
//! up to a fifth under them). WGSL twin: `shaders/cirrus.wgsl`.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::lighting::{ALBEDO, phase_hg};
use super::sky::{SkyLight, aerial, sky_ambient, sun_light_at};

/// The cirrus layer (scene table `[render.cirrus]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CirrusLayer {
    /// The share of the sky the streaks cover, 0..=1; 0 (the default)
    /// draws no layer and compiles none into the shaders.
    pub cover: f32,
    /// The layer's height above the ground, m (4000..=15000). Default 9000.
    pub altitude_m: f32,
    /// The streaks' direction, degrees clockwise from north (+z), as the
    /// wind at their height blows them (-360..=360). Default 60.
    pub direction_deg: f32,
    /// The vertical optical depth of the thickest streaks (0..=3).
    /// Default 0.2: thin cirrus, the sun shows through.
    pub optical_depth: f32,
}

impl Default for CirrusLayer {
    fn default() -> Self {
        Self {
            cover: 0.0,
            altitude_m: 9000.0,
            direction_deg: 60.0,
            optical_depth: 0.2,
        }
    }
}

impl CirrusLayer {
    /// The layer when it is drawn (`cover > 0`).
    pub fn drawn(self) -> Option<Self> {
        (self.cover > 0.0).then_some(self)
    }
}

/// The streaks' length scale along the layer's direction, m.
pub const CIRRUS_ALONG_M: f32 = 9000.0;
/// Their length scale across it, m: streaks about six times longer than
/// wide.
pub const CIRRUS_ACROSS_M: f32 = 1500.0;
/// Octaves of the fBm: the finest is 1/16 of the first, about 100 m
/// across.
pub const CIRRUS_OCTAVES: u32 = 5;
/// How much finer across the streaks each octave is than the one before
/// (along them, twice): above 2, the fine octaves are thin fibres.
pub const CIRRUS_FIBRE_GROWTH: f32 = 2.8;
/// How far the noise's contrast is widened around 0.5 before the cover
/// thresholds it, so that `cover` is about the share covered.
pub const CIRRUS_CONTRAST: f32 = 3.0;
/// The width of a streak's soft edge, in the widened noise's units.
pub const CIRRUS_EDGE: f32 = 0.35;
/// The asymmetry of the ice crystals' phase function (Henyey-Greenstein):
/// a strong forward peak, as measured for cirrus (g about 0.7-0.8).
pub const CIRRUS_PHASE_G: f32 = 0.75;
/// The smallest `μ` (the ray's upward cosine) the slant path uses: the
/// layer's optical depth grows as `1/μ` toward the horizon, up to this.
pub const CIRRUS_MU_MIN: f32 = 0.03;

/// An integer hash of the lattice point `(ix, iy)` to `[0, 1)` (PCG's
/// output permutation): the same bits on the CPU and the GPU. (Not the
/// land's `field_hash`: `land` imports `frame`, which holds this module's
/// layer, and the render modules' imports may not form a circle.)
#[inline]
pub fn cirrus_hash(ix: i32, iy: i32) -> f32 {
    let mut h = (ix as u32).wrapping_mul(0x8da6_b343) ^ (iy as u32).wrapping_mul(0xd816_3841);
    h = h.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    h = ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737);
    h ^= h >> 22;
    (h >> 8) as f32 / 16_777_216.0
}

/// Value noise at `(x, y)` (lattice units): the hashes of the four
/// corners blended with a smoothstep, in `[0, 1)`.
#[inline]
pub fn cirrus_noise(x: f32, y: f32) -> f32 {
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i32, fy as i32);
    let (u, v) = (x - fx, y - fy);
    let (su, sv) = (u * u * (3.0 - 2.0 * u), v * v * (3.0 - 2.0 * v));
    let a = cirrus_hash(ix, iy);
    let b = cirrus_hash(ix + 1, iy);
    let c = cirrus_hash(ix, iy + 1);
    let d = cirrus_hash(ix + 1, iy + 1);
    let top = a + (b - a) * su;
    let bottom = c + (d - c) * su;
    top + (bottom - top) * sv
}

/// The layer's density at world `(x, z)`, 0..=1: the fBm of
/// [`cirrus_noise`] in coordinates stretched along `layer.direction_deg`,
/// its contrast widened, thresholded at `1 - cover` with a soft edge. An
/// octave whose width across the streaks is under twice `footprint_m`
/// (what a pixel covers on the layer) fades to its mean: far streaks do
/// not alias into stripes.
#[inline]
pub fn cirrus_density(x: f32, z: f32, footprint_m: f32, layer: &CirrusLayer) -> f32 {
    let (s, c) = layer.direction_deg.to_radians().sin_cos();
    let along = (x * s + z * c) / CIRRUS_ALONG_M;
    let across = (x * c - z * s) / CIRRUS_ACROSS_M;
    let (mut sum, mut amplitude, mut total) = (0.0, 1.0, 0.0);
    let (mut f_along, mut f_across) = (1.0, 1.0);
    for k in 0..CIRRUS_OCTAVES {
        // Each octave shifted, so their lattices do not line up, and
        // stretched further than the one before: the fine octaves are
        // the fibres.
        let shift = 17.31 * k as f32;
        let resolved = (CIRRUS_ACROSS_M / (f_across * footprint_m.max(1e-3)) - 1.0).clamp(0.0, 1.0);
        let n = cirrus_noise(along * f_along + shift, across * f_across - shift);
        sum += amplitude * (0.5 + (n - 0.5) * resolved);
        total += amplitude;
        amplitude *= 0.5;
        f_along *= 2.0;
        f_across *= CIRRUS_FIBRE_GROWTH;
    }
    let n = (0.5 + (sum / total - 0.5) * CIRRUS_CONTRAST).clamp(0.0, 1.0);
    let threshold = 1.0 - layer.cover;
    ((n - threshold) / CIRRUS_EDGE).clamp(0.0, 1.0)
}

/// `background` (the sky, and the sun disk, seen along `dir` from `eye`)
/// behind the cirrus layer: dimmed by the layer's transmittance along the
/// ray, plus the light it scatters, hazed by the air in front of it as
/// the cumulus are ([`aerial`]). `spread` is the pixel's cone angle
/// (radians): the footprint on the layer grows with the distance and the
/// slant. Rays that do not rise to the layer, and an eye at or above it,
/// see the background alone, as every ray does without a `layer`.
pub fn cirrus_over(
    sky: &SkyLight,
    eye: Vec3,
    dir: Vec3,
    sun_dir: Vec3,
    spread: f32,
    layer: Option<&CirrusLayer>,
    background: Vec3,
) -> Vec3 {
    let Some(layer) = layer else {
        return background;
    };
    if dir.y <= 0.0 || eye.y >= layer.altitude_m {
        return background;
    }
    let t = (layer.altitude_m - eye.y) / dir.y;
    let p = eye + dir * t;
    let mu = dir.y.max(CIRRUS_MU_MIN);
    let density = cirrus_density(p.x, p.z, spread * t / mu, layer);
    if density <= 0.0 {
        return background;
    }
    let tau = density * layer.optical_depth / mu;
    let opacity = 1.0 - (-tau).exp();
    let sun = sun_light_at(sky, layer.altitude_m, sun_dir);
    let ambient = sky_ambient(sky, sun_dir) * 0.25;
    let light = (sun * phase_hg(dir.dot(sun_dir), CIRRUS_PHASE_G) + ambient) * (ALBEDO * opacity);
    let (inscatter, haze) = aerial(sky, dir, t, sun_dir);
    background * (1.0 - opacity) + light * haze + inscatter * opacity
}

#[cfg(test)]
mod tests {
    use super::*;

    fn covered_share(layer: &CirrusLayer) -> f32 {
        let n = 200;
        let mut covered = 0;
        for i in 0..n {
            for j in 0..n {
                let (x, z) = (i as f32 * 731.0, j as f32 * 517.0);
                if cirrus_density(x, z, 1.0, layer) > 0.0 {
                    covered += 1;
                }
            }
        }
        covered as f32 / (n * n) as f32
    }

    #[test]
    fn the_cover_is_about_the_share_covered() {
        for cover in [0.2_f32, 0.5, 0.8] {
            let layer = CirrusLayer {
                cover,
                ..CirrusLayer::default()
            };
            let share = covered_share(&layer);
            assert!((share - cover).abs() < 0.15, "cover {cover}: {share}");
        }
        let none = CirrusLayer::default();
        assert_eq!(covered_share(&none), 0.0);
        assert!(none.drawn().is_none());
    }

    #[test]
    fn streaks_run_along_the_layers_direction() {
        // The density changes little along the streaks and much across
        // them: the mean absolute difference over 500 m, both ways.
        let layer = CirrusLayer {
            cover: 0.5,
            direction_deg: 30.0,
            ..CirrusLayer::default()
        };
        let (s, c) = 30.0_f32.to_radians().sin_cos();
        let (mut along, mut across) = (0.0, 0.0);
        for i in 0..400 {
            let (x, z) = (i as f32 * 913.0, (i * i % 97) as f32 * 611.0);
            let d = cirrus_density(x, z, 1.0, &layer);
            along += (cirrus_density(x + 500.0 * s, z + 500.0 * c, 1.0, &layer) - d).abs();
            across += (cirrus_density(x + 500.0 * c, z - 500.0 * s, 1.0, &layer) - d).abs();
        }
        assert!(across > 3.0 * along, "across {across}, along {along}");
    }

    #[test]
    fn the_hash_is_uniform_and_the_noise_continuous() {
        let n = 100_000;
        let mean = (0..n).map(|k| cirrus_hash(k % 317, k / 317)).sum::<f32>() / n as f32;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        for k in 0..1000 {
            let (x, y) = (k as f32 * 0.37 - 150.0, k as f32 * 0.11 - 40.0);
            let jump = (cirrus_noise(x + 1e-3, y) - cirrus_noise(x, y)).abs();
            assert!(jump < 0.01, "at ({x}, {y}): {jump}");
        }
    }

    #[test]
    fn the_layer_dims_the_sky_and_glows_toward_the_sun() {
        let sky = SkyLight::analytic(25_000.0);
        let sun_dir = Vec3::new(0.0, 0.5, 0.866).normalize();
        let layer = CirrusLayer {
            cover: 1.0,
            ..CirrusLayer::default()
        };
        let eye = Vec3::new(0.0, 100.0, 0.0);
        let background = Vec3::splat(1.0);
        // Summed over rays fanned across the sky toward the sun and their
        // mirror images away from it (a single ray may meet a gap).
        let (mut lit, mut back) = (Vec3::ZERO, Vec3::ZERO);
        for k in 0..40 {
            let x = -0.4 + 0.02 * k as f32;
            let toward = Vec3::new(x, 0.45, 0.89).normalize();
            let away = Vec3::new(x, 0.45, -0.89).normalize();
            lit += cirrus_over(&sky, eye, toward, sun_dir, 1e-3, Some(&layer), Vec3::ZERO);
            back += cirrus_over(&sky, eye, away, sun_dir, 1e-3, Some(&layer), Vec3::ZERO);
        }
        assert!(lit.y > 3.0 * back.y, "toward the sun {lit}, away {back}");
        // Over a black sky it adds light; over a bright one it hides some.
        assert!(back.min_element() > 0.0);
        let dimmed = cirrus_over(&sky, eye, Vec3::Y, sun_dir, 1e-3, Some(&layer), background);
        assert!(dimmed.is_finite());
        // Without a layer, below the horizon, or from above the layer: the
        // background.
        assert_eq!(
            cirrus_over(&sky, eye, Vec3::Y, sun_dir, 1e-3, None, background),
            background
        );
        let down = Vec3::new(0.0, -0.2, 1.0).normalize();
        assert_eq!(
            cirrus_over(&sky, eye, down, sun_dir, 1e-3, Some(&layer), background),
            background
        );
        let high = Vec3::new(0.0, 10_000.0, 0.0);
        assert_eq!(
            cirrus_over(&sky, high, Vec3::Y, sun_dir, 1e-3, Some(&layer), background),
            background
        );
        // A grazing ray stays finite and at most opaque.
        let grazing = Vec3::new(0.0, 1e-4, 1.0).normalize();
        let g = cirrus_over(&sky, eye, grazing, sun_dir, 1e-3, Some(&layer), background);
        assert!(g.is_finite(), "{g}");
    }
}
