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
            value: shortest(value),
        }
    }

    /// A check that `value` is finite and in `lo..=hi`.
    pub fn range(
        key: impl Into<Cow<'static, str>>,
        value: f64,
        lo: f64,
        hi: f64,
        expected: &'static str,
    ) -> Self {
        Self::new(key, finite_in(value, lo, hi), expected, value)
    }
}

/// `value` as the user wrote it: a value read into an `f32` field and
/// widened (every f32 is an f64) printed as the f32 it is, `-89.9` and
/// not `-89.9000015258789`; any other as the f64.
fn shortest(value: f64) -> String {
    let narrow = value as f32;
    if f64::from(narrow) == value {
        narrow.to_string()
    } else {
        value.to_string()
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
    fn values_read_as_f32_are_reported_as_written() {
        // A scene's camera_pitch_deg is an f32; the error once said
        // "is -89.9000015258789".
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
        assert_eq!(Check::new("k", true, "", 1e300).value, 1e300.to_string());
    }
}
