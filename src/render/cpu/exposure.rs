//! The exposure of a low sun and of twilight (`render.auto_exposure`):
//! the PNG pictures' exposure opens as the light on the ground fades
//! below a sun [`AUTO_EXPOSURE_FROM_DEG`] high, as a camera's incident
//! light meter would, so a sunset or a twilight sky is a picture, not
//! black (at the set exposure a sun 6° below the horizon leaves the sky
//! at about a five-thousandth of its radiance under a sun 30° up). Both
//! renderers use the number this computes (the GPU's as its `exposure`
//! uniform): the scene meters, not the frame, so a picture's exposure
//! does not depend on where the camera looks.

use std::sync::{Mutex, MutexGuard, OnceLock, PoisonError};

use glam::Vec3;

use super::sky::{AtmosphereConfig, SkyLight, SkyModel, sky_ambient, sun_direction, sun_light_at};
use super::sky_luts::SkyLuts;
use super::tone_map::luminance;

/// The sun's elevation, degrees, at and above which the exposure is
/// `render.exposure` itself (every shipped scene's sun is higher); below
/// it, the metered exposure opens ([`auto_exposure_factor`]).
pub const AUTO_EXPOSURE_FROM_DEG: f32 = 5.0;

/// The fraction of the fall in the ground's illuminance below
/// [`AUTO_EXPOSURE_FROM_DEG`] that the exposure makes up (in stops). All
/// of it would show twilight as bright as a low sun's day; a camera and
/// the eye keep dusk darker than day. Under the default physical sky
/// the ground's light falls 9.6 stops from a sun 5° up to one 6° below
/// the horizon; 0.8 opens the exposure 7.7 of them (docs/sky.md).
pub const AUTO_EXPOSURE_POWER: f32 = 0.8;

/// The most the metered exposure multiplies `render.exposure` by: 2^20,
/// 20 stops (a sun 10° below the horizon asks for 12.7).
pub const AUTO_EXPOSURE_MAX: f32 = 1_048_576.0;

/// The illuminance of level ground under the clear sky (its luminance, in
/// the renderer's radiance units): the sky's cosine-weighted mean
/// radiance over the upper hemisphere times π ([`sky_ambient`]) and the
/// sun's irradiance at `altitude_m` on the level ([`sun_light_at`]; none
/// once the sun is below the level, as a level surface sees it).
pub fn ground_illuminance(sky: &SkyLight, altitude_m: f32, sun_dir: Vec3) -> f32 {
    let sun = luminance(sun_light_at(sky, altitude_m, sun_dir)) * sun_dir.y.max(0.0);
    std::f32::consts::PI * luminance(sky_ambient(sky, sun_dir)) + sun
}

/// The factor on `render.exposure` for a sun at `sun_elevation_deg` seen
/// from `altitude_m` under `atmosphere`: 1 at and above
/// [`AUTO_EXPOSURE_FROM_DEG`] (nothing is built), below it
/// `(E(5°) / E(sun))^`[`AUTO_EXPOSURE_POWER`] of the ground's illuminance
/// ([`ground_illuminance`]) under the same atmosphere, at most
/// [`AUTO_EXPOSURE_MAX`]. The sun's azimuth changes neither term (the
/// sky-ambient table averages over it). Under the physical sky this
/// builds the sky's tables for both suns on the CPU (about 0.13 s on two
/// cores); the last [`METERED_KEPT`] results are kept, so a caller that
/// asks again for the same sky (the CLI, a panel moving another slider)
/// pays it once.
pub fn auto_exposure_factor(
    atmosphere: &AtmosphereConfig,
    sun_elevation_deg: f32,
    altitude_m: f32,
) -> f32 {
    if sun_elevation_deg >= AUTO_EXPOSURE_FROM_DEG {
        return 1.0;
    }
    let altitude_m = altitude_m.max(0.0);
    let key = MeterKey {
        model: atmosphere.model,
        aerosol_optical_depth: atmosphere.aerosol_optical_depth.to_bits(),
        sun_elevation_deg: sun_elevation_deg.to_bits(),
        altitude_m: altitude_m.to_bits(),
    };
    let kept = METERED.get_or_init(|| Mutex::new(Vec::new()));
    if let Some(&(_, f)) = lock(kept).iter().find(|(k, _)| *k == key) {
        return f;
    }
    let f = meter(atmosphere, sun_elevation_deg, altitude_m);
    let mut kept = lock(kept);
    if kept.len() >= METERED_KEPT {
        kept.remove(0);
    }
    kept.push((key, f));
    f
}

/// How many metered exposures [`auto_exposure_factor`] keeps.
pub const METERED_KEPT: usize = 8;

/// What the metered exposure depends on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct MeterKey {
    model: SkyModel,
    aerosol_optical_depth: u32,
    sun_elevation_deg: u32,
    altitude_m: u32,
}

