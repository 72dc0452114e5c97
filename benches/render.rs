//! Cloud-map generation, P's spread, the light volume's steps (its
//! transport per million photons), CPU rendering of a 320x240 frame, and the endless
//! database's distances between its volumes (beside a plain sum in
//! doubles, the baseline for their speed).
//!
//! `cargo bench --bench render`

use criterion::{Criterion, criterion_group, criterion_main};
use cumulus::endless::distances;
use cumulus::prepare::Prepared;
use cumulus::render::cloud_map::{CloudMap, CloudMapConfig};
use cumulus::render::cpu::light_grid::{
    LIGHT_SEED, LightVolumeGrid, cell_extinction, light_photons,
};
use cumulus::render::cpu::light_transport::trace;
use cumulus::render::cpu::light_volume::sh_planes;
use cumulus::render::cpu::sky::sun_direction;
use cumulus::render::cpu::stills::render_linear;
use cumulus::render::soft_field::{SPREAD_M, soft_field};
use cumulus::scene::Scene;

fn render(c: &mut Criterion) {
    c.bench_function("cloud_map_256", |b| {
        b.iter(|| CloudMap::generate(&CloudMapConfig::default()))
    });
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/fair_weather.toml");
    let scene = Scene::load(&path).expect("shipped scene");
    let prepared = Prepared::from_scene(&scene, || {}).expect("prepares");
    // P's spread, done on every upload of P: at the scene's extent and at
    // the extent of `cumulus bench`'s 12-parcel sky (sqrt(12/160) of it),
    // where the kernel spans more texels.
    let extent = prepared.map_extent_m as f32;
    c.bench_function("soft_field_fair_weather", |b| {
        b.iter(|| soft_field(&prepared.field, SPREAD_M, extent))
    });
    c.bench_function("soft_field_12_parcels", |b| {
        b.iter(|| {
            soft_field(
                &prepared.field,
                SPREAD_M,
                extent * (12.0_f32 / 160.0).sqrt(),
            )
        })
    });
    let r = &scene.render;
    let frame = prepared.frame(r, r.quality());
    let sun = sun_direction(r.sun_elevation_deg, r.sun_azimuth_deg);
    let grid = LightVolumeGrid::new(&frame.density);
    c.bench_function("light_volume_cell_extinction", |b| {
        b.iter(|| cell_extinction(&grid, &frame.fields, &frame.density))
    });
    let sigma = cell_extinction(&grid, &frame.fields, &frame.density);
    // The transport: a build traces `light_photons` (16 M here, about 16
    // times this million's time); ten samples, each a few seconds.
    let mut slow = c.benchmark_group("light_volume_slow");
    slow.sample_size(10);
    eprintln!(
        "a build traces {} photons",
        light_photons(&grid, r.light_photons)
    );
    slow.bench_function("light_volume_trace_1m_photons", |b| {
        b.iter(|| trace(&grid, &sigma, sun, 1 << 20, LIGHT_SEED))
    });
    slow.finish();
    let sh = trace(&grid, &sigma, sun, 1 << 16, LIGHT_SEED);
    c.bench_function("light_volume_sh_planes", |b| b.iter(|| sh_planes(&sh)));
    c.bench_function("cpu_render_320x240_fair_weather", |b| {
        b.iter(|| render_linear(320, 240, &frame))
    });
    let mut plain = frame;
    plain.density.detail_strength = 0.0;
    c.bench_function("cpu_render_320x240_fair_weather_no_detail", |b| {
        b.iter(|| render_linear(320, 240, &plain))
    });
}

/// The distances summed the plain way: every pair both ways round, in
/// doubles, rows in parallel (the baseline for [`distances`]' speed).
fn distances_in_doubles(volumes: &[Vec<u8>]) -> Vec<f64> {
    use rayon::prelude::*;
    let n = volumes.len();
    let mut d = vec![0.0; n * n];
    d.par_chunks_mut(n.max(1)).enumerate().for_each(|(k, row)| {
        for (l, out) in row.iter_mut().enumerate() {
            if l != k {
                *out = volumes[k]
                    .iter()
                    .zip(&volumes[l])
                    .map(|(a, b)| {
                        let x = (*a as f64 - *b as f64) / 255.0;
                        x * x
                    })
                    .sum();
            }
        }
    });
    d
}

fn endless(c: &mut Criterion) {
    // 24 volumes of 128x16x128 (the shipped endless scene's size), bytes
    // as the sampler writes them: a smooth field, mostly empty.
    let volumes: Vec<Vec<u8>> = (0..24u32)
        .map(|v| {
            (0..128 * 16 * 128u32)
                .map(|i| ((i.wrapping_mul(2_654_435_761) ^ v.wrapping_mul(40_503)) >> 26) as u8 * 4)
                .collect()
        })
        .collect();
    assert_eq!(distances(&volumes)[1], {
        let d = distances_in_doubles(&volumes)[1];
        (d * 65025.0).round() / 65025.0
    });
    c.bench_function("endless_distances_24x128x16x128", |b| {
        b.iter(|| distances(&volumes))
    });
    c.bench_function("endless_distances_24x128x16x128_doubles_both_ways", |b| {
        b.iter(|| distances_in_doubles(&volumes))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(5));
    targets = render, endless
}
criterion_main!(benches);
