//! Tests of `light_volume.rs`: the slab solution, the sweeps' settling,
//! light across clear air, the sun's depth.

use super::*;

/// The cells' extinction of a 1 km ball of cloud (0.03/m) around
/// `centre`, clear air elsewhere.
fn cloud_ball(g: &DiffusionGrid, centre: Vec3) -> Vec<f32> {
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

fn grid(cells: UVec3, cell_m: f32) -> DiffusionGrid {
    DiffusionGrid {
        cells,
        cell_m: Vec3::splat(cell_m),
        bottom_m: 1000.0,
    }
}

/// A layer of uniform cloud under a sun in the zenith is a slab: the
/// fluence solves `-D φ'' + σ_a φ = ϖ σ e^{-k (H - y)}`, `k = (1 - g) σ`
/// ([`first_scattering`]), with `φ = 0` at the band's floor and
/// ceiling: `φ = A e^{κy} + B e^{-κy} + C e^{k y}`, `κ² = σ_a / D`,
/// `C = ϖ σ e^{-k H} / (σ_a - D k²)`. The grid's solution agrees
/// within 3 % in the middle half of the layer (20 m cells; the
/// source's e-folding length spans 8 of them).
#[test]
fn a_uniform_layer_diffuses_as_the_slab_solution() {
    let g = grid(UVec3::new(8, 64, 8), 20.0);
    let s = 0.0125;
    let sigma = vec![s; g.len()];
    let v = LightVolume::solve(g, &sigma, Vec3::Y, 3000);
    let (dc, a) = (diffusion_coefficient(s) as f64, absorption(s) as f64);
    let (s, h) = (s as f64, 64.0 * 20.0);
    let k = (1.0 - PHASE_MEAN_COSINE as f64) * s;
    let kappa = (a / dc).sqrt();
    let c = ALBEDO as f64 * s * (-k * h).exp() / (a - dc * k * k);
    // φ(0) = φ(h) = 0, y from the band's floor.
    let (e0, eh) = (c, c * (k * h).exp());
    // A + B = -e0; A e^{κh} + B e^{-κh} = -eh.
    let (p, m) = ((kappa * h).exp(), (-kappa * h).exp());
    let b = (-eh + e0 * p) / (m - p);
    let a_ = -e0 - b;
    for j in 16..48 {
        let y = 20.0 * (j as f64 + 0.5);
        let exact = a_ * (kappa * y).exp() + b * (-kappa * y).exp() + c * (k * y).exp();
        let got = v.fluence[g.index(3, j, 5)] as f64;
        assert!(
            (got / exact - 1.0).abs() < 0.03,
            "layer {j}: {got} vs {exact}"
        );
        // The net flux, -D φ': vertical, within 5 % of the exact one
        // (or 2 % of the fluence where it crosses zero), and under
        // the limit here.
        let slope =
            a_ * kappa * (kappa * y).exp() - b * kappa * (-kappa * y).exp() + c * k * (k * y).exp();
        let exact_flux = -dc * slope;
        let f = v.flux[g.index(3, j, 5)];
        assert!(f.x.abs() < 1e-6 && f.z.abs() < 1e-6, "layer {j}: {f}");
        assert!(exact_flux.abs() < FLUX_LIMIT as f64 * exact, "layer {j}");
        let err = (f.y as f64 - exact_flux).abs();
        assert!(
            err < 0.05 * exact_flux.abs() || err < 0.02 * exact,
            "layer {j}: flux {} vs {exact_flux}",
            f.y
        );
    }
}

/// From nothing, [`LIGHT_SWEEPS`] sweeps bring a 1 km cloud's
/// fluence within 1 % of the settled one (2000 sweeps) at 80 m cells.
#[test]
fn the_sweeps_settle_on_a_cloud() {
    let g = grid(UVec3::new(32, 20, 32), 80.0);
    let centre = g.centre(16, 10, 16);
    let sigma = cloud_ball(&g, centre);
    let sun = Vec3::new(0.5, 0.8, 0.2).normalize();
    let fast = LightVolume::solve(g, &sigma, sun, LIGHT_SWEEPS);
    let slow = LightVolume::solve(g, &sigma, sun, 2000);
    let (mut err, mut total) = (0.0, 0.0);
    for ((s, f), settled) in sigma.iter().zip(&fast.fluence).zip(&slow.fluence) {
        if *s > 0.0 {
            err += (f - settled).abs();
            total += settled;
        }
    }
    assert!(total > 0.0);
    assert!(err / total < 0.01, "{}", err / total);
    // The light flows out of the cloud: at its shaded side (away from
    // the sun) the flux points away from the sun, at every cell it is
    // within the limit.
    let shaded = centre - sun * 400.0;
    let idx = g.index(
        (shaded.x / 80.0) as i32,
        ((shaded.y - g.bottom_m) / 80.0) as i32,
        (shaded.z / 80.0) as i32,
    );
    assert!(sigma[idx] > 0.0);
    assert!(slow.flux[idx].dot(sun) < 0.0, "{}", slow.flux[idx]);
    for (f, phi) in slow.flux.iter().zip(&slow.fluence) {
        assert!(f.length() <= FLUX_LIMIT * phi.max(0.0) * 1.0001 + 1e-9);
    }
}

/// Clouds light each other across clear air: a 1 km cloud beside
/// another like it (centres 1.12 km apart, 120 m of clear air between
/// them), under a sun in the zenith, holds at least
/// 1 % more diffused light than alone (3.1 %; 0.4 % when clear air
/// absorbed the light within a cell, before [`CLEAR_AIR_LOSS_M`]).
/// And clear air does not pile light up: no clear cell is brighter
/// than the clouds' brightest.
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
            .map(|i| v.fluence[i])
            .collect();
        inside.iter().sum::<f32>() / inside.len() as f32
    };
    let alone = LightVolume::solve(g, &lone, Vec3::Y, LIGHT_SWEEPS);
    let beside = LightVolume::solve(g, &pair, Vec3::Y, LIGHT_SWEEPS);
    let gain = mean_in_lone(&beside) / mean_in_lone(&alone);
    assert!(gain > 1.01, "{gain}");
    let peak = (0..g.len())
        .filter(|i| pair[*i] > 0.0)
        .map(|i| beside.fluence[i])
        .fold(0.0, f32::max);
    assert!(
        (0..g.len())
            .filter(|i| pair[*i] == 0.0)
            .all(|i| beside.fluence[i] < peak)
    );
}

/// The optical depth toward the sun of a uniform layer is its path
/// length through the rest of the band times σ, at any sun.
#[test]
fn the_sun_depth_of_a_uniform_layer_is_its_slant_path() {
    let g = grid(UVec3::new(16, 10, 16), 50.0);
    let sigma = vec![0.01; g.len()];
    for sun in [Vec3::Y, Vec3::new(0.8, 0.3, -0.4).normalize()] {
        let tau = sun_depth(&g, &sigma, sun);
        for j in 0..10 {
            let rise = 500.0 - 50.0 * (j as f32 + 0.5);
            let exact = 0.01 * rise / sun.y;
            let got = tau[g.index(7, j, 3)];
            assert!((got / exact - 1.0).abs() < 1e-4, "{j}: {got} vs {exact}");
        }
    }
    let low = sun_depth(&g, &sigma, Vec3::new(1.0, 0.01, 0.0).normalize());
    assert!(low.iter().all(|t| *t == LIGHT_DEPTH_NONE));
}
