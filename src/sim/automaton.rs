//! Cellular-automaton clouds (Dobashi et al. 2000, as restated by Qin &
//! Lv, paper 001 in `shared/papers`): the other way to animate the sky
//! that `[simulation] method = "automaton"` chooses. A voxel grid over the
//! cloud band holds three bits per cell, `hum` (enough vapour), `act`
//! (ready to condense) and `cld` (cloud), advanced by Boolean rules; the
//! paper's extinction and supply probabilities keep clouds forming and
//! dying, and the wind shifts each layer downstream.
//!
//! One step, for every cell at once (`f_act`: an `act` among the six face
//! neighbours, the four cells two apart in the plane, or the cell two
//! below, so activation climbs faster than it spreads):
//! ```text
//! hum' = hum ∧ ¬act            cld' = cld ∨ act
//! act' = ¬act ∧ hum ∧ f_act
//! cld' = cld' ∧ (rnd ≥ p_ext)  hum' = hum' ∨ (rnd < p_hum)
//! act' = act' ∨ (rnd < p_act)
//! ```
//! then each layer moves downwind by the whole cells its wind has carried
//! it (the remainder is kept for the next step).
//!
//! The probabilities come from ellipsoids, as in Dobashi's paper: one on
//! each spawn site of the parcel method (the cloud map's cells), its flat
//! base on the band's bottom, its top somewhere in the band. Inside, supply
//! is likely and extinction rare; outside, the reverse. The sites stay put
//! (thermals rooted to the ground) while the wind carries the cloud away.
//!
//! The cloud bits are smoothed into a density (a box average of `cld`, the
//! paper's Eq. 8 without its time window) and projected into P column by
//! column ([`Automaton::project_into`]), so the same renderer draws them:
//! coverage is the column's densest cell, height its top, fill its mean.
//! Every random draw is keyed by (seed, step, cell, stream): a run is the
//! same for a seed whatever the thread count.

use glam::DVec2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::check::Check;
use super::config::PhysicsConfig;
use super::parcels::keyed_uniform;
use super::projection::{Band, ProjectedField};
use super::update::wind_at;

/// The `hum` bit: enough vapour to form a cloud.
pub const HUM: u8 = 1;
/// The `act` bit: the phase transition is about to happen.
pub const ACT: u8 = 2;
/// The `cld` bit: cloud.
pub const CLD: u8 = 4;

/// `[simulation.automaton]`: the automaton's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AutomatonConfig {
    /// Seconds of sky per automaton step (0.5..=120). Default 5.
    pub step_s: f64,
    /// Cells across the band's height (2..=64). The horizontal cells are
    /// P's texels. Default 12.
    pub layers: usize,
    /// Probability per step that a cell inside an ellipsoid's core gains
    /// vapour (`p_hum`, 0..=1). Default 0.1.
    pub humidity_supply: f64,
    /// Probability per step that a core cell activates on its own
    /// (`p_act`, 0..=1). Default 0.01.
    pub activation: f64,
    /// Probability per step that a cloud cell outside every ellipsoid
    /// evaporates (`p_ext`, 0..=1); in a core it is 5 % of this.
    /// Default 0.05.
    pub extinction: f64,
    /// Horizontal semi-axis of the ellipsoids, m (> 0); each site's is
    /// drawn in 0.6..1.4 times this. Default 500.
    pub ellipsoid_radius_m: f64,
    /// Half-width of the smoothing box, cells (0..=4). Default 1.
    pub smoothing_cells: usize,
}

impl Default for AutomatonConfig {
    fn default() -> Self {
        Self {
            step_s: 5.0,
            layers: 12,
            humidity_supply: 0.1,
            activation: 0.01,
            extinction: 0.05,
            ellipsoid_radius_m: 500.0,
            smoothing_cells: 1,
        }
    }
}

impl AutomatonConfig {
    /// Every field against its domain (`prefix`: the section's key).
    pub fn checks(&self, prefix: &str) -> Vec<Check> {
        let k = |name: &str| format!("{prefix}.{name}");
        vec![
            Check::range(k("step_s"), self.step_s, 0.5, 120.0, "0.5..=120 s"),
            Check::new(
                k("layers"),
                (2..=64).contains(&self.layers),
                "2..=64 cells",
                self.layers as f64,
            ),
            Check::range(
                k("humidity_supply"),
                self.humidity_supply,
                0.0,
                1.0,
                "a probability in 0..=1",
            ),
            Check::range(
                k("activation"),
                self.activation,
                0.0,
                1.0,
                "a probability in 0..=1",
            ),
            Check::range(
                k("extinction"),
                self.extinction,
                0.0,
                1.0,
                "a probability in 0..=1",
            ),
            Check::new(
                k("ellipsoid_radius_m"),
                self.ellipsoid_radius_m.is_finite() && self.ellipsoid_radius_m > 0.0,
                "a radius > 0 m",
                self.ellipsoid_radius_m,
            ),
            Check::new(
                k("smoothing_cells"),
                self.smoothing_cells <= 4,
                "0..=4 cells",
                self.smoothing_cells as f64,
            ),
        ]
    }
}

