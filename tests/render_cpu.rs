//! The CPU reference renderer: density, lighting and image properties.

use cumulus::render::camera::Camera;
use cumulus::render::cloud_map::{CloudMap, CloudMapConfig};
use cumulus::render::cpu::density::{
    BASE_RAMP, DensityParams, Fields, band_segment, density_at, footprint,
};
use cumulus::render::cpu::frame::{Frame, Quality};
use cumulus::render::cpu::light_volume::LightVolume;
use cumulus::render::cpu::lighting::ALBEDO;
use cumulus::render::cpu::lighting::{
    SHADOW_STEP_SPAN_M, ShadowSteps, phase_dual, shadow_ray_length, sun_optical_depth,
    sun_transmittance,
};
use cumulus::render::cpu::renderer::{flat_ground_shadow, march_ray};
use cumulus::render::cpu::sea::sea_waves_at;
use cumulus::render::cpu::sea::{ReflectionLight, reflected_clouds, sea_reflection};
use cumulus::render::cpu::sky::{
    AtmosphereConfig, LAND_ALBEDO, SkyModel, background_radiance, sun_direction, sun_light_at,
};
use cumulus::render::cpu::stills::render_linear;
use cumulus::render::cpu::tone_map::to_srgb8;
use cumulus::render::cpu::waves::{
    REFLECTION_MIN_ELEVATION, cross_slope, reflected_elevation, reflected_ray,
};
use cumulus::render::cpu::waves::{flat_sea, slope_variance};
use cumulus::sim::ProjectedField;
use glam::Vec3;

const D: DensityParams = DensityParams {
    band_bottom_m: 600.0,
    band_top_m: 1600.0,
    coverage: 0.75,
    extinction_per_m: 0.04,
    map_extent_m: 10_000.0,
    detail_strength: 0.0,
    detail_scale_m: 250.0,
    fine_detail: true,
};

/// `steps` shadow steps, no more toward the sun, each sample at its
/// step's centre.
fn centred(steps: u32) -> ShadowSteps {
    ShadowSteps {
        steps,
        forward: 1.0,
        offset: 0.5,
    }
}

fn cloud_map() -> CloudMap {
    CloudMap::generate(&CloudMapConfig {
        size: 128,
        ..CloudMapConfig::default()
    })
}

#[test]
fn density_is_zero_outside_the_band_and_where_coverage_is_zero() {
    let cm = cloud_map();
    let full = ProjectedField::uniform(32, 32, [1.0, 0.8, 1.0]);
    let empty = ProjectedField::uniform(32, 32, [0.0, 0.8, 1.0]);
    let f = Fields {
        p: &full,
        cloud_map: &cm,
    };
    let e = Fields {
        p: &empty,
        cloud_map: &cm,
    };
    let mut inside = 0;
    for i in 0..2000 {
        let (x, z) = ((i * 37 % 1000) as f32 * 10.0, (i * 91 % 1000) as f32 * 10.0);
        for y in [0.0, 599.0, 1601.0, 5000.0] {
            assert_eq!(density_at(Vec3::new(x, y, z), &f, &D, true, 0.0), 0.0);
        }
        let p = Vec3::new(x, 700.0, z);
        assert_eq!(density_at(p, &e, &D, true, 0.0), 0.0);
        inside += usize::from(density_at(p, &f, &D, true, 0.0) > 0.0);
    }
    assert!(
        inside > 200,
        "full coverage gives cloud somewhere ({inside} of 2000)"
    );
}

/// No cloud ends in a wall where the parcels' spread coverage ends. At a
/// coverage just over `footprint`'s cut (0.1 %), the mixed field's
/// highest values could make full-density cloud up to the cut, inside
/// the simulated domain and in the warped sky around it (where the
/// weather multiplies the cover by up to 1.4); the density there is
/// nearly 0, while a coverage of a few percent still makes dense cloud.
#[test]
fn clouds_fade_out_before_the_coverage_cut() {
    let cm = cloud_map();
    let d = DensityParams {
        detail_strength: 0.5,
        ..D
    };
    let densest = |coverage: f32| {
        let p = ProjectedField::uniform(32, 32, [coverage, 0.8, 1.0]);
        let f = Fields {
            p: &p,
            cloud_map: &cm,
        };
        let mut most: f32 = 0.0;
        for i in 0..20_000 {
            let t = i as f32;
            // Inside the domain and far outside it (the warp and the
            // weather at full weight).
            let far = if i % 2 == 0 { 0.0 } else { 40_000.0 };
            let x = far + (t * 0.618_034).fract() * 10_000.0;
            let z = far + (t * 0.414_213).fract() * 10_000.0;
            let y = 620.0 + (t * 0.732_05).fract() * 600.0;
            most = most.max(density_at(Vec3::new(x, y, z), &f, &d, true, 0.0));
        }
        most
    };
    let full = d.extinction_per_m;
    let at_cut = densest(1.05e-3);
    assert!(at_cut < 0.02 * full, "{at_cut} at the cut, {full} full");
    let cloudy = densest(0.05);
    assert!(cloudy > 0.5 * full, "{cloudy} at 5 % coverage");
}

/// The base is flat: across a cloud, density switches on within the
/// same height ramp everywhere (BASE_RAMP of the band, 40 m here).
#[test]
fn cloud_base_is_flat() {
    let cm = cloud_map();
    let p = ProjectedField::uniform(32, 32, [1.0, 0.9, 1.0]);
    let f = Fields {
        p: &p,
        cloud_map: &cm,
    };
    let ramp_m = BASE_RAMP * (D.band_top_m - D.band_bottom_m);
    let mut onsets = Vec::new();
    for i in 0..400 {
        let (x, z) = (
            (i % 20) as f32 * 500.0 + 13.0,
            (i / 20) as f32 * 500.0 + 7.0,
        );
        let onset = (0..2000)
            .map(|k| D.band_bottom_m + k as f32)
            .find(|&y| density_at(Vec3::new(x, y, z), &f, &D, true, 0.0) > 0.0);
        if let Some(y) = onset {
            onsets.push(y);
        }
    }
    assert!(onsets.len() > 50);
    let (lo, hi) = onsets
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &y| (a.min(y), b.max(y)));
    // Onset varies by less than the ramp: 4 % of the band depth.
    assert!(hi - lo <= ramp_m, "base from {lo} to {hi} m");
}

