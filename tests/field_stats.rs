//! `report::field_stats` on synthetic fields whose answers are known: the
//! area-perimeter dimension of discs (1) and of quadratic Koch islands
//! (log 8 / log 4 = 1.5, exactly, on the pixel grid), and the exponent of
//! a power-law size density.

use cumulus::report::field_stats::{Cloud, Mask, area_perimeter_fit, size_density, size_fit};

/// Tolerance on the discs' D: the fit of pixelated circles over 1.5-2
/// decades of area, measured 1.016 (`cargo test --release --test
/// field_stats -- --nocapture`), three times that off 1.
const DISC_D_TOLERANCE: f64 = 0.05;
/// Tolerance on the Koch islands' D, whose outlines are exact on the
/// pixel grid: measured 1.5000 to four decimals, so only the fit's
/// rounding is allowed.
const KOCH_D_TOLERANCE: f64 = 5e-4;

fn blank(w: usize, h: usize) -> Mask {
    Mask::from_fn(w, h, 10.0, |_, _| false)
}

#[test]
fn discs_have_dimension_one_and_fail_the_natural_range() {
    let mut clouds = Vec::new();
    for r in [3.0, 5.0, 8.0, 13.0, 21.0, 34.0, 55.0] {
        let n = (2.0 * r) as usize + 8;
        let mut m = blank(n, n);
        let c = n as f64 / 2.0;
        for y in 0..n {
            for x in 0..n {
                let (dx, dy) = (x as f64 + 0.5 - c, y as f64 + 0.5 - c);
                m.cells[y * n + x] = dx * dx + dy * dy <= r * r;
            }
        }
        clouds.extend(m.clouds());
    }
    assert_eq!(clouds.len(), 7);
    let d = 2.0 * area_perimeter_fit(&clouds, 1).expect("fit").slope;
    eprintln!("discs: D = {d:.4}");
    assert!((d - 1.0).abs() < DISC_D_TOLERANCE, "discs: D = {d}");
    // Real cloud fields: 1.30..=1.40 (Lovejoy 1982); a disc field is not one.
    assert!(!(1.30..=1.40).contains(&d));
}

/// The quadratic Koch island of generation `g` on a square of side 4^g
/// cells (every segment one cell long at the end), as a closed polygon.
fn koch_island(g: u32) -> Vec<(i64, i64)> {
    let s = 4i64.pow(g);
    let mut pts = vec![(0, 0), (s, 0), (s, s), (0, s), (0, 0)];
    for _ in 0..g {
        let mut next = vec![pts[0]];
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let v = ((b.0 - a.0) / 4, (b.1 - a.1) / 4);
            let n = (-v.1, v.0);
            let at = |i: i64, j: i64| (a.0 + i * v.0 + j * n.0, a.1 + i * v.1 + j * n.1);
            next.extend([
                at(1, 0),
                at(1, 1),
                at(2, 1),
                at(2, 0),
                at(2, -1),
                at(3, -1),
                at(3, 0),
                b,
            ]);
        }
        pts = next;
    }
    pts
}

/// Cells whose centres the rectilinear polygon `pts` encloses (even-odd
/// rule along each row), the polygon shifted by `off`.
fn rasterise(m: &mut Mask, pts: &[(i64, i64)], off: i64) {
    for y in 0..m.height {
        let yc = y as f64 + 0.5 - off as f64;
        let mut xs: Vec<f64> = pts
            .windows(2)
            .filter(|w| w[0].0 == w[1].0)
            .filter(|w| {
                let (lo, hi) = (w[0].1.min(w[1].1) as f64, w[0].1.max(w[1].1) as f64);
                lo < yc && yc < hi
            })
            .map(|w| (w[0].0 + off) as f64)
            .collect();
        xs.sort_by(f64::total_cmp);
        for pair in xs.chunks_exact(2) {
            for x in pair[0].ceil() as usize..pair[1].ceil() as usize {
                m.cells[y * m.width + x] = true;
            }
        }
    }
}

#[test]
fn quadratic_koch_islands_have_dimension_one_and_a_half() {
    let mut clouds = Vec::new();
    for g in 1..=4 {
        let s = 4i64.pow(g);
        let n = (2 * s + 8) as usize;
        let mut m = blank(n, n);
        rasterise(&mut m, &koch_island(g), s / 2 + 4);
        let c = m.clouds();
        assert_eq!(c.len(), 1, "generation {g}");
        // The island keeps the square's area; its outline is 4 * 8^g cells.
        assert_eq!(c[0].cells as i64, s * s, "generation {g}");
        assert_eq!(c[0].perimeter_m, 10.0 * (4 * 8i64.pow(g)) as f64);
        clouds.extend(c);
    }
    let d = 2.0 * area_perimeter_fit(&clouds, 1).expect("fit").slope;
    eprintln!("Koch islands: D = {d:.6}");
    assert!((d - 1.5).abs() < KOCH_D_TOLERANCE, "Koch islands: D = {d}");
}

