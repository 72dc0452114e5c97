//! Log-log line plots as PNG (plotters, drawn into memory, then written
//! atomically). The font is embedded (DejaVu Sans, Bitstream Vera licence)
//! so plots need no system font library.

use std::path::Path;
use std::sync::Once;

use plotters::coord::combinators::BindKeyPoints;
use plotters::prelude::*;
use plotters::style::FontStyle;

use super::ReportError;
use crate::io::write_png_atomically;

static FONT: &[u8] = include_bytes!("DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// One named series of `(x, y)` points.
pub struct Series {
    /// Points joined by a line (a curve), or alone (a scatter).
    pub joined: bool,
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// Registers the embedded font (once) and gives the error constructor
/// for plots into `path`.
fn plot_error(path: &Path) -> impl Fn(&dyn std::fmt::Display) -> ReportError + '_ {
    REGISTER.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
    move |e: &dyn std::fmt::Display| ReportError::Plot {
        path: path.to_owned(),
        message: e.to_string(),
    }
}

/// `v` as an axis label: at most three significant digits, no trailing
/// zeros (0.5, 10, 0.001), powers of ten beyond 1e5 or below 1e-3 as
/// `1e-4` (not `1.00e-4`).
fn tick_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    let text = if (-3..6).contains(&e) {
        let decimals = (2 - e).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.2e}")
    };
    let (mantissa, exponent) = match text.split_once('e') {
        Some((m, x)) => (m.to_owned(), Some(x.to_owned())),
        None => (text, None),
    };
    let mantissa = if mantissa.contains('.') {
        mantissa
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_owned()
    } else {
        mantissa
    };
    match exponent {
        Some(x) => format!("{mantissa}e{x}"),
        None => mantissa,
    }
}

