//! The automaton's rules on tiny grids, its probabilities, wind,
//! projection and determinism.

use super::*;

const BAND: Band = Band {
    bottom_m: 1000.0,
    top_m: 1700.0,
};

/// A still `n x n x n` grid with no ellipsoid and every probability 0.
fn tiny(n: usize) -> Automaton {
    let cfg = AutomatonConfig {
        layers: n,
        humidity_supply: 0.0,
        activation: 0.0,
        extinction: 0.0,
        ..AutomatonConfig::default()
    };
    let mut a = Automaton::new(&cfg, &PhysicsConfig::default(), BAND, &[], n, n);
    a.set_drift(DVec2::ZERO);
    a
}

#[test]
fn activation_spreads_to_the_rule_s_neighbours_and_climbs() {
    let mut a = tiny(9);
    for k in 0..9 {
        for j in 0..9 {
            for i in 0..9 {
                a.set_cell(i, j, k, HUM);
            }
        }
    }
    a.set_cell(4, 4, 4, ACT);
    a.step();
    // The active cell condensed and lost its activation; it had no
    // vapour, so it has none now.
    assert_eq!(a.cell(4, 4, 4), CLD);
    let mut reached = vec![
        (5, 4, 4),
        (3, 4, 4),
        (4, 5, 4),
        (4, 3, 4),
        (4, 4, 5),
        (4, 4, 3),
        (6, 4, 4),
        (2, 4, 4),
        (4, 6, 4),
        (4, 2, 4),
        // Two above: a cell is reached from two below, not two above.
        (4, 4, 6),
    ];
    reached.sort();
    let mut active = Vec::new();
    for k in 0..9 {
        for j in 0..9 {
            for i in 0..9 {
                let c = a.cell(i, j, k);
                if c & ACT != 0 {
                    active.push((i, j, k));
                    // Activation uses up the vapour only on the next step.
                    assert_eq!(c, HUM | ACT, "({i},{j},{k})");
                } else if (i, j, k) != (4, 4, 4) {
                    assert_eq!(c, HUM, "({i},{j},{k})");
                }
            }
        }
    }
    active.sort();
    assert_eq!(active, reached);
    assert_eq!(a.cell(4, 4, 2) & ACT, 0, "two below is not reached");
    // Next step the reached cells condense and lose their vapour.
    a.step();
    for &(i, j, k) in &reached {
        assert_eq!(a.cell(i, j, k) & (CLD | HUM), CLD, "({i},{j},{k})");
    }
}

#[test]
fn without_vapour_nothing_activates_and_without_extinction_clouds_stay() {
    let mut a = tiny(6);
    a.set_cell(2, 2, 2, ACT);
    a.set_cell(0, 0, 0, CLD);
    for _ in 0..5 {
        a.step();
    }
    assert_eq!(a.count(ACT), 0);
    assert_eq!(a.count(HUM), 0);
    assert_eq!(a.cell(2, 2, 2), CLD);
    assert_eq!(a.cell(0, 0, 0), CLD);
    assert_eq!(a.count(CLD), 2);
}

#[test]
fn extinction_one_clears_every_cloud_and_supply_one_moistens_every_cell() {
    let mut a = tiny(5);
    a.set_cell(1, 1, 1, CLD);
    a.set_cell(3, 3, 3, CLD | HUM);
    a.set_odds(CellOdds {
        hum: 1.0,
        act: 0.0,
        ext: 1.0,
    });
    a.step();
    assert_eq!(a.count(CLD), 0);
    assert_eq!(a.count(HUM), 125);
}

#[test]
fn extinction_odds_are_met_in_frequency() {
    let mut a = tiny(16);
    for k in 0..16 {
        for j in 0..16 {
            for i in 0..16 {
                a.set_cell(i, j, k, CLD);
            }
        }
    }
    a.set_odds(CellOdds {
        hum: 0.0,
        act: 0.0,
        ext: 0.3,
    });
    a.step();
    let kept = a.count(CLD) as f64 / 4096.0;
    // Binomial(4096, 0.7): standard deviation 0.007.
    assert!((kept - 0.7).abs() < 0.03, "kept {kept}");
}

#[test]
fn wind_moves_each_layer_by_whole_cells_keeping_the_rest() {
    let mut a = tiny(8);
    a.set_cell(2, 3, 1, CLD);
    a.set_drift(DVec2::new(0.5, -1.0));
    a.step();
    // Half a cell east: not yet; one cell south (-y): moved.
    assert_eq!(a.cell(2, 2, 1), CLD);
    a.step();
    assert_eq!(a.cell(3, 1, 1), CLD);
    assert_eq!(a.count(CLD), 1);
    // Across the periodic edge.
    for _ in 0..2 {
        a.step();
    }
    assert_eq!(a.cell(4, 7, 1), CLD);
}

