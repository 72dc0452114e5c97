//! The CPU still from fewer marches ([`render_still_adaptive`]): one
//! march through every pixel, the rest of the still's marches only where
//! the picture has an edge, and the dither's grain taken out of the
//! clouds elsewhere by an edge-stopping filter. About a fifth of the
//! marches of averaging every pixel's (`stills::render_still`), for a
//! picture that measures as close to the converged one
//! (docs/renderer.md, "Error against cost (stills)").

use glam::Vec3;
use rayon::prelude::*;

use super::frame::Frame;
use super::renderer::RaySample;
use super::stills::{PixelMarches, frame_march, in_bands};
use super::tone_map::luminance;

/// The contrast, in natural log of luminance, between a pixel and any of
/// its eight neighbours above which the first march does not suffice and
/// the pixel takes all the still's marches: 0.3 is a 35 % step, an
/// outline against the sky or a cloud in front of another, which one
/// march through the centre draws as a staircase; the dither's grain
/// inside a cloud stays under it on most pixels.
pub const EDGE_LOG_CONTRAST: f32 = 0.3;

/// Radius of the grain filter, pixels (a 5 x 5 window).
pub const FILTER_RADIUS: i32 = 2;
/// The filter's spatial weight falls as `exp(-r² / (2 σ²))` with this σ,
/// pixels: the blue-noise dither's grain lives at the finest scale, so a
/// small kernel takes most of it out.
pub const FILTER_SIGMA_PX: f32 = 1.2;
/// How different a neighbour's transmittance may be before it stops
/// counting: `exp(-(ΔT / this)²)`.
pub const FILTER_TRANSMITTANCE: f32 = 0.12;
/// How different a neighbour's cloud light may be, in natural log of
/// luminance, before it stops counting: `exp(-(Δ / this)²)`.
pub const FILTER_LOG_LIGHT: f32 = 0.25;
/// Luminance added before taking logs, so black stays finite.
const LOG_FLOOR: f32 = 1e-4;

/// One pixel's marches so far: the sums of their radiance, cloud light and
/// transmittance, and how many.
#[derive(Clone, Copy, Default)]
struct Marched {
    radiance: Vec3,
    clouds: Vec3,
    transmittance: f32,
    reads: u32,
    marches: u32,
}

impl Marched {
    fn add(&mut self, s: RaySample) {
        self.radiance += s.radiance;
        self.clouds += s.clouds;
        self.transmittance += s.transmittance;
        self.reads += s.reads;
        self.marches += 1;
    }

    fn mean(&self) -> RaySample {
        let n = self.marches.max(1) as f32;
        RaySample {
            radiance: self.radiance / n,
            clouds: self.clouds / n,
            transmittance: self.transmittance / n,
            reads: self.reads,
        }
    }
}

/// What [`render_still_adaptive`] made: the linear picture and how many
/// marches it took.
pub struct AdaptiveStill {
    /// Linear radiance, row-major.
    pub linear: Vec<Vec3>,
    /// Marches of all pixels together (the machine-independent cost: a
    /// still of `offsets` marches everywhere takes `offsets` per pixel).
    pub marches: u64,
    /// Pixels that took every march (edges).
    pub edge_pixels: u64,
    /// Density reads of all marches together, their shadow rays' too
    /// (`RaySample::reads`).
    pub reads: u64,
}

impl AdaptiveStill {
    /// Marches per pixel, on average.
    pub fn marches_per_pixel(&self) -> f64 {
        self.marches as f64 / self.linear.len().max(1) as f64
    }

    /// Density reads per pixel, on average.
    pub fn reads_per_pixel(&self) -> f64 {
        self.reads as f64 / self.linear.len().max(1) as f64
    }
}

