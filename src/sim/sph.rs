//! SPH pressure and viscosity between parcels (Müller et al. 2003), with a
//! hashed uniform grid for the neighbour search.
//!
//! The grid's cells are at least `h` wide, so all neighbours of a parcel lie
//! in its 27 surrounding cells. Cells hash into `2n` buckets (Teschner et al.
//! 2003): any `h`, however small next to the domain, costs memory in the
//! parcel count only. The 27 cells' buckets are de-duplicated before they are
//! visited, so a periodic domain only a few cells wide, or two cells sharing
//! a bucket, never counts a neighbour twice; the distance test discards the
//! strangers a bucket collision brings in.

use glam::DVec3;
use rayon::prelude::*;

use super::kernels::{Kernel, Poly6, Spiky, Viscosity};

/// Above this many active parcels the SPH passes run on all cores (rayon);
/// below it the thread hand-off costs more than it saves (measured with
/// `cargo bench --bench physics`, see README).
pub const PARALLEL_THRESHOLD: usize = 512;

/// Parameters of one SPH evaluation.
#[derive(Debug, Clone, Copy)]
pub struct SphParams {
    /// Smoothing length, m.
    pub h: f64,
    /// Side of the periodic domain, m.
    pub domain_m: f64,
    /// Sound speed, m/s.
    pub sound_speed: f64,
    /// Kinematic viscosity, m²/s.
    pub viscosity: f64,
}

/// Reusable neighbour grid.
#[derive(Debug, Clone, Default)]
pub struct NeighbourGrid {
    starts: Vec<u32>,
    order: Vec<u32>,
    keys: Vec<u32>,
    density: Vec<f64>,
    pressure: Vec<f64>,
    nx: i64,
    cell_xy: f64,
    h: f64,
}

impl NeighbourGrid {
    fn bucket(&self, ix: i64, iy: i64, iz: i64) -> u32 {
        let (ix, iy) = (ix.rem_euclid(self.nx), iy.rem_euclid(self.nx));
        let h = (ix as u64).wrapping_mul(73_856_093)
            ^ (iy as u64).wrapping_mul(19_349_663)
            ^ (iz as u64).wrapping_mul(83_492_791);
        (h % (self.starts.len() as u64 - 1)) as u32
    }

    fn cell(&self, p: DVec3) -> (i64, i64, i64) {
        (
            (p.x / self.cell_xy).floor() as i64,
            (p.y / self.cell_xy).floor() as i64,
            (p.z / self.h).floor() as i64,
        )
    }

    /// Sorts the active parcels into buckets.
    fn build(&mut self, pos: &[DVec3], active: &[u32], p: &SphParams) {
        self.h = p.h;
        self.nx = ((p.domain_m / p.h).floor() as i64).max(1);
        self.cell_xy = p.domain_m / self.nx as f64;
        let buckets = (2 * active.len()).max(1);
        self.starts.clear();
        self.starts.resize(buckets + 1, 0);
        self.keys.clear();
        for &i in active {
            let (x, y, z) = self.cell(pos[i as usize]);
            let b = self.bucket(x, y, z);
            self.keys.push(b);
            self.starts[b as usize + 1] += 1;
        }
        for b in 0..buckets {
            self.starts[b + 1] += self.starts[b];
        }
        self.order.clear();
        self.order.resize(active.len(), 0);
        let mut fill = self.starts.clone();
        for (k, &i) in active.iter().enumerate() {
            let b = self.keys[k] as usize;
            self.order[fill[b] as usize] = i;
            fill[b] += 1;
        }
    }

    /// Calls `f(j, x_i - x_j, r)` for every other active parcel `j` with
    /// `r < h` (minimum-image distance in the periodic plane).
    #[inline]
    fn for_each_neighbour(&self, i: usize, pos: &[DVec3], l: f64, mut f: impl FnMut(usize, DVec3, f64)) {
        let pi = pos[i];
        let (cx, cy, cz) = self.cell(pi);
        let mut buckets = [0u32; 27];
        let mut n = 0;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    buckets[n] = self.bucket(cx + dx, cy + dy, cz + dz);
                    n += 1;
                }
            }
        }
        buckets.sort_unstable();
        let h2 = self.h * self.h;
        let mut last = u32::MAX;
        for &b in &buckets {
            if b == last {
                continue;
            }
            last = b;
            let (s, e) = (self.starts[b as usize] as usize, self.starts[b as usize + 1] as usize);
            for &j in &self.order[s..e] {
                let j = j as usize;
                if j == i {
                    continue;
                }
                let mut d = pi - pos[j];
                d.x -= l * (d.x / l).round();
                d.y -= l * (d.y / l).round();
                let r2 = d.length_squared();
                if r2 < h2 {
                    f(j, d, r2.sqrt());
                }
            }
        }
    }
}

