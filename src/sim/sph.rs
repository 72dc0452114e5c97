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
/// (docs/physics.md, "Speed").
pub const PARALLEL_THRESHOLD: usize = 2048;

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
pub const CELLS_PER_PARCEL: usize = 2;

/// Reusable neighbour grid.
#[derive(Debug, Clone, Default)]
pub struct NeighbourGrid {
    starts: Vec<u32>,
    /// Parcel index of each slot (slots are in cell order).
    order: Vec<u32>,
    keys: Vec<u32>,
    fill: Vec<u32>,
    /// Positions and velocities copied into slot order, so a query reads
    /// its candidates contiguously.
    pos: Vec<DVec3>,
    vel: Vec<DVec3>,
    /// Per slot: density, and `p/ρ²`.
    density: Vec<f64>,
    p_rho2: Vec<f64>,
    acc: Vec<DVec3>,
    /// Per chunk of queries: the neighbour pairs pass 1 found (kept from
    /// step to step, so a step allocates nothing once warm).
    chunks: Vec<ChunkPairs>,
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

    /// Sorts the active parcels into cells and copies their positions and
    /// velocities into slot order.
    fn build(&mut self, pos: &[DVec3], vel: &[DVec3], active: &[u32], p: &SphParams) {
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
        self.fill.clear();
        self.fill.extend_from_slice(&self.starts);
        for (k, &i) in active.iter().enumerate() {
            let c = self.keys[k] as usize;
            self.order[self.fill[c] as usize] = i;
            self.fill[c] += 1;
        }
        self.pos.clear();
        self.pos.extend(self.order.iter().map(|&i| pos[i as usize]));
        self.vel.clear();
        self.vel.extend(self.order.iter().map(|&i| vel[i as usize]));
    }

