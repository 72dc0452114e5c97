//! Sounding files: CSV with the header
//! `height_m,pressure_hPa,temperature_C,dewpoint_C` (or
//! `relative_humidity_pct` in place of the dewpoint), one row per level,
//! strictly increasing in height. Pressure may be left empty: it is then
//! filled by hydrostatic integration from the nearest level below that has
//! one (or, for the lowest levels, from the nearest above, or from the
//! scene's surface pressure when no row has one).

use std::path::{Path, PathBuf};

use super::check::number;
use super::constants::{G, R_D, ZERO_CELSIUS_K};
use super::sounding_formats::{
    Format, HEIGHT_MAX_M, detect, igra2_to_csv, sharppy_to_csv, wyoming_to_csv,
};
use super::thermo::{
    mixing_ratio_from_dewpoint, saturation_mixing_ratio, saturation_vapour_pressure,
};

/// The most relative humidity a sounding's level may have, as a fraction:
/// the parametric profile's bound on `surface_relative_humidity` (1.2).
/// Air in nature is supersaturated by well under a percent, and a
/// radiosonde's humidity errs by a few; beyond a fifth the row is a
/// mistake (a bound of 150 %, or of a dewpoint 10 K above the
/// temperature, some 180 % at 25 °C, would let such rows through).
pub const RH_MAX: f64 = 1.2;

/// How far a dewpoint may lie above its temperature whatever the
/// humidity it gives, K: in the cold upper air a kelvin is a large step
/// of relative humidity over water (2 K at -60 °C is some 130 %), and a
/// frost point written as a dewpoint in an ice-supersaturated layer is
/// ordinary radiosonde data.
pub const DEWPOINT_EXCESS_MAX_K: f64 = 2.0;

/// The relative humidity over liquid water of a dewpoint `td_c` at
/// temperature `t_c` (°C), as a fraction.
fn dewpoint_humidity(td_c: f64, t_c: f64) -> f64 {
    saturation_vapour_pressure(td_c + ZERO_CELSIUS_K)
        / saturation_vapour_pressure(t_c + ZERO_CELSIUS_K)
}

/// What went wrong reading a sounding; every message names the file and,
/// where there is one, the line and column.
#[derive(Debug, thiserror::Error)]
pub enum SoundingError {
    // The OS error is part of the message, not a `source`, so a report
    // that prints the error chain does not print it twice.
    #[error("{path}: cannot read sounding: {err}")]
    Io { path: PathBuf, err: std::io::Error },
    #[error("{path}:{line}: {message}")]
    Invalid {
        path: PathBuf,
        line: u64,
        message: String,
    },
}

/// One level of a sounding, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    /// Height above ground, m.
    pub height_m: f64,
    /// Pressure, Pa (always `Some` once the sounding is loaded).
    pub pressure_pa: Option<f64>,
    /// Temperature, K.
    pub temperature_k: f64,
    /// Water-vapour mixing ratio, kg/kg (may exceed saturation).
    pub mixing_ratio: f64,
}

/// A validated sounding.
#[derive(Debug, Clone)]
pub struct Sounding {
    levels: Vec<Level>,
    source: PathBuf,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Humidity {
    DewpointC,
    RelativeHumidityPct,
}

impl Humidity {
    /// The column's name.
    fn column(self) -> &'static str {
        match self {
            Humidity::DewpointC => "dewpoint_C",
            Humidity::RelativeHumidityPct => "relative_humidity_pct",
        }
    }
}

/// Makes the error of a line of the file being read.
type LineError<'a> = dyn Fn(u64, String) -> SoundingError + 'a;

/// Where a CSV sounding's columns are.
struct Columns {
    height: usize,
    pressure: usize,
    temperature: usize,
    humidity_column: usize,
    humidity: Humidity,
    header_line: u64,
}

/// What is wrong with a row the csv crate cannot read, without the
/// crate's own line number ([`csv_line`] gives the right one).
fn csv_reason(e: &csv::Error) -> String {
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("{len} fields, expected {expected_len} as in the header"),
        csv::ErrorKind::Utf8 { err, .. } => format!("not UTF-8 text: {err}"),
        _ => e.to_string(),
    }
}

