//! The field the density reads: P with its coverage spread by a Gaussian
//! of the clouds' merging scale.
//!
//! P gives each condensed parcel a hard disc of its radius, so a density
//! that cut clouds at P's edge would make every cloud a disc of one parcel's
//! size. Spread out, the coverage of a lone parcel stays low and only the
//! highest points of the multi-scale cloud map rise through it (a few
//! small clouds), while the coverages of neighbouring parcels add up and
//! their clouds merge into one large one: the sizes of the clouds come
//! from how the simulation clusters its parcels, and their outlines from
//! the cloud map's level sets.
//!
//! Height and fill are spread with the same kernel, weighted by coverage
//! (a texel's height is that of the parcels whose coverage reaches it).
//! Both renderers read the spread field: the GPU's `update_field` builds
//! it from the P it is given, the CPU reference is handed it by `prepare`.

use rayon::prelude::*;

use crate::sim::ProjectedField;

/// Standard deviation of the spread, m: about a cumulus parcel's radius
/// (250-400 m in the shipped scenes), so the coverages of parcels a few
/// radii apart add up into one cloud's. Chosen with `cumulus stats`: at
/// 150 m the clouds keep the parcels' disc outlines (area-perimeter
/// dimension 1.16-1.18), at 400 m the map's outlines show (1.30-1.32).
pub const SPREAD_M: f32 = 400.0;

/// `p` with coverage, height and fill spread by a periodic Gaussian of
/// `sigma_m` (P spans `extent_m`); coverage is scaled so that a field
/// covered everywhere stays covered everywhere (1), and a disc much larger
/// than the kernel keeps its coverage in its middle. `sigma_m <= 0`
/// returns `p` unchanged.
pub fn soft_field(p: &ProjectedField, sigma_m: f32, extent_m: f32) -> ProjectedField {
    let (w, h) = (p.width(), p.height());
    if !(sigma_m > 0.0 && extent_m.is_finite() && extent_m > 0.0) || w == 0 || h == 0 {
        return p.clone();
    }
    // Weighted channels: coverage, coverage·height, coverage·fill.
    let a: Vec<[f32; 3]> = p
        .texels()
        .iter()
        .map(|t| [t[0], t[0] * t[1], t[0] * t[2]])
        .collect();
    let kx = gaussian_kernel(sigma_m, extent_m / w as f32, w);
    let ky = gaussian_kernel(sigma_m, extent_m / h as f32, h);
    let b = blur_axis(&a, w, h, &kx, true);
    let a = blur_axis(&b, w, h, &ky, false);
    let texels = a
        .into_iter()
        .map(|[c, ch, cf]| {
            if c <= 1e-6 {
                [0.0, 0.0, 0.0]
            } else {
                [
                    c.min(1.0),
                    (ch / c).clamp(0.0, 1.0),
                    (cf / c).clamp(0.0, 1.0),
                ]
            }
        })
        .collect();
    ProjectedField::from_texels(w, h, texels).unwrap_or_else(|| p.clone())
}

/// The normalised Gaussian of `sigma_m` sampled at texels of `texel_m`
/// along an axis of `n` texels: three standard deviations each side, so
/// the cost stays within texels x width. A Gaussian wider than that
/// around the period is wrapped onto it instead, one weight per texel
/// (the tails of every period summed): on an even axis its two end taps
/// are the same texel, each with half its weight. Cut to `n - 1` taps,
/// an even axis would leave the texel opposite each source with no share
/// of it (domains under about six spreads, 2.4 km at the shipped 400 m;
/// none of the shipped scenes).
fn gaussian_kernel(sigma_m: f32, texel_m: f32, n: usize) -> Vec<f32> {
    let s = (sigma_m / texel_m).max(1e-3);
    let gauss = |x: f32| (-0.5 * (x / s).powi(2)).exp();
    let full = (3.0 * s).ceil() as i64;
    let n_i = n as i64;
    let k: Vec<f32> = if full <= (n_i - 1) / 2 {
        (-full..=full).map(|i| gauss(i as f32)).collect()
    } else {
        let r = n_i / 2;
        let periods = full / n_i.max(1) + 1;
        (-r..=r)
            .map(|i| {
                let wrapped: f32 = (-periods..=periods)
                    .map(|m| gauss((i + m * n_i) as f32))
                    .sum();
                if 2 * r + 1 > n_i && i.abs() == r {
                    0.5 * wrapped
                } else {
                    wrapped
                }
            })
            .collect()
    };
    let sum: f32 = k.iter().sum();
    k.into_iter().map(|x| x / sum).collect()
}

