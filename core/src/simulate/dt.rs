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
use crate::model::{Bounds, ModelInfo};
use crate::prs::Prs;
use crate::system::System;

/// The rule's bound on `h L_k`: Euler-Maruyama's relative error on the fastest mode per step.
pub const RULE: f64 = 0.05;

/// The accuracy rule's bound: Euler-Maruyama's bias accumulated up to the end of a report
/// interval, `(h / 2) a_k tau_k`, at most this part of the smallest half-width of the set there.
pub const ACCURACY: f64 = 0.05;

/// Most Euler-Maruyama steps the rule takes per report interval (a `--dt` is not capped).
pub const MAX_STEPS: u32 = 100;

/// Where the steps came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DtSource {
    /// The rule (no `--dt`).
    Rule,
    /// The `--dt` option.
    Option,
    /// A discrete-time model: one step per step of its map, exact.
    Map,
}

impl DtSource {
    /// `rule` or `option`.
    pub fn name(self) -> &'static str {
        match self {
            DtSource::Rule => "rule",
            DtSource::Option => "option",
            DtSource::Map => "map",
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
    /// The largest bias bound `(h_k / 2) a_k tau_k` over the report intervals, as a part of the
    /// set's smallest half-width there (the accuracy rule asks at most [`ACCURACY`]; `inf` where
    /// `a_k` is not finite).
    pub bias_max: f64,
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

/// What the rules see on one report interval: `L_k`, the bound `a_k` of `|D_x f f|_inf`, the
/// time `tau_k` over which Euler-Maruyama's bias accumulates, and the smallest half-width of
/// the set.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Scales {
    l: f64,
    a: f64,
    tau: f64,
    half: f64,
}

impl Scales {
    /// The bias bound of a step `h` as a part of the set's half-width: `(h / 2) a tau / half`.
    fn bias(&self, h: f64) -> f64 {
        if self.half.is_infinite() || self.a * self.tau == 0.0 {
            return 0.0;
        }
        let b = 0.5 * h * self.a * self.tau / self.half;
        if b.is_nan() {
            f64::INFINITY
        } else {
            b
        }
    }

    /// The rules' step on an interval of width `w`: [`rule_step`], and at most the step whose
    /// [`Scales::bias`] is [`ACCURACY`] (0 when a bound is not finite).
    fn step(&self, w: f64) -> f64 {
        let stable = rule_step(w, self.l);
        let b = self.bias(w);
        if !b.is_finite() {
            0.0
        } else if b <= ACCURACY {
            stable
        } else {
            stable.min(w * ACCURACY / b)
        }
    }
}

/// Equal steps of at most `h` over a width `w` (the slack keeps a step of exactly `h`, up to
/// rounding, from being split in two).
fn steps_of(w: f64, h: f64) -> f64 {
    (w / h * (1.0 - 1e-12)).ceil().max(1.0)
}

/// [`Scales`] on the report interval `[t0, t1]` ending at report step `k`, over the bounding
/// box `X` of the span of `k` (intersected with the other metrics' boxes and with the domain),
/// the input box and `[t0, t1]`: `L_k` [`norm_bound`] of `D_x f`; `a_k` the largest entry of
/// `D_x f f` at the centre of `X` (over the inputs and times); `tau_k = t1`, or `1 / |mu|`
/// where the Jacobian's logarithmic norm `mu` (infinity norm) is negative and that is shorter
/// (a damped bias stops growing); the smallest positive half-width of the result's bounding
/// boxes at report steps `k - 1` and `k` (of `X` where one has none).
fn bound_on<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    k: usize,
    (t0, t1): (f64, f64),
) -> Scales {
    let none = Scales {
        l: f64::INFINITY,
        a: f64::INFINITY,
        tau: t1,
        half: 0.0,
    };
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
        return none;
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
        return none;
    };
    let mut j = vec![Interval::ZERO; n * n];
    sys.jac_x_interval(&x, &u, t, &mut j);
    let finite = |v: f64| if v.is_finite() { v } else { f64::INFINITY };
    // The bias of the paths in common, at the box's centre (the spread's own error, relative
    // to the spread, is the first rule's).
    let centre: Vec<Interval> = x.iter().map(|xi| Interval::point(xi.mid())).collect();
    let (mut jc, mut f) = (vec![Interval::ZERO; n * n], vec![Interval::ZERO; n]);
    sys.jac_x_interval(&centre, &u, t, &mut jc);
    sys.drift_interval(&centre, &u, t, &mut f);
    let a = (0..n)
        .map(|i| {
            finite(
                (0..n)
                    .fold(Interval::ZERO, |s, c| s + jc[i * n + c] * f[c])
                    .mag(),
            )
        })
        .fold(0.0, f64::max);
    let mu = (0..n)
        .map(|i| {
            (0..n).fold(finite(j[i * n + i].hi()), |s, c| {
                if c == i {
                    s
                } else {
                    s + finite(j[i * n + c].mag())
                }
            })
        })
        .fold(f64::NEG_INFINITY, f64::max);
    // The set's own width at the interval's ends (the span's box also holds its motion over
    // the interval, which is no width of the set).
    let ends: Vec<Bounds> = match (result.hull_at(k - 1), result.hull_at(k)) {
        (Some(a), Some(b)) => a.into_iter().chain(b).collect(),
        _ => x.iter().map(|xi| Bounds::new(xi.lo(), xi.hi())).collect(),
    };
    let half = ends
        .iter()
        .map(|b| 0.5 * (b.hi - b.lo))
        .filter(|&h| h > 0.0)
        .fold(f64::INFINITY, f64::min);
    Scales {
        l: norm_bound(&j, n),
        a,
        tau: if mu < 0.0 { t1.min(-1.0 / mu) } else { t1 },
        half,
    }
}

