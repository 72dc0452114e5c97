//! An optional heightfield terrain: a seeded, tileable fBm height texture
//! (sampled on a 4D torus like the cloud map), ray-marched on the CPU and,
//! later, rasterised as a mesh on the GPU. It receives cloud shadows.

use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// `[render.terrain]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TerrainConfig {
    /// Off: no terrain is built or marched (a flat hazy ground is drawn
    /// below the horizon). Default false.
    pub enabled: bool,
    /// Height of the highest hills above the lowest valleys, m (0..=5000).
    /// Default 400.
    pub relief_m: f32,
    /// Side of the tileable height texture, m (> 0). Default 20000.
    pub extent_m: f32,
    /// Hills across the texture (1..=64). Default 6.
    pub hills: f64,
    /// Texels per side (16..=2048). Default 256.
    pub size: usize,
    /// Seed. Default 3.
    pub seed: u32,
}

impl Default for TerrainConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            relief_m: 400.0,
            extent_m: 20_000.0,
            hills: 6.0,
            size: 256,
            seed: 3,
        }
    }
}

/// The height texture: `size²` heights in metres, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Heightfield {
    size: usize,
    extent_m: f32,
    heights: Vec<f32>,
    max_m: f32,
}

impl Heightfield {
    /// Generates the heightfield (deterministic for a seed).
    pub fn generate(cfg: &TerrainConfig) -> Self {
        let n = cfg.size.max(2);
        let raw: Vec<f64> = (0..n * n)
            .into_par_iter()
            .map_init(
                || Fbm::<Perlin>::new(cfg.seed).set_octaves(6),
                |fbm, k| {
                    let (u, v) = ((k % n) as f64 / n as f64, (k / n) as f64 / n as f64);
                    let r = cfg.hills / std::f64::consts::TAU;
                    let (a, b) = (u * std::f64::consts::TAU, v * std::f64::consts::TAU);
                    fbm.get([r * a.cos(), r * a.sin(), r * b.cos(), r * b.sin()])
                },
            )
            .collect();
        let lo = raw.iter().copied().fold(f64::MAX, f64::min);
        let hi = raw.iter().copied().fold(f64::MIN, f64::max);
        let heights: Vec<f32> = raw
            .iter()
            .map(|h| {
                if hi > lo {
                    ((h - lo) / (hi - lo)).powf(1.4) as f32 * cfg.relief_m
                } else {
                    0.0
                }
            })
            .collect();
        let max_m = heights.iter().copied().fold(0.0, f32::max);
        Self {
            size: n,
            extent_m: cfg.extent_m,
            heights,
            max_m,
        }
    }

    /// Texels per side.
    pub fn size(&self) -> usize {
        self.size
    }

    /// Heights, m, row-major (`size²`).
    pub fn heights(&self) -> &[f32] {
        &self.heights
    }

    /// Side of the texture, m.
    pub fn extent_m(&self) -> f32 {
        self.extent_m
    }

    /// Highest point, m.
    pub fn max_m(&self) -> f32 {
        self.max_m
    }

    /// Height at world `(x, z)`, bilinear and periodic, m.
    pub fn height_at(&self, x: f32, z: f32) -> f32 {
        let n = self.size;
        let (fx, fz) = (x / self.extent_m * n as f32, z / self.extent_m * n as f32);
        let (x0, z0) = (fx.floor(), fz.floor());
        let (tx, tz) = (fx - x0, fz - z0);
        let w = |i: f32| (i as i64).rem_euclid(n as i64) as usize;
        let h = |a: usize, b: usize| self.heights[b * n + a];
        let (xa, xb, za, zb) = (w(x0), w(x0 + 1.0), w(z0), w(z0 + 1.0));
        let top = h(xa, za) + (h(xb, za) - h(xa, za)) * tx;
        let bottom = h(xa, zb) + (h(xb, zb) - h(xa, zb)) * tx;
        top + (bottom - top) * tz
    }

    /// Distance along the ray to the first terrain hit within `max_t`: steps
    /// that grow with distance (5 m + 1 %), then bisection.
    pub fn intersect(&self, origin: glam::Vec3, dir: glam::Vec3, max_t: f32) -> Option<f32> {
        if dir.y >= 0.0 && origin.y > self.max_m {
            return None;
        }
        let above = |t: f32| {
            let p = origin + dir * t;
            p.y - self.height_at(p.x, p.z)
        };
        if above(0.0) < 0.0 {
            return Some(0.0);
        }
        let mut t = 0.0;
        while t < max_t {
            let step = 5.0 + 0.01 * t;
            let next = t + step;
            let p = origin + dir * next;
            if p.y > self.max_m && dir.y >= 0.0 {
                return None;
            }
            if above(next) < 0.0 {
                let (mut a, mut b) = (t, next);
                for _ in 0..12 {
                    let m = 0.5 * (a + b);
                    if above(m) < 0.0 { b = m } else { a = m }
                }
                return Some(0.5 * (a + b));
            }
            t = next;
        }
        None
    }

    /// Unit surface normal at `(x, z)` by central differences.
    pub fn normal_at(&self, x: f32, z: f32) -> glam::Vec3 {
        let e = self.extent_m / self.size as f32;
        let dx = self.height_at(x + e, z) - self.height_at(x - e, z);
        let dz = self.height_at(x, z + e) - self.height_at(x, z - e);
        glam::Vec3::new(-dx, 2.0 * e, -dz).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn ray_hits_the_surface_it_reports() {
        let h = Heightfield::generate(&TerrainConfig {
            enabled: true,
            size: 64,
            ..TerrainConfig::default()
        });
        let o = Vec3::new(100.0, 800.0, 100.0);
        let d = Vec3::new(0.6, -0.2, 0.77).normalize();
        let t = h
            .intersect(o, d, 50_000.0)
            .expect("a downward ray hits the ground");
        let p = o + d * t;
        assert!(
            (p.y - h.height_at(p.x, p.z)).abs() < 0.5,
            "{} vs {}",
            p.y,
            h.height_at(p.x, p.z)
        );
        assert!(
            h.intersect(Vec3::new(0.0, 1000.0, 0.0), Vec3::Y, 1e5)
                .is_none()
        );
    }
}