    /// Calls `f(j, x_i - x_j, r)` for the slot `j` of every other active
    /// parcel with `r < h` from the parcel in slot `i` (minimum-image
    /// distance in the periodic plane).
    #[inline]
    fn for_each_neighbour(&self, i: usize, l: f64, mut f: impl FnMut(usize, DVec3, f64)) {
        let pos = &self.pos;
        let pi = pos[i];
        // The cells the sphere of radius h around the parcel overlaps, per
        // axis (at most 3, as cells are at least h wide), wrapped in the
        // plane and each visited once. Along x they are contiguous in
        // memory, so each (y, z) row is read as at most two runs of cells.
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
        let x_runs = {
            let (lo, hi) = (
                floor_i64((pi.x - self.h) / self.cell_xy),
                floor_i64((pi.x + self.h) / self.cell_xy),
            );
            let n = self.nx;
            if hi - lo + 1 >= n {
                ([(0, n - 1), (0, -1)], 1)
            } else {
                let (a, b) = (lo.rem_euclid(n), hi.rem_euclid(n));
                if a <= b {
                    ([(a, b), (0, -1)], 1)
                } else {
                    ([(a, n - 1), (0, b)], 2)
                }
            }
        };
        let (ys, my) = span(pi.y - self.h, pi.y + self.h, self.cell_xy, self.nx, true);
        let (zs, mz) = span(pi.z - self.h, pi.z + self.h, self.cell_z, self.nz, false);
        let h2 = self.h * self.h;
        let half = 0.5 * l;
        for &iz in &zs[..mz] {
            for &iy in &ys[..my] {
                for &(a, b) in &x_runs.0[..x_runs.1] {
                    let s = self.starts[self.index(a, iy, iz)] as usize;
                    let e = self.starts[self.index(b, iy, iz) + 1] as usize;
                    for (j, &pj) in pos[s..e].iter().enumerate() {
                        let j = s + j;
                        if j == i {
                            continue;
                        }
                        let mut d = pi - pj;
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
    grid.build(pos, vel, active, p);
    let m = active.len();
    let rho0 = Poly6::w(0.0, p.h);
    let c2 = p.sound_speed * p.sound_speed;
    let l = p.domain_m;
    let chunk_count = m.div_ceil(QUERY_CHUNK);
    let mut chunks = std::mem::take(&mut grid.chunks);
    chunks.resize_with(chunk_count, ChunkPairs::default);
    let mut density_v = std::mem::take(&mut grid.density);
    density_v.resize(m, 0.0);
    let mut p_rho2_v = std::mem::take(&mut grid.p_rho2);
    p_rho2_v.resize(m, 0.0);
    let mut acc_sorted = std::mem::take(&mut grid.acc);
    acc_sorted.resize(m, DVec3::ZERO);

    // Pass 1, density: each chunk of queries (slots in cell order, so
    // consecutive queries read the same cells) walks the grid once and
    // keeps its neighbour pairs for pass 2.
    let g: &NeighbourGrid = grid;
    let density_chunk = |(c, ((rho_out, pr_out), out)): DensityChunk| {
        out.pairs.clear();
        out.ends.clear();
        for (k, (rho_k, pr_k)) in rho_out.iter_mut().zip(pr_out.iter_mut()).enumerate() {
            let mut rho = rho0;
            g.for_each_neighbour(c * QUERY_CHUNK + k, l, |j, d, r| {
                rho += Poly6::w(r, p.h);
                out.pairs.push(Pair { j: j as u32, d, r });
            });
            out.ends.push(out.pairs.len() as u32);
            *rho_k = rho;
            *pr_k = c2 * (rho - rho0).max(0.0) / (rho * rho);
        }
    };
    if parallel {
        density_v
            .par_chunks_mut(QUERY_CHUNK)
            .zip(p_rho2_v.par_chunks_mut(QUERY_CHUNK))
            .zip(chunks.par_iter_mut())
            .enumerate()
            .for_each(density_chunk);
    } else {
        density_v
            .chunks_mut(QUERY_CHUNK)
            .zip(p_rho2_v.chunks_mut(QUERY_CHUNK))
            .zip(chunks.iter_mut())
            .enumerate()
            .for_each(density_chunk);
    }

    // Pass 2, forces, over the kept pairs.
    let (density, p_rho2) = (&density_v[..], &p_rho2_v[..]);
    let vel_sorted = &g.vel;
    let force_chunk = |(c, (acc_out, pairs)): (usize, (&mut [DVec3], &ChunkPairs))| {
        let mut start = 0usize;
        for (k, (a_out, &end)) in acc_out.iter_mut().zip(&pairs.ends).enumerate() {
            let i = c * QUERY_CHUNK + k;
            let (pi_rho2, vi) = (p_rho2[i], vel_sorted[i]);
            let mut a = DVec3::ZERO;
            for pair in &pairs.pairs[start..end as usize] {
                let j = pair.j as usize;
                a -= Spiky::grad_w(pair.d, pair.r, p.h) * (pi_rho2 + p_rho2[j]);
                a += (vel_sorted[j] - vi)
                    * (p.viscosity * Viscosity::laplacian(pair.r, p.h) / density[j]);
            }
            start = end as usize;
            *a_out = a;
        }
    };
    if parallel {
        acc_sorted
            .par_chunks_mut(QUERY_CHUNK)
            .zip(chunks.par_iter())
            .enumerate()
            .for_each(force_chunk);
    } else {
        acc_sorted
            .chunks_mut(QUERY_CHUNK)
            .zip(chunks.iter())
            .enumerate()
            .for_each(force_chunk);
    }
    for (&i, &a) in grid.order.iter().zip(&acc_sorted) {
        acc[i as usize] = a;
    }
    grid.density = density_v;
    grid.p_rho2 = p_rho2_v;
    grid.acc = acc_sorted;
    grid.chunks = chunks;
}

/// One chunk of pass 1's work: its index, its slots' densities and `p/ρ²`
/// to write, and its pair list to refill.
type DensityChunk<'a> = (usize, ((&'a mut [f64], &'a mut [f64]), &'a mut ChunkPairs));

/// Queries per unit of parallel work.
const QUERY_CHUNK: usize = 128;

/// A neighbour found in pass 1: slot, `x_i - x_j`, distance.
#[derive(Debug, Clone, Copy)]
struct Pair {
    j: u32,
    d: DVec3,
    r: f64,
}

/// The pairs of one chunk of queries.
#[derive(Debug, Clone, Default)]
struct ChunkPairs {
    pairs: Vec<Pair>,
    /// End of each query's pairs in `pairs`.
    ends: Vec<u32>,
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
            grid.build(&pos, &pos, &active, &p);
            for slot in 0..pos.len() {
                let i = grid.order[slot] as usize;
                let mut found = Vec::new();
                grid.for_each_neighbour(slot, domain, |j, _, _| found.push(grid.order[j] as usize));
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
    fn a_reused_grid_gives_what_a_fresh_one_gives() {
        // The grid keeps its buffers from call to call: shrinking and
        // scattered active sets must not read anything stale.
        let pos: Vec<DVec3> = (0..800)
            .map(|i| {
                let u = |s| crate::sim::parcels::keyed_uniform(9, i, 0, s);
                DVec3::new(u(0) * 2000.0, u(1) * 2000.0, u(2) * 300.0)
            })
            .collect();
        let vel: Vec<DVec3> = (0..800)
            .map(|i| DVec3::new(0.0, i as f64 * 1e-3, 0.0))
            .collect();
        let sets: [Vec<u32>; 3] = [
            (0..800).collect(),
            (0..300).collect(),
            (0..800).filter(|i| i % 7 == 3).collect(),
        ];
        let mut reused = NeighbourGrid::default();
        for (k, active) in sets.iter().enumerate() {
            for parallel in [false, true] {
                let (mut a, mut b) = (Vec::new(), Vec::new());
                let p = params(2000.0);
                accelerations(&mut reused, &pos, &vel, active, &p, parallel, &mut a);
                let mut fresh = NeighbourGrid::default();
                accelerations(&mut fresh, &pos, &vel, active, &p, parallel, &mut b);
                assert_eq!(a, b, "set {k}, parallel {parallel}");
                assert!(a.iter().any(|x| x.length() > 0.0), "set {k} has contacts");
            }
        }
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
