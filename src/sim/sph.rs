//! SPH pressure and viscosity between parcels (Müller et al. 2003), with a
//! hashed uniform grid for the neighbour search. (Over 400 lines because a
//! third of it is the tests of the grid against a brute-force search; the
//! grid and the two SPH passes read best together.)
//!
//! The grid is dense: cell `(ix, iy, iz)` at index `(iz * nx + iy) * nx +
//! ix`, filled by a counting sort, so the three cells along x of each of the
//! 9 (y, z) rows of a query are neighbours in memory. Cells are at least `h`
//! wide (all neighbours of a parcel lie in its 27 surrounding cells); when a
//! sparse domain would need more than [`CELLS_PER_PARCEL`] cells a parcel,
//! the cells grow, which only adds candidates for the distance test. A
//! periodic domain fewer than 3 cells wide wraps offsets onto one cell;
//! those are visited once.

use glam::DVec3;
use rayon::prelude::*;

use super::kernels::{Kernel, Poly6, Spiky, Viscosity};

/// Above this many active parcels the solver runs the SPH passes on all
/// cores (rayon); below it the thread hand-off costs more than it saves.
/// The crossover is measured by `cargo bench --bench physics -- sph_crossover`
/// (README, Speed).
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

/// `floor(v)` without a libm call (the baseline x86-64 target has no
/// rounding instruction).
#[inline]
fn floor_i64(v: f64) -> i64 {
    let t = v as i64;
    if (t as f64) > v { t - 1 } else { t }
}

/// Most cells the grid may have per active parcel (plus a fixed 4096).
pub const CELLS_PER_PARCEL: usize = 8;

/// Reusable neighbour grid.
#[derive(Debug, Clone, Default)]
pub struct NeighbourGrid {
    starts: Vec<u32>,
    order: Vec<u32>,
    keys: Vec<u32>,
    density: Vec<f64>,
    pressure: Vec<f64>,
    nx: i64,
    nz: i64,
    cell_xy: f64,
    cell_z: f64,
    h: f64,
}

impl NeighbourGrid {
    #[inline]
    fn cell(&self, p: DVec3) -> (i64, i64, i64) {
        (
            // Positions are >= 0 here, so truncation is the floor.
            ((p.x / self.cell_xy) as i64).clamp(0, self.nx - 1),
            ((p.y / self.cell_xy) as i64).clamp(0, self.nx - 1),
            ((p.z / self.cell_z) as i64).clamp(0, self.nz - 1),
        )
    }

    #[inline]
    fn index(&self, ix: i64, iy: i64, iz: i64) -> usize {
        ((iz * self.nx + iy) * self.nx + ix) as usize
    }

    /// Sorts the active parcels into cells.
    fn build(&mut self, pos: &[DVec3], active: &[u32], p: &SphParams) {
        self.h = p.h;
        let z_max = active
            .iter()
            .map(|&i| pos[i as usize].z)
            .fold(0.0_f64, f64::max);
        let budget = (CELLS_PER_PARCEL * active.len() + 4096) as f64;
        let mut cell = p.h;
        loop {
            let nx = (p.domain_m / cell).floor().max(1.0);
            let nz = (z_max / cell).floor() + 1.0;
            if nx * nx * nz <= budget {
                self.nx = nx as i64;
                self.nz = nz as i64;
                break;
            }
            cell *= 1.25;
        }
        self.cell_xy = p.domain_m / self.nx as f64;
        self.cell_z = cell;
        let cells = (self.nx * self.nx * self.nz) as usize;
        self.starts.clear();
        self.starts.resize(cells + 1, 0);
        self.keys.clear();
        for &i in active {
            let (x, y, z) = self.cell(pos[i as usize]);
            let k = self.index(x, y, z);
            self.keys.push(k as u32);
            self.starts[k + 1] += 1;
        }
        for c in 0..cells {
            self.starts[c + 1] += self.starts[c];
        }
        self.order.clear();
        self.order.resize(active.len(), 0);
        let mut fill = self.starts.clone();
        for (k, &i) in active.iter().enumerate() {
            let c = self.keys[k] as usize;
            self.order[fill[c] as usize] = i;
            fill[c] += 1;
        }
    }

