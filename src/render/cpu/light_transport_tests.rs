//! Tests of `light_transport.rs`: the transport against theory on
//! uniform layers, its estimator's scale, its determinism.

use glam::UVec3;

use super::*;

/// A band `layers` cells of 50 m high over a 640 m square that
/// repeats (so, endless), of uniform extinction `sigma` per metre.
fn layer(sigma: f32, layers: u32) -> (LightVolumeGrid, Vec<f32>) {
    let grid = LightVolumeGrid {
        cells: UVec3::new(8, layers, 8),
        cell_m: Vec3::new(80.0, 50.0, 80.0),
        bottom_m: 1000.0,
    };
    let n = grid.len();
    (grid, vec![sigma; n])
}

/// The mean of `values` over layer `j`.
fn layer_mean<T: Copy + std::iter::Sum<T> + std::ops::Div<f32, Output = T>>(
    grid: &LightVolumeGrid,
    values: &[T],
    j: u32,
) -> T {
    let n = (grid.cells.x * grid.cells.z) as usize;
    let j = j as usize;
    values[j * n..(j + 1) * n].iter().copied().sum::<T>() / n as f32
}

fn fluences(sh: &[[f32; 9]]) -> Vec<f32> {
    sh.iter().map(sh_fluence).collect()
}

fn fluxes(sh: &[[f32; 9]]) -> Vec<Vec3> {
    sh.iter().map(sh_flux).collect()
}

#[test]
fn clear_air_under_a_uniform_sky_holds_its_radiance() {
    // Radiance L from every direction of the upper hemisphere: the
    // fluence is 2π L and the net flux π L straight down, at every
    // height (nothing scatters or absorbs it).
    let (grid, sigma) = layer(0.0, 6);
    let sky = Vec3::new(0.2, 0.5, 1.0);
    let (phi, sh) = trace_sky(&grid, &sigma, &|_| sky, true, 400_000, 3);
    let flux = fluxes(&sh);
    let lum = luminance(sky);
    for j in 0..6 {
        let p = layer_mean(&grid, &phi, j);
        let f = layer_mean(&grid, &flux, j);
        let expected = sky * 2.0 * PI;
        assert!(
            ((p - expected) / expected).abs().max_element() < 0.03,
            "layer {j}: {p} vs {expected}"
        );
        assert!((f.y / (-PI * lum) - 1.0).abs() < 0.01, "layer {j}: {f}");
        assert!(f.x.abs().max(f.z.abs()) < 0.02 * PI * lum, "layer {j}: {f}");
    }
    // From below instead, the flux points up.
    let (_, sh) = trace_sky(&grid, &sigma, &|_| sky, false, 100_000, 4);
    assert!(layer_mean(&grid, &fluxes(&sh), 3).y > 0.99 * PI * lum);
}

#[test]
fn deep_in_a_thick_layer_the_light_decays_at_the_diffusion_rate() {
    // Far from a thick layer's faces the scattered light settles into
    // its slowest mode, which falls as e^{-κ z}; for weak absorption
    // κ = σ √(3 (1 - ϖ)(1 - g)) (the diffusion length; Case & Zweifel's
    // asymptotic mode to first order in 1 - ϖ), 0.0072/m here. Every
    // layer of 50 m deeper keeps e^{-50 κ} = 0.70 of the light.
    let sigma_t = 0.06;
    let (grid, sigma) = layer(sigma_t, 24);
    let sh = trace(&grid, &sigma, Vec3::Y, 400_000, 5);
    let (phi, flux) = (fluences(&sh), fluxes(&sh));
    let kappa = sigma_t * (3.0 * (1.0 - ALBEDO) * (1.0 - 0.525_f32)).sqrt();
    // Layers 9-15: 450-750 m from the top (optical depth 27-45),
    // 450 m and more from the floor.
    let rate = (layer_mean(&grid, &phi, 15) / layer_mean(&grid, &phi, 9)).ln() / (6.0 * 50.0);
    assert!(
        (rate / kappa - 1.0).abs() < 0.1,
        "decay {rate} /m against {kappa} /m"
    );
    // The light flows down, away from the sun's side.
    assert!(layer_mean(&grid, &flux, 12).y < 0.0);
    // Near the top, what the layer reflects flows back up.
    assert!(layer_mean(&grid, &flux, 23).y > 0.0);
}

