//! Tests of `light_volume.rs`: the planes the renderers read, light
//! across clear air, the light's direction around a cloud. The transport
//! itself is checked against theory in `light_transport.rs`.

use super::*;
use crate::render::cpu::light_grid::LIGHT_CELLS_MAX;
use crate::render::cpu::light_transport::{sh_fluence, sh_flux};
use glam::UVec3;

/// The cells' extinction of a 1 km ball of cloud (0.03/m) around
/// `centre`, clear air elsewhere.
fn cloud_ball(g: &LightVolumeGrid, centre: Vec3) -> Vec<f32> {
    (0..g.len())
        .map(|idx| {
            let (i, j, k) = g.cell(idx);
            if (g.centre(i, j, k) - centre).length() < 500.0 {
                0.03
            } else {
                0.0
            }
        })
        .collect()
}

fn grid(cells: UVec3, cell_m: f32) -> LightVolumeGrid {
    LightVolumeGrid {
        cells,
        cell_m: Vec3::splat(cell_m),
        bottom_m: 1000.0,
    }
}

/// At a cell's centre the planes give the coefficients' sum through the
/// phase's moments: an isotropic light (l = 0 alone) scatters its
/// radiance in every direction, and a light with a net flux scatters
/// more along it.
#[test]
fn the_planes_scatter_the_light_through_the_phase() {
    let g = grid(UVec3::new(4, 4, 4), 100.0);
    let mut sh = vec![[0.0f32; 9]; g.len()];
    let radiance = 0.3;
    for c in &mut sh {
        c[0] = radiance / 0.282_094_8;
    }
    let v = LightVolume {
        grid: g,
        planes: sh_planes(&sh),
        sh,
    };
    let p = g.centre(1, 2, 3);
    for d in [Vec3::X, -Vec3::Y, Vec3::new(0.6, 0.0, 0.8)] {
        let got = v.light_toward(p, d, 400.0);
        assert!((got - radiance).abs() < 1e-5, "{d}: {got}");
    }
    // A different light in every cell: a cell's centre reads its own.
    let sh: Vec<[f32; 9]> = (0..g.len())
        .map(|i| std::array::from_fn(|k| 0.1 * (i as f32 + 1.0) * (1.0 + k as f32 * 0.05)))
        .collect();
    let planes = sh_planes(&sh);
    let v = LightVolume {
        grid: g,
        planes,
        sh: sh.clone(),
    };
    for (i, j, k) in [(0, 0, 0), (1, 2, 3), (3, 1, 2)] {
        let c = &sh[g.index(i, j, k)];
        let d = Vec3::new(0.48, 0.6, 0.64);
        let y = crate::render::cpu::lighting::sh9(d);
        let expected: f32 = (0..9)
            .map(|n| c[n] * PHASE_MOMENTS[SH_BAND[n]] * y[n])
            .sum();
        let got = v.light_toward(g.centre(i, j, k), d, 400.0);
        assert!(
            (got - expected).abs() < 1e-4 * expected.abs(),
            "cell ({i}, {j}, {k}): {got} vs {expected}"
        );
    }
    // A beam straight down: l = 1 along -y.
    let mut sh = vec![[0.0f32; 9]; g.len()];
    for c in &mut sh {
        c[0] = 1.0;
        c[1] = -1.0;
    }
    let v = LightVolume {
        grid: g,
        planes: sh_planes(&sh),
        sh,
    };
    let down = v.light_toward(p, -Vec3::Y, 400.0);
    let up = v.light_toward(p, Vec3::Y, 400.0);
    let expected = 0.282_094_8 + PHASE_MOMENTS[1] * 0.488_602_5;
    assert!((down - expected).abs() < 1e-5, "{down} vs {expected}");
    assert!(up < down);
}

/// The build traces a fixed number of photons per column, so a larger
/// domain has no noisier light.
#[test]
fn the_photons_follow_the_columns() {
    let small = grid(UVec3::new(10, 8, 10), 80.0);
    let large = grid(UVec3::new(40, 8, 40), 80.0);
    assert_eq!(light_photons(&large, 64), 16 * light_photons(&small, 64));
    assert_eq!(light_photons(&small, 64), 6400);
}