/// Per-cell probabilities of one step: supply, activation, extinction.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CellOdds {
    pub hum: f32,
    pub act: f32,
    pub ext: f32,
}

/// The automaton: `nx x ny x nz` cells over a periodic square of side
/// `domain_m` and the band's height.
#[derive(Debug, Clone)]
pub struct Automaton {
    nx: usize,
    ny: usize,
    nz: usize,
    domain_m: f64,
    band: Band,
    seed: u64,
    step_s: f64,
    smoothing: usize,
    steps: u64,
    state: Vec<u8>,
    next: Vec<u8>,
    odds: Vec<CellOdds>,
    /// Each layer's wind (cells per step) and what it has not yet moved.
    drift: Vec<(DVec2, DVec2)>,
}

impl Automaton {
    /// An empty sky (no bit set anywhere) with ellipsoids on `sites`
    /// (metres in the periodic square), the wind of `physics` and P's
    /// `nx x ny` columns.
    pub fn new(
        cfg: &AutomatonConfig,
        physics: &PhysicsConfig,
        band: Band,
        sites: &[DVec2],
        nx: usize,
        ny: usize,
    ) -> Self {
        let nz = cfg.layers.max(1);
        let domain_m = physics.domain_size_m;
        let n = nx * ny * nz;
        let mut a = Self {
            nx,
            ny,
            nz,
            domain_m,
            band,
            seed: physics.seed,
            step_s: cfg.step_s,
            smoothing: cfg.smoothing_cells,
            steps: 0,
            state: vec![0; n],
            next: vec![0; n],
            odds: vec![CellOdds::default(); n],
            drift: Vec::with_capacity(nz),
        };
        let cell = a.cell_size();
        for k in 0..nz {
            let z = band.bottom_m + (k as f64 + 0.5) * cell.z;
            let v = wind_at(physics, z) * cfg.step_s;
            a.drift
                .push((DVec2::new(v.x / cell.x, v.y / cell.y), DVec2::ZERO));
        }
        a.set_ellipsoids(cfg, sites);
        a
    }

    /// Cell size, m (x, y horizontal; z vertical).
    pub fn cell_size(&self) -> glam::DVec3 {
        glam::DVec3::new(
            self.domain_m / self.nx.max(1) as f64,
            self.domain_m / self.ny.max(1) as f64,
            (self.band.top_m - self.band.bottom_m) / self.nz.max(1) as f64,
        )
    }