#[test]
fn the_scene_s_wind_shears_the_layers_apart() {
    let physics = PhysicsConfig::default();
    let cfg = AutomatonConfig::default();
    let a = Automaton::new(&cfg, &physics, BAND, &[], 64, 64);
    let cell = a.cell_size();
    let bottom = a.drift[0].0 * cell.x;
    let top = a.drift[cfg.layers - 1].0 * cell.x;
    let expect = |z: f64| wind_at(&physics, z).length() * cfg.step_s;
    let z0 = BAND.bottom_m + 0.5 * cell.z;
    assert!((bottom.length() - expect(z0)).abs() < 1e-9);
    assert!(top.length() > bottom.length(), "shear speeds the top up");
}

#[test]
fn smoothing_and_projection_of_a_known_column() {
    let mut a = tiny(8);
    // A column of cloud in layers 0..=3 at (4, 4) only.
    for k in 0..4 {
        a.set_cell(4, 4, k, CLD);
    }
    let q = a.density();
    // Box of 3 in x and y: a lone column is 1/9 of the box in each layer;
    // in z the mean of the cells inside the band.
    let at = |i: usize, j: usize, k: usize| q[(k * 8 + j) * 8 + i];
    assert!((at(4, 4, 1) - 1.0 / 9.0).abs() < 1e-6);
    assert!((at(4, 4, 0) - 1.0 / 9.0).abs() < 1e-6, "cut at the bottom");
    assert!((at(4, 4, 4) - 1.0 / 27.0).abs() < 1e-6);
    assert_eq!(at(6, 4, 1), 0.0);

    // A solid block 3 wide, layers 0..=5 of 8: the centre column's top
    // cell at least a quarter full is layer 5 (layer 6 averages 1/3).
    let mut a = tiny(8);
    for k in 0..6 {
        for j in 3..6 {
            for i in 3..6 {
                a.set_cell(i, j, k, CLD);
            }
        }
    }
    let mut p = ProjectedField::new(1, 1);
    a.project_into(&mut p);
    assert_eq!((p.width(), p.height()), (8, 8));
    let [c, h, fill] = p.at(4, 4);
    assert_eq!(c, 1.0);
    let eta = 7.0 / 8.0; // top of layer 6 (1/3 full)
    assert!((h - (eta - 0.2) / 0.8).abs() < 1e-6, "h {h}");
    assert!(fill > 0.5 && fill <= 1.0, "fill {fill}");
    assert_eq!(p.at(0, 0), [0.0; 3], "clear air projects nothing");
}

fn grown(seed: u64) -> Automaton {
    let physics = PhysicsConfig {
        seed,
        domain_size_m: 6400.0,
        ..PhysicsConfig::default()
    };
    let sites = [DVec2::new(1600.0, 1600.0), DVec2::new(4800.0, 4000.0)];
    let mut a = Automaton::new(&AutomatonConfig::default(), &physics, BAND, &sites, 64, 64);
    for _ in 0..120 {
        a.step();
    }
    a
}

#[test]
fn clouds_grow_in_the_ellipsoids_and_drift_downwind() {
    let a = grown(1);
    let mut p = ProjectedField::new(1, 1);
    a.project_into(&mut p);
    let covered = p.covered_fraction();
    assert!(covered > 0.02 && covered < 0.6, "covered {covered}");
    // The default wind blows towards +x: more cloud downwind of a site
    // than upwind of it.
    let cell = a.cell_size().x;
    let column = |x_m: f64, y_m: f64| {
        let (i, j) = (
            (x_m / cell).rem_euclid(64.0) as usize,
            (y_m / cell).rem_euclid(64.0) as usize,
        );
        p.at(i, j)[0]
    };
    let (mut down, mut up) = (0.0f32, 0.0f32);
    for (x, y) in [(1600.0, 1600.0), (4800.0, 4000.0)] {
        for d in 1..=30 {
            let off = 60.0 * d as f64;
            down += column(x + off, y);
            up += column(x - off, y);
        }
    }
    assert!(down > up, "downwind {down} upwind {up}");
}

#[test]
fn a_seed_gives_the_same_sky_on_any_thread_count() {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("pool");
    let a = one.install(|| grown(7));
    let b = three.install(|| grown(7));
    assert_eq!(a.state, b.state);
    let c = grown(8);
    assert_ne!(a.state, c.state, "another seed, another sky");
}
