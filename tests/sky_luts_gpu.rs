//! The sky tables built on the GPU (`SkyLutsPass`, `shaders/sky_luts_build.wgsl`)
//! against their CPU twins (`render::cpu::sky_luts`), and the rebuilds the
//! pass skips. Runs on whatever adapter exists (lavapipe in CI). Without one
//! each test prints `SKIPPED: no GPU adapter` and passes, unless
//! `CUMULUS_REQUIRE_GPU=1`.

mod common;

use common::gpu;
use cumulus::render::cpu::sky_luts::{Lut2, SKY_VIEW_HALF, SkyLuts, SkyParams};
use cumulus::render::gpu::GpuContext;
use cumulus::render::gpu::sky_luts_pass::{SkyLutsPass, SkyTable, TableBuilds};
use glam::Vec3;

/// Relative differences are taken against `max(|cpu|, FLOOR)`: texels
/// darker than this (transmittance along grazing rays from the ground,
/// down to 1e-9 in the blue) are compared in absolute terms, where f32
/// round-off of a large optical depth is all either side can resolve.
const FLOOR: f32 = 1e-4;
/// Transmittance, GPU against CPU (measured on lavapipe: 6.9e-4 at the
/// horizon column; 99% of texels within 3.2e-4). Both run the same 40
/// midpoint steps in f32, but the GPU's exp and sqrt are not correctly
/// rounded and it may fuse multiply-adds; the optical depths τ agree to
/// ~1e-5 relative and exp(-τ) amplifies that by τ (up to ~10 along the
/// horizon column, the worst).
const TRANSMITTANCE_REL: f32 = 2e-3;
/// Multiple scattering (measured: 1.1e-4): the same differences, plus
/// those of the transmittance table it reads and of the GPU's cos/sin of
/// the Fibonacci directions' azimuths (up to 151 rad).
const MULTI_SCATTERING_REL: f32 = 5e-4;
/// Sky view, every row but the horizon's (measured: 2.2e-4 under a 30° sun
/// from 500 m; 2.5e-3 under a 2° one from 8 km, on rows within 4 of the
/// horizon, where rays graze the ground or the haze over ~100 km; 99% of
/// texels within 1.4e-3): the same again, plus the GPU's acos/cos of the
/// rows' zenith angles.
const SKY_VIEW_REL: f32 = 5e-3;
/// Sky view, the lower half's horizon row `SKY_VIEW_HALF - 1` (measured:
/// 6.9e-3 under a 30° sun, 2.9e-2 under a 2° one, toward the sun): it
/// grazes the ground exactly, where the distance to the ground is the
/// square root of a difference that vanishes (`distance_to_ground`), so a
/// last-bit change of its cos zenith moves the march's end by hundreds of
/// metres.
const SKY_VIEW_HORIZON_REL: f32 = 0.1;

/// The relative differences of two tables, texel by texel (the largest of
/// the RGB channels'), sorted, with the worst texel.
struct Differences {
    sorted: Vec<f32>,
    worst: (u32, u32),
    gpu: Vec3,
    cpu: Vec3,
}

impl Differences {
    /// Over the rows where `keep_row`.
    fn new(gpu: &Lut2, cpu: &Lut2, keep_row: impl Fn(u32) -> bool) -> Self {
        assert_eq!((gpu.width, gpu.height), (cpu.width, cpu.height));
        let mut all = Vec::new();
        let mut worst = (-1.0f32, (0, 0));
        for y in (0..cpu.height).filter(|y| keep_row(*y)) {
            for x in 0..cpu.width {
                let (g, c) = (gpu.texel(x, y), cpu.texel(x, y));
                assert!(g.is_finite(), "GPU texel ({x}, {y}) is {g}");
                let rel = ((g - c).abs() / c.abs().max(Vec3::splat(FLOOR))).max_element();
                all.push(rel);
                if rel > worst.0 {
                    worst = (rel, (x, y));
                }
            }
        }
        all.sort_by(f32::total_cmp);
        let (x, y) = worst.1;
        Self {
            sorted: all,
            worst: worst.1,
            gpu: gpu.texel(x, y),
            cpu: cpu.texel(x, y),
        }
    }

    fn max(&self) -> f32 {
        *self.sorted.last().expect("texels")
    }

    fn quantile(&self, q: f64) -> f32 {
        self.sorted[((self.sorted.len() - 1) as f64 * q).round() as usize]
    }
}

/// Rows of a table: all, all but the sky view's horizon row, or that row.
fn all_rows(_: u32) -> bool {
    true
}

fn off_horizon(y: u32) -> bool {
    y != SKY_VIEW_HALF - 1
}

fn on_horizon(y: u32) -> bool {
    y == SKY_VIEW_HALF - 1
}

/// A table, the rows compared, the bound, and what to call them.
type Check<'a> = (SkyTable, &'a Lut2, fn(u32) -> bool, f32, &'static str);

