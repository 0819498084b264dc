//! The Euler-Maruyama step of a simulation, chosen from the dynamics (method.md, "The
//! Euler-Maruyama step").
//!
//! Euler-Maruyama's error per step grows like `h L`, `L` a bound of the drift's Jacobian: on a
//! fast mode `x' = -L x` one step multiplies by `1 - h L` where the flow multiplies by
//! `e^(-h L)`. A step fine for the report grid can then be far too coarse for the model, and
//! the Monte Carlo check would test the integrator, not the PRS. So each report interval `k`
//! gets its own step: `L_k = min(||J||_inf, ||J||_1)` of the enclosure `J` of `D_x f` over the
//! analysis' own set on that interval (the span's bounding box, inside the domain when the spec
//! has one), the input box and the interval's times; then `h_k L_k <= RULE`, `h_k` at most the
//! report step, and at most [`MAX_STEPS`] steps per report interval. A `--dt` is honoured as
//! given; [`DtUsed`] records how every step compares with the rule.

use crate::interval::Interval;
use crate::model::ModelInfo;
use crate::prs::Prs;
use crate::system::System;

/// The rule's bound on `h L_k`: Euler-Maruyama's relative error on the fastest mode per step.
pub const RULE: f64 = 0.05;

/// Most Euler-Maruyama steps the rule takes per report interval (a `--dt` is not capped).
pub const MAX_STEPS: u32 = 100;

/// Where the steps came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DtSource {
    /// The rule (no `--dt`).
    Rule,
    /// The `--dt` option.
    Option,
}

impl DtSource {
    /// `rule` or `option`.
    pub fn name(self) -> &'static str {
        match self {
            DtSource::Rule => "rule",
            DtSource::Option => "option",
        }
    }
}

/// The Euler-Maruyama steps of a simulation and how they compare with the rule
/// `h_k L_k <=` [`RULE`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DtUsed {
    /// Where the steps came from.
    pub source: DtSource,
    /// The smallest step used (over the report intervals).
    pub min: f64,
    /// The largest step used.
    pub max: f64,
    /// The smallest step the rule asks for over the report intervals, before the cap of
    /// [`MAX_STEPS`] (0 where `L_k` is not finite).
    pub rule_min: f64,
    /// The largest `h_k L_k` over the report intervals (`inf` where `L_k` is not finite).
    pub hl_max: f64,
    /// The report intervals whose step is coarser than the rule asks: with the rule, where the
    /// cap of [`MAX_STEPS`] binds; with `--dt`, where the option is coarser.
    pub coarse: u64,
}

impl DtUsed {
    /// Whether every step meets the rule.
    pub fn meets_rule(&self) -> bool {
        self.coarse == 0
    }
}

/// `min(||J||_inf, ||J||_1)` of the `n x n` row-major interval matrix `j`, from the entries'
/// magnitudes: a bound of `||A||_2`, hence of every eigenvalue's modulus, for every `A` in `j`
/// (`inf` if an entry is unbounded or not a number).
fn norm_bound(j: &[Interval], n: usize) -> f64 {
    let mag = |i: usize, c: usize| {
        let m = j[i * n + c].mag();
        if m.is_finite() {
            m
        } else {
            f64::INFINITY
        }
    };
    let rows = (0..n)
        .map(|i| (0..n).map(|c| mag(i, c)).sum::<f64>())
        .fold(0.0, f64::max);
    let cols = (0..n)
        .map(|c| (0..n).map(|i| mag(i, c)).sum::<f64>())
        .fold(0.0, f64::max);
    rows.min(cols)
}

/// The rule's step on a report interval of width `w` whose Jacobian bound is `l`:
/// `min(w, RULE / l)` (0 when `l` is not finite).
fn rule_step(w: f64, l: f64) -> f64 {
    if !l.is_finite() {
        0.0
    } else if l * w <= RULE {
        w
    } else {
        RULE / l
    }
}

/// Equal steps of at most `h` over a width `w` (the slack keeps a step of exactly `h`, up to
/// rounding, from being split in two).
fn steps_of(w: f64, h: f64) -> f64 {
    (w / h * (1.0 - 1e-12)).ceil().max(1.0)
}

