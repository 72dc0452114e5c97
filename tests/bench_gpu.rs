//! `cumulus bench`, its per-parcel pseudo-spheroid renderer and that
//! renderer's CPU twin. Needs a GPU adapter (any:
//! lavapipe in CI); without one each test prints `SKIPPED: no GPU adapter`
//! and passes, unless `CUMULUS_REQUIRE_GPU=1`.

use std::process::Command;

mod common;

use common::gpu;

use cumulus::endless::{Database, Player};
use cumulus::prepare::Prepared;
use cumulus::render::camera::Camera;
use cumulus::render::cpu::sky::sun_direction;
use cumulus::render::cpu::sky::{Land, SkyModel};
use cumulus::render::cpu::spheroids::{LightGrid, render_spheroids_srgb8};
use cumulus::render::cpu::tone_map::to_srgb8;
use cumulus::render::cpu::volume::render_volume;
use cumulus::render::gpu::Headless;
use cumulus::render::gpu::headless::TARGET_FORMAT;
use cumulus::render::gpu::spheroids::SpheroidRenderer;
use cumulus::render::gpu::volume_pass::VolumeRenderer;
use cumulus::report::gpu_bench::FEATURES;
use cumulus::scene::Scene;
use cumulus::sim::ProjectedField;
use glam::Vec3;

