//! Cloud-map generation and CPU rendering of a 320x240 frame.
//!
//! `cargo bench --bench render`

use criterion::{Criterion, criterion_group, criterion_main};
use cumulus::prepare::Prepared;
use cumulus::render::cloud_map::{CloudMap, CloudMapConfig};
use cumulus::render::cpu::renderer::render_linear;
use cumulus::scene::Scene;

fn render(c: &mut Criterion) {
    c.bench_function("cloud_map_256", |b| {
        b.iter(|| CloudMap::generate(&CloudMapConfig::default()))
    });
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/fair_weather.toml");
    let scene = Scene::load(&path).expect("shipped scene");
    let prepared = Prepared::from_scene(&scene, || {}).expect("prepares");
    let r = &scene.render;
    let frame = prepared.frame(r, r.quality());
    c.bench_function("cpu_render_320x240_fair_weather", |b| {
        b.iter(|| render_linear(320, 240, &frame))
    });
    let mut plain = frame;
    plain.density.detail_strength = 0.0;
    c.bench_function("cpu_render_320x240_fair_weather_no_detail", |b| {
        b.iter(|| render_linear(320, 240, &plain))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(5));
    targets = render
}
criterion_main!(benches);
