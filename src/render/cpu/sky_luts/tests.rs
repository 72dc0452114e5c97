//! The atmosphere against closed forms and fine integration, the tables
//! against direct marches, and the sun disk against its irradiance.

use std::sync::OnceLock;

use glam::Vec3;

use super::*;

/// A noon sun: high enough that the blue transmittance at the ground,
/// e^{-0.271 / sin e}, stays above 0.75 (it is 0.76 at 85°, 0.73 at 60°).
const NOON_DEG: f32 = 85.0;

fn dir_at(elevation_deg: f32, azimuth_deg: f32) -> Vec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos())
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// The default atmosphere's transmittance and multiple-scattering tables.
fn tables() -> &'static (Lut2, Lut2) {
    static TABLES: OnceLock<(Lut2, Lut2)> = OnceLock::new();
    TABLES.get_or_init(|| {
        let t = build_transmittance(&SkyParams::default());
        let ms = build_multi_scattering(&SkyParams::default(), &t);
        (t, ms)
    })
}

/// The tables for a sun at `elevation_deg` (azimuth 0) and a camera.
fn luts(elevation_deg: f32, camera_altitude_m: f32) -> SkyLuts {
    let (p, (t, ms)) = (SkyParams::default(), tables());
    let sun_dir = dir_at(elevation_deg, 0.0);
    let sky_view = build_sky_view(&p, t, ms, sun_dir, camera_altitude_m);
    let (transmittance, multi_scattering) = (t.clone(), ms.clone());
    SkyLuts {
        sky_ambient: build_sky_ambient(&p, &sky_view, camera_altitude_m),
        params: p,
        transmittance,
        multi_scattering,
        sky_view,
        camera_altitude_m,
        sun_dir,
    }
}

fn fine_transmittance(r: f32, mu: f32, p: &SkyParams) -> Vec3 {
    (-optical_depth(r, mu, distance_to_top(r, mu, p.top_radius_km), 10_000, p)).exp()
}

fn assert_relative(a: Vec3, b: Vec3, tolerance: f32, what: &str) {
    let error = ((a - b).abs() / b.abs()).max_element();
    assert!(
        error <= tolerance,
        "{what}: {a} against {b}, relative error {error}"
    );
}

#[test]
fn zenith_transmittance_matches_truncated_exponential_column() {
    // The 40 midpoint steps of 2.5 km underestimate an exponential layer
    // of scale H by (x/2)/sinh(x/2), x = 2.5/H: 16 % of the Mie column
    // (8e-4 of optical depth) and 0.4 % of the Rayleigh one (1e-3): 0.2 %.
    const TOLERANCE: f32 = 0.005;
    let p = SkyParams::default();
    let depth = p.top_radius_km - p.ground_radius_km;
    let column = |h: f32| h * (1.0 - (-depth / h).exp());
    let tau = p.rayleigh_scattering * column(p.rayleigh_scale_height_km)
        + Vec3::splat(p.mie_extinction * column(p.mie_scale_height_km))
        + p.ozone_absorption * (0.5 * p.ozone_width_km);
    let lut = transmittance_to_top(&tables().0, p.ground_radius_km, 1.0, &p);
    assert_relative(lut, (-tau).exp(), TOLERANCE, "zenith transmittance");
}

#[test]
fn transmittance_uv_round_trips() {
    // f32 on radii of 6400 km: the distances carry ~1e-3 km of rounding.
    const UV_TOLERANCE: f32 = 1e-4;
    let p = SkyParams::default();
    for i in 0..=40 {
        for j in 0..=20 {
            let (u, v) = (
                unit_to_uv(i as f32 / 40.0, 256),
                unit_to_uv(j as f32 / 20.0, 64),
            );
            let (r, mu) = transmittance_uv_to_r_mu(u, v, &p);
            let (u2, v2) = transmittance_r_mu_to_uv(r, mu, &p);
            assert!(
                (u2 - u).abs() < UV_TOLERANCE && (v2 - v).abs() < UV_TOLERANCE,
                "{u},{v}"
            );
        }
    }
    let (r, mu) = transmittance_uv_to_r_mu(unit_to_uv(1.0, 256), unit_to_uv(0.0, 64), &p);
    assert!(
        (r - p.ground_radius_km).abs() < 1e-3 && mu.abs() < 1e-4,
        "ground horizon"
    );
}