#[test]
fn bench_quick_writes_well_formed_results() {
    if gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args(["bench", "--quick", "--out"])
        .arg(dir.path())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("binary runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let mut r = csv::Reader::from_path(dir.path().join("bench.csv")).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(
        header,
        "group,renderer,width,height,coverage,parcels,tsaa,terrain,shadow_steps,octaves,detail,sky,aerial,frames,p_covered,median_ms,p95_ms,timing,reads_mean,reads_max"
            .split(',')
            .collect::<Vec<_>>()
    );
    let col = |n: &str| header.iter().position(|h| h == n).unwrap();
    let mut groups = std::collections::BTreeSet::new();
    let (mut timed, mut total) = (0, 0);
    let mut feature_reads = Vec::new();
    let mut skies = std::collections::BTreeSet::new();
    for rec in r.records() {
        total += 1;
        let rec = rec.unwrap();
        groups.insert(rec[col("group")].to_owned());
        assert_eq!(rec.len(), header.len());
        if &rec[col("group")] == "features" {
            skies.insert((rec[col("sky")].to_owned(), rec[col("aerial")].to_owned()));
        }
        if &rec[col("timing")] == "skipped" {
            assert_eq!(
                &rec[col("renderer")],
                "per_parcel",
                "only the spheroids may skip"
            );
            continue;
        }
        assert!(["gpu", "wall"].contains(&&rec[col("timing")]));
        for c in ["median_ms", "p95_ms"] {
            let v: f64 = rec[col(c)].parse().unwrap();
            assert!(v.is_finite() && v > 0.0, "{c} = {v}");
        }
        let (m, p): (f64, f64) = (
            rec[col("median_ms")].parse().unwrap(),
            rec[col("p95_ms")].parse().unwrap(),
        );
        assert!(p >= m, "p95 {p} < median {m}");
        // The cloud map's frames count their density reads per pixel:
        // at least the one a pixel whose ray crosses the band, at most
        // the mean's own bound; the shadows-off row reads less than the
        // defaults.
        if &rec[col("renderer")] == "cloud_map" {
            let (mean, max): (f64, f64) = (
                rec[col("reads_mean")].parse().unwrap(),
                rec[col("reads_max")].parse().unwrap(),
            );
            assert!(
                mean > 0.0 && max >= mean && max.is_finite(),
                "reads {mean} / {max}"
            );
            if &rec[col("group")] == "features" {
                feature_reads.push((rec[col("shadow_steps")].to_owned(), mean));
            }
        }
        timed += 1;
    }
    // The defaults (the first features row) read more than the frame
    // without shadows, which reads no shadow ray.
    let defaults = feature_reads.first().expect("a features row").1;
    let unshadowed = feature_reads
        .iter()
        .find(|(steps, _)| steps == "0")
        .expect("a shadows-off row")
        .1;
    assert!(
        unshadowed < defaults,
        "reads without shadows {unshadowed}, defaults {defaults}"
    );
    assert_eq!(
        total,
        2 + 4 + FEATURES.len() + 2 * 4,
        "resolutions, coverages, features, parcels x 2"
    );
    // The sky's cost: the default physical sky, the analytic one, and
    // aerial perspective off.
    for pair in [
        ("physical", "true"),
        ("analytic", "true"),
        ("physical", "false"),
    ] {
        assert!(
            skies.contains(&(pair.0.to_owned(), pair.1.to_owned())),
            "{skies:?}"
        );
    }
    assert!(timed >= 16, "{timed} timed rows");
    for g in ["resolution", "coverage", "parcels", "features"] {
        assert!(groups.contains(g), "no {g} rows");
    }

    let mut r = csv::Reader::from_path(dir.path().join("physics_in_frame.csv")).unwrap();
    let mut n = 0;
    for rec in r.records() {
        let rec = rec.unwrap();
        for k in 1..rec.len() {
            let v: f64 = rec[k].parse().unwrap();
            assert!(
                v.is_finite() && v > 0.0,
                "physics_in_frame column {k} = {v}"
            );
        }
        n += 1;
    }
    assert_eq!(n, 4, "12, 85, 1,000 and 10,000 parcels");

    // The methods side by side: one row each, every time positive.
    let mut r = csv::Reader::from_path(dir.path().join("methods.csv")).unwrap();
    let mut methods = Vec::new();
    for rec in r.records() {
        let rec = rec.unwrap();
        methods.push(format!("{}+{}", &rec[0], &rec[1]));
        for k in [5, 6, 8, 9] {
            let v: f64 = rec[k].parse().unwrap();
            assert!(v.is_finite() && v > 0.0, "methods.csv {rec:?} column {k}");
        }
        let grid: f64 = rec[10].parse().unwrap();
        assert_eq!(grid > 0.0, &rec[1] == "spheroids", "{rec:?}");
        let bytes: usize = rec[11].parse().unwrap();
        assert!(bytes > 0, "{rec:?}");
    }
    assert_eq!(
        methods,
        [
            "parcels+cloud_map",
            "parcels+spheroids",
            "automaton+cloud_map",
            "endless+volume"
        ]
    );
    // The endless playback against its temperature: one row each.
    let mut r = csv::Reader::from_path(dir.path().join("endless_threshold.csv")).unwrap();
    assert_eq!(r.records().count(), 6);

    let mut r = csv::Reader::from_path(dir.path().join("render_error.csv")).unwrap();
    let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
    for knob in ["steps", "shadow_steps", "octaves", "tsaa_frames"] {
        let of: Vec<&csv::StringRecord> = rows.iter().filter(|x| &x[0] == knob).collect();
        assert!(of.len() >= 4, "{knob}");
        assert_eq!(
            of.iter().filter(|x| &x[4] == "true").count(),
            1,
            "{knob}: one default"
        );
        for x in of {
            let (ms, e): (f64, f64) = (x[2].parse().unwrap(), x[3].parse().unwrap());
            assert!(
                ms > 0.0 && ms.is_finite() && (0.0..1.0).contains(&e),
                "{x:?}"
            );
        }
    }

    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("bench.json")).unwrap()).unwrap();
    assert!(json["adapter"].as_str().is_some_and(|s| !s.is_empty()));
    assert!(json["driver"].is_string());
    assert_eq!(
        json["rows"].as_array().map(Vec::len),
        Some(total),
        "JSON and CSV rows"
    );
    for png in [
        "ms_vs_coverage.png",
        "ms_vs_parcels.png",
        "ms_per_feature.png",
        "render_error.png",
    ] {
        let img = image::open(dir.path().join(png)).unwrap();
        assert!(img.width() > 100, "{png}");
    }
}

/// Cloud mask of an image against the clear sky: channels summed differ
/// by more than 24 levels.
fn mask(img: &[u8], clear: &[u8]) -> Vec<bool> {
    img.chunks_exact(3)
        .zip(clear.chunks_exact(3))
        .map(|(a, b)| {
            a.iter()
                .zip(b)
                .map(|(x, y)| x.abs_diff(*y) as u32)
                .sum::<u32>()
                > 24
        })
        .collect()
}

/// Two 8-bit pictures' mean channel difference, in levels, and the
/// fraction of channels within 3 levels.
fn agreement(gpu: &[u8], cpu: &[u8]) -> (f64, f64) {
    let diff: Vec<u32> = gpu
        .iter()
        .zip(cpu)
        .map(|(a, b)| a.abs_diff(*b) as u32)
        .collect();
    let mean = diff.iter().sum::<u32>() as f64 / diff.len() as f64;
    let within = diff.iter().filter(|d| **d <= 3).count() as f64 / diff.len() as f64;
    (mean, within)
}