/// `src` (`w x h`, row-major) convolved with the centred kernel `k` along
/// rows (`along_x`) or columns, periodically; `k` is at most `w + 1`
/// (rows) or `h + 1` (columns) long (a kernel wrapped onto an even
/// axis), and `w` and `h` are at least 1 ([`soft_field`] returns early
/// otherwise). Rows run in parallel; each texel sums its
/// taps in the kernel's order, so the result does not depend on the
/// threads.
fn blur_axis(src: &[[f32; 3]], w: usize, h: usize, k: &[f32], along_x: bool) -> Vec<[f32; 3]> {
    let r = k.len() / 2;
    let mut out = vec![[0.0_f32; 3]; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        if along_x {
            // The row wrapped by r texels at each end: every tap in bounds.
            let line = &src[y * w..(y + 1) * w];
            let padded: Vec<[f32; 3]> = (0..w + 2 * r).map(|i| line[(i + w - r) % w]).collect();
            for (x, o) in row.iter_mut().enumerate() {
                for (kv, t) in k.iter().zip(&padded[x..]) {
                    for c in 0..3 {
                        o[c] += kv * t[c];
                    }
                }
            }
        } else {
            // Whole source rows, scaled and added: contiguous reads.
            for (j, kv) in k.iter().enumerate() {
                let sy = (y + h + j - r) % h;
                for (o, t) in row.iter_mut().zip(&src[sy * w..(sy + 1) * w]) {
                    for c in 0..3 {
                        o[c] += kv * t[c];
                    }
                }
            }
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A field of `w x h` random texels, some of them clear.
    fn random_texels(w: usize, h: usize, mut seed: u32) -> Vec<[f32; 3]> {
        let mut rnd = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        (0..w * h)
            .map(|_| {
                let c = if rnd() < 0.4 { rnd() } else { 0.0 };
                [c, rnd(), rnd()]
            })
            .collect()
    }

    /// The separable, parallel blur against a direct periodic 2D sum, on
    /// fields neither square nor smooth, with kernels of different lengths
    /// along x and y (a swapped axis or an off-by-one wrap shows here); the
    /// second case's kernels are cut to the field's size on both axes.
    #[test]
    fn the_spread_equals_a_direct_periodic_convolution() {
        for (w, h, extent, sigma) in [
            (24_usize, 10_usize, 2400.0_f32, 230.0_f32),
            (24, 6, 2400.0, 900.0),
        ] {
            let texels = random_texels(w, h, 7);
            let p = ProjectedField::from_texels(w, h, texels.clone()).expect("size");
            let got = soft_field(&p, sigma, extent);
            let kx = gaussian_kernel(sigma, extent / w as f32, w);
            let ky = gaussian_kernel(sigma, extent / h as f32, h);
            assert!(kx.len() > ky.len(), "the axes get different kernels");
            let (rx, ry) = ((kx.len() / 2) as i64, (ky.len() / 2) as i64);
            for y in 0..h {
                for x in 0..w {
                    let mut a = [0.0_f64; 3];
                    for (j, vy) in ky.iter().enumerate() {
                        for (i, vx) in kx.iter().enumerate() {
                            let sx = (x as i64 + i as i64 - rx).rem_euclid(w as i64) as usize;
                            let sy = (y as i64 + j as i64 - ry).rem_euclid(h as i64) as usize;
                            let t = texels[sy * w + sx];
                            let wgt = f64::from(vx * vy);
                            a[0] += wgt * f64::from(t[0]);
                            a[1] += wgt * f64::from(t[0] * t[1]);
                            a[2] += wgt * f64::from(t[0] * t[2]);
                        }
                    }
                    let t = got.at(x, y);
                    assert!(
                        (f64::from(t[0]) - a[0].min(1.0)).abs() < 1e-5,
                        "{w}x{h} ({x},{y}) coverage {t:?} vs {a:?}"
                    );
                    if a[0] > 1e-3 {
                        assert!(
                            (f64::from(t[1]) - a[1] / a[0]).abs() < 1e-4,
                            "{w}x{h} ({x},{y}) height"
                        );
                        assert!(
                            (f64::from(t[2]) - a[2] / a[0]).abs() < 1e-4,
                            "{w}x{h} ({x},{y}) fill"
                        );
                    }
                }
            }
        }
    }

    /// The parallel blur gives a serial loop's result bit for bit (one
    /// texel at a time, its taps in kernel order, wrapped with
    /// `rem_euclid`), along both axes, with kernels as long as the field
    /// allows.
    #[test]
    fn the_parallel_blur_is_the_serial_sum_bit_for_bit() {
        fn serial(src: &[[f32; 3]], w: usize, h: usize, k: &[f32], along_x: bool) -> Vec<[f32; 3]> {
            let r = (k.len() / 2) as i64;
            let mut out = vec![[0.0_f32; 3]; w * h];
            for y in 0..h {
                for x in 0..w {
                    let mut s = [0.0_f32; 3];
                    for (j, kv) in k.iter().enumerate() {
                        let o = j as i64 - r;
                        let t = if along_x {
                            src[y * w + (x as i64 + o).rem_euclid(w as i64) as usize]
                        } else {
                            src[(y as i64 + o).rem_euclid(h as i64) as usize * w + x]
                        };
                        for c in 0..3 {
                            s[c] += kv * t[c];
                        }
                    }
                    out[y * w + x] = s;
                }
            }
            out
        }
        let (w, h) = (24, 7);
        let src = random_texels(w, h, 11);
        for (len, along_x) in [(23, true), (9, true), (7, false), (3, false)] {
            let k: Vec<f32> = (0..len).map(|i| 0.3 + 0.1 * ((i * 7) % 5) as f32).collect();
            assert_eq!(
                blur_axis(&src, w, h, &k, along_x),
                serial(&src, w, h, &k, along_x),
                "length {len}, along x {along_x}"
            );
        }
    }

    /// A spread wider than the field wraps around it: a lone texel's
    /// coverage on an axis of 8 and of 7 texels is the Gaussian summed
    /// over every period, at every texel (cut to 7 taps, the even axis
    /// would give the texel opposite the source nothing).
    #[test]
    fn a_spread_wider_than_the_field_wraps_around_it() {
        for n in [8_usize, 7] {
            let (texel, sigma) = (100.0_f32, 300.0_f32);
            let mut texels = vec![[0.0; 3]; n];
            texels[0] = [1.0, 0.5, 0.5];
            let p = ProjectedField::from_texels(n, 1, texels).expect("size");
            let spread = soft_field(&p, sigma, n as f32 * texel);
            let s = f64::from(sigma / texel);
            let periodic = |d: usize| -> f64 {
                (-20..=20_i64)
                    .map(|m| {
                        let x = d as f64 + (m * n as i64) as f64;
                        (-0.5 * (x / s).powi(2)).exp()
                    })
                    .sum()
            };
            let total: f64 = (0..n).map(periodic).sum();
            for d in 0..n {
                let want = periodic(d) / total;
                let got = f64::from(spread.at(d, 0)[0]);
                assert!(
                    (got - want).abs() < 1e-5,
                    "n {n}, texel {d}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn a_uniform_field_stays_uniform_and_a_lone_texel_spreads_and_keeps_its_height() {
        let p = ProjectedField::uniform(32, 32, [1.0, 0.6, 0.8]);
        let s = soft_field(&p, 200.0, 3200.0);
        for t in s.texels() {
            assert!((t[0] - 1.0).abs() < 1e-5 && (t[1] - 0.6).abs() < 1e-5);
        }
        let mut texels = vec![[0.0; 3]; 32 * 32];
        texels[5 * 32 + 31] = [1.0, 0.7, 0.5];
        let p = ProjectedField::from_texels(32, 32, texels).expect("size");
        let s = soft_field(&p, 200.0, 3200.0);
        let total: f32 = s.texels().iter().map(|t| t[0]).sum();
        assert!((total - 1.0).abs() < 1e-4, "coverage conserved: {total}");
        // Spread across the periodic edge, with the texel's height: a
        // Gaussian of two texels (200 m over 100 m texels) gives the
        // neighbour k(1)·k(0) of the normalised weights.
        let k: Vec<f32> = (-6..=6_i32)
            .map(|i| (-(i * i) as f32 / 8.0).exp())
            .collect();
        let sum: f32 = k.iter().sum();
        let want = k[7] / sum * k[6] / sum;
        let t = s.at(0, 5);
        assert!(
            (t[0] - want).abs() < 1e-5 && (t[1] - 0.7).abs() < 1e-5,
            "{t:?} vs {want}"
        );
        assert!(s.at(31, 5)[0] < 0.5, "a lone parcel's coverage falls");
    }
}
