//! Times in messages, printed as the decimals they stand for.

/// A report time for messages: `k * step` as computed (e.g. `0.8999999999999999`) printed as
/// the decimal it stands for (`0.9`): 12 significant digits, trailing zeros dropped. JSON and
/// CSV keep the exact values.
pub fn time(t: f64) -> String {
    if !t.is_finite() || t == 0.0 {
        return format!("{t}");
    }
    let s = format!("{t:.11e}");
    // `{:e}` of the rounded value drops the trailing zeros of the mantissa; `{}` prints it
    // without an exponent for the usual magnitudes.
    let rounded: f64 = s.parse().unwrap_or(t);
    format!("{rounded}")
}