#[test]
fn cloud_top_rises_with_the_parcel_height_channel() {
    let cm = cloud_map();
    let top_of = |h: f32| {
        let p = ProjectedField::uniform(16, 16, [1.0, h, 1.0]);
        let f = Fields {
            p: &p,
            cloud_map: &cm,
        };
        (0..400)
            .map(|i| {
                footprint(
                    (i % 20) as f32 / 20.0,
                    (i / 20) as f32 / 20.0,
                    0.0,
                    0.0,
                    &f,
                    &D,
                )
                .1
            })
            .fold(0.0, f32::max)
    };
    let (low, mid, high) = (top_of(0.1), top_of(0.5), top_of(1.0));
    assert!(low < mid && mid < high, "{low} {mid} {high}");
}

#[test]
fn band_segment_handles_camera_below_inside_and_above() {
    let (b, t) = (600.0, 1600.0);
    let up = Vec3::Y;
    assert_eq!(
        band_segment(Vec3::new(0.0, 0.0, 0.0), up, b, t, 1e5),
        Some((600.0, 1600.0))
    );
    assert_eq!(
        band_segment(Vec3::new(0.0, 1000.0, 0.0), up, b, t, 1e5),
        Some((0.0, 600.0))
    );
    assert_eq!(
        band_segment(Vec3::new(0.0, 2000.0, 0.0), -up, b, t, 1e5),
        Some((400.0, 1400.0))
    );
    assert_eq!(
        band_segment(Vec3::new(0.0, 2000.0, 0.0), up, b, t, 1e5),
        None
    );
    assert_eq!(
        band_segment(Vec3::new(0.0, 1000.0, 0.0), Vec3::X, b, t, 500.0),
        Some((0.0, 500.0))
    );
}

#[test]
fn transmittance_is_in_unit_range_and_monotone_along_a_ray() {
    let cm = cloud_map();
    let p = ProjectedField::uniform(16, 16, [1.0, 1.0, 1.0]);
    let f = Fields {
        p: &p,
        cloud_map: &cm,
    };
    let sun = Vec3::new(0.3, 0.8, 0.5).normalize();
    let mut prev = 1.0;
    // Walking toward the sun from deep below, less cloud lies ahead: the
    // transmittance of what is left only grows.
    for k in 0..50 {
        let start = Vec3::new(1234.0, 500.0, 777.0) + sun * (k as f32 * 40.0);
        let t = sun_transmittance(start, sun, centred(64), 0.0, &f, &D);
        assert!((0.0..=1.0).contains(&t));
        if k > 0 {
            assert!(t >= prev - 1e-6, "step {k}: {t} < {prev}");
        }
        prev = t;
    }
}

/// The optical depth over `length` m from `start` toward `sun`, by an
/// `n`-point midpoint quadrature of the density (detail at `footprint`).
fn optical_depth_quadrature(
    start: Vec3,
    sun: Vec3,
    length: f32,
    n: u32,
    footprint: f32,
    f: &Fields,
    d: &DensityParams,
) -> f64 {
    let dt = length / n as f32;
    (0..n)
        .map(|i| density_at(start + sun * ((i as f32 + 0.5) * dt), f, d, true, footprint) as f64)
        .sum::<f64>()
        * dt as f64
}

#[test]
fn a_low_suns_shadow_ray_crosses_the_whole_band() {
    // From the band's bottom toward a sun 8° up, the light crosses 7.2 km
    // of a 1 km band. The shadow ray's optical depth must be that whole
    // path's, as a 100,000-point quadrature of the same density along it
    // finds it: a ray capped at 2 km would see under half of it. A wide
    // footprint keeps the detail noise smooth, so the 50-60
    // steps' estimate is a quadrature too (tolerance 5 %).
    let cm = cloud_map();
    let p = ProjectedField::uniform(16, 16, [1.0, 1.0, 1.0]);
    let f = Fields {
        p: &p,
        cloud_map: &cm,
    };
    let d = DensityParams {
        extinction_per_m: 0.001,
        detail_strength: 1.0,
        ..D
    };
    let el = 8f32.to_radians();
    let sun = Vec3::new(el.cos() * 0.6, el.sin(), el.cos() * 0.8);
    let footprint = 400.0;
    for start in [
        Vec3::new(1234.0, 600.0, 777.0),
        Vec3::new(8000.0, 900.0, 3000.0),
    ] {
        let length = shadow_ray_length(start, sun, &d);
        let through = (d.band_top_m - start.y) / sun.y;
        assert!(
            (length - through).abs() < 1.0 && length > 2.0 * SHADOW_STEP_SPAN_M,
            "{length} m"
        );
        let exact = optical_depth_quadrature(start, sun, length, 100_000, footprint, &f, &d);
        let tau = sun_optical_depth(start, sun, centred(20), footprint, &f, &d) as f64;
        assert!(exact > 1.0, "a real shadow: τ = {exact}");
        assert!(
            (tau / exact - 1.0).abs() < 0.05,
            "from {start}: {tau} vs {exact}"
        );
    }
}

