//! Soundings as meteorologists download them, read into the CSV that
//! [`super::Sounding::parse`] reads: the University of Wyoming text listing
//! (`TEXT:LIST`) and SHARPpy's `%RAW%` files. Each line of the original
//! becomes one line of the CSV (a data row, or a `#` comment for headers,
//! missing levels and trailers), so an error still names the line of the
//! original file. Heights above sea level become heights above the lowest
//! level.

/// The highest level a sounding may have, m above its lowest (in
/// every format): the scene's bound on heights
/// (`atmosphere.inversion_base_m`, the band). The pressures are filled
/// and the atmosphere's table is built metre by metre up to the top, so
/// a level at 1e15 m never finished loading.
pub(crate) const HEIGHT_MAX_M: f64 = 1e5;

/// A format of sounding file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// `height_m,pressure_hPa,temperature_C,dewpoint_C` (ours).
    Csv,
    /// University of Wyoming `TEXT:LIST`: fixed columns of 7 characters,
    /// `PRES HGHT TEMP DWPT ...` in hPa, m above sea level, °C, °C.
    Wyoming,
    /// SHARPpy: `%RAW%` ... `%END%`, comma-separated `LEVEL, HGHT, TEMP,
    /// DWPT, WDIR, WSPD` in hPa, m above sea level, °C, °C; -9999 missing.
    Sharppy,
    /// IGRA2 sounding data: a `#` header record (`#` and an 11-character
    /// station id, then the year), then fixed-column levels: pressure (Pa,
    /// columns 10-15), geopotential height (m, 17-21), temperature (0.1 °C,
    /// 23-27), dewpoint depression (0.1 °C, 35-39); -9999 and -8888 missing.
    /// The first sounding of a file is read.
    Igra2,
}

/// The format of sounding text, from its content.
pub fn detect(text: &str) -> Format {
    if text.lines().any(|l| l.trim() == "%RAW%") {
        Format::Sharppy
    } else if text.lines().any(is_wyoming_header) {
        Format::Wyoming
    } else if text.lines().next().is_some_and(is_igra2_header) {
        Format::Igra2
    } else {
        Format::Csv
    }
}

fn is_wyoming_header(line: &str) -> bool {
    let w: Vec<&str> = line.split_whitespace().collect();
    w.len() >= 4 && w[..4] == ["PRES", "HGHT", "TEMP", "DWPT"]
}

fn is_igra2_header(line: &str) -> bool {
    let b = line.as_bytes();
    b.len() >= 17
        && b[0] == b'#'
        && b[1..12].iter().all(|c| c.is_ascii_alphanumeric())
        && b[12] == b' '
        && b[13..17].iter().all(u8::is_ascii_digit)
}

const HEADER: &str = "height_m,pressure_hPa,temperature_C,dewpoint_C";

/// A line that cannot be read, with its 1-based number and what is wrong.
pub type LineError = (u64, String);

/// The rows of `(pressure_hPa, height_m_asl, temperature_C, dewpoint_C)`
/// per line of the original (`None`: not a level) as our CSV, heights above
/// the lowest level; `height` names the original's height column in errors.
fn to_csv(lines: &[Option<[f64; 4]>], height: &str) -> Result<String, LineError> {
    let ground = lines.iter().flatten().map(|r| r[1]).next();
    let Some(ground) = ground else {
        return Err((
            1,
            "no levels with pressure, height, temperature and dewpoint".into(),
        ));
    };
    if lines.first().is_some_and(Option::is_some) {
        return Err((
            1,
            "the first line is a level; expected a title or header".into(),
        ));
    }
    let mut out = String::with_capacity(lines.len() * 40);
    let mut below: Option<(f64, usize)> = None;
    for (k, l) in lines.iter().enumerate() {
        match (k, l) {
            (0, _) => out.push_str(HEADER),
            (_, Some([p, h, t, td])) => {
                // Said here in the original's own terms: the CSV reader
                // would blame `height_m` for a height the file never had
                // (this level's less the lowest one's).
                if let Some((h0, k0)) = below
                    && *h <= h0
                {
                    return Err((
                        k as u64 + 1,
                        format!(
                            "{height} is {h} m, not above the previous level's {h0} m (line {}): \
                             levels must rise",
                            k0 + 1
                        ),
                    ));
                }
                if *h - ground > HEIGHT_MAX_M {
                    return Err((
                        k as u64 + 1,
                        format!(
                            "{height} is {} m, {} m above the lowest level's {ground} m; \
                             expected at most {HEIGHT_MAX_M} m above it",
                            super::check::number(*h),
                            super::check::number(*h - ground)
                        ),
                    ));
                }
                below = Some((*h, k));
                out.push_str(&format!("{},{p},{t},{td}", h - ground));
            }
            (_, None) => out.push('#'),
        }
        out.push('\n');
    }
    Ok(out)
}