    /// Grid size in cells.
    pub fn dims(&self) -> [usize; 3] {
        [self.nx, self.ny, self.nz]
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Seconds of sky per step.
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.ny + j) * self.nx + i
    }

    /// The bits of cell `(i, j, k)` (`k` up).
    pub fn cell(&self, i: usize, j: usize, k: usize) -> u8 {
        self.state[self.index(i, j, k)]
    }

    /// Sets the bits of cell `(i, j, k)` (for tests and tools).
    pub fn set_cell(&mut self, i: usize, j: usize, k: usize, bits: u8) {
        let c = self.index(i, j, k);
        self.state[c] = bits & (HUM | ACT | CLD);
    }

    /// Replaces every cell's probabilities (for tests and tools).
    pub fn set_odds(&mut self, odds: CellOdds) {
        self.odds.fill(odds);
    }

    /// Replaces every layer's wind, in cells per step (for tests).
    pub fn set_drift(&mut self, cells_per_step: DVec2) {
        for d in &mut self.drift {
            *d = (cells_per_step, DVec2::ZERO);
        }
    }

    /// Cells with `bit` set.
    pub fn count(&self, bit: u8) -> usize {
        self.state.iter().filter(|&&s| s & bit != 0).count()
    }

    /// The ellipsoids' probabilities: each site's semi-axes drawn from the
    /// seed, the odds of a cell set by the nearest ellipsoid's weight
    /// `w = max(0, 1 - r²)` (r: the cell's ellipsoidal distance).
    fn set_ellipsoids(&mut self, cfg: &AutomatonConfig, sites: &[DVec2]) {
        let cell = self.cell_size();
        let span = self.band.top_m - self.band.bottom_m;
        let l = self.domain_m;
        let shapes: Vec<(DVec2, f64, f64)> = sites
            .iter()
            .enumerate()
            .map(|(s, &c)| {
                let a = cfg.ellipsoid_radius_m
                    * (0.6 + 0.8 * keyed_uniform(self.seed, s as u64, 0, 0x0e11_0001));
                let h = span * (0.45 + 0.55 * keyed_uniform(self.seed, s as u64, 0, 0x0e11_0002));
                (c, a, h)
            })
            .collect();
        let (nx, ny) = (self.nx, self.ny);
        self.odds
            .par_chunks_mut(nx * ny)
            .enumerate()
            .for_each(|(k, layer)| {
                let z = (k as f64 + 0.5) * cell.z;
                for j in 0..ny {
                    for i in 0..nx {
                        let p = DVec2::new((i as f64 + 0.5) * cell.x, (j as f64 + 0.5) * cell.y);
                        let w = shapes
                            .iter()
                            .map(|&(c, a, h)| {
                                let d = periodic(p - c, l);
                                let r2 = d.length_squared() / (a * a) + (z / h).powi(2);
                                (1.0 - r2).max(0.0)
                            })
                            .fold(0.0, f64::max);
                        layer[j * nx + i] = CellOdds {
                            hum: (cfg.humidity_supply * w) as f32,
                            act: (cfg.activation * w) as f32,
                            ext: (cfg.extinction * (1.0 - 0.95 * w.min(1.0))) as f32,
                        };
                    }
                }
            });
    }

    /// Whether an `act` bit reaches cell `(i, j, k)` (the rule's `f_act`).
    fn f_act(&self, i: usize, j: usize, k: usize) -> bool {
        let (nx, ny, nz) = (self.nx as i64, self.ny as i64, self.nz as i64);
        let (i, j, k) = (i as i64, j as i64, k as i64);
        const REACH: [(i64, i64, i64); 11] = [
            (1, 0, 0),
            (-1, 0, 0),
            (0, 1, 0),
            (0, -1, 0),
            (0, 0, 1),
            (0, 0, -1),
            (2, 0, 0),
            (-2, 0, 0),
            (0, 2, 0),
            (0, -2, 0),
            (0, 0, -2),
        ];
        REACH.iter().any(|&(di, dj, dk)| {
            let kk = k + dk;
            if !(0..nz).contains(&kk) {
                return false;
            }
            let ii = (i + di).rem_euclid(nx) as usize;
            let jj = (j + dj).rem_euclid(ny) as usize;
            self.state[(kk as usize * self.ny + jj) * self.nx + ii] & ACT != 0
        })
    }

    /// One step: the rules, the probabilities, then the wind.
    pub fn step(&mut self) {
        let (nx, ny) = (self.nx, self.ny);
        let layer = nx * ny;
        let step = self.steps;
        let seed = self.seed;
        let mut next = std::mem::take(&mut self.next);
        next.par_chunks_mut(layer.max(1))
            .enumerate()
            .for_each(|(k, out)| {
                for j in 0..ny {
                    for i in 0..nx {
                        let c = (k * ny + j) * nx + i;
                        out[j * nx + i] = self.rule(c, self.f_act(i, j, k), seed, step);
                    }
                }
            });
        self.next = std::mem::replace(&mut self.state, next);
        self.advect();
        self.steps += 1;
    }

    /// The new bits of cell `c` (`reached`: its `f_act`).
    fn rule(&self, c: usize, reached: bool, seed: u64, step: u64) -> u8 {
        let s = self.state[c];
        let (hum, act, cld) = (s & HUM != 0, s & ACT != 0, s & CLD != 0);
        let mut hum2 = hum && !act;
        let mut cld2 = cld || act;
        let mut act2 = !act && hum && reached;
        let o = self.odds[c];
        let draw = |stream: u32| keyed_uniform(seed, c as u64, step as u32, stream) as f32;
        if cld2 && o.ext > 0.0 && draw(1) < o.ext {
            cld2 = false;
        }
        if !hum2 && o.hum > 0.0 && draw(2) < o.hum {
            hum2 = true;
        }
        if !act2 && o.act > 0.0 && draw(3) < o.act {
            act2 = true;
        }
        (hum2 as u8 * HUM) | (act2 as u8 * ACT) | (cld2 as u8 * CLD)
    }

    /// Shifts each layer by the whole cells its wind has carried it.
    fn advect(&mut self) {
        let (nx, ny) = (self.nx, self.ny);
        let layer = nx * ny;
        for k in 0..self.nz {
            let (v, rest) = self.drift[k];
            let moved = rest + v;
            let shift = moved.floor();
            self.drift[k].1 = moved - shift;
            let (sx, sy) = (shift.x as i64, shift.y as i64);
            if sx == 0 && sy == 0 {
                continue;
            }
            let src = &self.state[k * layer..(k + 1) * layer];
            let dst = &mut self.next[k * layer..(k + 1) * layer];
            for j in 0..ny {
                let jj = (j as i64 - sy).rem_euclid(ny as i64) as usize;
                for i in 0..nx {
                    let ii = (i as i64 - sx).rem_euclid(nx as i64) as usize;
                    dst[j * nx + i] = src[jj * nx + ii];
                }
            }
            self.state[k * layer..(k + 1) * layer].copy_from_slice(dst);
        }
    }

    /// The smoothed cloud density `q` in 0..=1 per cell: the mean of `cld`
    /// over a box of `2s + 1` cells a side (periodic across, cut at the
    /// band's bottom and top), as separable running sums.
    pub fn density(&self) -> Vec<f32> {
        let (nx, ny, nz) = (self.nx, self.ny, self.nz);
        let s = self.smoothing as i64;
        let mut a: Vec<f32> = self
            .state
            .iter()
            .map(|&b| if b & CLD != 0 { 1.0 } else { 0.0 })
            .collect();
        let mut b = vec![0.0f32; a.len()];
        let offs: Vec<i64> = (-s..=s).collect();
        let w = (2 * s + 1) as f32;
        // x, periodic.
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let sum: f32 = offs
                        .iter()
                        .map(|&d| {
                            a[(k * ny + j) * nx + (i as i64 + d).rem_euclid(nx as i64) as usize]
                        })
                        .sum();
                    b[(k * ny + j) * nx + i] = sum / w;
                }
            }
        }
        // y, periodic.
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let sum: f32 = offs
                        .iter()
                        .map(|&d| {
                            b[(k * ny + (j as i64 + d).rem_euclid(ny as i64) as usize) * nx + i]
                        })
                        .sum();
                    a[(k * ny + j) * nx + i] = sum / w;
                }
            }
        }
        // z, cut at the band's ends (the mean of the cells inside).
        for k in 0..nz as i64 {
            let (lo, hi) = ((k - s).max(0), (k + s).min(nz as i64 - 1));
            let n = (hi - lo + 1) as f32;
            for c in 0..nx * ny {
                let sum: f32 = (lo..=hi).map(|kk| a[kk as usize * nx * ny + c]).sum();
                b[k as usize * nx * ny + c] = sum / n;
            }
        }
        b
    }

    /// Projects the smoothed density into `field` (resized to the grid's
    /// columns): coverage the column's densest cell (×2, capped: a cell
    /// half full after smoothing is the cloud's edge), height the top of
    /// its cells at least a quarter full (in the renderer's terms: the
    /// local top `0.2 + 0.8 h`), fill the mean density of those cells.
    pub fn project_into(&self, field: &mut ProjectedField) {
        let (nx, ny, nz) = (self.nx, self.ny, self.nz);
        let q = self.density();
        let texels = (0..nx * ny)
            .map(|c| {
                let column = (0..nz).map(|k| q[k * nx * ny + c]);
                let densest = column.clone().fold(0.0f32, f32::max);
                let cloudy: Vec<(usize, f32)> =
                    column.enumerate().filter(|&(_, v)| v >= 0.25).collect();
                let Some(&(top, _)) = cloudy.last() else {
                    return [0.0; 3];
                };
                let eta = (top + 1) as f32 / nz as f32;
                let mean = cloudy.iter().map(|&(_, v)| v).sum::<f32>() / cloudy.len() as f32;
                [
                    (2.0 * densest).min(1.0),
                    ((eta - 0.2) / 0.8).clamp(0.0, 1.0),
                    mean,
                ]
            })
            .collect();
        *field = ProjectedField::from_texels(nx, ny, texels).unwrap_or_else(|| {
            // The texels are built from the grid's own columns.
            ProjectedField::new(nx, ny)
        });
    }
}

/// The shortest periodic offset in a square of side `l`.
fn periodic(d: DVec2, l: f64) -> DVec2 {
    d - (d / l).round() * l
}

#[cfg(test)]
#[path = "automaton_tests.rs"]
mod tests;