#[test]
fn horizontal_transmittance_at_the_ground_matches_fine_integration() {
    // The ground's horizon is a texel centre: this is the 40-step
    // integration of a 1134 km path against 10⁴ steps.
    const TOLERANCE: f32 = 0.01;
    let p = SkyParams::default();
    let lut = transmittance_to_top(&tables().0, p.ground_radius_km, 0.0, &p);
    let fine = fine_transmittance(p.ground_radius_km, 0.0, &p);
    assert_relative(lut, fine, TOLERANCE, "horizontal");
}

#[test]
fn transmittance_between_texels_matches_fine_integration() {
    // Bilinear filtering of e^{-τ} between two rows whose τ differs by
    // Δτ errs by up to Δτ²/8; near the ground's horizon (blue, 64 rows)
    // Δτ ≈ 0.33, so 1.4 %.
    const TOLERANCE: f32 = 0.02;
    let p = SkyParams::default();
    for (h, mu) in [
        (0.0, 0.013),
        (0.7, 0.0),
        (3.3, -0.02),
        (0.2, 0.1),
        (10.0, 0.3),
    ] {
        let r = p.ground_radius_km + h;
        let lut = transmittance_to_top(&tables().0, r, mu, &p);
        assert_relative(
            lut,
            fine_transmittance(r, mu, &p),
            TOLERANCE,
            "between texels",
        );
    }
}

#[test]
fn noon_zenith_is_blue_and_sunlight_near_white() {
    let sky = luts(NOON_DEG, 0.0);
    let zenith = sky_view_radiance(&sky, Vec3::Y, sky.sun_dir);
    assert!(
        zenith.z > zenith.y && zenith.y > zenith.x,
        "zenith {zenith}"
    );
    let sun = sun_radiance_at(&sky, 0.0, sky.sun_dir) / sky.params.sun_irradiance;
    assert!(
        sun.min_element() > 0.75 && sun.x / sun.z < 1.3,
        "sunlight {sun}"
    );
}

#[test]
fn noon_zenith_luminance_is_on_the_renderers_scale() {
    // The analytic sky's noon zenith is ~0.3; this atmosphere's is
    // physically dimmer (0.24, of which Mie glow 5° from the sun).
    let sky = luts(NOON_DEG, 0.0);
    let zenith = luminance(sky_view_radiance(&sky, Vec3::Y, sky.sun_dir));
    assert!((0.1..0.6).contains(&zenith), "zenith luminance {zenith}");
}

#[test]
fn low_sun_light_is_red_and_sky_near_it_warm() {
    let sky = luts(2.0, 0.0);
    let sun = sun_radiance_at(&sky, 0.0, sky.sun_dir);
    assert!(sun.x > 2.0 * sun.z, "sunlight {sun}");
    let near = sky_view_radiance(&sky, dir_at(1.0, 3.0), sky.sun_dir);
    assert!(
        near.x > near.y && near.y > near.z,
        "sky near the sun {near}"
    );
}

#[test]
fn twilight_zenith_is_dim_but_lit() {
    let noon = luminance(sky_view_radiance(
        &luts(NOON_DEG, 0.0),
        Vec3::Y,
        dir_at(NOON_DEG, 0.0),
    ));
    let dusk = luminance(sky_view_radiance(
        &luts(-4.0, 0.0),
        Vec3::Y,
        dir_at(-4.0, 0.0),
    ));
    let ratio = dusk / noon;
    assert!((1e-3..1e-1).contains(&ratio), "twilight / noon {ratio}");
}