#[test]
fn the_shadow_rays_offsets_average_to_the_exact_optical_depth() {
    // Each shadow sample sits at `offset` of its step (`shadow_offset`):
    // over offsets spread evenly in [0, 1) a step is sampled all along
    // it, so the mean optical depth is the ray's whole integral, as a
    // 200,000-point quadrature finds it, however fine the detail. At the
    // steps' centres alone the same 20 steps miss the eroded detail's
    // structure by several per cent.
    let cm = cloud_map();
    let p = ProjectedField::uniform(16, 16, [1.0, 1.0, 1.0]);
    let f = Fields {
        p: &p,
        cloud_map: &cm,
    };
    let d = DensityParams {
        extinction_per_m: 0.01,
        detail_strength: 1.0,
        detail_scale_m: 120.0,
        ..D
    };
    let el = 25f32.to_radians();
    let sun = Vec3::new(el.cos() * 0.8, el.sin(), el.cos() * 0.6);
    let mut centred_worst = 0.0_f64;
    for start in [
        Vec3::new(1234.0, 700.0, 777.0),
        Vec3::new(8000.0, 1100.0, 3000.0),
        Vec3::new(4321.0, 900.0, 6543.0),
    ] {
        let length = shadow_ray_length(start, sun, &d);
        let exact = optical_depth_quadrature(start, sun, length, 200_000, 0.0, &f, &d);
        assert!(exact > 1.0, "a real shadow: τ = {exact}");
        let offsets = 128;
        let mean: f64 = (0..offsets)
            .map(|k| {
                let offset = (k as f32 + 0.5) / offsets as f32;
                sun_optical_depth(
                    start,
                    sun,
                    ShadowSteps {
                        offset,
                        ..centred(20)
                    },
                    0.0,
                    &f,
                    &d,
                ) as f64
            })
            .sum::<f64>()
            / offsets as f64;
        assert!(
            (mean / exact - 1.0).abs() < 0.005,
            "from {start}: mean over offsets {mean} vs {exact}"
        );
        let at_centres = sun_optical_depth(start, sun, centred(20), 0.0, &f, &d) as f64;
        centred_worst = centred_worst.max((at_centres / exact - 1.0).abs());
    }
    // The test means something: one placement alone is off.
    assert!(centred_worst > 0.02, "centred steps off by {centred_worst}");
}

/// Beer-Lambert tolerance, relative: 2e-5, five times the measured 3.9e-6
/// (f32 rounding of the march's products; `cargo test --release --test
/// render_cpu constant_slab -- --nocapture`).
const BEER_LAMBERT_TOLERANCE: f32 = 2e-5;

#[test]
fn constant_slab_transmittance_matches_beer_lambert() {
    // A horizontally uniform slab (uniform P, under a cloud cell's middle)
    // seen straight up: the renderer's transmittance must be the
    // Beer-Lambert exp(-∫σ dy), the integral taken by a 200,000-point
    // quadrature of the same density.
    let cm = CloudMap::generate(&CloudMapConfig {
        size: 16,
        cells: 1.0,
        ..CloudMapConfig::default()
    });
    let p = ProjectedField::uniform(8, 8, [1.0, 1.0, 1.0]);
    let fields = Fields {
        p: &p,
        cloud_map: &cm,
    };
    let d = DensityParams {
        extinction_per_m: 0.001,
        ..D
    };
    // Under the thickest column of a coarse scan of the domain (the tiles'
    // shifts and the weather move the clouds off the map's own cells).
    let column_tau = |x: f32, z: f32| -> f32 {
        (0..100)
            .map(|k| {
                let y = d.band_bottom_m + (k as f32 + 0.5) * 10.0;
                density_at(Vec3::new(x, y, z), &fields, &d, true, 0.0) * 10.0
            })
            .sum()
    };
    let (mut best, mut origin) = (0.0, Vec3::ZERO);
    for j in 0..48 {
        for i in 0..48 {
            let (x, z) = (
                (i as f32 + 0.5) * 10_000.0 / 48.0,
                (j as f32 + 0.5) * 10_000.0 / 48.0,
            );
            let t = column_tau(x, z);
            if t > best {
                (best, origin) = (t, Vec3::new(x, 0.0, z));
            }
        }
    }
    // Numerical optical depth along the vertical with a fine quadrature.
    let n = 200_000;
    let dy = (d.band_top_m - d.band_bottom_m) / n as f32;
    let tau: f64 = (0..n)
        .map(|i| {
            density_at(
                origin + Vec3::Y * (d.band_bottom_m + (i as f32 + 0.5) * dy),
                &fields,
                &d,
                true,
                0.0,
            ) as f64
                * dy as f64
        })
        .sum();
    assert!(tau > 0.1, "a real slab: τ = {tau}");
    let frame = Frame {
        view: Camera {
            position_m: origin,
            yaw_deg: 0.0,
            pitch_deg: 89.9,
            fov_deg: 1.0,
        }
        .view(1.0, 1e5),
        sun_elevation_deg: 60.0,
        sun_azimuth_deg: 0.0,
        fields,
        density: d,
        quality: Quality {
            steps: 2048,
            shadow_steps: 0,
            octaves: 0,
            light_photons: 0,
            haze_distance_m: 1e9,
            max_distance_m: 1e5,
            exposure: 1.0,
            sun_glare: 1.0,
            sea_wind_mps: None,
            sea_wind_toward_deg: 90.0,
            sea_time_s: 0.0,
            land_fields: false,
            atmosphere: AtmosphereConfig {
                model: SkyModel::Analytic,
                ..AtmosphereConfig::default()
            },
            single_scattering: false,
            cirrus: None,
        },
        terrain: None,
        sky: None,
        cloud_cover: 0.0,
        light: None,
    };
    let s = march_ray(origin, Vec3::Y, 0.5, 0.0, &frame);
    let expected = (-tau).exp() as f32;
    eprintln!(
        "slab transmittance off Beer-Lambert by {:.2e}",
        (s.transmittance - expected).abs() / expected
    );
    assert!(
        (s.transmittance - expected).abs() / expected < BEER_LAMBERT_TOLERANCE,
        "{} vs {expected}",
        s.transmittance
    );
    // The sun's light scattered once, with no shadow ray (the sun
    // unattenuated inside the slab): the same in-scattered light at every
    // sample, so the radiance is that light times the opacity, exactly
    // (the steps' `integrate_step` telescopes), and no sky, ground or
    // background light is added.
    let single = Frame {
        quality: Quality {
            single_scattering: true,
            ..frame.quality
        },
        ..frame
    };
    let s1 = march_ray(origin, Vec3::Y, 0.5, 0.0, &single);
    let sun_dir = sun_direction(60.0, 0.0);
    let sun = sun_light_at(
        &single.sky_light(),
        0.5 * (d.band_bottom_m + d.band_top_m),
        sun_dir,
    );
    let once = sun * (phase_dual(sun_dir.y, 1.0) * ALBEDO * (1.0 - s1.transmittance));
    assert!(
        (s1.radiance - once).abs().max_element() <= 1e-3 * once.max_element(),
        "{} vs {once}",
        s1.radiance
    );
}