/// `L_k` on the report interval `[t0, t1]` ending at report step `k`: [`norm_bound`] of
/// `D_x f` over the bounding box of the span of `k` (intersected with the other metrics'
/// boxes and with the domain), the input box and `[t0, t1]`.
fn bound_on<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    k: usize,
    (t0, t1): (f64, f64),
) -> f64 {
    let n = sys.n();
    let hull = |r: &Prs| -> Option<Vec<Interval>> {
        r.steps.get(k)?;
        (r.n() == n).then_some(())?;
        r.own_span_hull_at(k)?
            .iter()
            .map(|b| Interval::try_new(b.lo, b.hi))
            .collect()
    };
    let Some(mut x) = hull(result) else {
        return f64::INFINITY;
    };
    let mut bounds: Vec<Vec<Interval>> = result.also.iter().filter_map(hull).collect();
    if info.has_domain {
        bounds.push(
            info.domain
                .iter()
                .map(|b| Interval::try_new(b.lo, b.hi).unwrap_or(Interval::ENTIRE))
                .collect(),
        );
    }
    for other in &bounds {
        for (xi, &oi) in x.iter_mut().zip(other) {
            // The sets all hold the paths the PRS claims; an empty meet keeps the span's box.
            *xi = xi.intersect(oi).unwrap_or(*xi);
        }
    }
    let u: Vec<Interval> = info
        .input_box
        .iter()
        .map(|b| Interval::try_new(b.lo, b.hi).unwrap_or(Interval::ENTIRE))
        .collect();
    let Some(t) = Interval::try_new(t0, t1) else {
        return f64::INFINITY;
    };
    let mut j = vec![Interval::ZERO; n * n];
    sys.jac_x_interval(&x, &u, t, &mut j);
    norm_bound(&j, n)
}

/// The number of Euler-Maruyama steps of each report interval of `times` and how they compare
/// with the rule: equal steps of at most `dt_option` when given, the rule's otherwise. An error
/// (a usage error) when `dt_option` gives more than `1e9` steps in one interval.
pub(crate) fn choose<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    times: &[f64],
    dt_option: Option<f64>,
) -> Result<(Vec<u32>, DtUsed), String> {
    let mut used = DtUsed {
        source: dt_option.map_or(DtSource::Rule, |_| DtSource::Option),
        min: f64::INFINITY,
        max: 0.0,
        rule_min: f64::INFINITY,
        hl_max: 0.0,
        coarse: 0,
    };
    let mut steps = Vec::with_capacity(times.len().saturating_sub(1));
    for (k, w) in times.windows(2).enumerate() {
        let width = w[1] - w[0];
        let l = bound_on(sys, info, result, k + 1, (w[0], w[1]));
        let rule = rule_step(width, l);
        let s = match dt_option {
            Some(dt) => steps_of(width, dt),
            None if rule > 0.0 => steps_of(width, rule).min(f64::from(MAX_STEPS)),
            None => f64::from(MAX_STEPS),
        };
        if s.is_nan() || s > 1e9 {
            return Err(format!(
                "dt = {} gives too many Euler steps",
                dt_option.unwrap_or(rule)
            ));
        }
        let h = width / s;
        let hl = if l.is_finite() { h * l } else { f64::INFINITY };
        used.min = used.min.min(h);
        used.max = used.max.max(h);
        used.rule_min = used.rule_min.min(rule);
        used.hl_max = used.hl_max.max(hl);
        // The slack of `steps_of`: a step of exactly the rule's is within it.
        used.coarse += u64::from(hl > RULE * (1.0 + 1e-9));
        steps.push(s as u32);
    }
    if steps.is_empty() {
        (used.min, used.rule_min) = (0.0, 0.0);
    }
    Ok((steps, used))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stiff example of issue 26: `x' = -20 x + y`, `y' = -y` has `||J||_inf = 21`,
    /// `||J||_1 = 20`, so `L = 20` and the rule asks for `h <= 0.05 / 20 = 0.0025`: 40 steps
    /// per report step of 0.1, where one step of 0.1 (the old default) has `h L = 2` and
    /// multiplies the fast mode by `1 - 2 = -1` instead of `e^-2 = 0.135`.
    #[test]
    fn the_rule_on_a_stiff_system() {
        let p = Interval::point;
        let j = [p(-20.0), p(1.0), p(0.0), p(-1.0)];
        assert_eq!(norm_bound(&j, 2), 20.0);
        assert_eq!(rule_step(0.1, 20.0), 0.0025);
        assert_eq!(steps_of(0.1, 0.0025), 40.0);
        // The old default, one step per report step: h L = 2, forty times the rule's bound.
        let old = 0.1 * norm_bound(&j, 2);
        assert_eq!(old, 2.0);
        assert!(old > RULE);
        // Slow dynamics: the report step itself.
        assert_eq!(rule_step(0.1, 0.5), 0.1);
        // No bound: the cap.
        assert_eq!(rule_step(0.1, f64::INFINITY), 0.0);
    }

    /// Interval entries count by magnitude; an unbounded entry gives no bound.
    #[test]
    fn norm_bound_of_intervals() {
        let j = [
            Interval::new(-3.0, 1.0),
            Interval::new(0.5, 2.0),
            Interval::point(0.0),
            Interval::new(-1.0, -0.5),
        ];
        // rows: 3 + 2 = 5, 0 + 1 = 1; columns: 3 + 0 = 3, 2 + 1 = 3.
        assert_eq!(norm_bound(&j, 2), 3.0);
        let unbounded = [Interval::ENTIRE, Interval::point(0.0)];
        assert_eq!(norm_bound(&unbounded[..1], 1), f64::INFINITY);
    }
}