/// A `width x height` still of `fr` in fewer marches than
/// `stills::render_still` at `offsets`:
/// 1. every pixel marched once, as the GPU's TSAA frame 0 (its jitter and
///    dither);
/// 2. pixels whose luminance differs from a neighbour's by more than
///    [`EDGE_LOG_CONTRAST`] take frames 1 to `offsets - 1` too, averaged
///    as `render_still` averages them (edges anti-aliased as the GPU's
///    accumulated frames are);
/// 3. elsewhere, where the ray met cloud, the clouds' light and
///    transmittance are the mean over a 5 x 5 window of the neighbours
///    alike in both ([`FILTER_TRANSMITTANCE`], [`FILTER_LOG_LIGHT`]), the
///    sky or ground behind kept sharp.
///
/// `offsets = 1` is one march a pixel, filtered. `progress` gets the share
/// of the work done (0 to 1), on the calling thread.
pub fn render_still_adaptive(
    width: u32,
    height: u32,
    fr: &Frame,
    offsets: u32,
    progress: &dyn Fn(f32),
) -> AdaptiveStill {
    let w = width as usize;
    let h = height as usize;
    let spread = fr.view.pixel_spread(width, height);
    let march = |x: usize, y: usize, k: u32| {
        let at = PixelMarches {
            x: x as u32,
            y: y as u32,
            width,
            height,
            spread,
        };
        frame_march(at, fr, k, true)
    };
    // The first march's share of the progress: about its share of the
    // time on the shipped views.
    let first_share = 0.6;
    let mut px = vec![Marched::default(); w * h];
    in_bands(&mut px, w, h, &|x, y, m| m.add(march(x, y, 0)), &|s| {
        progress(first_share * s)
    });
    let log_y: Vec<f32> = px
        .iter()
        .map(|m| (luminance(m.radiance) + LOG_FLOOR).ln())
        .collect();
    let edge: Vec<bool> = (0..w * h)
        .map(|i| offsets > 1 && is_edge(&log_y, w, h, i % w, i / w))
        .collect();
    in_bands(
        &mut px,
        w,
        h,
        &|x, y, m| {
            if edge[y * w + x] {
                for k in 1..offsets {
                    m.add(march(x, y, k));
                }
            }
        },
        &|s| progress(first_share + (1.0 - first_share) * s),
    );
    let means: Vec<RaySample> = px.iter().map(Marched::mean).collect();
    let linear = (0..w * h)
        .into_par_iter()
        .map(|i| {
            if edge[i] || means[i].transmittance >= 1.0 {
                means[i].radiance
            } else {
                filtered(&means, w, h, i % w, i / w)
            }
        })
        .collect();
    AdaptiveStill {
        linear,
        marches: px.iter().map(|m| m.marches as u64).sum(),
        edge_pixels: edge.iter().filter(|e| **e).count() as u64,
        reads: px.iter().map(|m| m.reads as u64).sum(),
    }
}

/// Whether pixel `(x, y)`'s log luminance differs from any of its eight
/// neighbours' by more than [`EDGE_LOG_CONTRAST`].
fn is_edge(log_y: &[f32], w: usize, h: usize, x: usize, y: usize) -> bool {
    let c = log_y[y * w + x];
    let (x0, x1) = (x.saturating_sub(1), (x + 1).min(w - 1));
    let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
    (y0..=y1).any(|j| (x0..=x1).any(|i| (log_y[j * w + i] - c).abs() > EDGE_LOG_CONTRAST))
}

/// Pixel `(x, y)` with its clouds' light and transmittance replaced by
/// the edge-stopping mean of its neighbours' (step 3 of
/// [`render_still_adaptive`]), over its own background: the radiance
/// behind the clouds, `(radiance - clouds) / transmittance`.
fn filtered(means: &[RaySample], w: usize, h: usize, x: usize, y: usize) -> Vec3 {
    let c = means[y * w + x];
    let log_light = |s: &RaySample| (luminance(s.clouds) + LOG_FLOOR).ln();
    let lc = log_light(&c);
    let mut clouds = Vec3::ZERO;
    let mut transmittance = 0.0;
    let mut total = 0.0;
    for dy in -FILTER_RADIUS..=FILTER_RADIUS {
        for dx in -FILTER_RADIUS..=FILTER_RADIUS {
            let (i, j) = (x as i32 + dx, y as i32 + dy);
            if i < 0 || j < 0 || i >= w as i32 || j >= h as i32 {
                continue;
            }
            let n = means[j as usize * w + i as usize];
            if n.transmittance >= 1.0 {
                continue;
            }
            let r2 = (dx * dx + dy * dy) as f32;
            let dt = (n.transmittance - c.transmittance) / FILTER_TRANSMITTANCE;
            let dl = (log_light(&n) - lc) / FILTER_LOG_LIGHT;
            let wgt = (-r2 / (2.0 * FILTER_SIGMA_PX * FILTER_SIGMA_PX) - dt * dt - dl * dl).exp();
            clouds += n.clouds * wgt;
            transmittance += n.transmittance * wgt;
            total += wgt;
        }
    }
    // The pixel itself always counts with weight 1, so total >= 1.
    let (clouds, transmittance) = (clouds / total, transmittance / total);
    let background = if c.transmittance > 1e-4 {
        (c.radiance - c.clouds) / c.transmittance
    } else {
        Vec3::ZERO
    };
    clouds + background * transmittance
}