fn small_frame<'a>(p: &'a ProjectedField, cm: &'a CloudMap) -> Frame<'a> {
    Frame {
        view: Camera {
            position_m: Vec3::new(0.0, 100.0, 0.0),
            yaw_deg: 30.0,
            pitch_deg: 15.0,
            fov_deg: 60.0,
        }
        .view(96.0 / 64.0, 40_000.0),
        sun_elevation_deg: 40.0,
        sun_azimuth_deg: 135.0,
        fields: Fields { p, cloud_map: cm },
        density: D,
        quality: Quality {
            steps: 48,
            shadow_steps: 4,
            octaves: 2,
            light_photons: 64,
            haze_distance_m: 25_000.0,
            max_distance_m: 40_000.0,
            exposure: 1.2,
            sun_glare: 1.0,
            sea_wind_mps: None,
            sea_wind_toward_deg: 90.0,
            sea_time_s: 0.0,
            land_fields: false,
            atmosphere: AtmosphereConfig {
                model: SkyModel::Analytic,
                ..AtmosphereConfig::default()
            },
            single_scattering: false,
            cirrus: None,
        },
        terrain: None,
        sky: None,
        cloud_cover: 0.0,
        light: None,
    }
}

#[test]
fn frame_is_finite_has_sky_and_cloud_and_is_deterministic() {
    let cm = cloud_map();
    // Coverage 0.7: a sky with gaps between clouds. (At full coverage the
    // map leaves almost none, and the pixels counted as sky would be thin
    // cloud over it, which the diffused sunlight whitens.)
    let p = ProjectedField::uniform(32, 32, [0.7, 0.8, 1.0]);
    let mut fr = small_frame(&p, &cm);
    // Lit as a scene's frame is: with the light volume.
    let sun = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let light = LightVolume::build(&fr.fields, &fr.density, sun, fr.quality.light_photons);
    fr.light = Some(&light);
    let img = render_linear(96, 64, &fr);
    assert!(img.iter().all(|c| c.is_finite()));
    // Of the pixels looking up: sky is bluer than red, cloud nearly grey.
    let up: Vec<Vec3> = img
        .iter()
        .enumerate()
        .filter(|(k, _)| {
            fr.view
                .camera_ray((k % 96) as f32 + 0.5, (k / 96) as f32 + 0.5, 96, 64)
                .y
                > 0.02
        })
        .map(|(_, c)| *c)
        .collect();
    let sky = up.iter().filter(|c| c.z > 1.3 * c.x).count();
    let cloud = up.iter().filter(|c| c.z < 1.15 * c.x && c.x > 0.05).count();
    assert!(
        sky > 100 && cloud > 100,
        "sky {sky}, cloud {cloud} of {}",
        img.len()
    );
    let a = to_srgb8(&img, 1.2);
    let b = to_srgb8(&render_linear(96, 64, &fr), 1.2);
    assert_eq!(a, b, "same scene, same bytes");
    // Without coverage the frame is all sky.
    let empty = ProjectedField::uniform(32, 32, [0.0, 0.8, 1.0]);
    let none = render_linear(96, 64, &small_frame(&empty, &cm));
    let grey = none
        .iter()
        .enumerate()
        .filter(|(k, c)| {
            fr.view
                .camera_ray((k % 96) as f32 + 0.5, (k / 96) as f32 + 0.5, 96, 64)
                .y
                > 0.02
                && c.z < 1.15 * c.x
        })
        .count();
    assert_eq!(grey, 0, "no cloud pixels without coverage");
}

/// Pixel `(x, y)` of a `w x h` picture of `f` made the long way, from its
/// definition rather than through `stills`: the mean of `frames` marches
/// ([`march_ray`]) from the eye through the pixel's centre, shifted (when
/// `jittered`) by frame `k`'s Halton (2, 3) sub-pixel offset, each with
/// the pixel's blue-noise dither plus `k` golden-ratio steps.
fn pixel_by_definition(
    f: &Frame,
    w: u32,
    h: u32,
    x: u32,
    y: u32,
    frames: u32,
    jittered: bool,
) -> Vec3 {
    use cumulus::render::cpu::renderer::pixel_dither;
    use cumulus::render::sampling::{GOLDEN, halton};
    let spread = f.view.pixel_spread(w, h);
    let mut sum = Vec3::ZERO;
    for k in 0..frames {
        let (jx, jy) = if jittered {
            (halton(k + 1, 2) - 0.5, halton(k + 1, 3) - 0.5)
        } else {
            (0.0, 0.0)
        };
        let golden = k as f64 * GOLDEN as f64;
        let dither = (pixel_dither(x, y) + (golden - golden.floor()) as f32).fract();
        let dir = f
            .view
            .camera_ray(x as f32 + 0.5 + jx, y as f32 + 0.5 + jy, w, h);
        sum += march_ray(f.view.eye(), dir, dither, spread, f).radiance;
    }
    sum / frames as f32
}

/// `img` (`w x h`, row-major) agrees with [`pixel_by_definition`] on a
/// spread of its pixels, to float rounding.
fn matches_definition(img: &[Vec3], f: &Frame, w: u32, h: u32, frames: u32, jittered: bool) {
    for (x, y) in (0..24).map(|i| ((i * 37 + 5) % w, (i * 23 + 3) % h)) {
        let want = pixel_by_definition(f, w, h, x, y, frames, jittered);
        let got = img[(y * w + x) as usize];
        assert!(
            (got - want).abs().max_element() <= 1e-5 * want.abs().max_element().max(1e-3),
            "pixel ({x}, {y}): {got} against {want} by definition ({frames} frames, jittered {jittered})"
        );
    }
}