#[test]
fn a_power_law_of_sizes_gives_its_exponent() {
    // Diameters at the quantiles of n(d) ∝ d^-2.5 from 100 m up: N(>d)
    // ∝ d^-1.5.
    let (n, alpha, d0) = (2000usize, 2.5, 100.0);
    let clouds: Vec<Cloud> = (0..n)
        .map(|i| {
            let d = d0 * ((i as f64 + 0.5) / n as f64).powf(-1.0 / (alpha - 1.0));
            let area = std::f64::consts::PI * d * d / 4.0;
            Cloud {
                cells: 100,
                area_m2: area,
                perimeter_m: std::f64::consts::PI * d,
                diameter_m: d,
            }
        })
        .collect();
    let bins = size_density(&clouds, 1, 1e10, 5);
    let (fit, decades) = size_fit(&bins);
    let slope = fit.expect("fit").slope;
    eprintln!("power law -2.5: fitted {slope:.3} over {decades:.2} decades");
    assert!(decades >= 2.0, "{decades} decades");
    assert!((slope + alpha).abs() < 0.15, "exponent {slope}");
}

/// The shipped trade-cumulus and fair-weather scenes, seen from above as
/// `cumulus stats` sees them, are natural cumulus fields by the measures
/// of `FieldStats::departures_from_nature` (clouds drawn without the
/// multi-scale cloud map and the spread P score D 0.99-1.02, exponents
/// -0.24 and -1.13, one size of blob). A field of discs of many sizes is
/// not (its D against the same range).
#[test]
fn shipped_scenes_seen_from_above_are_natural_cumulus_fields_and_discs_are_not() {
    use cumulus::prepare::Prepared;
    use cumulus::report::field_stats::{column_field, field_stats};
    use cumulus::scene::Scene;
    for name in ["bomex", "fair_weather"] {
        let sc = Scene::load(std::path::Path::new(&format!("scenes/{name}.toml")))
            .expect("shipped scene");
        let p = Prepared::from_scene(&sc, || {}).expect("prepare");
        let r = &sc.render;
        let s = field_stats(
            &column_field(&p.density_frame(r, r.quality()), 512, 48),
            1.0,
            4,
        );
        eprintln!(
            "{name}: cloud fraction {:.3}, D {:?}, exponent {:?} over {:.1} decades",
            s.cloud_fraction,
            s.dimension,
            s.size_fit.map(|f| f.slope),
            s.size_decades
        );
        let off = s.departures_from_nature();
        assert!(off.is_empty(), "{name}: {off:?}");
    }
    // Discs of many sizes drawn from a -2 power law: a natural exponent,
    // but outlines of dimension 1.
    let mut m = blank(1024, 1024);
    let mut k = 0usize;
    for (i, r) in [40.0, 25.0, 16.0, 10.0, 6.5, 4.0, 2.5].iter().enumerate() {
        let count = 2usize.pow(i as u32 + 1);
        for _ in 0..count {
            // A deterministic scatter on a grid of slots.
            let (cx, cy) = ((k * 97 % 1024) as f64 + 0.5, (k * 61 % 1024) as f64 + 0.5);
            k += 1;
            let rr = *r;
            for y in (cy - rr) as i64..=(cy + rr) as i64 {
                for x in (cx - rr) as i64..=(cx + rr) as i64 {
                    let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
                    if dx * dx + dy * dy <= rr * rr {
                        let (xx, yy) = (x.rem_euclid(1024) as usize, y.rem_euclid(1024) as usize);
                        m.cells[yy * 1024 + xx] = true;
                    }
                }
            }
        }
    }
    let clouds = m.clouds();
    let fit = area_perimeter_fit(&clouds, 4).expect("fit");
    let d = 2.0 * fit.slope;
    eprintln!("disc field: {} clouds, D = {d:.3}", clouds.len());
    assert!(
        !cumulus::report::field_stats::NATURAL_DIMENSION.contains(&d),
        "discs: D = {d}"
    );
}

/// From high above, the shipped scenes do not repeat: over five domain
/// widths around the simulated one, the cloud mask correlates with itself
/// shifted by one domain width no more than shifted as far in other
/// directions. Without the domain warp it is 0.50-0.57 against at most
/// 0.04 (rows of the same clouds to the horizon).
#[test]
fn shipped_scenes_do_not_repeat_at_the_domain_period() {
    use cumulus::prepare::Prepared;
    use cumulus::report::field_stats::{column_field_over, repetition};
    use cumulus::scene::Scene;
    for name in ["bomex", "fair_weather"] {
        let sc = Scene::load(std::path::Path::new(&format!("scenes/{name}.toml")))
            .expect("shipped scene");
        let p = Prepared::from_scene(&sc, || {}).expect("prepare");
        let r = &sc.render;
        let l = sc.physics.domain_size_m;
        let wide = column_field_over(&p.density_frame(r, r.quality()), -2.0 * l, 5.0 * l, 640, 24);
        let rep = repetition(&wide.mask(1.0), 128);
        eprintln!(
            "{name}: {:.3} at the period, at most {:.3} elsewhere",
            rep.period_max(),
            rep.other_max()
        );
        assert!(rep.hidden(), "{name}: {rep:?}");
    }
}
