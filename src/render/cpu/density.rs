//! Cloud density inside the height band, from P and the cloud map
//! (rendering.md section 2).

use glam::Vec3;

use crate::render::cloud_map::CloudMap;
use crate::sim::ProjectedField;

/// What the density needs besides the textures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DensityParams {
    /// Cloud base, m.
    pub band_bottom_m: f32,
    /// Highest possible cloud top, m.
    pub band_top_m: f32,
    /// Fraction of each P-covered cloud cell that becomes cloud, 0..=1.
    pub coverage: f32,
    /// Extinction of the densest cloud, 1/m.
    pub extinction_per_m: f32,
    /// Side of the square that P and the cloud map span, m.
    pub map_extent_m: f32,
}

/// The textures the density reads.
#[derive(Clone, Copy)]
pub struct Fields<'a> {
    pub p: &'a ProjectedField,
    pub cloud_map: &'a CloudMap,
}

/// Normalised height `η` of `y_m` in the band (may lie outside 0..1).
#[inline]
pub fn height_fraction(y_m: f32, d: &DensityParams) -> f32 {
    (y_m - d.band_bottom_m) / (d.band_top_m - d.band_bottom_m)
}

/// The part `[t0, t1]` of the ray `origin + t dir` (`t >= 0`, `t <= max_t`)
/// inside the slab `bottom <= y <= top`: camera below, inside or above the
/// band alike. `None` where the ray misses it.
#[inline]
pub fn band_segment(
    origin: Vec3,
    dir: Vec3,
    bottom: f32,
    top: f32,
    max_t: f32,
) -> Option<(f32, f32)> {
    let (t0, t1) = if dir.y.abs() < 1e-8 {
        if origin.y < bottom || origin.y > top {
            return None;
        }
        (0.0, max_t)
    } else {
        let (ta, tb) = ((bottom - origin.y) / dir.y, (top - origin.y) / dir.y);
        (ta.min(tb).max(0.0), ta.max(tb).min(max_t))
    };
    (t1 > t0).then_some((t0, t1))
}

#[inline]
fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Normalised height below which the base ramps up: the base is flat
/// because this ramp is the same everywhere.
pub const BASE_RAMP: f32 = 0.04;

/// The 2D footprint of the cloud at map coordinate `uv`: `(shape, η_top)`,
/// where shape is the cloud-map cell remapped by coverage and P's coverage,
/// and `η_top` the local cloud top (taller with the parcel height `h` and in
/// the cell's middle: rounded tops). `(0, 0)` where there is no cloud.
#[inline]
pub fn footprint(u: f32, v: f32, f: &Fields, d: &DensityParams) -> (f32, f32, f32) {
    let [c, h, fill] = f.p.sample(u, v);
    if c <= 1e-3 {
        return (0.0, 0.0, 0.0);
    }
    let [n, coarse] = f.cloud_map.sample(u, v);
    let cov = (d.coverage * c).clamp(0.0, 1.0);
    let shape = ((n - (1.0 - cov)) / cov.max(1e-3)).clamp(0.0, 1.0);
    if shape <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    let top = (0.15 + 0.85 * h).clamp(0.0, 1.0) * shape.sqrt() * (0.75 + 0.25 * coarse);
    (shape, top, fill)
}

/// Extinction coefficient σ_t (1/m) at world point `p`: zero outside the
/// band and where P has no coverage; a flat base ramp, a dome falling to
/// zero at the local top, scaled by P's fill density.
#[inline]
pub fn density_at(p: Vec3, f: &Fields, d: &DensityParams) -> f32 {
    let eta = height_fraction(p.y, d);
    if !(0.0..=1.0).contains(&eta) {
        return 0.0;
    }
    let (shape, top, fill) = footprint(p.x / d.map_extent_m, p.z / d.map_extent_m, f, d);
    if shape <= 0.0 || eta >= top {
        return 0.0;
    }
    let base = smoothstep(0.0, BASE_RAMP, eta);
    let t = eta / top;
    let dome = ((1.0 - t * t) * 3.0).clamp(0.0, 1.0);
    d.extinction_per_m * (0.3 + 0.7 * fill) * base * dome * (shape * 4.0).min(1.0)
}