/// A CPU still (`render_still`, what `cumulus render --backend cpu`
/// writes) averages its `cpu_offsets` marches as the GPU's first TSAA
/// frames, sub-pixel jitter included (each pixel the mean of its marches
/// by definition, [`pixel_by_definition`]): it lands closer to a 4x4
/// box-filtered image of the same scene than the same four marches
/// through the pixels' centres, whose cloud outlines and far ground
/// shadows are staircases; one offset is one march through the centre.
#[test]
fn a_still_is_anti_aliased_like_the_gpus_frames() {
    use cumulus::prepare::Prepared;
    use cumulus::render::cpu::stills::{render_linear_offsets, render_still, supersampled_srgb8};
    let mut sc = cumulus::scene::Scene::load(std::path::Path::new("scenes/fair_weather.toml"))
        .expect("shipped scene");
    sc.render.time_s = 1800.0;
    sc.render.light_photons = 16;
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    let r = &sc.render;
    let (w, h) = (96, 72);
    let f = p.frame(r, r.quality());
    let reference = supersampled_srgb8(w, h, 4, &f);
    let err = |img: &[Vec3]| {
        let b = to_srgb8(img, r.exposure);
        b.iter()
            .zip(&reference)
            .map(|(x, y)| x.abs_diff(*y) as f64)
            .sum::<f64>()
            / (255.0 * b.len() as f64)
    };
    let still = render_still(w, h, &f, 4);
    matches_definition(&still, &f, w, h, 4, true);
    matches_definition(&render_still(w, h, &f, 1), &f, w, h, 1, false);
    let (e_still, e_centres) = (err(&still), err(&render_linear_offsets(w, h, &f, 4)));
    eprintln!("against 4x4 supersampling: still {e_still:.5}, centres {e_centres:.5}");
    assert!(
        e_still < 0.9 * e_centres,
        "still {e_still}, centres {e_centres}"
    );
}

/// Averaging the march over shifted sample offsets (the dither half of what
/// `render.cpu_offsets` does for CPU pictures) takes the fixed dither's pattern out: at 16 steps,
/// four offsets land at least a third closer to a 384-step image than one
/// (measured 0.60 times as far); both are the mean of their marches by
/// definition ([`pixel_by_definition`]).
/// 16 steps, because at 24 the dither's part of the error is small (the
/// horizon's grazing rays take more steps), and the rest, clouds that
/// fall between the coarse steps' fixed ends, is the same for every
/// offset, so four offsets gain less than a third there.
#[test]
fn averaged_offsets_approach_the_many_step_image() {
    use cumulus::prepare::Prepared;
    use cumulus::render::cpu::stills::render_linear_offsets;
    let mut sc = cumulus::scene::Scene::load(std::path::Path::new("scenes/fair_weather.toml"))
        .expect("shipped scene");
    sc.render.time_s = 1800.0;
    sc.render.light_photons = 16;
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    let r = &sc.render;
    let (w, h) = (96, 72);
    let frame = |steps| {
        let mut q = r.quality();
        q.steps = steps;
        p.frame(r, q)
    };
    let reference = to_srgb8(&render_linear(w, h, &frame(384)), r.exposure);
    let err = |img: &[Vec3]| {
        let b = to_srgb8(img, r.exposure);
        b.iter()
            .zip(&reference)
            .map(|(x, y)| x.abs_diff(*y) as f64)
            .sum::<f64>()
            / (255.0 * b.len() as f64)
    };
    let f16 = frame(16);
    let one = render_linear_offsets(w, h, &f16, 1);
    matches_definition(&one, &f16, w, h, 1, false);
    let four = render_linear_offsets(w, h, &f16, 4);
    matches_definition(&four, &f16, w, h, 4, false);
    let (e1, e4) = (err(&one), err(&four));
    eprintln!("16 steps: one offset {e1:.5}, four offsets {e4:.5} from 384 steps");
    assert!(e4 < 0.67 * e1, "one offset {e1}, four {e4}");
}