#[test]
fn no_light_without_a_sun_or_photons() {
    let (grid, sigma) = layer(0.02, 4);
    let low = Vec3::new(1.0, 0.5 * LIGHT_SUN_MIN, 0.0).normalize();
    for (sun, photons) in [(low, 1000), (Vec3::Y, 0)] {
        let sh = trace(&grid, &sigma, sun, photons, 1);
        assert_eq!(sh.len(), grid.len());
        assert!(sh.iter().flatten().all(|c| *c == 0.0));
    }
}

#[test]
fn the_same_seed_gives_the_same_light() {
    // However rayon splits the photons among threads.
    let (grid, sigma) = layer(0.03, 6);
    let sun = Vec3::new(0.3, 0.8, 0.2).normalize();
    let a = trace(&grid, &sigma, sun, 20_000, 9);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool of one thread");
    let b = one.install(|| trace(&grid, &sigma, sun, 20_000, 9));
    assert_eq!(a, b);
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("a pool of three threads");
    assert_eq!(a, three.install(|| trace(&grid, &sigma, sun, 20_000, 9)));
    let c = trace(&grid, &sigma, sun, 20_000, 10);
    assert_ne!(a, c);
}

/// `∫ f(ω) dω` over the sphere, by the midpoint rule in cos θ and φ.
fn sphere_integral(f: impl Fn(Vec3) -> f64) -> f64 {
    let (nu, nphi) = (400, 800);
    let mut s = 0.0;
    for i in 0..nu {
        let z = -1.0 + (i as f64 + 0.5) * 2.0 / nu as f64;
        let r = (1.0 - z * z).sqrt();
        for k in 0..nphi {
            let phi = (k as f64 + 0.5) * 2.0 * std::f64::consts::PI / nphi as f64;
            let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            s += f(d);
        }
    }
    s * 4.0 * std::f64::consts::PI / (nu * nphi) as f64
}

#[test]
fn the_harmonics_are_orthonormal() {
    for i in 0..9 {
        for j in 0..9 {
            let v = sphere_integral(|d| (sh9(d)[i] * sh9(d)[j]) as f64);
            let expected = if i == j { 1.0 } else { 0.0 };
            assert!((v - expected).abs() < 1e-3, "<Y{i}, Y{j}> = {v}");
        }
    }
}

#[test]
fn the_phase_moments_are_the_dual_lobe_s() {
    // p_l = 2π ∫ p(μ) P_l(μ) dμ for the phase the photons scatter by.
    use crate::render::cpu::lighting::phase_dual;
    let legendre = [|_: f64| 1.0, |m: f64| m, |m: f64| 0.5 * (3.0 * m * m - 1.0)];
    for (l, p) in legendre.iter().enumerate() {
        let n = 200_000;
        let m: f64 = (0..n)
            .map(|i| {
                let mu = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
                phase_dual(mu as f32, 1.0) as f64 * p(mu) * 2.0 * std::f64::consts::PI * 2.0
                    / n as f64
            })
            .sum();
        assert!((m - PHASE_MOMENTS[l] as f64).abs() < 2e-3, "l = {l}: {m}");
    }
    // Through the addition theorem, a beam of coefficients `Y(b)`
    // scatters toward `w` as `Σ_l p_l (2l + 1) / 4π P_l(b · w)`: the
    // harmonics' order and signs are consistent.
    for (b, w) in [
        (Vec3::Y, Vec3::X),
        (
            Vec3::new(0.3, -0.8, 0.52).normalize(),
            Vec3::new(-0.6, 0.1, 0.79).normalize(),
        ),
        (Vec3::Z, Vec3::new(0.0, 0.6, 0.8)),
    ] {
        let (yb, yw) = (sh9(b), sh9(w));
        let got: f32 = (0..9)
            .map(|k| PHASE_MOMENTS[SH_BAND[k]] * yb[k] * yw[k])
            .sum();
        let mu = b.dot(w) as f64;
        let expected: f64 = (0..3)
            .map(|l| {
                PHASE_MOMENTS[l] as f64 * (2 * l + 1) as f64 * legendre[l](mu)
                    / (4.0 * std::f64::consts::PI)
            })
            .sum();
        assert!(
            (got as f64 - expected).abs() < 1e-5,
            "{b} {w}: {got} vs {expected}"
        );
    }
}

#[test]
fn the_basis_is_orthonormal_and_square_to_the_direction() {
    for d in [Vec3::X, -Vec3::Z, Vec3::new(0.3, -0.8, 0.52).normalize()] {
        let (a, b) = orthonormal_pair(d);
        for (u, v) in [(a, b), (a, d), (b, d)] {
            assert!(u.dot(v).abs() < 1e-5);
        }
        assert!((a.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
    }
}
