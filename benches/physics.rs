//! One physics frame (default dt, SPH, entrainment, detrainment, recycling,
//! wind all on) with 12 to 100,000 parcels, and the projection into P.
//! The domain keeps one parcel per km² (12 parcels: 3.5 km square; 10,000:
//! 100 km; 100,000: 316 km), the parcels are spun up for 20 minutes first so they are
//! released, rising and condensing.
//!
//! Also the LCL and the pseudo-adiabatic parcel of an analytic tropical
//! sounding of 17, 401 and 4,001 levels: `lift_parcel` (MetPy's work) and
//! `lift_sounding` (what `cumulus profile` computes, with the
//! environment and the buoyancy); `benches/metpy_profile_timing.py` times
//! MetPy's `lcl` + `parcel_profile` on the same soundings.
//!
//! `cargo bench --bench physics`

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cumulus::sim::lift::{Adiabat, lift_parcel, lift_sounding};
use cumulus::sim::{
    Atmosphere, Band, ParametricProfile, PhysicsConfig, ProjectedField, Simulation, Sounding,
};

fn spun_up(n: usize) -> Simulation {
    let cfg = PhysicsConfig {
        parcels: n,
        domain_size_m: 1000.0 * (n as f64).sqrt(),
        release_stagger_s: 600.0,
        ..PhysicsConfig::default()
    };
    let mut sim = Simulation::new(
        cfg,
        Atmosphere::from_parametric(&ParametricProfile::FAIR_WEATHER),
    );
    for _ in 0..600 {
        sim.step();
    }
    sim
}

const BAND: Band = Band {
    bottom_m: 600.0,
    top_m: 1600.0,
};

fn physics(c: &mut Criterion) {
    let mut g = c.benchmark_group("step");
    for n in [12, 100, 1000, 10_000, 100_000] {
        let mut sim = spun_up(n);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| sim.step())
        });
    }
    g.finish();
    let mut g = c.benchmark_group("project_128");
    for n in [12, 1000, 10_000, 100_000] {
        let sim = spun_up(n);
        let mut field = ProjectedField::new(128, 128);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| sim.project_into(&mut field, BAND))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("step_and_project_128");
    let mut sim = spun_up(10_000);
    let mut field = ProjectedField::new(128, 128);
    g.bench_function("10000", |b| {
        b.iter(|| {
            sim.step();
            sim.project_into(&mut field, BAND)
        })
    });
    g.finish();
}

/// The SPH passes sequential and with rayon, to place
/// `sph::PARALLEL_THRESHOLD`.
fn sph_crossover(c: &mut Criterion) {
    use cumulus::sim::sph::{NeighbourGrid, SphParams, accelerations};
    let mut g = c.benchmark_group("sph_crossover");
    for n in [128usize, 256, 512, 1024, 2048, 4096] {
        let sim = spun_up(n);
        let p = sim.parcels();
        let active: Vec<u32> = (0..n as u32)
            .filter(|&i| p.life[i as usize].released())
            .collect();
        let params = SphParams {
            h: 600.0,
            domain_m: sim.config().domain_size_m,
            sound_speed: 3.0,
            viscosity: 100.0,
        };
        let mut grid = NeighbourGrid::default();
        let mut acc = Vec::new();
        for parallel in [false, true] {
            let id = BenchmarkId::new(if parallel { "rayon" } else { "sequential" }, n);
            g.bench_function(id, |b| {
                b.iter(|| {
                    accelerations(
                        &mut grid, &p.pos, &p.vel, &active, &params, parallel, &mut acc,
                    )
                })
            });
        }
    }
    g.finish();
}

fn profile(c: &mut Criterion) {
    let mut g = c.benchmark_group("lcl_and_pseudo_profile");
    for n in [17, 401, 4001] {
        let s = Sounding::analytic_tropical(n);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| lift_sounding(&s, Adiabat::Pseudo))
        });
    }
    g.finish();
    // MetPy's work alone (`lcl` + `parcel_profile`: the LCL and the
    // parcel's temperature at each pressure): what the Python package's
    // `parcel_profile` calls. It also gives the parcel's vapour.
    let mut g = c.benchmark_group("lcl_and_pseudo_parcel");
    for n in [17, 401, 4001] {
        let s = Sounding::analytic_tropical(n);
        let p: Vec<f64> = s
            .levels()
            .iter()
            .map(|l| l.pressure_pa.unwrap_or(0.0))
            .collect();
        let (t0, q0) = (s.levels()[0].temperature_k, s.levels()[0].mixing_ratio);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| lift_parcel(t0, q0, p[0], &p, Adiabat::Pseudo))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3)).warm_up_time(std::time::Duration::from_secs(1));
    targets = physics, sph_crossover, profile
}
criterion_main!(benches);
