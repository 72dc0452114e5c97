//! Temporal anti-aliasing: the jitter sequence, the camera-cut rule and the
//! ping-pong history (the pass itself is `shaders/tsaa.wgsl`).

use crate::render::cpu::camera::Camera;

/// The radical inverse of `index` in `base` (Halton 1964), in `[0, 1)`.
pub fn halton(mut index: u32, base: u32) -> f32 {
    let (mut f, mut r) = (1.0_f32, 0.0_f32);
    while index > 0 {
        f /= base as f32;
        r += f * (index % base) as f32;
        index /= base;
    }
    r
}

/// Frames in the jitter cycle.
pub const JITTER_CYCLE: u32 = 16;

/// The jitter of frame `n`: a sub-pixel ray offset in `[-0.5, 0.5)²` pixels
/// from Halton(2, 3), and a march-dither offset in `[0, 1)` from Halton(5),
/// cycling every [`JITTER_CYCLE`] frames.
pub fn jitter(n: u32) -> [f32; 3] {
    let i = n % JITTER_CYCLE + 1;
    [halton(i, 2) - 0.5, halton(i, 3) - 0.5, halton(i, 5)]
}

/// The camera moved so far in one frame that the history is useless: more
/// than [`CUT_DISTANCE_M`] or turned by more than [`CUT_ANGLE_DEG`], or the
/// field of view changed by more than a degree.
pub const CUT_DISTANCE_M: f32 = 500.0;
/// See [`CUT_DISTANCE_M`].
pub const CUT_ANGLE_DEG: f32 = 30.0;

/// Whether going from `a` to `b` in one frame is a camera cut.
pub fn is_cut(a: &Camera, b: &Camera) -> bool {
    let (fa, _, _) = a.basis();
    let (fb, _, _) = b.basis();
    a.position_m.distance(b.position_m) > CUT_DISTANCE_M
        || fa.dot(fb).clamp(-1.0, 1.0).acos().to_degrees() > CUT_ANGLE_DEG
        || (a.fov_deg - b.fov_deg).abs() > 1.0
}

/// TSAA settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TsaaSettings {
    /// Weight of the new frame in the history, `(0, 1]` (0.1: about the
    /// last ten frames).
    pub blend: f32,
}

impl Default for TsaaSettings {
    fn default() -> Self {
        Self { blend: 0.1 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_is_the_radical_inverse() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(2, 2), 0.25);
        assert_eq!(halton(3, 2), 0.75);
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-7);
        assert!((halton(5, 3) - 7.0 / 9.0).abs() < 1e-7);
    }

    #[test]
    fn jitter_averages_to_the_pixel_centre() {
        let (mut sx, mut sy) = (0.0, 0.0);
        for n in 0..JITTER_CYCLE {
            let [x, y, d] = jitter(n);
            assert!(
                (-0.5..0.5).contains(&x) && (-0.5..0.5).contains(&y) && (0.0..1.0).contains(&d)
            );
            sx += x;
            sy += y;
        }
        assert!((sx / 16.0).abs() < 0.05 && (sy / 16.0).abs() < 0.05);
    }
}
