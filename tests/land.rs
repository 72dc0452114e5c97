//! The land drawn as fields and woods (`[render.ground] land`), through the
//! renderer: the flat ground's pixels carry the land's albedo where their
//! ray meets it, the mean light of the land stays the plain land's, and
//! the terrain's level ground is tinted the same way.

use cumulus::prepare::Prepared;
use cumulus::render::cpu::renderer::march_ray;
use cumulus::render::cpu::sky::{Land, Surface};
use cumulus::render::cpu::stills::render_linear;
use cumulus::scene::Scene;
use glam::Vec3;

const W: u32 = 64;
const H: u32 = 48;

fn lum(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// fair_weather seen from 400 m looking 35° down, its ground `land`,
/// rendered on the CPU at 64x48 (one march per pixel).
fn ground_view(land: Land, scene: &str) -> Vec<Vec3> {
    let mut sc = Scene::load(std::path::Path::new(scene)).expect("shipped scene");
    // A quick light volume: the scenes' 1024 photons a column take a
    // minute to build on lavapipe; these tests do not measure the light.
    sc.render.light_photons = 16;
    sc.render.camera_position_m = [5000.0, 400.0, 5000.0];
    sc.render.camera_pitch_deg = -35.0;
    sc.render.ground.land = land;
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    let fr = p.frame(&sc.render, sc.render.quality());
    render_linear(W, H, &fr)
}

/// The pixels' luminance ratios `fields / plain`, their mean and their
/// standard deviation.
fn luminance_ratios(fields: &[Vec3], plain: &[Vec3]) -> (Vec<f32>, f32, f32) {
    let ratios: Vec<f32> = fields
        .iter()
        .zip(plain)
        .map(|(f, p)| lum(*f) / lum(*p))
        .collect();
    let n = ratios.len() as f32;
    let mean = ratios.iter().sum::<f32>() / n;
    let spread = (ratios.iter().map(|r| (r - mean).powi(2)).sum::<f32>() / n).sqrt();
    (ratios, mean, spread)
}

#[test]
fn fields_vary_the_land_around_the_plain_lands_light() {
    let fields = ground_view(Land::Fields, "scenes/fair_weather.toml");
    let plain = ground_view(Land::Plain, "scenes/fair_weather.toml");
    // Pixel by pixel over the plain land (the clouds' shadows and the
    // haze are the same in both): the fields' albedo shows as the ratio's
    // spread, within the darkest and the brightest tint over the plain
    // land's (woods about 0.55, stubble about 1.6). The mean over the land
    // is the plain land's (land.rs's tests); this view of a kilometre or
    // two has its own share of woods.
    let (ratios, mean, spread) = luminance_ratios(&fields, &plain);
    assert!(
        spread > 0.12,
        "the ratio's spread {spread} (mean {mean}): the fields do not show"
    );
    for r in &ratios {
        assert!((0.4..2.0).contains(r), "a pixel's ratio {r}");
    }
}

#[test]
fn a_ground_pixel_is_the_land_where_its_ray_meets_it() {
    use cumulus::render::cpu::frame::Quality;
    use cumulus::render::cpu::land::{flat_ground_albedo, land_albedo};
    use cumulus::render::cpu::renderer::flat_ground_shadow;
    use cumulus::render::cpu::sky::{LAND_ALBEDO, background_radiance, sun_direction};
    let mut sc = Scene::load(std::path::Path::new("scenes/fair_weather.toml")).expect("scene");
    sc.render.light_photons = 16;
    sc.render.camera_position_m = [5000.0, 400.0, 5000.0];
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    let fr = p.frame(&sc.render, sc.render.quality());
    let sun = sun_direction(sc.render.sun_elevation_deg, sc.render.sun_azimuth_deg);
    let origin = Vec3::new(5000.0, 400.0, 5000.0);
    let spread = 1e-3;
    let mut differs = 0;
    for k in 0..64 {
        // Rays down to the ground 0.5-3 km away, under the band.
        let a = k as f32 * 0.37;
        let dir = Vec3::new(a.cos(), -0.25 - 0.01 * (k % 7) as f32, a.sin()).normalize();
        let albedo = flat_ground_albedo(origin, dir, spread, &fr);
        // The land where this ray meets the ground, found here.
        let t = origin.y / -dir.y;
        let hit = origin + dir * t;
        let own = land_albedo(
            hit.x,
            hit.z,
            spread * t / -dir.y,
            fr.fields.cloud_map.noise(),
        );
        assert!(
            (albedo - own).abs().max_element() < 1e-6,
            "{albedo} against {own}"
        );
        let sky = fr.sky_light();
        let shadow = flat_ground_shadow(origin, dir, sun, &fr);
        let expected = background_radiance(&sky, dir, sun, None, shadow, albedo, (Vec3::ZERO, 1.0));
        let pixel = march_ray(origin, dir, 0.5, spread, &fr).radiance;
        assert!(
            (pixel - expected).abs().max_element() <= 1e-5 * expected.max_element(),
            "{pixel} against {expected}"
        );
        differs += ((albedo - LAND_ALBEDO).abs().max_element() > 0.005) as u32;
    }
    assert!(
        differs > 40,
        "{differs} of 64 points off the plain land's albedo"
    );
    // Near the rays' end the land fades to the plain land's colour, so
    // it has no seam where the rays stop; plain land is that colour.
    let max_d = fr.quality.max_distance_m;
    let dir = Vec3::new(1.0, -400.0 / (0.995 * max_d), 0.0).normalize();
    let far = flat_ground_albedo(origin, dir, spread, &fr);
    assert!(
        (far - LAND_ALBEDO).abs().max_element() < 0.03 * LAND_ALBEDO.max_element(),
        "{far}"
    );
    let q = Quality {
        land_fields: false,
        ..sc.render.quality()
    };
    let plain = p.frame(&sc.render, q);
    let down = Vec3::new(0.3, -0.5, 0.2).normalize();
    assert_eq!(
        flat_ground_albedo(origin, down, spread, &plain),
        LAND_ALBEDO
    );
}

#[test]
fn the_terrains_level_ground_is_tinted_too() {
    let fields = ground_view(Land::Fields, "scenes/evening.toml");
    let plain = ground_view(Land::Plain, "scenes/evening.toml");
    let (_, _, spread) = luminance_ratios(&fields, &plain);
    assert!(spread > 0.1, "the ratio's spread on the terrain {spread}");
}

#[test]
fn the_sea_has_no_fields() {
    let mut sc = Scene::load(std::path::Path::new("scenes/bomex.toml")).expect("scene");
    sc.render.light_photons = 16;
    assert_eq!(sc.render.ground.surface, Surface::Sea);
    sc.render.ground.land = Land::Fields;
    assert!(!sc.render.quality().land_fields);
}
