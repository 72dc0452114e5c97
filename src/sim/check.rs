//! [`Check`]: one configuration value against its domain. Each
//! configuration section lists its own checks next to its field docs;
//! the scene reports the first that fails, with the key's file and line.

use std::borrow::Cow;

/// One key's value against its domain.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// The dotted key, e.g. `physics.sph.sound_speed_mps`.
    pub key: Cow<'static, str>,
    pub ok: bool,
    /// The domain, as the error message states it.
    pub expected: Cow<'static, str>,
    /// The value, as the error message states it.
    pub value: String,
}

impl Check {
    /// A check of `value` that passes when `ok`.
    pub fn new(
        key: impl Into<Cow<'static, str>>,
        ok: bool,
        expected: impl Into<Cow<'static, str>>,
        value: f64,
    ) -> Self {
        Self {
            key: key.into(),
            ok,
            expected: expected.into(),
            value: number(value),
        }
    }

    /// A check that `value` is finite and in `lo..=hi`. A value read
    /// into an `f32` field (and widened) is held against the bounds as
    /// `f32`s: `1e-6` written for a bound of `1e-6` reads as the f32
    /// nearest it, 9.99999997e-7, which the f64 bound would refuse.
    pub fn range(
        key: impl Into<Cow<'static, str>>,
        value: f64,
        lo: f64,
        hi: f64,
        expected: &'static str,
    ) -> Self {
        let (lo, hi) = if f64::from(value as f32) == value {
            (f64::from(lo as f32), f64::from(hi as f32))
        } else {
            (lo, hi)
        };
        Self::new(key, finite_in(value, lo, hi), expected, value)
    }
}

/// `value` as the user wrote it, for a message: a value read into an
/// `f32` field and widened (every f32 is an f64) printed as the f32 it
/// is, `-89.9` and not `-89.9000015258789`; any other as the f64; in
/// scientific notation (`1e308`) from 1e15 up or below 1e-5, where the
/// plain form runs to hundreds of digits.
pub fn number(value: f64) -> String {
    let narrow = value as f32;
    let scientific = value.is_finite() && value != 0.0 && !(1e-5..1e15).contains(&value.abs());
    match (f64::from(narrow) == value, scientific) {
        (true, false) => narrow.to_string(),
        (true, true) => format!("{narrow:e}"),
        (false, false) => value.to_string(),
        (false, true) => format!("{value:e}"),
    }
}

/// Whether `v` is finite and in `lo..=hi`.
pub fn finite_in(v: f64, lo: f64, hi: f64) -> bool {
    v.is_finite() && v >= lo && v <= hi
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_f32_value_written_as_its_bound_is_within_it() {
        // `render.extinction_per_m = 1e-6` is read into an f32 just under
        // the f64 bound, and must not be refused as "is 0.000001,
        // expected 1e-6..=10".
        for (v, lo, hi) in [(1e-6_f32, 1e-6, 10.0), (0.1, 0.1, 1.0), (0.3, 0.0, 0.3)] {
            let c = Check::range("k", f64::from(v), lo, hi, "");
            assert!(c.ok, "{v} in {lo}..={hi}");
        }
        // Just outside stays outside.
        assert!(!Check::range("k", f64::from(0.99e-6_f32), 1e-6, 10.0, "").ok);
        assert!(!Check::range("k", f64::from(0.30001_f32), 0.0, 0.3, "").ok);
        // An f64 value keeps the f64 bounds.
        assert!(!Check::range("k", 0.999_999_999_9e-6, 1e-6, 10.0, "").ok);
    }

    #[test]
    fn values_read_as_f32_are_reported_as_written() {
        // A scene's camera_pitch_deg is an f32; the error says -89.9,
        // not "is -89.9000015258789".
        let c = Check::range(
            "render.camera_pitch_deg",
            f64::from(-89.9_f32),
            -89.0,
            89.0,
            "-89..=89",
        );
        assert!(!c.ok);
        assert_eq!(c.value, "-89.9");
        assert_eq!(Check::new("k", true, "", 0.1).value, "0.1");
        assert_eq!(Check::new("k", true, "", 12.0).value, "12");
        assert_eq!(Check::new("k", true, "", f64::NAN).value, "NaN");
        assert_eq!(Check::new("k", true, "", 1e300).value, "1e300");
        assert_eq!(Check::new("k", true, "", -1e308).value, "-1e308");
        assert_eq!(Check::new("k", true, "", 2.5e-9).value, "2.5e-9");
        assert_eq!(Check::new("k", true, "", 123456.0).value, "123456");
    }
}