/// SPH accelerations (m/s²) of the `active` parcels into `acc` (indexed like
/// `pos`; inactive entries are set to zero).
///
/// Every parcel has unit mass, so the density is a number density (1/m³) and
/// `ρ_0` is a lone parcel's own density `W(0, h)`: any overlap pushes apart,
/// nothing pulls together. The acceleration
/// `a_i = -Σ (p_i/ρ_i² + p_j/ρ_j²) ∇W_spiky + ν Σ (v_j - v_i)/ρ_j ∇²W_visc`
/// is antisymmetric in `i, j`, so momentum is conserved.
pub fn accelerations(
    grid: &mut NeighbourGrid,
    pos: &[DVec3],
    vel: &[DVec3],
    active: &[u32],
    p: &SphParams,
    acc: &mut Vec<DVec3>,
) {
    acc.clear();
    acc.resize(pos.len(), DVec3::ZERO);
    if active.is_empty() {
        return;
    }
    grid.build(pos, active, p);
    let n = pos.len();
    let rho0 = Poly6::w(0.0, p.h);
    let c2 = p.sound_speed * p.sound_speed;
    let l = p.domain_m;
    let parallel = active.len() >= PARALLEL_THRESHOLD;

    let mut density = std::mem::take(&mut grid.density);
    let mut pressure = std::mem::take(&mut grid.pressure);
    density.clear();
    density.resize(n, rho0);
    pressure.clear();
    pressure.resize(n, 0.0);
    let density_of = |i: usize| {
        let mut rho = rho0;
        grid.for_each_neighbour(i, pos, l, |_, _, r| rho += Poly6::w(r, p.h));
        rho
    };
    let rho: Vec<(u32, f64)> = if parallel {
        active.par_iter().map(|&i| (i, density_of(i as usize))).collect()
    } else {
        active.iter().map(|&i| (i, density_of(i as usize))).collect()
    };
    for (i, r) in rho {
        density[i as usize] = r;
        pressure[i as usize] = c2 * (r - rho0).max(0.0);
    }

    let accel_of = |i: usize| {
        let (pi_rho2, vi) = (pressure[i] / (density[i] * density[i]), vel[i]);
        let mut a = DVec3::ZERO;
        grid.for_each_neighbour(i, pos, l, |j, d, r| {
            let pj_rho2 = pressure[j] / (density[j] * density[j]);
            a -= Spiky::grad_w(d, r, p.h) * (pi_rho2 + pj_rho2);
            a += (vel[j] - vi) * (p.viscosity * Viscosity::laplacian(r, p.h) / density[j]);
        });
        a
    };
    let out: Vec<(u32, DVec3)> = if parallel {
        active.par_iter().map(|&i| (i, accel_of(i as usize))).collect()
    } else {
        active.iter().map(|&i| (i, accel_of(i as usize))).collect()
    };
    for (i, a) in out {
        acc[i as usize] = a;
    }
    grid.density = density;
    grid.pressure = pressure;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(domain: f64) -> SphParams {
        SphParams {
            h: 100.0,
            domain_m: domain,
            sound_speed: 3.0,
            viscosity: 10.0,
        }
    }

    fn brute_force_neighbours(pos: &[DVec3], i: usize, h: f64, l: f64) -> Vec<usize> {
        (0..pos.len())
            .filter(|&j| {
                let mut d = pos[i] - pos[j];
                d.x -= l * (d.x / l).round();
                d.y -= l * (d.y / l).round();
                j != i && d.length() < h
            })
            .collect()
    }

    #[test]
    fn grid_finds_exactly_the_brute_force_neighbours() {
        // Small periodic domains (1, 2, 3 cells) exercise the wrap-around
        // de-duplication; a large one exercises bucket collisions.
        for domain in [120.0, 250.0, 330.0, 5000.0] {
            let pos: Vec<DVec3> = (0..300)
                .map(|i| {
                    let u = |s| crate::sim::parcels::keyed_uniform(3, i, 0, s);
                    DVec3::new(u(0) * domain, u(1) * domain, u(2) * 400.0)
                })
                .collect();
            let active: Vec<u32> = (0..pos.len() as u32).collect();
            let mut grid = NeighbourGrid::default();
            let p = params(domain);
            grid.build(&pos, &active, &p);
            for i in 0..pos.len() {
                let mut found = Vec::new();
                grid.for_each_neighbour(i, &pos, domain, |j, _, _| found.push(j));
                found.sort_unstable();
                assert_eq!(found, brute_force_neighbours(&pos, i, p.h, domain), "domain {domain}, parcel {i}");
            }
        }
    }

    #[test]
    fn overlapping_parcels_repel_and_conserve_momentum() {
        let pos = vec![DVec3::new(500.0, 500.0, 300.0), DVec3::new(540.0, 500.0, 300.0)];
        let vel = vec![DVec3::ZERO; 2];
        let mut acc = Vec::new();
        accelerations(&mut NeighbourGrid::default(), &pos, &vel, &[0, 1], &params(2000.0), &mut acc);
        assert!(acc[0].x < 0.0 && acc[1].x > 0.0, "{acc:?}");
        assert!((acc[0] + acc[1]).length() < 1e-15 * acc[0].length().max(1.0));
    }

    #[test]
    fn coincident_parcels_stay_finite() {
        let pos = vec![DVec3::new(10.0, 10.0, 10.0); 50];
        let vel = vec![DVec3::ZERO; 50];
        let active: Vec<u32> = (0..50).collect();
        let mut acc = Vec::new();
        accelerations(&mut NeighbourGrid::default(), &pos, &vel, &active, &params(1000.0), &mut acc);
        assert!(acc.iter().all(|a| a.is_finite()));
    }
}