#[test]
fn sun_light_vanishes_once_set_but_lights_the_air_above() {
    // At 10 km the horizon dips 3.2°: a sun 1° below the ground's
    // horizon still shines there.
    let sky = luts(-1.0, 0.0);
    assert_eq!(sun_radiance_at(&sky, 0.0, sky.sun_dir), Vec3::ZERO);
    assert!(sun_radiance_at(&sky, 10_000.0, sky.sun_dir).min_element() > 0.0);
}

#[test]
fn multiple_scattering_brightens_noon_zenith_modestly() {
    let sky = luts(NOON_DEG, 0.0);
    let zero = Lut2 {
        width: 2,
        height: 2,
        texels: vec![[0.0; 4]; 4],
    };
    let single = SkyLuts {
        multi_scattering: zero,
        ..sky.clone()
    };
    let with = luminance(sky_radiance_marched(&sky, 0.0, Vec3::Y, sky.sun_dir));
    let without = luminance(sky_radiance_marched(&single, 0.0, Vec3::Y, sky.sun_dir));
    let gain = with / without - 1.0;
    assert!(
        (0.05..0.40).contains(&gain),
        "multiple scattering adds {gain}"
    );
}

#[test]
fn multi_scattering_table_is_finite_and_non_negative() {
    let ms = &tables().1;
    assert!(
        ms.texels
            .iter()
            .flatten()
            .all(|v| v.is_finite() && *v >= 0.0)
    );
    assert!(ms.texels.iter().any(|t| t[2] > 0.01), "Ψ_ms all but zero");
}

#[test]
fn sky_view_texel_coords_invert_texel_direction() {
    let p = SkyParams::default();
    let r = radius_at_altitude(500.0, &p);
    // Rows 53 and 54 are both the horizon (from below and from above).
    for (x, y) in [(0, 0), (7, 20), (100, 52), (150, 55), (191, 107), (33, 80)] {
        let (mu, azimuth) = sky_view_texel_direction(x, y, r, &p);
        let (fx, fy, lo, hi) = sky_view_texel_coords(mu, azimuth, r, &p);
        assert!(
            (fx - x as f32).abs() < 1e-2 && (fy - y as f32).abs() < 1e-2,
            "{x},{y}"
        );
        assert!((lo..=hi).contains(&y));
    }
}

#[test]
fn sky_view_lookup_matches_direct_march() {
    // Bilinear between texels; the latitude rows are densest at the
    // horizon, where the radiance changes fastest (measured: < 1 %).
    const TOLERANCE: f32 = 0.03;
    for sun_deg in [30.0, 2.0] {
        let sky = luts(sun_deg, 500.0);
        let dirs = [
            (90.0, 0.0),
            (45.0, 90.0),
            (10.0, 40.0),
            (1.0, 100.0),
            (0.1, 20.0),
        ];
        let below = [
            (0.3, 170.0),
            (-0.5, 30.0),
            (-10.0, 60.0),
            (sun_deg + 3.0, 2.0),
        ];
        for (e, a) in dirs.into_iter().chain(below) {
            let dir = dir_at(e, a);
            let lut = sky_view_radiance(&sky, dir, sky.sun_dir);
            let march = sky_radiance_marched(&sky, 500.0, dir, sky.sun_dir);
            assert_relative(
                lut,
                march,
                TOLERANCE,
                &format!("sun {sun_deg}°, view {e}°, {a}°"),
            );
        }
    }
}

#[test]
fn aerial_perspective_vanishes_at_zero_distance() {
    let sky = luts(30.0, 0.0);
    let (inscatter, t) = aerial_perspective(&sky, 300.0, dir_at(0.0, 90.0), 0.0, sky.sun_dir);
    assert_eq!((inscatter, t), (Vec3::ZERO, Vec3::ONE));
    let (inscatter, t) = aerial_perspective(&sky, 300.0, dir_at(0.0, 90.0), 1.0, sky.sun_dir);
    assert!(inscatter.max_element() < 1e-4 && t.min_element() > 0.9999);
}

