//! The tone map of the PNG pictures (ACES filmic, then sRGB), the twin
//! of `shaders/tone_map.wgsl` (`tone_map`, `aces_curve`) and of
//! `shaders/composite.wgsl`'s sRGB output.

use glam::Vec3;

/// The filmic curve of ACES's reference rendering transform followed by
/// its sRGB output transform, as Stephen Hill fitted it with one rational
/// function per channel (applied in the transform's working space, see
/// [`tone_map`]): 0 stays 0, mid grey 0.18 becomes 0.10, 1 becomes 0.62,
/// and highlights roll off toward 1 (0.97 at 10) instead of clipping.
#[inline]
pub fn aces_curve(v: Vec3) -> Vec3 {
    let a = v * (v + 0.024_578_6) - 0.000_090_537;
    let b = v * (0.983_729 * v + 0.432_951) + 0.238_081;
    a / b
}

/// sRGB (Rec. 709 primaries) to the working space of the fitted ACES
/// transform (the sRGB-to-AP1 matrix with the RRT's saturation folded in),
/// row by row.
pub const ACES_INPUT: [[f32; 3]; 3] = [
    [0.597_19, 0.354_58, 0.048_23],
    [0.076_00, 0.908_34, 0.015_66],
    [0.028_40, 0.133_83, 0.837_77],
];

/// The fitted transform's working space back to linear sRGB, row by row.
pub const ACES_OUTPUT: [[f32; 3]; 3] = [
    [1.604_75, -0.531_08, -0.073_67],
    [-0.102_08, 1.108_13, -0.006_05],
    [-0.003_27, -0.072_76, 1.076_02],
];

#[inline]
fn mul_rows(m: &[[f32; 3]; 3], v: Vec3) -> Vec3 {
    Vec3::new(
        m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
        m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
        m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z,
    )
}

/// The tone map of the PNG pictures: ACES filmic (the fitted reference
/// rendering and sRGB output transforms, [`aces_curve`]) of the linear
/// radiance times `exposure`, to display-linear `0..1`. Bright sunlit
/// cloud rolls off to white and desaturates as film does, instead of the
/// grey that a per-channel exponential leaves it at. The images, the
/// quality report and the GPU's composite pass (`tone_map` in WGSL) use it.
#[inline]
pub fn tone_map(c: Vec3, exposure: f32) -> Vec3 {
    let v = mul_rows(&ACES_INPUT, c.max(Vec3::ZERO) * exposure);
    mul_rows(&ACES_OUTPUT, aces_curve(v)).clamp(Vec3::ZERO, Vec3::ONE)
}