/// The sea mirrors the clouds above it: under a cloud layer its reflected
/// ray is dimmed and carries the clouds' light, and the sea pixel's
/// radiance changes with it; over land, looking up, or with no clouds
/// there is nothing to mirror.
#[test]
fn the_sea_mirrors_the_clouds_above_it() {
    let cm = cloud_map();
    let cloudy = ProjectedField::uniform(32, 32, [1.0, 0.8, 1.0]);
    let clear = ProjectedField::new(32, 32);
    let sea = |p| {
        let mut fr = small_frame(p, &cm);
        fr.quality.sea_wind_mps = Some(7.0);
        fr
    };
    let origin = Vec3::new(0.0, 100.0, 0.0);
    let sun = sun_direction(40.0, 135.0);
    // Reflected rays through the band, down at 20° to 60°, all around.
    let mut dimmed = 0;
    let mut changed = 0;
    let n = 36;
    for k in 0..n {
        let a = k as f32 * 10f32.to_radians();
        let e = (20.0 + 40.0 * (k % 4) as f32 / 3.0).to_radians();
        let dir = Vec3::new(e.cos() * a.sin(), -e.sin(), e.cos() * a.cos());
        // Pixels so wide (0.3 rad) that no wave is resolved: the sea
        // with the reflection is then exactly the bare sea plus the
        // reflection's change (sea_reflection_change takes the flat
        // sea's mirror and Fresnel factor).
        let spread = 0.3;
        let (light, t) = sea_reflection(origin, dir, 0.5, sun, spread, &sea(&cloudy));
        assert!((0.0..=1.0).contains(&t) && light.is_finite());
        if t < 0.5 {
            assert!(light.max_element() > 0.0, "a cloud mirrored without light");
            dimmed += 1;
        }
        // The pixel (the view ray stays under the band) is the sea with
        // this reflection, and the reflection changes it.
        let fr = sea(&cloudy);
        let sky = fr.sky_light();
        let shadow = flat_ground_shadow(origin, dir, sun, &fr);
        let pixel = march_ray(origin, dir, 0.5, spread, &fr).radiance;
        let waves = sea_waves_at(origin, dir, spread, &fr);
        assert_eq!(waves, Some(flat_sea(7.0)));
        let mirrored = background_radiance(&sky, dir, sun, waves, shadow, LAND_ALBEDO, (light, t));
        let bare = background_radiance(
            &sky,
            dir,
            sun,
            waves,
            shadow,
            LAND_ALBEDO,
            (Vec3::ZERO, 1.0),
        );
        assert!((pixel - mirrored).abs().max_element() <= 1e-6 * mirrored.max_element().max(1.0));
        changed += ((mirrored - bare).abs().max_element() > 1e-3 * bare.max_element()) as u32;
        // No clouds, land, or a ray that looks up: nothing mirrored.
        let none = (Vec3::ZERO, 1.0);
        assert_eq!(
            sea_reflection(origin, dir, 0.5, sun, 1e-3, &sea(&clear)).1,
            1.0
        );
        let land = small_frame(&cloudy, &cm);
        assert_eq!(sea_reflection(origin, dir, 0.5, sun, 1e-3, &land), none);
        let up = Vec3::new(dir.x, -dir.y, dir.z);
        assert_eq!(
            sea_reflection(origin, up, 0.5, sun, 1e-3, &sea(&cloudy)),
            none
        );
    }
    assert!(dimmed > n / 4, "{dimmed} of {n} reflections meet cloud");
    assert!(
        changed >= dimmed,
        "{changed} sea pixels changed by their reflection"
    );
}

/// The sea shows its waves where a pixel resolves them: seen from 30 m,
/// 15° down, neighbouring pixels differ by several per cent (the resolved
/// waves tilt the mirror and the Fresnel factor); 0.5° down, 3.4 km out,
/// no wave is resolved (the footprint is 99 m across, by the cap on its anisotropy, and 394 m
/// along)
/// and the sea is smooth. A sea that is a function of the ray's
/// direction alone, a smooth gradient near and far, fails here.
#[test]
fn the_sea_shows_its_waves_near_the_camera_and_not_far_off() {
    let cm = cloud_map();
    let clear = ProjectedField::new(32, 32);
    let mut fr = small_frame(&clear, &cm);
    fr.quality.sea_wind_mps = Some(7.0);
    let origin = Vec3::new(0.0, 30.0, 0.0);
    let sun = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    // A row of pixels 1 mrad apart, away from the sun.
    let row = |down_deg: f32| -> f32 {
        let e = down_deg.to_radians();
        let l: Vec<f32> = (0..200)
            .map(|i| {
                let a = (-20.0 + 0.0573 * i as f32).to_radians();
                let dir = Vec3::new(e.cos() * a.sin(), -e.sin(), -e.cos() * a.cos());
                lum(march_ray(origin, dir, 0.5, 1e-3, &fr).radiance)
            })
            .collect();
        let mean = l.iter().sum::<f32>() / l.len() as f32;
        let step = l.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f32>() / (l.len() - 1) as f32;
        assert!(sun.y > 0.0 && mean > 0.0);
        step / mean
    };
    let e = 0.5f32.to_radians();
    let far_dir = Vec3::new(0.0, -e.sin(), -e.cos());
    assert_eq!(
        sea_waves_at(origin, far_dir, 1e-3, &fr),
        Some(flat_sea(7.0))
    );
    let (near, far) = (row(15.0), row(0.5));
    assert!(near > 0.02, "near: neighbours differ by {near}");
    assert!(far < 0.002, "far: neighbours differ by {far}");
}

/// The waves turn the reflected ray up and down: its elevation spreads
/// about the mirror ray's with the deviation √(2 · mean square slope) of
/// Cox and Munk's slopes (0.28 rad at 7 m/s, 0.077 on a calm sea), and
/// never below the horizon.
#[test]
fn the_waves_spread_the_reflected_rays_elevation() {
    let n = 20_000;
    for (wind, deviation) in [
        (7.0_f32, (2.0 * (0.003 + 0.00512 * 7.0_f32)).sqrt()),
        (0.0, 0.077),
    ] {
        // A high mirror ray: the spread is whole, centred on it.
        let mirror = 1.2;
        let e: Vec<f32> = (0..n)
            .map(|i| reflected_elevation(mirror, slope_variance(wind), (i as f32 + 0.5) / n as f32))
            .collect();
        let mean = e.iter().sum::<f32>() / n as f32;
        let sd = (e.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / n as f32).sqrt();
        assert!(
            (mean - mirror).abs() < 0.01 * deviation,
            "wind {wind}: mean {mean}"
        );
        assert!(
            (sd / deviation - 1.0).abs() < 0.03,
            "wind {wind}: {sd} vs {deviation}"
        );
        // It grows with the quantile.
        assert!(e.windows(2).all(|w| w[1] >= w[0]));
        // A grazing mirror ray: the waves send it up, none of it down.
        for i in 0..n {
            let low = reflected_elevation(0.005, slope_variance(wind), (i as f32 + 0.5) / n as f32);
            assert!(
                low >= REFLECTION_MIN_ELEVATION * 0.999,
                "wind {wind}: {low}"
            );
        }
    }
}