/// The ticks of a log axis over `[lo, hi]`: labelled ones (every decade;
/// also 2 and 5 times it when the axis spans under three decades, so
/// that a short axis has labels everywhere, not only above its first
/// power of ten; every multiple 1..9 when it spans under one, so that a
/// flat curve's axis is not left with one label) and unlabelled grid
/// lines (the other multiples of each decade).
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (lo.min(hi), lo.max(hi));
    if !(lo > 0.0 && hi.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let steps: &[f64] = if hi / lo < 10.0 {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else if hi / lo < 1000.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let (mut bold, mut light) = (Vec::new(), Vec::new());
    for k in lo.log10().floor() as i32..=hi.log10().ceil() as i32 {
        for m in 1..10 {
            // Divided below 1, so that 3 tenths is the literal 0.3.
            let v = if k >= 0 {
                m as f64 * 10f64.powi(k)
            } else {
                m as f64 / 10f64.powi(-k)
            };
            if v < lo || v > hi {
                continue;
            }
            if steps.contains(&(m as f64)) {
                bold.push(v);
            } else {
                light.push(v);
            }
        }
    }
    (bold, light)
}

/// Where the legend goes: the corner of the plot (as fractions of its
/// width and height, y up) whose legend-sized box holds the fewest of
/// `points` and of their segments' midpoints (`points` already mapped to
/// `[0, 1]²`); upper right on a tie.
fn legend_corner(points: &[(f64, f64)], box_w: f64, box_h: f64) -> SeriesLabelPosition {
    let corners = [
        (SeriesLabelPosition::UpperRight, 1.0 - box_w, 1.0 - box_h),
        (SeriesLabelPosition::UpperLeft, 0.0, 1.0 - box_h),
        (SeriesLabelPosition::LowerRight, 1.0 - box_w, 0.0),
        (SeriesLabelPosition::LowerLeft, 0.0, 0.0),
    ];
    let inside = |x0: f64, y0: f64| {
        points
            .iter()
            .filter(|p| p.0 >= x0 && p.0 <= x0 + box_w && p.1 >= y0 && p.1 <= y0 + box_h)
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|&(_, x0, y0)| inside(x0, y0))
        .map_or(SeriesLabelPosition::UpperRight, |c| c.0)
}

/// About how wide a character of the plots' labels is, px.
const CHAR_PX: f64 = 7.0;
/// About the size of a log-log plot's area inside its 900 x 600 px
/// image, px: less the margins (15 each side), the y labels (70) and
/// the x labels and caption (45 and about 30).
const PLOT_PX: (f64, f64) = (900.0 - 30.0 - 70.0, 600.0 - 30.0 - 45.0 - 30.0);

/// The height of a ring's label, px (its 15 px font and a little room).
const LABEL_PX: f64 = 18.0;

/// Where each ring's label starts, as a pixel offset of its top-left
/// corner from the ring's centre, for rings at `(x, y, characters)` (px
/// in the plot area, y down): the first of eight places around the ring
/// (right of it first, then left, then above and below those, then
/// straight above and below) whose box stays inside
/// the plot and overlaps neither an earlier label's box nor another
/// ring; if none is, the first that stays inside the plot (else the
/// right-hand place), so that two defaults that sit at nearly the same
/// cost and error do not have their labels drawn over each other.
fn label_offsets(rings: &[(f64, f64, usize)]) -> Vec<(i32, i32)> {
    const GAP: f64 = 14.0;
    const RING: f64 = 10.0;
    let mut boxes: Vec<[f64; 4]> = Vec::new();
    let overlaps =
        |a: &[f64; 4], b: &[f64; 4]| a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
    rings
        .iter()
        .enumerate()
        .map(|(i, &(x, y, chars))| {
            let w = chars as f64 * CHAR_PX;
            let h = LABEL_PX;
            let places = [
                (GAP, -8.0),
                (-GAP - w, -8.0),
                (GAP, -8.0 - h),
                (GAP, -8.0 + h),
                (-GAP - w, -8.0 - h),
                (-GAP - w, -8.0 + h),
                (-0.5 * w, -GAP - h),
                (-0.5 * w, GAP),
            ]
            .map(|(dx, dy): (f64, f64)| (dx.round(), dy.round()));
            let inside = |&(dx, dy): &(f64, f64)| {
                x + dx >= 0.0 && x + dx + w <= PLOT_PX.0 && y + dy >= 0.0 && y + dy + h <= PLOT_PX.1
            };
            let free = |&(dx, dy): &(f64, f64)| {
                let b = [x + dx, y + dy, x + dx + w, y + dy + h];
                let clear_rings = rings.iter().enumerate().all(|(j, r)| {
                    j == i || !overlaps(&b, &[r.0 - RING, r.1 - RING, r.0 + RING, r.1 + RING])
                });
                inside(&(dx, dy)) && clear_rings && boxes.iter().all(|o| !overlaps(&b, o))
            };
            let (dx, dy) = places
                .iter()
                .copied()
                .find(|p| free(p))
                .or_else(|| places.iter().copied().find(|p| inside(p)))
                .unwrap_or(places[0]);
            boxes.push([x + dx, y + dy, x + dx + w, y + dy + h]);
            (dx as i32, dy as i32)
        })
        .collect()
}

/// Draws the series on log-log axes; `marked` points get a black ring and
/// a label.
pub fn loglog_png(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    marked: &[(f64, f64, String)],
) -> Result<(), ReportError> {
    let err = plot_error(path);
    let (w, h) = (900u32, 600u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    // Each series' points a log axis can show.
    let kept: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|p| p.0 > 0.0 && p.1 > 0.0)
                .collect()
        })
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in kept.iter().flatten() {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (1.0, 10.0, 1.0, 10.0);
    }
    let (xr, yr) = ((x0 / 1.5, x1 * 1.5), (y0 / 2.0, y1 * 2.0));
    let (x_bold, x_light) = log_ticks(xr.0, xr.1);
    let (y_bold, y_light) = log_ticks(yr.0, yr.1);
    // Where each point and segment midpoint lies in the plot, as fractions.
    let unit = |p: (f64, f64)| {
        let f = |v: f64, r: (f64, f64)| (v / r.0).ln() / (r.1 / r.0).ln();
        (f(p.0, xr), f(p.1, yr))
    };
    let mut placed = Vec::new();
    for (s, points) in series.iter().zip(&kept) {
        let pts: Vec<(f64, f64)> = points.iter().copied().map(unit).collect();
        placed.extend(pts.iter().copied());
        if s.joined {
            placed.extend(
                pts.windows(2)
                    .map(|w| (0.5 * (w[0].0 + w[1].0), 0.5 * (w[0].1 + w[1].1))),
            );
        }
    }
    // The legend's box: about 22 px per series high, the longest name
    // plus the swatch wide, over the plot area.
    let longest = series
        .iter()
        .map(|s| s.name.chars().count())
        .max()
        .unwrap_or(0);
    let legend_w = ((longest as f64 * CHAR_PX + 60.0) / PLOT_PX.0).min(0.5);
    let legend_h = ((series.len() as f64 * 22.0 + 20.0) / PLOT_PX.1).min(0.5);
    let corner = legend_corner(&placed, legend_w, legend_h);
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (xr.0..xr.1)
                    .log_scale()
                    .with_key_points(x_bold)
                    .with_light_points(x_light),
                (yr.0..yr.1)
                    .log_scale()
                    .with_key_points(y_bold)
                    .with_light_points(y_light),
            )
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&|v| tick_label(*v))
            .y_label_formatter(&|v| tick_label(*v))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| err(&e))?;
        for (k, (s, points)) in series.iter().zip(&kept).enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let line = if s.joined { points.clone() } else { Vec::new() };
            chart
                .draw_series(LineSeries::new(line, color.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(s.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(|e| err(&e))?;
        }
        // Each label beside its ring, clear of the labels placed before it.
        let rings: Vec<(f64, f64, usize)> = marked
            .iter()
            .map(|(x, y, label)| {
                let (u, v) = unit((*x, *y));
                (u * PLOT_PX.0, (1.0 - v) * PLOT_PX.1, label.chars().count())
            })
            .collect();
        for ((x, y, label), (dx, dy)) in marked.iter().zip(label_offsets(&rings)) {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((*x, *y))
                        + Circle::new((0, 0), 9, BLACK.stroke_width(2))
                        + Text::new(label.clone(), (dx, dy), ("sans-serif", 15)),
                ))
                .map_err(|e| err(&e))?;
        }
        chart
            .configure_series_labels()
            .position(corner)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or_else(|| err(&"buffer size"))?;
    write_png_atomically(path, &img).map_err(|source| ReportError::Write {
        path: path.to_owned(),
        source,
    })
}

