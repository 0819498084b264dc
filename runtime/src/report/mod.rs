//! Renderings of typed results, the one place where results become text: JSON (documented in
//! docs/results.md), CSV and text summaries of a [`Prs`](reachc_core::Prs)
//! ([`result`]) and of a Monte Carlo [`SimReport`](reachc_core::simulate::SimReport)
//! ([`simulation`]), written through the types of their JSON documents ([`schema`], which the
//! plots read back).

pub mod probability;
pub mod result;
pub mod schema;
pub mod simulation;
pub mod tightening;

pub use reachc_core::decimal::time;
pub use result::{summary, to_json, to_json_with, to_json_within, write_csv, MEMBERS_BUDGET};

/// `n` and the noun, singular or plural: `1 thread`, `4 threads`.
pub fn count(n: u64, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// A number for a summary: 6 decimals, or scientific notation where that would be long.
fn num(v: f64) -> String {
    if v.is_finite() && v.abs() >= 1e6 {
        format!("{v:.6e}")
    } else {
        format!("{v:.6}")
    }
}

/// About ten evenly spaced step indices, always including the first and the last.
fn summary_indices(len: usize) -> Vec<usize> {
    if len == 0 {
        return Vec::new();
    }
    let last = len - 1;
    let mut idx: Vec<usize> = (0..10).map(|k| k * last / 10).collect();
    idx.push(last);
    idx.dedup();
    idx
}

/// Quotes a CSV field when it needs it (state names are identifiers, possibly `x[3]`).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
