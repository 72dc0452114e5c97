//! Tests of `sky.rs`: the sea and the land under the analytic sky, and
//! the physical sky's sun, air, disk and ground light.

mod analytic {
    use super::super::*;
    use crate::render::cpu::waves::flat_sea;

    /// No clouds in the sea's mirror.
    const NONE: (Vec3, f32) = (Vec3::ZERO, 1.0);

    #[test]
    fn fresnel_goes_from_two_percent_to_all() {
        assert!((fresnel_water(1.0) - 0.0204).abs() < 1e-6);
        assert!((fresnel_water(0.0) - 1.0).abs() < 1e-6);
        let mut last = 1.0;
        for i in 0..=100 {
            let f = fresnel_water(i as f32 / 100.0);
            assert!(f <= last + 1e-7);
            last = f;
        }
    }

    /// Looking down the sea is darker than the sky it mirrors, near the
    /// horizon it is nearly the horizon sky, and the brightest point is
    /// the glint where the sun's mirror image lies; a stronger wind
    /// spreads the glint wider and dimmer.
    #[test]
    fn the_sea_mirrors_the_sky_and_glints_under_the_sun() {
        let sun = sun_direction(30.0, 180.0);
        let a = &SkyLight::analytic(25_000.0);
        let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        let at = |elev_deg: f32, az_deg: f32, wind: f32| {
            let d = -sun_direction(elev_deg, az_deg) * Vec3::new(-1.0, 1.0, -1.0);
            sea_radiance(a, d.normalize(), sun, flat_sea(wind), 1.0, NONE)
        };
        // Away from the sun (azimuth 0), straight down and near the horizon.
        let down = lum(at(80.0, 0.0, 7.0));
        let sky_up = lum(sky_radiance(a, Vec3::Y, sun));
        assert!(down < 0.2 * sky_up, "{down} {sky_up}");
        let near = at(0.5, 0.0, 7.0);
        let horizon = sky_radiance(a, Vec3::new(0.0, 0.0, 1.0), sun);
        assert!((lum(near) - lum(horizon)).abs() < 0.1 * lum(horizon));
        // The mirror image of the sun: 30° below the horizon toward it.
        let glint = lum(at(30.0, 180.0, 7.0));
        let beside = lum(at(30.0, 140.0, 7.0));
        assert!(
            glint > 10.0 * beside && glint > 5.0 * sky_up,
            "{glint} {beside}"
        );
        let rough = lum(at(30.0, 180.0, 20.0));
        assert!(rough < glint && lum(at(30.0, 160.0, 20.0)) > lum(at(30.0, 160.0, 7.0)));
        // The background picks the sea below the horizon only, and a
        // cloud's shadow dims the glint.
        let up = Vec3::new(0.0, 0.5, 0.866);
        assert_eq!(
            background_radiance(a, up, sun, Some(flat_sea(7.0)), 0.0, LAND_ALBEDO, NONE),
            background_radiance(a, up, sun, None, 1.0, LAND_ALBEDO, NONE)
        );
        let d = Vec3::new(0.0, -0.5, 0.866);
        assert_ne!(
            background_radiance(a, d, sun, Some(flat_sea(7.0)), 1.0, LAND_ALBEDO, NONE),
            background_radiance(a, d, sun, None, 1.0, LAND_ALBEDO, NONE)
        );
        let g = -sun * Vec3::new(-1.0, 1.0, -1.0);
        let shaded = lum(sea_radiance(a, g, sun, flat_sea(7.0), 0.1, NONE));
        assert!(shaded < 0.2 * glint, "{shaded} {glint}");
        // The land in a cloud's shadow is darker by the sun's part, and
        // keeps the sky's: on a clear day the sky gives 10-30 % of the
        // irradiance on level ground at a 30° sun.
        let (lit, dark) = (
            land_radiance(a, d, sun, 1.0, LAND_ALBEDO),
            land_radiance(a, d, sun, 0.0, LAND_ALBEDO),
        );
        let ratio = lum(dark) / lum(lit);
        assert!((0.1..0.3).contains(&ratio), "{ratio}");
    }
}

mod physical {
    use super::super::*;

    fn luts(sun_elevation_deg: f32, altitude_m: f32) -> (SkyLuts, Vec3) {
        let sun = sun_direction(sun_elevation_deg, 135.0);
        let params = AtmosphereConfig::default().sky_params().expect("physical");
        (SkyLuts::build(params, sun, altitude_m), sun)
    }