/// The number of Euler-Maruyama steps of each report interval of `times` and how they compare
/// with the rule: equal steps of at most `dt_option` when given, the rule's otherwise. An error
/// (a usage error: the step, given or the rule's) when it gives more than `1e9` steps in one
/// The steps of a discrete-time model with sampling period `period` over `times` (whole
/// numbers of periods apart): one per step of its map.
fn map_steps(times: &[f64], period: f64) -> (Vec<u32>, DtUsed) {
    let steps = times
        .windows(2)
        .map(|w| {
            ((w[1] - w[0]) / period)
                .round()
                .clamp(1.0, f64::from(u32::MAX)) as u32
        })
        .collect();
    let used = DtUsed {
        source: DtSource::Map,
        min: period,
        max: period,
        rule_min: period,
        hl_max: 0.0,
        bias_max: 0.0,
        coarse: 0,
    };
    (steps, used)
}

/// interval.
pub(crate) fn choose<S: System + ?Sized>(
    sys: &S,
    info: &ModelInfo,
    result: &Prs,
    times: &[f64],
    dt_option: Option<f64>,
) -> Result<(Vec<u32>, DtUsed), f64> {
    if let Some(period) = info.time().period() {
        return Ok(map_steps(times, period));
    }
    let mut used = DtUsed {
        source: dt_option.map_or(DtSource::Rule, |_| DtSource::Option),
        min: f64::INFINITY,
        max: 0.0,
        rule_min: f64::INFINITY,
        hl_max: 0.0,
        bias_max: 0.0,
        coarse: 0,
    };
    let mut steps = Vec::with_capacity(times.len().saturating_sub(1));
    for (k, w) in times.windows(2).enumerate() {
        let width = w[1] - w[0];
        let bounds = bound_on(sys, info, result, k + 1, (w[0], w[1]));
        let (l, rule) = (bounds.l, bounds.step(width));
        let s = match dt_option {
            Some(dt) => steps_of(width, dt),
            None if rule > 0.0 => steps_of(width, rule).min(f64::from(MAX_STEPS)),
            None => f64::from(MAX_STEPS),
        };
        if s.is_nan() || s > 1e9 {
            return Err(dt_option.unwrap_or(rule));
        }
        let h = width / s;
        let hl = if l.is_finite() { h * l } else { f64::INFINITY };
        used.min = used.min.min(h);
        used.max = used.max.max(h);
        used.rule_min = used.rule_min.min(rule);
        used.hl_max = used.hl_max.max(hl);
        let bias = bounds.bias(h);
        used.bias_max = used.bias_max.max(bias);
        // The slack of `steps_of`: a step of exactly the rule's is within it.
        used.coarse += u64::from(hl > RULE * (1.0 + 1e-9) || bias > ACCURACY * (1.0 + 1e-9));
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

    /// The bias rule on `x' = 2 - x` from a box of half-width 0.01 (tests/good/drift_bias.sde):
    /// at `t = 0.1` the drift's `|D_x f f| = |-(2 - x)|` is about 1.8 and the bias of a step
    /// `h` over `tau = 0.1` is `(h / 2) 1.8 0.1 / 0.01 = 9 h`, so the rule asks
    /// `h <= 0.05 / 9`, where the stability rule alone (`L = 1`) takes the report step 0.1.
    #[test]
    fn the_bias_rule_on_a_small_set_moving_fast() {
        let s = Scales {
            l: 1.0,
            a: 1.8,
            tau: 0.1,
            half: 0.01,
        };
        assert_eq!(rule_step(0.1, s.l), 0.05);
        assert!((s.bias(0.1) - 0.9).abs() < 1e-12);
        let h = s.step(0.1);
        assert!((h - 0.05 / 9.0).abs() < 1e-12, "{h}");
        assert!((s.bias(h) - ACCURACY).abs() < 1e-12);
        // A wide set, or no drift: the stability rule alone.
        assert_eq!(Scales { half: 10.0, ..s }.step(0.1), 0.05);
        assert_eq!(Scales { a: 0.0, ..s }.step(0.1), 0.05);
        // No finite bound: the cap.
        assert_eq!(
            Scales {
                a: f64::INFINITY,
                ..s
            }
            .step(0.1),
            0.0
        );
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