/// The sRGB transfer function of a display-linear value in `0..1`.
#[inline]
pub fn srgb_encode(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Tone map ([`tone_map`]), sRGB-encode and dither ([`dither_encoded`]
/// by [`output_dither`] of the pixel's row-major index) to 8 bits: the
/// pictures.
pub fn to_srgb8(linear: &[Vec3], exposure: f32) -> Vec<u8> {
    quantize(linear, exposure, true)
}

/// [`to_srgb8`] without the dither: for measurements of an image's own
/// fine structure (the high-pass energy of `report::render_quality`),
/// which the dither's grain would add to.
pub fn to_srgb8_exact(linear: &[Vec3], exposure: f32) -> Vec<u8> {
    quantize(linear, exposure, false)
}

fn quantize(linear: &[Vec3], exposure: f32, dither: bool) -> Vec<u8> {
    linear
        .iter()
        .enumerate()
        .flat_map(|(i, &c)| {
            let noise = if dither { output_dither(i as u32) } else { 0.0 };
            let enc = |x: f32| {
                let e = dither_encoded(srgb_encode(x).clamp(0.0, 1.0), noise);
                (e * 255.0 + 0.5).floor().clamp(0.0, 255.0) as u8
            };
            let m = tone_map(c, exposure);
            [enc(m.x), enc(m.y), enc(m.z)]
        })
        .collect()
}

/// A 32-bit integer hash (Chris Wellons' "lowbias32"; `hash_u32` in
/// WGSL): every input bit changes about half the output bits.
#[inline]
pub fn hash_u32(x: u32) -> u32 {
    let mut x = x;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The 8-bit output's dither at pixel `index` (row-major; `output_dither`
/// in WGSL, which takes `y · width + x`), in 8-bit levels, `(-1, 1)`: the
/// sum of two uniform values from [`hash_u32`] less 1, a triangular
/// distribution, whose rounding error has a mean and a variance that do
/// not depend on the value rounded (a uniform dither's variance does).
/// The same for the three channels: grain in brightness, not in colour.
#[inline]
pub fn output_dither(index: u32) -> f32 {
    let h = hash_u32(index);
    let a = ((h & 0xffff) as f32 + 0.5) / 65536.0;
    let b = ((h >> 16) as f32 + 0.5) / 65536.0;
    a + b - 1.0
}

/// The sRGB-encoded value `e` (0..1) plus `noise` levels of 255
/// (`dither_encoded` in WGSL), before the rounding to 8 bits. Without it
/// a smooth gradient that spans a few levels (a dusk sky: the whole
/// twilight arch within 10-20 levels) rounds into flat bands with
/// visible steps; with it each pixel rounds up or down in proportion to
/// where its value lies between the levels, and the eye averages the
/// grain back into the gradient. The noise fades out within a level of
/// black and of white, so black stays black and white stays white.
#[inline]
pub fn dither_encoded(e: f32, noise: f32) -> f32 {
    let room = (e.min(1.0 - e) * 255.0).clamp(0.0, 1.0);
    e + noise * room / 255.0
}

/// Rec. 709 luminance of a linear sRGB colour.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dither keeps what lies between two levels: a flat value 0.3 of
    /// a level above level 40 rounds to 40 everywhere without it (0.3
    /// levels off in the mean, a band), and to a mix of 39s, 40s and 41s whose
    /// mean is within 0.03 levels of 40.3 with it. Black and white stay
    /// exact, and the noise is triangular: mean 0, variance 1/6.
    #[test]
    fn the_dither_keeps_the_levels_between_levels() {
        // The radiance whose tone map encodes to 40.3 levels (bisection).
        let target = 40.3 / 255.0;
        let (mut lo, mut hi) = (0.0_f32, 1.0_f32);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if srgb_encode(tone_map(Vec3::splat(mid), 1.0).y) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let flat = vec![Vec3::splat(lo); 64 * 64];
        let bytes = to_srgb8(&flat, 1.0);
        let mean = bytes.iter().map(|&b| b as f64).sum::<f64>() / bytes.len() as f64;
        assert!((mean - 40.3).abs() < 0.03, "{mean}");
        // Within a level of it (triangular noise spans two).
        assert!(bytes.iter().all(|&b| (39..=41).contains(&b)));
        // Black and white are not dithered.
        assert!(
            to_srgb8(&vec![Vec3::ZERO; 4096], 1.0)
                .iter()
                .all(|&b| b == 0)
        );
        assert!(
            to_srgb8(&vec![Vec3::splat(1e6); 4096], 1.0)
                .iter()
                .all(|&b| b == 255)
        );
        // Triangular over (-1, 1).
        let n = 1 << 16;
        let v: Vec<f64> = (0..n).map(|i| output_dither(i) as f64).collect();
        let m = v.iter().sum::<f64>() / n as f64;
        let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n as f64;
        assert!(
            m.abs() < 0.01 && (var - 1.0 / 6.0).abs() < 0.01,
            "{m} {var}"
        );
        assert!(v.iter().all(|x| x.abs() < 1.0));
    }

    /// The fitted ACES curve's landmarks, its monotony and its roll-off:
    /// black stays black, a neutral grey stays neutral, brighter is never
    /// darker, and a highlight 30 times mid grey is near white but not
    /// clipped (an exponential map reaches 0.997 there).
    #[test]
    fn the_tone_map_is_filmic() {
        assert!(tone_map(Vec3::ZERO, 1.0).max_element() < 2e-3);
        let grey = tone_map(Vec3::splat(0.18), 1.0);
        assert!(
            (grey.x - grey.y).abs() < 2e-3 && (grey.y - grey.z).abs() < 2e-3,
            "{grey}"
        );
        assert!((0.08..0.13).contains(&grey.y), "{grey}");
        let mut last = -1.0;
        for i in 0..200 {
            let x = 10f32.powf(-3.0 + 5.0 * i as f32 / 199.0);
            let y = tone_map(Vec3::splat(x), 1.0).y;
            assert!(y >= last, "{x}: {y} < {last}");
            last = y;
        }
        let hi = tone_map(Vec3::splat(5.4), 1.0).y;
        assert!((0.85..0.97).contains(&hi), "{hi}");
        // Exposure scales the input.
        assert_eq!(tone_map(Vec3::splat(0.5), 2.0), tone_map(Vec3::ONE, 1.0));
        // A saturated bright blue is desaturated toward white, not clipped
        // per channel into cyan.
        let b = tone_map(Vec3::new(0.5, 1.0, 8.0), 1.0);
        assert!(b.z < 1.0 && b.x > 0.1, "{b}");
    }
}