/// The 1-based line of `text` on which the record at the csv crate's
/// `position` is. The crate's own line number is not it: it leaves out
/// blank lines and comment lines ended by `\r\n`, and the position's
/// byte is where the crate began to look for the record, before the
/// blank and comment lines it then passed over. Those are passed over
/// here too.
fn csv_line(text: &str, pos: Option<&csv::Position>) -> u64 {
    let b = text.as_bytes();
    let mut at = pos.map_or(0, |p| p.byte() as usize).min(b.len());
    loop {
        match b.get(at) {
            Some(b'\r' | b'\n') => at += 1,
            Some(b'#') => {
                at = b[at..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |n| at + n + 1);
            }
            _ => break,
        }
    }
    b[..at].iter().filter(|&&c| c == b'\n').count() as u64 + 1
}

impl Columns {
    /// Reads the header: height, pressure and temperature, and a dewpoint
    /// or else a relative humidity column.
    fn read(
        reader: &mut csv::Reader<&[u8]>,
        text: &str,
        err: &LineError,
    ) -> Result<Self, SoundingError> {
        let headers = reader
            .headers()
            .map_err(|e| {
                err(
                    csv_line(text, e.position()),
                    format!("cannot read header: {}", csv_reason(&e)),
                )
            })?
            .clone();
        let col = |name: &str| headers.iter().position(|h| h.eq_ignore_ascii_case(name));
        let header_line = csv_line(text, headers.position());
        let missing = |name: &str| {
            err(
                header_line,
                format!(
                    "missing column `{name}`; expected header \
                     `height_m,pressure_hPa,temperature_C,dewpoint_C` \
                     (or relative_humidity_pct instead of dewpoint_C)"
                ),
            )
        };
        let need = |name: &str| col(name).ok_or_else(|| missing(name));
        let height = need("height_m")?;
        let pressure = need("pressure_hPa")?;
        let temperature = need("temperature_C")?;
        let (humidity_column, humidity) = match (col("dewpoint_C"), col("relative_humidity_pct")) {
            (Some(c), _) => (c, Humidity::DewpointC),
            (None, Some(c)) => (c, Humidity::RelativeHumidityPct),
            (None, None) => return Err(missing("dewpoint_C")),
        };
        Ok(Self {
            height,
            pressure,
            temperature,
            humidity_column,
            humidity,
            header_line,
        })
    }

    /// One data row, on `line`, its values in range.
    fn row(
        &self,
        record: &csv::StringRecord,
        line: u64,
        err: &LineError,
    ) -> Result<Row, SoundingError> {
        let field = |c: usize, name: &str| -> Result<Option<f64>, SoundingError> {
            let s = record.get(c).unwrap_or("");
            if s.is_empty() {
                return Ok(None);
            }
            // An unclosed quote runs to the file's end: say so, not all
            // the lines it took in.
            if s.contains(['\n', '\r']) {
                return Err(err(
                    line,
                    format!(
                        "`{name}` is a quoted field that runs past its line \
                         (a `\"` not closed?), expected a number"
                    ),
                ));
            }
            let v: f64 = s
                .parse()
                .map_err(|_| err(line, format!("`{name}` is `{s}`, expected a number")))?;
            if !v.is_finite() {
                return Err(err(
                    line,
                    format!("`{name}` is `{s}`, expected a finite number"),
                ));
            }
            Ok(Some(v))
        };
        let required = |c: usize, name: &str| -> Result<f64, SoundingError> {
            field(c, name)?.ok_or_else(|| err(line, format!("`{name}` is empty")))
        };
        let h = required(self.height, "height_m")?;
        let p = field(self.pressure, "pressure_hPa")?;
        let t = required(self.temperature, "temperature_C")?;
        let hum = required(self.humidity_column, self.humidity.column())?;
        if !(0.0..=HEIGHT_MAX_M).contains(&h) {
            return Err(err(
                line,
                format!(
                    "`height_m` is {}, expected 0..={HEIGHT_MAX_M} m (height above ground)",
                    number(h)
                ),
            ));
        }
        if let Some(p) = p
            && !(1.0..=1200.0).contains(&p)
        {
            return Err(err(
                line,
                format!("`pressure_hPa` is {}, expected 1..=1200", number(p)),
            ));
        }
        if !(-120.0..=70.0).contains(&t) {
            return Err(err(
                line,
                format!("`temperature_C` is {}, expected -120..=70", number(t)),
            ));
        }
        match self.humidity {
            Humidity::DewpointC
                if hum < -150.0
                    || (hum > t + DEWPOINT_EXCESS_MAX_K && dewpoint_humidity(hum, t) > RH_MAX) =>
            {
                return Err(err(
                    line,
                    format!(
                        "`dewpoint_C` is {}, expected -150 or more, and at most \
                         {DEWPOINT_EXCESS_MAX_K} K above `temperature_C` {t} or \
                         {:.0} % relative humidity (it gives {:.0} %)",
                        number(hum),
                        RH_MAX * 100.0,
                        dewpoint_humidity(hum, t) * 100.0
                    ),
                ));
            }
            Humidity::RelativeHumidityPct if !(0.0..=RH_MAX * 100.0).contains(&hum) => {
                return Err(err(
                    line,
                    format!(
                        "`relative_humidity_pct` is {}, expected 0..={:.0}",
                        number(hum),
                        RH_MAX * 100.0
                    ),
                ));
            }
            _ => {}
        }
        Ok(Row { line, h, p, t, hum })
    }
}