/// A number, or `None` for a blank field or a missing-value code.
fn number(s: &str, line: u64, what: &str) -> Result<Option<f64>, LineError> {
    let s = s.trim();
    if s.is_empty() {
        return Ok(None);
    }
    let v: f64 = s
        .parse()
        .map_err(|_| (line, format!("`{what}` is `{s}`, expected a number")))?;
    if !v.is_finite() {
        return Err((line, format!("`{what}` is `{s}`, expected a finite number")));
    }
    Ok((v > -9998.0).then_some(v))
}

/// The University of Wyoming `TEXT:LIST` listing as our CSV. Levels with a
/// blank temperature or dewpoint (the upper air often has none) are left
/// out; the table ends at the first line that is not a level ("Station
/// information and sounding indices").
pub fn wyoming_to_csv(text: &str) -> Result<String, LineError> {
    let all: Vec<&str> = text.lines().collect();
    let Some(header) = all.iter().position(|l| is_wyoming_header(l)) else {
        return Err((1, "no `PRES HGHT TEMP DWPT` header".into()));
    };
    let mut rows: Vec<Option<[f64; 4]>> = vec![None; all.len()];
    let mut in_table = false;
    for (k, l) in all.iter().enumerate().skip(header + 1) {
        let line = k as u64 + 1;
        if l.trim_start().starts_with('-') {
            in_table = true;
            continue;
        }
        if !in_table {
            continue;
        }
        let field = |i: usize| l.get(7 * i..(7 * i + 7).min(l.len())).unwrap_or("");
        // The table ends where the pressure column stops being a number.
        if field(0).trim().parse::<f64>().is_err() {
            break;
        }
        let [p, h, t, td] = [
            number(field(0), line, "PRES")?,
            number(field(1), line, "HGHT")?,
            number(field(2), line, "TEMP")?,
            number(field(3), line, "DWPT")?,
        ];
        if let (Some(p), Some(h), Some(t), Some(td)) = (p, h, t, td) {
            rows[k] = Some([p, h, t, td]);
        }
    }
    to_csv(&rows, "HGHT")
}

/// A SHARPpy `%RAW%` file as our CSV. Levels with a missing (-9999)
/// pressure, height, temperature or dewpoint are left out.
pub fn sharppy_to_csv(text: &str) -> Result<String, LineError> {
    let all: Vec<&str> = text.lines().collect();
    let mut rows: Vec<Option<[f64; 4]>> = vec![None; all.len()];
    let mut in_raw = false;
    for (k, l) in all.iter().enumerate() {
        let line = k as u64 + 1;
        match l.trim() {
            "%RAW%" => in_raw = true,
            "%END%" => in_raw = false,
            "" => {}
            t if in_raw => {
                let f: Vec<&str> = t.split(',').collect();
                if f.len() < 4 {
                    return Err((
                        line,
                        format!(
                            "{} fields, expected LEVEL, HGHT, TEMP, DWPT[, WDIR, WSPD]",
                            f.len()
                        ),
                    ));
                }
                let [p, h, t, td] = [
                    number(f[0], line, "LEVEL")?,
                    number(f[1], line, "HGHT")?,
                    number(f[2], line, "TEMP")?,
                    number(f[3], line, "DWPT")?,
                ];
                if let (Some(p), Some(h), Some(t), Some(td)) = (p, h, t, td) {
                    rows[k] = Some([p, h, t, td]);
                }
            }
            _ => {}
        }
    }
    to_csv(&rows, "HGHT")
}