    /// Calls `f(j, x_i - x_j, r)` for every other active parcel `j` with
    /// `r < h` (minimum-image distance in the periodic plane).
    #[inline]
    fn for_each_neighbour(
        &self,
        i: usize,
        pos: &[DVec3],
        l: f64,
        mut f: impl FnMut(usize, DVec3, f64),
    ) {
        let pi = pos[i];
        // The cells the sphere of radius h around the parcel overlaps, per
        // axis (at most 3, as cells are at least h wide), wrapped in the
        // plane and each visited once.
        let span = |lo_m: f64, hi_m: f64, cell: f64, n: i64, wrap: bool| {
            let (lo, hi) = (floor_i64(lo_m / cell), floor_i64(hi_m / cell));
            let mut v = [0i64; 3];
            let mut m = 0;
            if wrap && hi - lo + 1 >= n {
                for x in 0..n {
                    v[m] = x;
                    m += 1;
                }
            } else {
                for x in lo..=hi {
                    let x = if wrap { x.rem_euclid(n) } else { x };
                    if (0..n).contains(&x) && m < 3 {
                        v[m] = x;
                        m += 1;
                    }
                }
            }
            (v, m)
        };
        let (xs, mx) = span(pi.x - self.h, pi.x + self.h, self.cell_xy, self.nx, true);
        let (ys, my) = span(pi.y - self.h, pi.y + self.h, self.cell_xy, self.nx, true);
        let (zs, mz) = span(pi.z - self.h, pi.z + self.h, self.cell_z, self.nz, false);
        let h2 = self.h * self.h;
        let half = 0.5 * l;
        for &iz in &zs[..mz] {
            for &iy in &ys[..my] {
                for &ix in &xs[..mx] {
                    let c = self.index(ix, iy, iz);
                    let (s, e) = (self.starts[c] as usize, self.starts[c + 1] as usize);
                    for &j in &self.order[s..e] {
                        let j = j as usize;
                        if j == i {
                            continue;
                        }
                        let mut d = pi - pos[j];
                        // Minimum image in the periodic plane (|d| < l before).
                        if d.x > half {
                            d.x -= l;
                        } else if d.x < -half {
                            d.x += l;
                        }
                        if d.y > half {
                            d.y -= l;
                        } else if d.y < -half {
                            d.y += l;
                        }
                        let r2 = d.length_squared();
                        if r2 < h2 {
                            f(j, d, r2.sqrt());
                        }
                    }
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
/// is antisymmetric in `i, j`, so momentum is conserved. `parallel` runs
/// the passes with rayon; the result is the same either way.
pub fn accelerations(
    grid: &mut NeighbourGrid,
    pos: &[DVec3],
    vel: &[DVec3],
    active: &[u32],
    p: &SphParams,
    parallel: bool,
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

    // Pass 1, density: each chunk of queries (in cell order, so consecutive
    // queries read the same cells) walks the grid once and keeps its
    // neighbour pairs for pass 2.
    let density_chunk = |queries: &[u32]| {
        let mut out = ChunkPairs::default();
        for &i in queries {
            let mut rho = rho0;
            grid.for_each_neighbour(i as usize, pos, l, |j, d, r| {
                rho += Poly6::w(r, p.h);
                out.pairs.push(Pair { j: j as u32, d, r });
            });
            out.ends.push(out.pairs.len() as u32);
            out.rho.push(rho);
        }
        out
    };
    let queries = &grid.order;
    let chunks: Vec<ChunkPairs> = if parallel {
        queries.par_chunks(QUERY_CHUNK).map(density_chunk).collect()
    } else {
        queries.chunks(QUERY_CHUNK).map(density_chunk).collect()
    };
    let mut density = std::mem::take(&mut grid.density);
    let mut pressure = std::mem::take(&mut grid.pressure);
    density.clear();
    density.resize(n, rho0);
    pressure.clear();
    pressure.resize(n, 0.0);
    for (qs, c) in queries.chunks(QUERY_CHUNK).zip(&chunks) {
        for (&i, &r) in qs.iter().zip(&c.rho) {
            density[i as usize] = r;
            pressure[i as usize] = c2 * (r - rho0).max(0.0);
        }
    }

    // Pass 2, forces, over the kept pairs.
    let force_chunk = |(qs, c): (&[u32], &ChunkPairs)| {
        let mut start = 0usize;
        qs.iter()
            .zip(&c.ends)
            .map(|(&i, &end)| {
                let i = i as usize;
                let (pi_rho2, vi) = (pressure[i] / (density[i] * density[i]), vel[i]);
                let mut a = DVec3::ZERO;
                for pair in &c.pairs[start..end as usize] {
                    let j = pair.j as usize;
                    let pj_rho2 = pressure[j] / (density[j] * density[j]);
                    a -= Spiky::grad_w(pair.d, pair.r, p.h) * (pi_rho2 + pj_rho2);
                    a += (vel[j] - vi)
                        * (p.viscosity * Viscosity::laplacian(pair.r, p.h) / density[j]);
                }
                start = end as usize;
                (i as u32, a)
            })
            .collect::<Vec<_>>()
    };
    let out: Vec<Vec<(u32, DVec3)>> = if parallel {
        queries
            .par_chunks(QUERY_CHUNK)
            .zip(chunks.par_iter())
            .map(force_chunk)
            .collect()
    } else {
        queries
            .chunks(QUERY_CHUNK)
            .zip(chunks.iter())
            .map(force_chunk)
            .collect()
    };
    for (i, a) in out.into_iter().flatten() {
        acc[i as usize] = a;
    }
    grid.density = density;
    grid.pressure = pressure;
}

/// Queries per unit of parallel work.
const QUERY_CHUNK: usize = 128;

/// A neighbour found in pass 1: index, `x_i - x_j`, distance.
#[derive(Clone, Copy)]
struct Pair {
    j: u32,
    d: DVec3,
    r: f64,
}

/// The pairs and densities of one chunk of queries.
#[derive(Default)]
struct ChunkPairs {
    pairs: Vec<Pair>,
    /// End of each query's pairs in `pairs`.
    ends: Vec<u32>,
    rho: Vec<f64>,
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
                assert_eq!(
                    found,
                    brute_force_neighbours(&pos, i, p.h, domain),
                    "domain {domain}, parcel {i}"
                );
            }
        }
    }

    #[test]
    fn overlapping_parcels_repel_and_conserve_momentum() {
        let pos = vec![
            DVec3::new(500.0, 500.0, 300.0),
            DVec3::new(540.0, 500.0, 300.0),
        ];
        let vel = vec![DVec3::ZERO; 2];
        let mut acc = Vec::new();
        accelerations(
            &mut NeighbourGrid::default(),
            &pos,
            &vel,
            &[0, 1],
            &params(2000.0),
            false,
            &mut acc,
        );
        assert!(acc[0].x < 0.0 && acc[1].x > 0.0, "{acc:?}");
        assert!((acc[0] + acc[1]).length() < 1e-15 * acc[0].length().max(1.0));
    }

    #[test]
    fn rayon_and_sequential_passes_agree_exactly() {
        let pos: Vec<DVec3> = (0..800)
            .map(|i| {
                let u = |s| crate::sim::parcels::keyed_uniform(5, i, 0, s);
                DVec3::new(u(0) * 2000.0, u(1) * 2000.0, u(2) * 300.0)
            })
            .collect();
        let vel: Vec<DVec3> = (0..800)
            .map(|i| DVec3::new(i as f64 * 1e-3, 0.0, 0.0))
            .collect();
        let active: Vec<u32> = (0..800).collect();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        accelerations(
            &mut NeighbourGrid::default(),
            &pos,
            &vel,
            &active,
            &params(2000.0),
            false,
            &mut a,
        );
        accelerations(
            &mut NeighbourGrid::default(),
            &pos,
            &vel,
            &active,
            &params(2000.0),
            true,
            &mut b,
        );
        assert_eq!(a, b);
        assert!(a.iter().any(|x| x.length() > 0.0));
    }

    #[test]
    fn coincident_parcels_stay_finite() {
        let pos = vec![DVec3::new(10.0, 10.0, 10.0); 50];
        let vel = vec![DVec3::ZERO; 50];
        let active: Vec<u32> = (0..50).collect();
        let mut acc = Vec::new();
        accelerations(
            &mut NeighbourGrid::default(),
            &pos,
            &vel,
            &active,
            &params(1000.0),
            true,
            &mut acc,
        );
        assert!(acc.iter().all(|a| a.is_finite()));
    }
}