/// One row of a CSV sounding as written: height (m), pressure (hPa, if
/// given), temperature (°C), dewpoint (°C) or relative humidity (%).
struct Row {
    line: u64,
    h: f64,
    p: Option<f64>,
    t: f64,
    hum: f64,
}

impl Row {
    /// The row lies above `prev`: higher, and at a lower pressure where
    /// both give one.
    fn check_above(&self, prev: &Row, err: &LineError) -> Result<(), SoundingError> {
        let (h, line) = (self.h, self.line);
        if h <= prev.h {
            return Err(err(
                line,
                format!(
                    "`height_m` is {h}, not above the previous row's {} (line {}): rows must be sorted by strictly increasing height",
                    prev.h, prev.line
                ),
            ));
        }
        if let (Some(p), Some(pp)) = (self.p, prev.p)
            && p >= pp
        {
            return Err(err(
                line,
                format!(
                    "`pressure_hPa` is {p}, not below the previous row's {pp}: pressure must fall with height"
                ),
            ));
        }
        Ok(())
    }
}

/// The levels of `rows` (at least 2) in SI units, each missing pressure
/// filled by hydrostatic integration from the nearest level below with
/// one (the lowest levels from the nearest above; from
/// `surface_pressure_pa` at the ground when no row has one).
fn levels(rows: &[Row], humidity: Humidity, surface_pressure_pa: f64) -> Vec<Level> {
    let mut p_pa: Vec<Option<f64>> = rows.iter().map(|r| r.p.map(|p| p * 100.0)).collect();
    let t_k: Vec<f64> = rows.iter().map(|r| r.t + ZERO_CELSIUS_K).collect();
    if p_pa.iter().all(Option::is_none) {
        p_pa[0] = Some(surface_pressure_pa);
    }
    let first = p_pa.iter().position(Option::is_some).unwrap_or(0);
    // Mixing ratio needs pressure; virtual temperature needs mixing
    // ratio; integrate level to level with 1 m sub-steps.
    let mixing = |i: usize, p: f64| -> f64 {
        match humidity {
            Humidity::DewpointC => mixing_ratio_from_dewpoint(rows[i].hum + ZERO_CELSIUS_K, p),
            Humidity::RelativeHumidityPct => {
                rows[i].hum / 100.0 * saturation_mixing_ratio(t_k[i], p)
            }
        }
    };
    let integrate = |from: usize, to: usize, p_from: f64| -> f64 {
        let (a, b) = (from, to);
        let dz_total = rows[b].h - rows[a].h;
        let steps = (dz_total.abs().ceil() as usize).max(1);
        let dz = dz_total / steps as f64;
        let mut ln_p = p_from.ln();
        let qa = mixing(a, p_from);
        let qb_guess = mixing(b, p_from);
        for s in 0..steps {
            let f0 = s as f64 / steps as f64;
            let f1 = (s + 1) as f64 / steps as f64;
            let tv = |f: f64| {
                let t = t_k[a] + f * (t_k[b] - t_k[a]);
                let q = qa + f * (qb_guess - qa);
                t * (1.0 + 0.608 * q)
            };
            ln_p -= G * dz * 0.5 * (1.0 / tv(f0) + 1.0 / tv(f1)) / R_D;
        }
        ln_p.exp()
    };
    for i in (0..first).rev() {
        let p_above = p_pa[i + 1].unwrap_or(surface_pressure_pa);
        p_pa[i] = Some(integrate(i + 1, i, p_above));
    }
    for i in first + 1..rows.len() {
        if p_pa[i].is_none() {
            let p_below = p_pa[i - 1].unwrap_or(surface_pressure_pa);
            p_pa[i] = Some(integrate(i - 1, i, p_below));
        }
    }
    rows.iter()
        .enumerate()
        .map(|(i, r)| {
            let p = p_pa[i].unwrap_or(surface_pressure_pa);
            Level {
                height_m: r.h,
                pressure_pa: Some(p),
                temperature_k: t_k[i],
                mixing_ratio: mixing(i, p).max(0.0),
            }
        })
        .collect()
}