fn compare(pass: &SkyLutsPass, ctx: &GpuContext, cpu: &SkyLuts, what: &str) {
    let checks: [Check; 5] = [
        (
            SkyTable::Transmittance,
            &cpu.transmittance,
            all_rows,
            TRANSMITTANCE_REL,
            "",
        ),
        (
            SkyTable::MultiScattering,
            &cpu.multi_scattering,
            all_rows,
            MULTI_SCATTERING_REL,
            "",
        ),
        (
            SkyTable::SkyView,
            &cpu.sky_view,
            off_horizon,
            SKY_VIEW_REL,
            " but the horizon row",
        ),
        (
            SkyTable::SkyView,
            &cpu.sky_view,
            on_horizon,
            SKY_VIEW_HORIZON_REL,
            ", horizon row",
        ),
        (
            SkyTable::SkyAmbient,
            &cpu.sky_ambient,
            all_rows,
            SKY_VIEW_REL,
            "",
        ),
    ];
    for (table, cpu_table, rows, bound, which) in checks {
        let gpu_table = pass.read_table(ctx, table).expect("readback");
        let d = Differences::new(&gpu_table, cpu_table, rows);
        let rel = d.max();
        eprintln!(
            "{what}: {}{which}: max relative difference {rel:.2e} at {:?} (GPU {}, CPU {}), \
             99% of texels within {:.2e}, median {:.2e} (bound {bound:.0e})",
            table.label(),
            d.worst,
            d.gpu,
            d.cpu,
            d.quantile(0.99),
            d.quantile(0.5),
        );
        assert!(
            rel <= bound,
            "{what}: {}{which}: {rel} > {bound}",
            table.label()
        );
    }
}

/// A sun at `elevation_deg` in the x-y plane turned by `azimuth_deg`.
fn sun(elevation_deg: f32, azimuth_deg: f32) -> Vec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

#[test]
fn gpu_tables_match_the_cpu_twins() {
    let Some(ctx) = gpu() else { return };
    let params = SkyParams::default();
    let (high, low, altitude_m) = (sun(30.0, 0.0), sun(2.0, 0.0), 500.0);
    let mut pass = SkyLutsPass::new(&ctx, &params, high, altitude_m).expect("sky tables");
    let mut cpu = SkyLuts::build(params, high, altitude_m);
    compare(&pass, &ctx, &cpu, "sun 30°");
    match pass.table_times_ms(&ctx).expect("timestamps") {
        Some([t, ms, sv, amb]) => eprintln!(
            "GPU time: transmittance {t:.3} ms, multiple scattering {ms:.3} ms, sky view {sv:.3} ms, sky ambient {amb:.3} ms"
        ),
        None => eprintln!("GPU time: no timestamp queries on this adapter"),
    }
    // A low sun (grazing rays, the planet's shadow) from high in the
    // atmosphere: the sky view alone is rebuilt.
    let start = std::time::Instant::now();
    let built = pass.rebuild_sky_view(&ctx, low, 8000.0).expect("sky view");
    ctx.wait().expect("idle");
    eprintln!(
        "sky view rebuilt in {:.1} ms wall time (submit to idle)",
        start.elapsed().as_secs_f64() * 1e3
    );
    assert_eq!(built.sky_view, 1);
    cpu.rebuild_sky_view(low, 8000.0);
    compare(&pass, &ctx, &cpu, "sun 2°, camera at 8 km");
}

#[test]
fn unchanged_inputs_skip_and_a_new_sun_rebuilds_only_the_sky_view() {
    let Some(ctx) = gpu() else { return };
    let params = SkyParams::default();
    let (sun_a, altitude_m) = (sun(30.0, 0.0), 500.0);
    let mut pass = SkyLutsPass::new(&ctx, &params, sun_a, altitude_m).expect("sky tables");
    let one = |t, m, s| TableBuilds {
        transmittance: t,
        multi_scattering: m,
        sky_view: s,
    };
    assert_eq!(pass.builds(), one(1, 1, 1));
    let none = TableBuilds::default();
    let again = pass.build_all(&ctx, &params, sun_a, altitude_m).unwrap();
    assert_eq!((again, pass.builds()), (none, one(1, 1, 1)));
    // The table's azimuth is relative to the sun's: turning it changes nothing.
    let turned = pass
        .build_all(&ctx, &params, sun(30.0, 70.0), altitude_m)
        .unwrap();
    assert_eq!((turned, pass.builds()), (none, one(1, 1, 1)));
    let sun_b = sun(10.0, 0.0);
    let new_sun = pass.build_all(&ctx, &params, sun_b, altitude_m).unwrap();
    assert_eq!((new_sun, pass.builds()), (one(0, 0, 1), one(1, 1, 2)));
    let same = pass.rebuild_sky_view(&ctx, sun_b, altitude_m).unwrap();
    assert_eq!((same, pass.builds()), (none, one(1, 1, 2)));
    // The rebuilt sky view is the new sun's, not the old one's.
    let cpu = SkyLuts::build(params, sun_b, altitude_m);
    let gpu_view = pass.read_table(&ctx, SkyTable::SkyView).unwrap();
    let rel = Differences::new(&gpu_view, &cpu.sky_view, off_horizon).max();
    assert!(rel <= SKY_VIEW_REL, "sky view after the new sun: {rel}");
    let higher = pass.rebuild_sky_view(&ctx, sun_b, 2000.0).unwrap();
    assert_eq!((higher, pass.builds()), (one(0, 0, 1), one(1, 1, 3)));
    let hazier = SkyParams {
        mie_scattering: 2.0 * params.mie_scattering,
        mie_extinction: 2.0 * params.mie_extinction,
        ..params
    };
    let all = pass.build_all(&ctx, &hazier, sun_b, 2000.0).unwrap();
    assert_eq!((all, pass.builds()), (one(1, 1, 1), one(2, 2, 4)));
}
