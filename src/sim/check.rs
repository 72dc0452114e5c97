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
    pub expected: &'static str,
    /// The value, as the error message states it.
    pub value: String,
}

impl Check {
    /// A check of `value` that passes when `ok`.
    pub fn new(
        key: impl Into<Cow<'static, str>>,
        ok: bool,
        expected: &'static str,
        value: f64,
    ) -> Self {
        Self {
            key: key.into(),
            ok,
            expected,
            value: value.to_string(),
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

/// Whether `v` is finite and in `lo..=hi`.
pub fn finite_in(v: f64, lo: f64, hi: f64) -> bool {
    v.is_finite() && v >= lo && v <= hi
}