impl Sounding {
    /// Reads and validates a sounding file. `surface_pressure_pa` anchors the
    /// hydrostatic integration when no row gives a pressure.
    pub fn load(path: &Path, surface_pressure_pa: f64) -> Result<Self, SoundingError> {
        let text = std::fs::read_to_string(path).map_err(|err| SoundingError::Io {
            path: path.to_owned(),
            err,
        })?;
        Self::parse(&text, path, surface_pressure_pa)
    }

    /// Parses sounding text in any of the [`Format`]s (recognised by
    /// content); `path` is only used in messages, whose line numbers are
    /// those of `text`.
    pub fn parse(text: &str, path: &Path, surface_pressure_pa: f64) -> Result<Self, SoundingError> {
        let converted = match detect(text) {
            Format::Csv => None,
            Format::Wyoming => Some(wyoming_to_csv(text)),
            Format::Sharppy => Some(sharppy_to_csv(text)),
            Format::Igra2 => Some(igra2_to_csv(text)),
        };
        match converted {
            None => Self::parse_csv(text, path, surface_pressure_pa),
            Some(Ok(csv)) => Self::parse_csv(&csv, path, surface_pressure_pa),
            Some(Err((line, message))) => Err(SoundingError::Invalid {
                path: path.to_owned(),
                line,
                message,
            }),
        }
    }

