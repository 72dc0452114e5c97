//! Same seed, same bytes, whatever the thread count: the SPH passes and the
//! per-parcel update run in parallel above their thresholds, and a run on
//! one, two or three threads must give bit-identical parcels.

use cumulus::sim::{Atmosphere, ParametricProfile, PhysicsConfig, Simulation};

fn run(threads: usize) -> Vec<u64> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let n = 3000;
        let cfg = PhysicsConfig {
            parcels: n,
            domain_size_m: 800.0 * (n as f64).sqrt(),
            release_stagger_s: 300.0,
            ..PhysicsConfig::default()
        };
        let mut sim = Simulation::new(
            cfg,
            Atmosphere::from_parametric(&ParametricProfile::FAIR_WEATHER),
        );
        for _ in 0..200 {
            sim.step();
        }
        let p = sim.parcels();
        p.pos
            .iter()
            .zip(&p.vel)
            .zip(p.theta_l.iter().zip(&p.qt))
            .flat_map(|((x, v), (t, q))| [x.x, x.y, x.z, v.x, v.y, v.z, *t, *q].map(f64::to_bits))
            .collect()
    })
}

#[test]
fn one_two_and_three_threads_give_the_same_bits() {
    let one = run(1);
    assert_eq!(one, run(2), "1 and 2 threads differ");
    assert_eq!(one, run(3), "1 and 3 threads differ");
}