    fn light(luts: &SkyLuts) -> SkyLight<'_> {
        SkyLight {
            luts: Some(luts),
            aerial_perspective: true,
            haze_distance_m: 25_000.0,
            camera_altitude_m: luts.camera_altitude_m,
            ground_cloud_light: Vec3::ZERO,
        }
    }

    /// A rough sea seen near the horizon mirrors the mean of the sky its
    /// waves send the reflected rays to (Cox and Munk's slopes at 7 m/s
    /// spread them by 16°, none below the horizon): `mirrored_sky`'s eight
    /// strata come within 1 % of that mean over 4000, which away from the
    /// sun is a few per cent darker than the sky at the horizon; a calm
    /// sea's mirror is the horizon's. A flat mirror would give the
    /// horizon's sky whatever the wind (3.4 % off here, more under a
    /// hazier horizon).
    #[test]
    fn a_rough_sea_mirrors_the_mean_sky_of_its_slopes() {
        let (l, sun) = luts(40.0, 30.0);
        let sky = &light(&l);
        let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        // Looking 1° down, away from the sun (in the south-east).
        let e = 1f32.to_radians();
        let away = Vec3::new(-sun.x, 0.0, -sun.z).normalize();
        let dir = away * e.cos() - Vec3::Y * e.sin();
        let horizon = lum(sky_above(sky, away * e.cos() + Vec3::Y * e.sin(), sun));
        let waves = crate::render::cpu::waves::flat_sea(7.0);
        let n = 4000;
        let mean = (0..n)
            .map(|k| {
                let u = (k as f32 + 0.5) / n as f32;
                let r = reflected_elevation(e, waves.z, u);
                lum(sky_above(sky, away * r.cos() + Vec3::Y * r.sin(), sun))
            })
            .sum::<f32>()
            / n as f32;
        let rough = lum(mirrored_sky(sky, dir, waves, sun));
        assert!((rough / mean - 1.0).abs() < 0.01, "{rough} vs {mean}");
        assert!(rough < 0.98 * horizon, "{rough} vs {horizon}");
        let calm = lum(mirrored_sky(sky, dir, Vec3::new(0.0, 0.0, 1e-5), sun));
        assert!((calm / horizon - 1.0).abs() < 0.01, "{calm} vs {horizon}");
    }

    /// The sun's light through the air follows its elevation: nearly
    /// white at noon (blue within 20 % of red), golden near the horizon
    /// (red at least twice blue at 5°, and dimmer), gone once it has set;
    /// the analytic model's air mass does the same but never sets.
    #[test]
    fn sunlight_warms_as_the_sun_sinks_and_goes_at_sunset() {
        let at = |e: f32| {
            let (l, sun) = luts(e, 1000.0);
            sun_light_at(&light(&l), 1500.0, sun)
        };
        let noon = at(80.0);
        assert!(noon.z > 0.8 * noon.x && noon.x < 8.0, "{noon}");
        let low = at(5.0);
        assert!(low.x > 2.0 * low.z && low.y < 0.8 * noon.y, "{low}");
        let set = at(-3.0);
        assert!(set.max_element() < 1e-3, "{set}");
    }

    /// The sky is blue overhead and paler toward the horizon at noon;
    /// distance fades things toward the horizon's light (a black ground
    /// 30 km off takes most of its light from the air, one 1 km off a
    /// little); with aerial perspective off nothing fades.
    #[test]
    fn the_sky_is_blue_and_distance_fades_into_it() {
        let (l, sun) = luts(60.0, 500.0);
        let s = &light(&l);
        let zenith = sky_above(s, Vec3::Y, sun);
        assert!(zenith.z > 1.5 * zenith.x, "{zenith}");
        let horizon = sky_above(s, Vec3::new(0.0, 0.02, -1.0).normalize(), sun);
        assert!(
            horizon.x / horizon.z > zenith.x / zenith.z,
            "{horizon} {zenith}"
        );
        let dir = Vec3::new(0.0, -0.01, -1.0).normalize();
        let (far, t_far) = aerial(s, dir, 30_000.0, sun);
        let (near, t_near) = aerial(s, dir, 1_000.0, sun);
        assert!(t_far.y < 0.5 && t_near.y > 0.85, "{t_far} {t_near}");
        assert!(far.y > 4.0 * near.y, "{far} {near}");
        let off = SkyLight {
            aerial_perspective: false,
            ..*s
        };
        assert_eq!(aerial(&off, dir, 30_000.0, sun), (Vec3::ZERO, Vec3::ONE));
        // The sky's mean light exceeds the zenith's (the horizon is brighter).
        assert!(sky_ambient(s, sun).y > zenith.y);
    }

    /// The limb-darkened disk carries the sun's irradiance at the camera:
    /// its integral over the disk (a fine grid of directions) is that
    /// irradiance within 2 %, and its centre is brighter than its edge.
    #[test]
    fn the_sun_disk_integrates_to_the_suns_irradiance() {
        let (l, sun) = luts(30.0, 0.0);
        let s = &light(&l);
        let e = sun_light_at(s, 0.0, sun);
        let radius = l.params.sun_angular_radius_deg.to_radians();
        let (u, v) = (
            sun.cross(Vec3::Y).normalize(),
            sun.cross(sun.cross(Vec3::Y)).normalize(),
        );
        let n = 200;
        let h = 2.4 * radius / n as f32;
        let mut sum = Vec3::ZERO;
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (
                    (i as f32 + 0.5) * h - 1.2 * radius,
                    (j as f32 + 0.5) * h - 1.2 * radius,
                );
                let d = (sun + u * x + v * y).normalize();
                sum += sun_disk(s, d, sun) * h * h;
            }
        }
        assert!((sum.y / e.y - 1.0).abs() < 0.02, "{sum} {e}");
        let edge = sun_disk(s, (sun + u * 0.95 * radius).normalize(), sun);
        assert!(edge.y < 0.75 * sun_disk(s, sun, sun).y);
    }

    /// Clouds' undersides see the ground: land sends up its sunlit albedo
    /// (brighter under a higher sun), the sea much less.
    #[test]
    fn the_ground_lights_from_below() {
        let (l, sun) = luts(60.0, 100.0);
        let s = &light(&l);
        let land = ground_up(s, sun, false);
        let sea = ground_up(s, sun, true);
        assert!(land.y > 3.0 * sea.y && sea.y > 0.0, "{land} {sea}");
        let (l5, sun5) = luts(5.0, 100.0);
        assert!(ground_up(&light(&l5), sun5, false).y < 0.5 * land.y);
    }
}