/// The waves turn the reflected ray sideways too: a facet tilted across
/// the line of sight by `s` sends the ray `s (sin(mirror) + sin(e))`
/// sideways (to first order), against the exact reflection off a facet
/// tilted toward or away from the viewer as well (by `α`, which sends
/// the ray to `e`); the slopes across spread with Cox and Munk's deviation in one
/// direction, `√(mss / 2)` (0.14 at 7 m/s). Rays that kept the view's
/// azimuth would draw a mirrored cloud's streak with the cloud's sharp
/// sides all the way down; `2 s sin(mirror)`, without the facet's tilt
/// toward the viewer, turns the steep rays near the horizon a fifth as
/// far as they go (0.6° for 2.8°), and `2 s sin((mirror + e) / 2)` errs
/// by up to 4 % at the steepest.
#[test]
fn the_waves_turn_the_reflected_rays_sideways() {
    let n = 20_000;
    let wind = 7.0_f32;
    let s: Vec<f32> = (0..n)
        .map(|i| cross_slope(slope_variance(wind), (i as f32 + 0.5) / n as f32))
        .collect();
    let mean = s.iter().sum::<f32>() / n as f32;
    let sd = (s.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / n as f32).sqrt();
    let deviation = (0.5 * (0.003 + 0.00512 * wind)).sqrt();
    assert!(mean.abs() < 1e-3, "{mean}");
    assert!((sd / deviation - 1.0).abs() < 0.03, "{sd} vs {deviation}");
    // The reflection off a facet of slope `slope` across and `alpha`
    // toward the viewer.
    let across = Vec3::new(0.6, 0.0, 0.8);
    let side = Vec3::new(-across.z, 0.0, across.x);
    for mirror_deg in [2.0_f32, 10.0, 40.0] {
        for alpha in [-0.07_f32, 0.0, 0.07, 0.14] {
            let m = mirror_deg.to_radians();
            let dir = across * m.cos() - Vec3::Y * m.sin();
            let slope = 0.02;
            let normal = (Vec3::Y - across * alpha + side * slope).normalize();
            let exact = dir - normal * (2.0 * dir.dot(normal));
            let e = exact.y.asin();
            if e < REFLECTION_MIN_ELEVATION {
                // Into the water: a facet the next wave hides.
                continue;
            }
            let r = reflected_ray(across, m, e, slope);
            assert!((r.length() - 1.0).abs() < 1e-5);
            let (sideways, exact_sideways) = (r.dot(side), exact.dot(side));
            assert!(
                exact_sideways > 0.0 && (sideways - exact_sideways).abs() < 0.05 * exact_sideways,
                "mirror {mirror_deg}°, alpha {alpha}: sideways {sideways} vs {exact_sideways}"
            );
            assert!(
                (r - exact).length() < 1e-3,
                "mirror {mirror_deg}°, alpha {alpha}: {r} vs {exact}"
            );
            // No slope across: the ray keeps the view's azimuth.
            assert!(reflected_ray(across, m, e, 0.0).dot(side).abs() < 1e-6);
        }
    }
}

/// A rough sea mirrors clouds its flat mirror ray misses: looking down
/// 0.3°, the mirror ray would reach the band 95 km out, beyond the 40 km
/// the march goes; the waves' steeper rays meet the cloud layer, and it
/// dims the mirrored sky. (One mirror ray, without the waves' spread,
/// leaves these pixels bare.)
#[test]
fn a_rough_sea_mirrors_clouds_the_mirror_ray_misses() {
    let cm = cloud_map();
    let cloudy = ProjectedField::uniform(32, 32, [1.0, 0.8, 1.0]);
    let mut fr = small_frame(&cloudy, &cm);
    fr.quality.sea_wind_mps = Some(7.0);
    let origin = Vec3::new(0.0, 100.0, 0.0);
    let sun = sun_direction(40.0, 135.0);
    let e = 0.3_f32.to_radians();
    for a in [0.0_f32, 1.0, 2.0, 3.0] {
        let dir = Vec3::new(e.cos() * a.sin(), -e.sin(), e.cos() * a.cos());
        let t_sea = origin.y / e.sin();
        let p = origin + dir * t_sea;
        let mirror = Vec3::new(dir.x, -dir.y, dir.z);
        assert_eq!(
            reflected_clouds(
                p,
                mirror,
                t_sea,
                0.5,
                sun,
                &ReflectionLight::new(&fr, sun, 7.0),
                1e-3,
                &fr
            ),
            (Vec3::ZERO, 1.0),
            "the mirror ray itself meets no cloud"
        );
        let (light, t) = sea_reflection(origin, dir, 0.5, sun, 1e-3, &fr);
        assert!(t < 0.9, "azimuth {a}: transmittance {t}");
        assert!(light.min_element() > 0.0, "azimuth {a}: {light}");
    }
}

/// The land in the clouds' full shade is lit by the sky and by the
/// sunlight the clouds scatter down onto it, as Mitsuba's path tracer
/// has it over a Lambertian plane under the same clouds
/// (docs/ground_truth/ground_shadow.py; its deepest-shade bin in
/// `ground_shadow_bins.csv`, τ toward the sun 8-16): the land's
/// irradiance over π within 12 % of the path tracer's for a sun 60° and
/// 30° high. The clear sky alone gives 0.33 and 0.27 against 0.66 and 0.40.
#[test]
fn the_shade_under_clouds_gets_the_path_tracers_light() {
    use cumulus::prepare::Prepared;
    use cumulus::render::cpu::sky::land_radiance;
    let bins = std::fs::read_to_string("docs/ground_truth/ground_shadow_bins.csv")
        .expect("the path tracer's reference");
    let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let mut sc = cumulus::scene::Scene::load(std::path::Path::new("scenes/fair_weather.toml"))
        .expect("shipped scene");
    sc.render.atmosphere.aerial_perspective = false;
    sc.render.light_photons = 16;
    let mut p = Prepared::from_scene(&sc, || {}).expect("prepare");
    for (view, elevation) in [("ground_high_sun", 60.0), ("ground_mid_sun", 30.0)] {
        p.clear_sky();
        let truth: f32 = bins
            .lines()
            .find(|l| l.starts_with(&format!("{view},8.0,16.0,")))
            .and_then(|l| l.split(',').nth(4))
            .and_then(|v| v.parse().ok())
            .expect("the deepest bin's Mitsuba value");
        let mut r = sc.render.clone();
        r.sun_elevation_deg = elevation;
        r.sun_azimuth_deg = 110.0;
        r.camera_position_m = [5000.0, 400.0, 5000.0];
        let frame = p.frame(&r, r.quality());
        let sun = sun_direction(elevation, 110.0);
        let dir = Vec3::new(0.0, -0.6, 0.8);
        let shade = lum(land_radiance(
            &frame.sky_light(),
            dir,
            sun,
            0.0,
            LAND_ALBEDO,
        )) / lum(LAND_ALBEDO);
        eprintln!("{view}: the shade's irradiance over π {shade:.3}, path tracer {truth:.3}");
        assert!(
            (shade / truth - 1.0).abs() < 0.12,
            "{view}: {shade} against the path tracer's {truth}"
        );
    }
}