#[test]
fn spheroids_and_cloud_map_draw_the_same_parcels() {
    let Some(ctx) = gpu() else { return };
    let mut sc = Scene::load(std::path::Path::new("scenes/fair_weather.toml")).unwrap();
    sc.render.light_photons = 16;
    sc.render.tsaa = false;
    // No shadows: the cloud map darkens the ground under its clouds (the
    // baseline does not), and the mask against the clear ground would
    // count those shadows as cloud.
    sc.render.shadow_steps = 0;
    // The baseline draws under the analytic sky: its clear sky is the mask's
    // reference.
    sc.render.atmosphere.model = SkyModel::Analytic;
    // The baseline's land is plain (its backgrounds have no fields): so is
    // the cloud map's here, or every ground pixel would differ from it.
    sc.render.ground.land = Land::Plain;
    let p = Prepared::from_scene(&sc, || {}).unwrap();
    let l = sc.physics.domain_size_m as f32;
    // Straight down on the whole domain from above the layer.
    let camera = Camera {
        position_m: Vec3::new(0.5 * l, 9_000.0, 0.5 * l),
        yaw_deg: 0.0,
        pitch_deg: -89.9,
        fov_deg: 2.0 * (0.5 * l / 7_500.0_f32).atan().to_degrees(),
    };
    let (w, h) = (48, 48);
    let settings = p.gpu_settings(&sc.render, sc.render.quality());
    let cloud_map = |field: &ProjectedField| {
        let mut hl = Headless::new(&ctx, field, &p.cloud_map, None, &settings, (w, h)).unwrap();
        hl.render(&ctx, &camera, 1).unwrap();
        hl.read_rgb8(&ctx).unwrap()
    };
    let baseline = |with_spheres: bool| {
        let mut b = SpheroidRenderer::new(
            &ctx.device,
            &ctx.queue,
            TARGET_FORMAT,
            &settings,
            p.cloud_map.noise(),
        );
        if with_spheres {
            b.update_spheroids(&p.spheroids());
        }
        b.read_rgb8(&ctx, &camera, w, h).unwrap()
    };
    let clear_sky = baseline(false);
    let a = mask(&cloud_map(&p.field), &clear_sky);
    let b = mask(&baseline(true), &clear_sky);
    let frac = |m: &[bool]| m.iter().filter(|x| **x).count() as f64 / m.len() as f64;
    // Coarse agreement: 6x6 blocks of 8x8 pixels, cloud fraction per block.
    let blocks = |m: &[bool]| -> Vec<f64> {
        (0..36)
            .map(|k| {
                let (bx, by) = (k % 6, k / 6);
                let mut n = 0;
                for y in by * 8..by * 8 + 8 {
                    for x in bx * 8..bx * 8 + 8 {
                        n += m[(y * w as usize) + x] as u32;
                    }
                }
                n as f64 / 64.0
            })
            .collect()
    };
    let (ba, bb) = (blocks(&a), blocks(&b));
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (ma, mb) = (mean(&ba), mean(&bb));
    let cov: f64 = ba.iter().zip(&bb).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let sd = |v: &[f64], m: f64| v.iter().map(|x| (x - m).powi(2)).sum::<f64>().sqrt();
    let corr = cov / (sd(&ba, ma) * sd(&bb, mb)).max(1e-12);
    eprintln!(
        "cloud fraction: cloud map {:.2}, spheroids {:.2}; block correlation {corr:.2}",
        frac(&a),
        frac(&b)
    );
    assert!(frac(&a) > 0.05 && frac(&b) > 0.05, "both draw clouds");
    assert!(
        frac(&a) / frac(&b) < 3.0 && frac(&b) / frac(&a) < 3.0,
        "cover within a factor 3"
    );
    assert!(
        corr > 0.4,
        "the clouds are where the parcels are in both (corr {corr})"
    );
}

