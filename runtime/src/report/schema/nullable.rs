//! Numbers that may be `null`: serde_json writes a non-finite `f64` (an infinite margin, an
//! unbounded rate, a ratio of zeros) as `null`, so a number that may be non-finite reads `null`
//! back as one. A plain number reads it as NaN (not finite, of unknown sign); the ends of a range
//! `[lo, hi]` as `-inf` and `+inf` (an unbounded side). Either way it is written again as `null`.

use serde::{Deserialize, Deserializer};

/// A number; `null` is NaN.
pub(super) fn number<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// An optional number written only where there is one (with `#[serde(default)]` for its
/// absence): `null` is `Some(NaN)`, so that it is written again.
pub(super) fn some_number<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    number(d).map(Some)
}

/// Numbers; each `null` is NaN.
pub(super) fn numbers<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    let v = Vec::<Option<f64>>::deserialize(d)?;
    Ok(v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect())
}

/// A range `[lo, hi]`; `null` is an unbounded end.
pub(super) fn range<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    <[Option<f64>; 2]>::deserialize(d).map(unbounded)
}

/// Ranges, as [`range`].
pub(super) fn ranges<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
    let v = Vec::<[Option<f64>; 2]>::deserialize(d)?;
    Ok(v.into_iter().map(unbounded).collect())
}

/// NaN: a number a file may lack (an older file).
pub(super) fn nan() -> f64 {
    f64::NAN
}

fn unbounded([lo, hi]: [Option<f64>; 2]) -> [f64; 2] {
    [lo.unwrap_or(f64::NEG_INFINITY), hi.unwrap_or(f64::INFINITY)]
}