#[test]
fn aerial_perspective_over_30_km_approaches_the_horizon_sky() {
    // A horizontal 30 km path rises 70 m: its transmittance is the
    // ground air's, e^{-σ_t(0)·30 km}, to within that rise (< 2 %).
    const FLAT_TOLERANCE: f32 = 0.02;
    // Its in-scattering is the horizon sky's times the share of the
    // horizon's opacity it holds, (1 - T_30)/(1 - T_horizon), to within
    // how much the source (sun transmittance, Mie) varies along the
    // horizon's path beyond 30 km (measured: 5 % in red).
    const SHARE_TOLERANCE: f32 = 0.1;
    let sky = luts(NOON_DEG, 0.0);
    let (dir, p) = (dir_at(0.0, 90.0), &sky.params);
    let (inscatter, t) = aerial_perspective(&sky, 0.0, dir, 30_000.0, sky.sun_dir);
    let flat = (-medium_at(0.0, p).extinction * 30.0).exp();
    assert_relative(t, flat, FLAT_TOLERANCE, "30 km transmittance");
    assert!(
        t.z < 0.5 && t.max_element() < 0.8,
        "30 km transmittance {t}"
    );
    let (horizon, t_horizon) = aerial_perspective(&sky, 0.0, dir, 1e7, sky.sun_dir);
    let sky_horizon = sky_view_radiance(&sky, dir, sky.sun_dir);
    assert_relative(
        horizon,
        sky_horizon,
        0.01,
        "whole path against the sky view",
    );
    let share = (Vec3::ONE - t) / (Vec3::ONE - t_horizon);
    assert_relative(
        inscatter,
        sky_horizon * share,
        SHARE_TOLERANCE,
        "30 km inscatter",
    );
}

#[test]
fn sun_disk_integrates_to_transmitted_irradiance() {
    // A 600² grid over the disk's tangent square: the limb's cells
    // (brightness 0.4, ~1/600 of the area each side) leave < 0.2 %.
    const TOLERANCE: f32 = 0.01;
    let sky = luts(20.0, 0.0);
    let irradiance = sun_radiance_at(&sky, 0.0, sky.sun_dir);
    let alpha = sky.params.sun_angular_radius_deg.to_radians();
    let e1 = sky.sun_dir.cross(Vec3::Y).normalize();
    let e2 = e1.cross(sky.sun_dir);
    let n = 600;
    let cell = 2.2 * alpha / n as f32;
    let mut sum = glam::DVec3::ZERO;
    for i in 0..n {
        for j in 0..n {
            let (a, b) = (
                (i as f32 + 0.5) * cell - 1.1 * alpha,
                (j as f32 + 0.5) * cell - 1.1 * alpha,
            );
            let dir = (sky.sun_dir + a * e1 + b * e2).normalize();
            let solid_angle = cell * cell / (1.0 + a * a + b * b).powf(1.5);
            sum +=
                (sun_disk_radiance(dir, sky.sun_dir, irradiance, alpha) * solid_angle).as_dvec3();
        }
    }
    assert_relative(sum.as_vec3(), irradiance, TOLERANCE, "disk integral");
    let centre = sun_disk_radiance(sky.sun_dir, sky.sun_dir, irradiance, alpha);
    let limb = sun_disk_radiance(
        (sky.sun_dir + 0.99 * alpha * e1).normalize(),
        sky.sun_dir,
        irradiance,
        alpha,
    );
    assert!(
        limb.x < 0.6 * centre.x,
        "limb {limb} against centre {centre}"
    );
}

#[test]
fn lut_sample_reads_texel_centres_and_clamps_to_edge() {
    let lut = Lut2::from_fn(4, 3, |x, y| Vec3::new(x as f32, y as f32, 1.0));
    assert_eq!(lut.sample(2.5 / 4.0, 1.5 / 3.0), Vec3::new(2.0, 1.0, 1.0));
    assert_eq!(lut.sample(2.0 / 4.0, 2.0 / 3.0), Vec3::new(1.5, 1.5, 1.0));
    assert_eq!(lut.sample(-1.0, 2.0), Vec3::new(0.0, 2.0, 1.0));
    assert_eq!(lut.sample_texels(1.0, 2.7, 0, 1), Vec3::new(1.0, 1.0, 1.0));
}