/// A reflected ray's march hides as much of the sky as its clouds do:
/// over many dithers its mean opacity is within 8 % of a 4000-step
/// march's along the same rays. Rays rising at 10° through the 1 km band
/// cross 5.8 km of it; four fixed steps, 1.4 km each, land in a cloud
/// or miss it, and their mean opacity is 0.82 of the fine march's (1.00
/// with `reflection_step_count`'s 16; on BOMEX's sea the mirrored clouds
/// show as sparse bright grain, too dark).
#[test]
fn a_reflected_rays_march_does_not_step_over_clouds() {
    use cumulus::render::cpu::sea::reflection_step_count;
    let cm = cloud_map();
    let p = ProjectedField::uniform(32, 32, [0.7, 0.8, 1.0]);
    let mut fr = small_frame(&p, &cm);
    fr.quality.sea_wind_mps = Some(7.0);
    let sun = sun_direction(40.0, 135.0);
    let light = ReflectionLight::new(&fr, sun, 7.0);
    let (spread, t_sea) = (1e-3, 2_000.0);
    let e = 10f32.to_radians();
    let (mut marched, mut fine) = (0.0_f64, 0.0_f64);
    for k in 0..24 {
        let a = k as f32 * 0.7;
        let r = Vec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos());
        let start = Vec3::new(k as f32 * 390.0, 0.0, k as f32 * 170.0);
        let (t0, t1) = band_segment(start, r, D.band_bottom_m, D.band_top_m, 40_000.0)
            .expect("a rising ray crosses the band");
        assert!(reflection_step_count(t1 - t0) > 4, "{}", t1 - t0);
        let n = 4000;
        let h = (t1 - t0) / n as f32;
        let tau: f32 = (0..n)
            .map(|i| {
                let t = t0 + (i as f32 + 0.5) * h;
                density_at(
                    start + r * t,
                    &fr.fields,
                    &D,
                    true,
                    (spread + light.blur) * (t_sea + t),
                ) * h
            })
            .sum();
        fine += 1.0 - (-tau as f64).exp();
        let dithers = 64;
        for j in 0..dithers {
            let dither = (j as f32 + 0.5) / dithers as f32;
            let (_, t) = reflected_clouds(start, r, t_sea, dither, sun, &light, spread, &fr);
            marched += (1.0 - t as f64) / dithers as f64;
        }
    }
    assert!(fine > 3.0, "the rays meet cloud: {fine}");
    let ratio = marched / fine;
    assert!(
        (ratio - 1.0).abs() < 0.08,
        "opacity {marched:.3} against {fine:.3}: {ratio:.3}"
    );
}

/// With a light volume the march reads the density only along the
/// shadow rays' near part (away from the sun) and takes the sun's depth
/// beyond from the volume: fewer reads for the same clouds, and on
/// average the optical depth it finds stays near the whole ray's. Toward
/// the sun it marches the whole ray. Counted in reads, not time.
#[test]
fn a_light_volume_spares_the_shadow_rays_reads() {
    use cumulus::render::cpu::renderer::shadow_depth;
    let cm = cloud_map();
    let p = ProjectedField::uniform(32, 32, [0.7, 0.8, 1.0]);
    let mut fr = small_frame(&p, &cm);
    let alone = fr;
    let sun = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let light = LightVolume::build(&fr.fields, &fr.density, sun, 8);
    fr.light = Some(&light);
    let d = fr.density;
    let ray = ShadowSteps {
        steps: 20,
        forward: 1.0,
        offset: 0.3,
    };
    let (mut reads, mut all_reads, mut tau, mut all_tau, mut lit) = (0, 0, 0.0, 0.0, 0);
    for i in 0..2000 {
        let p = Vec3::new(
            (37.0 * i as f32) % d.map_extent_m,
            d.band_bottom_m
                + (0.1 + 0.5 * ((i % 7) as f32 / 7.0)) * (d.band_top_m - d.band_bottom_m),
            (53.0 * i as f32 + 11.0) % d.map_extent_m,
        );
        if density_at(p, &fr.fields, &d, true, 10.0) <= 0.0 {
            continue;
        }
        lit += 1;
        let a = shadow_depth(p, sun, ray, 0.0, 10.0, &fr);
        let b = shadow_depth(p, sun, ray, 0.0, 10.0, &alone);
        reads += a.reads;
        all_reads += b.reads;
        tau += a.tau as f64;
        all_tau += b.tau as f64;
        // Looking at the sun: the whole ray, the same reads.
        let c = shadow_depth(p, sun, ray, 1.0, 10.0, &fr);
        assert_eq!(c.reads, b.reads);
        assert!(
            (c.tau - b.tau).abs() <= 1e-4 * b.tau.max(1e-3),
            "{c:?} {b:?}"
        );
    }
    eprintln!(
        "{lit} lit samples: {reads} reads against {all_reads}; depth {tau:.1} against {all_tau:.1}"
    );
    assert!(lit > 50, "{lit} samples in cloud");
    assert!(reads * 2 < all_reads, "{reads} reads against {all_reads}");
    assert!(
        (tau - all_tau).abs() < 0.25 * all_tau,
        "depth {tau} against {all_tau}"
    );
}