/// A cumulus band 1 km deep gets layers about 40 m tall under cells
/// about 80 m wide (26 layers, not the 12 of cubic cells), and a band
/// too deep for 48 such layers gets taller ones.
#[test]
fn the_layers_are_half_as_tall_as_the_cells_are_wide() {
    let band = |bottom: f32, top: f32| DensityParams {
        band_bottom_m: bottom,
        band_top_m: top,
        coverage: 0.75,
        extinction_per_m: 0.04,
        map_extent_m: 10_080.0,
        detail_strength: 0.6,
        detail_scale_m: 180.0,
        fine_detail: true,
    };
    let g = LightVolumeGrid::new(&band(579.0, 1600.0));
    assert_eq!(g.cells, UVec3::new(126, 26, 126));
    assert!((g.cell_m.x - 80.0).abs() < 1e-3, "{}", g.cell_m);
    assert!((g.cell_m.y - 39.27).abs() < 0.01, "{}", g.cell_m);
    assert_eq!(g.bottom_m, 579.0);
    let deep = LightVolumeGrid::new(&band(1000.0, 13_000.0));
    assert_eq!(deep.cells.y, LIGHT_CELLS_MAX.y);
    assert!((deep.cell_m.y - 250.0).abs() < 1e-3, "{}", deep.cell_m);
}

/// Around a 1 km cloud under a sun in the zenith: the light in its base
/// flows down, away from the sun, and scatters down more than up (1.45
/// times: what makes a backlit cloud's shaded side bright), while above
/// its top the light the cloud reflects flows up.
#[test]
fn light_leaves_a_cloud_away_from_the_sun() {
    let g = grid(UVec3::new(24, 20, 24), 80.0);
    let centre = g.centre(12, 10, 12);
    let sigma = cloud_ball(&g, centre);
    let v = LightVolume::trace(g, &sigma, Vec3::Y, 400_000);
    let cell = |p: Vec3| {
        let (i, j, k) = (
            (p.x / 80.0) as i32,
            ((p.y - g.bottom_m) / 80.0) as i32,
            (p.z / 80.0) as i32,
        );
        g.index(i, j, k)
    };
    let below = centre - Vec3::Y * 400.0;
    assert!(sigma[cell(below)] > 0.0);
    assert!(sh_flux(&v.sh[cell(below)]).y < 0.0);
    let down = v.light_toward(below, -Vec3::Y, 1920.0);
    let up = v.light_toward(below, Vec3::Y, 1920.0);
    assert!(down > 1.2 * up, "down {down}, up {up}");
    let above = centre + Vec3::Y * 560.0;
    assert_eq!(sigma[cell(above)], 0.0);
    assert!(sh_flux(&v.sh[cell(above)]).y > 0.0);
}

/// Clouds light each other across clear air: a 1 km cloud beside
/// another like it (centres 1.12 km apart, 120 m of clear air between
/// them), under a sun in the zenith, holds at least 1 % more scattered
/// light than alone. And clear air does not pile light up: no clear
/// cell is brighter than the clouds' brightest.
#[test]
fn a_cloud_lights_its_neighbour_across_clear_air() {
    let g = grid(UVec3::new(48, 20, 32), 80.0);
    let lone = cloud_ball(&g, g.centre(28, 10, 16));
    let pair: Vec<f32> = cloud_ball(&g, g.centre(14, 10, 16))
        .iter()
        .zip(&lone)
        .map(|(a, b)| a.max(*b))
        .collect();
    let mean_in_lone = |v: &LightVolume| {
        let inside: Vec<f32> = (0..g.len())
            .filter(|i| lone[*i] > 0.0)
            .map(|i| sh_fluence(&v.sh[i]))
            .collect();
        inside.iter().sum::<f32>() / inside.len() as f32
    };
    let photons = 1_000_000;
    let alone = LightVolume::trace(g, &lone, Vec3::Y, photons);
    let beside = LightVolume::trace(g, &pair, Vec3::Y, photons);
    let gain = mean_in_lone(&beside) / mean_in_lone(&alone);
    assert!(gain > 1.01, "{gain}");
    let peak = (0..g.len())
        .filter(|i| pair[*i] > 0.0)
        .map(|i| sh_fluence(&beside.sh[i]))
        .fold(0.0, f32::max);
    assert!(
        (0..g.len())
            .filter(|i| pair[*i] == 0.0)
            .all(|i| sh_fluence(&beside.sh[i]) < peak)
    );
}

