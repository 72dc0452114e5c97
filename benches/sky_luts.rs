//! The CPU sky tables of `render::cpu::sky_luts`: each table's build, and
//! 10k sky-view lookups and aerial-perspective calls.
//!
//! `cargo bench --bench sky_luts`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use cumulus::render::cpu::sky_luts::{
    SkyLuts, SkyParams, aerial_perspective, build_multi_scattering, build_sky_view,
    build_transmittance, fibonacci_direction, sky_view_radiance,
};
use glam::Vec3;

/// Calls per lookup benchmark.
const CALLS: u32 = 10_000;

fn sky_luts(c: &mut Criterion) {
    let params = SkyParams::default();
    let sun_dir = Vec3::new(0.0, 0.5, 0.866).normalize();
    let camera_altitude_m = 500.0;
    let sky = SkyLuts::build(params, sun_dir, camera_altitude_m);
    c.bench_function("sky_luts_transmittance_256x64", |b| {
        b.iter(|| build_transmittance(black_box(&params)))
    });
    c.bench_function("sky_luts_multi_scattering_32x32", |b| {
        b.iter(|| build_multi_scattering(black_box(&params), &sky.transmittance))
    });
    c.bench_function("sky_luts_sky_view_192x108", |b| {
        b.iter(|| {
            build_sky_view(
                black_box(&params),
                &sky.transmittance,
                &sky.multi_scattering,
                sun_dir,
                camera_altitude_m,
            )
        })
    });
    // Directions over the whole sphere, above and below the horizon.
    let dirs: Vec<Vec3> = (0..CALLS).map(|i| fibonacci_direction(i, CALLS)).collect();
    c.bench_function("sky_luts_sky_view_lookup_10k", |b| {
        b.iter(|| {
            dirs.iter().fold(Vec3::ZERO, |sum, &d| {
                sum + sky_view_radiance(&sky, d, sun_dir)
            })
        })
    });
    // Paths of 0 to 50 km, the range of a cloud scene's view rays.
    c.bench_function("sky_luts_aerial_perspective_10k", |b| {
        b.iter(|| {
            dirs.iter().enumerate().fold(Vec3::ZERO, |sum, (i, &d)| {
                let distance_m = 5.0 * i as f32;
                let (inscatter, t) =
                    aerial_perspective(&sky, camera_altitude_m, d, distance_m, sun_dir);
                sum + inscatter + t
            })
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(5));
    targets = sky_luts
}
criterion_main!(benches);