    /// Parses our CSV: the header's columns ([`Columns::read`]), each row
    /// read and checked against its ranges and the row before, then the
    /// missing pressures filled ([`levels`]).
    fn parse_csv(text: &str, path: &Path, surface_pressure_pa: f64) -> Result<Self, SoundingError> {
        let err = |line: u64, message: String| SoundingError::Invalid {
            path: path.to_owned(),
            line,
            message,
        };
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let columns = Columns::read(&mut reader, text, &err)?;
        let mut rows: Vec<Row> = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|e| {
                let line = csv_line(text, e.position());
                err(line, format!("malformed row: {}", csv_reason(&e)))
            })?;
            let row = columns.row(&record, csv_line(text, record.position()), &err)?;
            if let Some(prev) = rows.last() {
                row.check_above(prev, &err)?;
            }
            rows.push(row);
        }
        if rows.len() < 2 {
            return Err(err(
                columns.header_line,
                format!("{} data rows, expected at least 2 levels", rows.len()),
            ));
        }
        Ok(Self {
            levels: levels(&rows, columns.humidity, surface_pressure_pa),
            source: path.to_owned(),
        })
    }

    /// An analytic deep tropical column of `n` levels (>= 2) from 0 to
    /// 16 km, for benchmarks and tests: T = 27 °C - 6.5 K/km up to 11 km,
    /// then isothermal; dewpoint depression 2 K + 1.5 K/km; 1010 hPa at the
    /// ground, pressures filled hydrostatically
    /// (`benches/metpy_profile_timing.py` builds the same one).
    pub fn analytic_tropical(n: usize) -> Self {
        let n = n.max(2);
        let mut text = String::from("height_m,pressure_hPa,temperature_C,dewpoint_C\n");
        for i in 0..n {
            let z = 16_000.0 * i as f64 / (n - 1) as f64;
            let t = 27.0 - 6.5e-3 * z.min(11_000.0);
            let td = t - 2.0 - 1.5e-3 * z;
            let p = if i == 0 { "1010" } else { "" };
            text.push_str(&format!("{z:.3},{p},{t:.4},{td:.4}\n"));
        }
        Self::parse(&text, Path::new("analytic_tropical.csv"), 101_000.0)
            .expect("the analytic column is a valid sounding")
    }

    /// The levels, lowest first.
    pub fn levels(&self) -> &[Level] {
        &self.levels
    }

    /// The file this sounding came from.
    pub fn source(&self) -> &Path {
        &self.source
    }

    /// The lowest level above 200 m from which temperature does not fall
    /// with height (a temperature inversion), if there is one below 6 km.
    pub fn inversion_base_m(&self) -> Option<f64> {
        self.levels
            .windows(2)
            .find(|w| {
                w[0].height_m >= 200.0
                    && w[0].height_m < 6000.0
                    && w[1].temperature_k >= w[0].temperature_k
            })
            .map(|w| w[0].height_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Sounding, SoundingError> {
        Sounding::parse(text, Path::new("s.csv"), 101_325.0)
    }

    #[test]
    fn empty_pressure_is_filled_hydrostatically() {
        let s = parse(
            "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,10\n1000,,13.5,5\n2000,,7,0\n",
        )
        .expect("valid");
        let p1 = s.levels()[1].pressure_pa.expect("filled");
        // Scale height ~ 8.4 km at 290 K: p(1 km) ≈ 887 hPa.
        assert!((p1 / 100.0 - 887.5).abs() < 2.0, "{p1}");
        let p2 = s.levels()[2].pressure_pa.expect("filled");
        assert!(p2 < p1);
    }

    #[test]
    fn unsorted_rows_name_the_line() {
        let e = parse("height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,10\n500,950,17,9\n400,960,18,9\n")
            .expect_err("unsorted");
        let msg = e.to_string();
        assert!(msg.starts_with("s.csv:4:"), "{msg}");
        assert!(msg.contains("strictly increasing height"), "{msg}");
    }

    #[test]
    fn non_numeric_field_names_column_and_line() {
        let e =
            parse("height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,warm,10\n10,999,20,10\n")
                .expect_err("non-numeric");
        let msg = e.to_string();
        assert!(
            msg.contains("s.csv:2:") && msg.contains("temperature_C"),
            "{msg}"
        );
    }

    #[test]
    fn supersaturation_beyond_a_fifth_is_refused_as_the_parametric_profile_does() {
        let h = "height_m,pressure_hPa,temperature_C,";
        // A dewpoint 5 K above the temperature (136 % at 25 °C), and 150 %.
        let e = parse(&format!("{h}dewpoint_C\n0,1000,25,30\n500,950,20,15\n"))
            .expect_err("supersaturated");
        let msg = e.to_string();
        assert!(msg.starts_with("s.csv:2: `dewpoint_C` is 30"), "{msg}");
        assert!(
            msg.contains("120 % relative humidity") && msg.contains("gives 13"),
            "{msg}"
        );
        let e = parse(&format!(
            "{h}relative_humidity_pct\n0,1000,25,150\n500,950,20,50\n"
        ))
        .expect_err("supersaturated");
        assert!(e.to_string().contains("expected 0..=120"), "{e}");
        // A little supersaturation, as radiosondes report in cloud, loads.
        parse(&format!("{h}dewpoint_C\n0,1000,20,21\n500,950,17,9\n")).expect("106 %");
        // A dewpoint 2 K above a -60 °C temperature (over 120 % there).
        parse(&format!("{h}dewpoint_C\n0,1000,20,10\n9000,300,-60,-58\n")).expect("cold air");
        parse(&format!(
            "{h}relative_humidity_pct\n0,1000,20,110\n500,950,17,9\n"
        ))
        .expect("110 %");
    }

    #[test]
    fn nan_is_rejected() {
        let e =
            parse("height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,NaN,10\n10,999,20,10\n")
                .expect_err("nan");
        assert!(e.to_string().contains("finite"), "{e}");
    }

    #[test]
    fn missing_column_is_named() {
        let e = parse("height_m,temperature_C,dewpoint_C\n0,20,10\n").expect_err("missing");
        assert!(e.to_string().contains("pressure_hPa"), "{e}");
    }
}