/// The filter keeps each cell's fluence (coefficient 0) and each layer's
/// total light, leaves a uniform light alone, and takes most of a cell-to-
/// cell noise out of the directional coefficients (the binomial 3 x 3
/// leaves 0.375 of its standard deviation).
#[test]
fn the_filter_smooths_the_directional_light_and_keeps_the_fluence() {
    let g = grid(UVec3::new(16, 3, 16), 80.0);
    let smooth = |idx: usize| -> [f32; 9] {
        std::array::from_fn(|k| 1.0 + 0.1 * k as f32 + 0.2 * (idx / 256) as f32)
    };
    let uniform: Vec<[f32; 9]> = (0..g.len()).map(smooth).collect();
    let same = filter_cells(&uniform, &g);
    for (a, b) in same.iter().zip(&uniform) {
        for k in 0..9 {
            assert!((a[k] - b[k]).abs() < 1e-5, "{a:?} against {b:?}");
        }
    }
    // A hash for noise in [-0.5, 0.5).
    let noise = |idx: usize, k: usize| {
        let h = (idx as u32 * 9 + k as u32).wrapping_mul(2_654_435_761) ^ 0x9e37_79b9;
        (h.wrapping_mul(2_246_822_519) >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    let noisy: Vec<[f32; 9]> = (0..g.len())
        .map(|idx| std::array::from_fn(|k| smooth(idx)[k] + noise(idx, k)))
        .collect();
    let filtered = filter_cells(&noisy, &g);
    let n = (g.cells.x * g.cells.z) as usize;
    let (mut before, mut after) = (0.0, 0.0);
    for idx in 0..g.len() {
        assert_eq!(
            filtered[idx][0], noisy[idx][0],
            "cell {idx}'s fluence changed"
        );
        for k in 1..9 {
            before += (noisy[idx][k] - smooth(idx)[k]).abs();
            after += (filtered[idx][k] - smooth(idx)[k]).abs();
        }
    }
    for j in 0..g.cells.y as usize {
        for k in 1..9 {
            let total = |v: &[[f32; 9]]| {
                v[j * n..(j + 1) * n]
                    .iter()
                    .map(|c| c[k] as f64)
                    .sum::<f64>()
            };
            let (a, b) = (total(&filtered), total(&noisy));
            assert!(
                (a - b).abs() < 1e-4 * b.abs(),
                "layer {j}, coefficient {k}: {a} against {b}"
            );
        }
    }
    assert!(
        after < 0.5 * before,
        "noise {after} after against {before} before"
    );
}

/// Through uniform cells the sun's depth from a cell's centre is the
/// extinction times the path to the grid's top, along a high sun and a
/// low one; a path longer than SHADOW_RAY_M stops there. Behind the
/// ball (from below it, toward the sun) the depth is the ball's; beside
/// it, none.
#[test]
fn the_sun_depth_integrates_the_cells_toward_the_sun() {
    use crate::render::cpu::light_grid::sun_depth;
    use crate::render::cpu::lighting::SHADOW_RAY_M;
    let g = grid(UVec3::new(16, 8, 16), 100.0);
    let top = g.bottom_m + 800.0;
    let uniform = vec![0.002f32; g.len()];
    for sun in [
        Vec3::new(0.3, 0.9, 0.2).normalize(),
        Vec3::new(0.99, 0.06, 0.1).normalize(),
    ] {
        let depth = sun_depth(&uniform, &g, sun);
        for idx in [0, 300, g.len() - 1] {
            let (i, j, k) = g.cell(idx);
            let path = ((top - g.centre(i, j, k).y) / sun.y).min(SHADOW_RAY_M);
            let expected = 0.002 * path;
            assert!(
                (depth[idx] - expected).abs() < 1e-3 * expected,
                "sun {sun}, cell {idx}: {} vs {expected}",
                depth[idx]
            );
        }
    }
    // A vertical sun over a ball of 0.03/m 1 km across: under its middle
    // the path crosses it (up to 30 optical depths), a column beside it
    // sees clear air.
    let g = grid(UVec3::new(32, 8, 32), 100.0);
    let ball = cloud_ball(&g, Vec3::new(1600.0, 1600.0, 1600.0));
    let depth = sun_depth(&ball, &g, Vec3::Y);
    let under = depth[g.index(15, 0, 15)];
    let beside = depth[g.index(2, 0, 2)];
    assert!(under > 10.0 && under < 31.0, "under the ball {under}");
    assert_eq!(beside, 0.0);
}

/// A cell's extinction as the sun sees it: the mean where its samples
/// agree, less than the mean where cloud fills part of it (light passes
/// through the clear part), and at least the extinction of the clear
/// part's share alone.
#[test]
fn a_part_filled_cell_lets_the_sun_through_its_clear_part() {
    use crate::render::cpu::light_grid::sun_extinction;
    let even = sun_extinction(&[0.01; 8], 80.0);
    assert!((even - 0.01).abs() < 1e-6, "{even}");
    let half = [0.05, 0.0, 0.05, 0.0, 0.05, 0.0, 0.05, 0.0];
    let seen = sun_extinction(&half, 80.0);
    let mean = 0.025;
    // Half the light crosses unhindered: at most ln 2 / 80 m.
    assert!(seen < mean && seen <= 2f32.ln() / 80.0 + 1e-6, "{seen}");
    assert!(seen > 0.0);
}