static METERED: OnceLock<Mutex<Vec<(MeterKey, f32)>>> = OnceLock::new();

/// The kept results, also after a panic elsewhere left the lock poisoned
/// (they are plain numbers, never half written).
fn lock(kept: &Mutex<Vec<(MeterKey, f32)>>) -> MutexGuard<'_, Vec<(MeterKey, f32)>> {
    kept.lock().unwrap_or_else(PoisonError::into_inner)
}

/// [`auto_exposure_factor`] below [`AUTO_EXPOSURE_FROM_DEG`], uncached.
fn meter(atmosphere: &AtmosphereConfig, sun_elevation_deg: f32, altitude_m: f32) -> f32 {
    let sun = sun_direction(sun_elevation_deg, 0.0);
    let reference = sun_direction(AUTO_EXPOSURE_FROM_DEG, 0.0);
    let (lit, metered) = match atmosphere.sky_params() {
        Some(params) => {
            let mut luts = SkyLuts::build(params, reference, altitude_m);
            let lit = ground_illuminance(&physical(&luts, altitude_m), altitude_m, reference);
            luts.rebuild_sky_view(sun, altitude_m);
            let metered = ground_illuminance(&physical(&luts, altitude_m), altitude_m, sun);
            (lit, metered)
        }
        None => {
            // The analytic sky's light has no haze in it.
            let sky = SkyLight::analytic(1.0);
            (
                ground_illuminance(&sky, altitude_m, reference),
                ground_illuminance(&sky, altitude_m, sun),
            )
        }
    };
    if metered.is_nan() || metered <= 0.0 {
        return AUTO_EXPOSURE_MAX;
    }
    (lit / metered)
        .max(1.0)
        .powf(AUTO_EXPOSURE_POWER)
        .min(AUTO_EXPOSURE_MAX)
}

/// The physical model's sky light for `luts`, clear of clouds.
fn physical(luts: &SkyLuts, altitude_m: f32) -> SkyLight<'_> {
    SkyLight {
        luts: Some(luts),
        aerial_perspective: true,
        haze_distance_m: 0.0,
        camera_altitude_m: altitude_m,
        ground_cloud_light: Vec3::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Through civil twilight the physical sky's light on level ground
    /// falls as measured: the AMS Glossary of Meteorology ("civil
    /// twilight") gives a clear evening's horizontal illuminance as about
    /// 585-410 lux at sunset and 3.5-2 lux with the sun 6° down, a fall
    /// of 117 to 292 times. Ours, at the ground under the default
    /// atmosphere, falls within that.
    #[test]
    fn the_ground_darkens_through_civil_twilight_as_measured() {
        let params = AtmosphereConfig::default().sky_params().expect("physical");
        let (set, dusk) = (sun_direction(0.0, 0.0), sun_direction(-6.0, 0.0));
        let mut luts = SkyLuts::build(params, set, 0.0);
        let at_sunset = ground_illuminance(&physical(&luts, 0.0), 0.0, set);
        luts.rebuild_sky_view(dusk, 0.0);
        let at_dusk = ground_illuminance(&physical(&luts, 0.0), 0.0, dusk);
        let fall = at_sunset / at_dusk;
        assert!((117.0..=292.0).contains(&fall), "{fall}");
    }

    #[test]
    fn the_exposure_opens_as_the_sun_goes_down() {
        for model in [SkyModel::Physical, SkyModel::Analytic] {
            let atmosphere = AtmosphereConfig {
                model,
                ..AtmosphereConfig::default()
            };
            let factor = |el: f32| auto_exposure_factor(&atmosphere, el, 100.0);
            // A day's sun keeps the set exposure.
            for el in [5.0, 8.0, 30.0, 90.0] {
                assert_eq!(factor(el), 1.0, "{model:?} at {el}°");
            }
            // Below 5° it opens, more the lower the sun.
            let mut last = 1.0;
            for el in [4.0, 2.0, 0.0, -3.0, -6.0, -10.0] {
                let f = factor(el);
                assert!(
                    f >= last && f <= AUTO_EXPOSURE_MAX,
                    "{model:?} at {el}°: {f}"
                );
                last = f;
            }
            if model == SkyModel::Physical {
                // Twilight's ground is thousands of times darker than a
                // low sun's: 6° below the horizon opens the exposure by
                // more than 2^7 (the analytic sky never darkens that far).
                // Measured: 2^7.7 and 2^12.7; the light was metered (not
                // the cap of a sky with no light at all).
                assert!(factor(-6.0) > 128.0, "{}", factor(-6.0));
                assert!(factor(-10.0) > 4.0 * factor(-6.0));
                assert!(factor(-10.0) < AUTO_EXPOSURE_MAX / 16.0);
                // Asked again, the kept result.
                assert_eq!(factor(-6.0), meter(&atmosphere, -6.0, 100.0));
            }
        }
    }
}
