//! Interval bounds of expressions over the model's domain, input box and time range.

use reachc_core::interval::Interval;

use crate::ir::{ExprId, VarValues};
use crate::model::{Bounds, Model};

fn to_interval(b: Bounds) -> Interval {
    Interval::new(b.lo, b.hi)
}

/// The time range Assumption 1 must hold on: `[0, longest horizon]`, or `[0, inf)` when the
/// model has no analysis.
pub fn time_range(model: &Model) -> Interval {
    let end = model
        .analyses
        .iter()
        .map(|a| a.spec.horizon)
        .reduce(f64::max)
        .unwrap_or(f64::INFINITY);
    Interval::new(0.0, end)
}

/// Encloses `roots` over all states in the domain, inputs in their box and `t` in `time`
/// (outward-rounded interval evaluation; shared sub-expressions evaluated once).
pub fn eval_box(model: &Model, roots: &[ExprId], time: Interval) -> Vec<Interval> {
    let states: Vec<Interval> = model.domain.iter().map(|&b| to_interval(b)).collect();
    let inputs: Vec<Interval> = model.input_box.iter().map(|&b| to_interval(b)).collect();
    // Noise never appears in drift or diffusion coefficients after checking; 0 is a placeholder.
    let noises = vec![Interval::ZERO; model.noises.len()];
    let vars = VarValues {
        states: &states,
        inputs: &inputs,
        noises: &noises,
        time,
    };
    model.pool.eval(roots, &vars, &model.tables)
}

/// Encloses every entry of a matrix of expressions (see [`eval_box`]). Each distinct
/// expression is evaluated once (most entries of a large Jacobian are the same constant 0).
pub fn bound_matrix(model: &Model, matrix: &[Vec<ExprId>], time: Interval) -> Vec<Vec<Interval>> {
    let mut index: rustc_hash::FxHashMap<ExprId, usize> = Default::default();
    let mut distinct = Vec::new();
    for &e in matrix.iter().flatten() {
        index.entry(e).or_insert_with(|| {
            distinct.push(e);
            distinct.len() - 1
        });
    }
    let values = eval_box(model, &distinct, time);
    matrix
        .iter()
        .map(|row| row.iter().map(|e| values[index[e]]).collect())
        .collect()
}