#[test]
fn the_spheroid_renderer_matches_its_cpu_twin() {
    let Some(ctx) = gpu() else { return };
    let mut sc = Scene::load(std::path::Path::new("scenes/spheroids.toml")).unwrap();
    sc.render.light_photons = 16;
    sc.render.time_s = 600.0;
    let (w, h) = (96, 64);
    sc.render.width = w;
    sc.render.height = h;
    let p = Prepared::from_scene(&sc, || {}).unwrap();
    let r = &sc.render;
    let spheroids = p.spheroids();
    assert!(spheroids.len() > 10, "{} spheroids", spheroids.len());
    let settings = p.gpu_settings(r, r.quality());
    let mut s = SpheroidRenderer::new(
        &ctx.device,
        &ctx.queue,
        TARGET_FORMAT,
        &settings,
        p.cloud_map.noise(),
    );
    s.update_spheroids(&spheroids);
    let gpu = s.read_rgb8(&ctx, &r.camera(), w, h).unwrap();
    let frame = p.frame(r, r.quality());
    let sun = sun_direction(r.sun_elevation_deg, r.sun_azimuth_deg);
    let grid = LightGrid::build(&spheroids, sun, frame.density.extinction_per_m);
    let cpu = render_spheroids_srgb8(w, h, &frame, &spheroids, &grid);
    let (mean, within) = agreement(&gpu, &cpu);
    // The clouds are in the picture: it is not the clear sky on both.
    let clear = {
        let mut s = SpheroidRenderer::new(
            &ctx.device,
            &ctx.queue,
            TARGET_FORMAT,
            &settings,
            p.cloud_map.noise(),
        );
        s.update_spheroids(&[]);
        s.read_rgb8(&ctx, &r.camera(), w, h).unwrap()
    };
    let m = mask(&gpu, &clear);
    let cloudy = m.iter().filter(|x| **x).count();
    let clear_diff: f64 = gpu
        .chunks_exact(3)
        .zip(cpu.chunks_exact(3))
        .zip(&m)
        .filter(|(_, c)| !**c)
        .map(|((a, b), _)| {
            a.iter()
                .zip(b)
                .map(|(x, y)| x.abs_diff(*y) as f64)
                .sum::<f64>()
                / 3.0
        })
        .sum::<f64>()
        / (m.len() - cloudy).max(1) as f64;
    eprintln!("clear-sky pixels differ by {clear_diff:.3} levels on average");
    eprintln!(
        "spheroids GPU against CPU: mean {mean:.3} levels, {within:.4} within 3; {cloudy} cloud pixels"
    );
    assert!(cloudy > (w * h / 20) as usize, "{cloudy} cloud pixels");
    // Measured on lavapipe: 0.08 levels, every channel within 3 (an
    // aerial perspective applied the wrong way round on the CPU gives 1.4).
    assert!(mean < 0.4, "mean difference {mean} levels");
    assert!(within > 0.999, "{within} of channels within 3 levels");
}

#[test]
fn the_volume_renderer_matches_its_cpu_twin_on_a_blend() {
    let Some(ctx) = gpu() else { return };
    let mut sc = Scene::load(std::path::Path::new("scenes/endless.toml")).unwrap();
    sc.render.light_photons = 16;
    sc.render.time_s = 600.0;
    let (w, h) = (96, 64);
    sc.render.width = w;
    sc.render.height = h;
    let mut cfg = sc.simulation.endless.clone();
    cfg.volumes = 3;
    cfg.cells = [48, 12, 48];
    let db = Database::build(&sc, &cfg, || {}).unwrap();
    assert_eq!(db.len(), 3);
    assert!(db.d(0, 1) > 0.0, "the clouds moved between volumes");
    let mut player = Player::new(&db, cfg.similarity, 1);
    // Halfway through the first interval: two volumes blended.
    let (stack, params) = db.stack(player.at(0.5 * db.interval_s, db.interval_s));
    let p = Prepared::unsimulated(&sc).unwrap();
    let r = &sc.render;
    let settings = p.gpu_settings(r, r.quality());
    let mut v = VolumeRenderer::new(
        &ctx.device,
        &ctx.queue,
        TARGET_FORMAT,
        &settings,
        &stack,
        params,
        p.cloud_map.noise(),
    )
    .unwrap();
    let gpu = v.read_rgb8(&ctx, &r.camera(), w, h).unwrap();
    let frame = p.frame(r, r.quality());
    let cpu = to_srgb8(
        &render_volume(w, h, &frame, &params, &stack, 1),
        frame.quality.exposure,
    );
    let (mean, within) = agreement(&gpu, &cpu);
    let mut empty = stack.clone();
    empty.texels.fill(0);
    let clear = to_srgb8(
        &render_volume(w, h, &frame, &params, &empty, 1),
        frame.quality.exposure,
    );
    let cloudy = mask(&cpu, &clear).iter().filter(|x| **x).count();
    eprintln!(
        "volumes GPU against CPU: mean {mean:.3} levels, {within:.4} within 3; {cloudy} cloud pixels"
    );
    assert!(cloudy > (w * h / 20) as usize, "{cloudy} cloud pixels");
    assert!(mean < 0.4, "mean difference {mean} levels");
    assert!(within > 0.999, "{within} of channels within 3 levels");
}