/// The first sounding of an IGRA2 sounding-data file as our CSV. Levels
/// without pressure, height, temperature or dewpoint depression are left
/// out; the next `#` header record ends the sounding.
pub fn igra2_to_csv(text: &str) -> Result<String, LineError> {
    let all: Vec<&str> = text.lines().collect();
    let mut rows: Vec<Option<[f64; 4]>> = vec![None; all.len()];
    for (k, l) in all.iter().enumerate().skip(1) {
        let line = k as u64 + 1;
        if l.starts_with('#') {
            break;
        }
        if l.trim().is_empty() {
            continue;
        }
        // Columns are 1-based and inclusive in the format's description.
        let col = |a: usize, b: usize| l.get(a - 1..b.min(l.len())).unwrap_or("");
        let code = |s: &str, what: &str| -> Result<Option<f64>, LineError> {
            let v = number(s, line, what)?;
            Ok(v.filter(|&v| v > -8887.0))
        };
        let p = code(col(10, 15), "PRESS")?;
        let z = code(col(17, 21), "GPH")?;
        let t = code(col(23, 27), "TEMP")?;
        let dpd = code(col(35, 39), "DPDP")?;
        if let (Some(p), Some(z), Some(t), Some(dpd)) = (p, z, t, dpd) {
            rows[k] = Some([p / 100.0, z, t / 10.0, (t - dpd) / 10.0]);
        }
    }
    to_csv(&rows, "GPH")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wyoming_columns_and_blanks() {
        let t = "Title line\n\
-----------------------------------------------------------------------------\n\
   PRES   HGHT   TEMP   DWPT   RELH   MIXR   DRCT   SKNT   THTA   THTE   THTV\n\
    hPa     m      C      C      %    g/kg    deg   knot     K      K      K \n\
-----------------------------------------------------------------------------\n\
 1012.0      2   27.2   23.2     79  18.07    110     10  299.3  351.7  302.6\n\
 1000.0    108   26.4   22.4     79  17.32    115     12  299.5  349.9  302.6\n\
  100.0  16580  -75.1                                                        \n\
Station information and sounding indices\n";
        assert_eq!(detect(t), Format::Wyoming);
        let csv = wyoming_to_csv(t).expect("reads");
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 9);
        assert_eq!(lines[0], HEADER);
        assert_eq!(lines[5], "0,1012,27.2,23.2");
        assert_eq!(lines[6], "106,1000,26.4,22.4");
        assert_eq!(lines[7], "#");
    }

    #[test]
    fn levels_out_of_order_are_named_in_the_originals_terms() {
        let t = "%TITLE%\n KEY\n%RAW%\n 1000.00, 500.00, 26, 22.37, 90, 5\n 1015, 5, 25, 20, 90, 5\n%END%\n";
        let (line, why) = sharppy_to_csv(t).expect_err("falling levels");
        assert_eq!(line, 5, "{why}");
        assert!(
            why.contains("HGHT is 5 m") && why.contains("500 m (line 4)"),
            "{why}"
        );
        assert!(!why.contains("height_m"), "{why}");
    }

    #[test]
    fn sharppy_rows_and_a_bad_line() {
        let t = "%TITLE%\n KEY 240601/1200\n\n   LEVEL       HGHT       TEMP       DWPT       WDIR       WSPD\n-------------------------------------------------------------------\n%RAW%\n1012.00, 2.00, 27.20, 23.20, 110.00, 10.00\n1000.00, 108.00, 26.40, -9999.00, 115.00, 12.00\n%END%\n";
        assert_eq!(detect(t), Format::Sharppy);
        let csv = sharppy_to_csv(t).expect("reads");
        assert_eq!(csv.lines().nth(6), Some("0,1012,27.2,23.2"));
        assert_eq!(csv.lines().nth(7), Some("#"));
        let bad = t.replace("26.40", "warm");
        assert_eq!(sharppy_to_csv(&bad).unwrap_err().0, 8);
    }
}