/// A bar chart of named values (linear axis from zero).
pub fn bars_png(
    path: &Path,
    title: &str,
    y_label: &str,
    bars: &[(String, f64)],
) -> Result<(), ReportError> {
    let err = plot_error(path);
    let (w, h) = (900u32, 600u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    let top = bars
        .iter()
        .map(|b| b.1)
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max)
        .max(1e-9)
        * 1.15;
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let n = bars.len().max(2);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((0..n - 1).into_segmented(), 0.0..top)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .y_desc(y_label)
            .x_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) => bars.get(*i).map_or(String::new(), |b| b.0.clone()),
                _ => String::new(),
            })
            // 4000, not 4000.0.
            .y_label_formatter(&|v| tick_label(*v))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| err(&e))?;
        chart
            .draw_series(
                bars.iter()
                    .enumerate()
                    .filter(|(_, b)| b.1.is_finite())
                    .map(|(i, b)| {
                        let mut r = Rectangle::new(
                            [
                                (SegmentValue::Exact(i), 0.0),
                                (SegmentValue::Exact(i + 1), b.1),
                            ],
                            Palette99::pick(0).filled(),
                        );
                        r.set_margin(0, 0, 12, 12);
                        r
                    }),
            )
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or_else(|| err(&"buffer size"))?;
    write_png_atomically(path, &img).map_err(|source| ReportError::Write {
        path: path.to_owned(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(100.0), "100");
        assert_eq!(tick_label(10.0), "10");
        assert_eq!(tick_label(0.5), "0.5");
        assert_eq!(tick_label(0.001), "0.001");
        assert_eq!(tick_label(2.5), "2.5");
        assert_eq!(tick_label(1e-4), "1e-4");
        assert_eq!(tick_label(2e6), "2e6");
    }

    #[test]
    fn a_short_log_axis_is_labelled_below_its_first_decade() {
        // The render-quality plot's time axis, 0.17 to 4.7 s: labelled
        // below 1 too, not at 1, 2, 3 and 4 only.
        let (bold, light) = log_ticks(0.17, 4.7);
        assert_eq!(bold, vec![0.2, 0.5, 1.0, 2.0]);
        assert!(light.contains(&0.3) && light.contains(&4.0) && !light.contains(&0.1));
        // Many decades: only the powers of ten are labelled.
        let (bold, _) = log_ticks(1e-4, 300.0);
        assert_eq!(bold.len(), 7);
        assert!(log_ticks(0.0, 1.0).0.is_empty());
        // Under a decade (a flat curve, 1.0 to 4.2 s): every multiple is
        // labelled (else the coverage plot's frame-time axis gets one label).
        let (bold, light) = log_ticks(980.0, 4200.0);
        assert_eq!(bold, vec![1000.0, 2000.0, 3000.0, 4000.0]);
        assert!(light.is_empty());
    }

    #[test]
    fn ring_labels_do_not_overlap() {
        // As on the H200's render-error plot: "octaves 3" and
        // "shadow_steps 20" ringed 18 px apart on one level, whose labels
        // must not both go right of their rings, one over the other.
        let rings = [(430.0, 340.0, 11), (448.0, 338.0, 17), (300.0, 340.0, 10)];
        let offsets = label_offsets(&rings);
        let boxes: Vec<[f64; 4]> = rings
            .iter()
            .zip(&offsets)
            .map(|(r, o)| {
                let (x, y) = (r.0 + o.0 as f64, r.1 + o.1 as f64);
                [x, y, x + r.2 as f64 * CHAR_PX, y + LABEL_PX]
            })
            .collect();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                let (a, b) = (boxes[i], boxes[j]);
                let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
                assert!(apart, "labels {i} and {j}: {a:?} {b:?}");
            }
        }
        // No label sits on another ring.
        for (k, b) in boxes.iter().enumerate() {
            for (j, r) in rings.iter().enumerate() {
                let clear = k == j
                    || b[2] <= r.0 - 10.0
                    || r.0 + 10.0 <= b[0]
                    || b[3] <= r.1 - 10.0
                    || r.1 + 10.0 <= b[1];
                assert!(clear, "label {k} on ring {j}");
            }
        }
        // Where every place is taken, a label still stays in the plot:
        // rings packed along the right edge.
        let packed: Vec<(f64, f64, usize)> = (0..12)
            .map(|k| (PLOT_PX.0 - 6.0, 100.0 + 4.0 * k as f64, 12))
            .collect();
        for ((x, _, n), (dx, _)) in packed.iter().zip(label_offsets(&packed)) {
            assert!(x + dx as f64 + *n as f64 * CHAR_PX <= PLOT_PX.0, "{dx}");
        }
        // A lone ring keeps the label on its right; one at the right edge
        // puts it on the left.
        assert_eq!(label_offsets(&[(100.0, 200.0, 8)]), vec![(14, -8)]);
        let (dx, _) = label_offsets(&[(PLOT_PX.0 - 5.0, 200.0, 8)])[0];
        assert!(dx < 0, "{dx}");
    }

    #[test]
    fn the_legend_avoids_the_curves() {
        // A curve falling from the upper left to the lower right (the
        // convergence plot's): the legend goes to an empty corner.
        let falling: Vec<(f64, f64)> = (0..=20)
            .map(|i| (i as f64 / 20.0, 1.0 - i as f64 / 20.0))
            .collect();
        let c = legend_corner(&falling, 0.2, 0.2);
        assert!(matches!(
            c,
            SeriesLabelPosition::UpperRight | SeriesLabelPosition::LowerLeft
        ));
        let rising: Vec<(f64, f64)> = falling.iter().map(|p| (p.0, 1.0 - p.1)).collect();
        let c = legend_corner(&rising, 0.2, 0.2);
        assert!(matches!(
            c,
            SeriesLabelPosition::UpperLeft | SeriesLabelPosition::LowerRight
        ));
        // Points in every corner but the lower left.
        let pts = [(0.9, 0.9), (0.1, 0.9), (0.9, 0.1)];
        assert!(matches!(
            legend_corner(&pts, 0.2, 0.2),
            SeriesLabelPosition::LowerLeft
        ));
    }
}
