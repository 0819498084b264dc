//! Constraint tightening for MPC (method.md 8.14): the constraints a nominal (noise-free) plan
//! must meet so that the stochastic system meets the original ones with probability at least
//! `1 - delta`, per report interval, from the stochastic radii of a result and the metrics
//! they are measured in.

use super::linalg;
use super::safety::Check;
use crate::interval::Interval;
use crate::model::{Bounds, Guarantee, UnsafeSet, UnsafeShape};
use crate::prs::{Prs, Role, Validation};

/// A state constraint of the stochastic system (a set the state must stay in).
#[derive(Clone, Debug, PartialEq)]
pub enum Constraint {
    /// `normal . x <= bound` (`normal`: one entry per state).
    HalfSpace {
        /// One entry per state.
        normal: Vec<f64>,
        /// The bound.
        bound: f64,
    },
    /// `lo <= x_i <= hi` for each `(i, [lo, hi])` listed (an end may be infinite).
    Box(Vec<(usize, Bounds)>),
}

/// The tightened constraints and inflated unsafe sets of one report interval.
#[derive(Clone, Debug, PartialEq)]
pub struct TightStep {
    /// The report time ending the interval (`(t_(k-1), t_k]`; `t = 0` alone for the first).
    pub t: f64,
    /// Each constraint as the nominal must meet it over the interval (the order given). A box
    /// whose bounds cross (`lo > hi`) cannot be met by any nominal.
    pub constraints: Vec<Constraint>,
    /// Each unsafe set given, inflated: the nominal must stay out of it over the interval.
    pub unsafe_sets: Vec<UnsafeSet>,
}

/// Tightened constraints for a nominal plan (method.md 8.14): if the noise-free solution from a
/// start in the result's initial set, under a deterministic input signal in the input box,
/// meets [`TightStep::constraints`] and avoids [`TightStep::unsafe_sets`] over every report
/// interval, then with probability at least `1 - delta` the stochastic state meets the original
/// constraints and avoids the original unsafe sets: over all of `[0, T]` at once for a uniform
/// guarantee, at each report time for a pointwise one.
#[derive(Clone, Debug, PartialEq)]
pub struct Tightening {
    /// The analysis.
    pub analysis: String,
    /// The probability level.
    pub delta: f64,
    /// All times at once, or each report time alone.
    pub guarantee: Guarantee,
    /// What is proved of the result the tightening comes from (it is proved as far as that).
    pub validation: Validation,
    /// One entry per report time.
    pub steps: Vec<TightStep>,
}

/// Why constraints cannot be tightened.
#[derive(Clone, Debug, PartialEq)]
pub enum TightenError {
    /// Constraint `index` does not fit a model of `n` states (a normal of another length, a
    /// state index out of range) or has a number that is not finite where it must be.
    Malformed {
        /// The constraint's place in the list.
        index: usize,
        /// What is wrong.
        what: &'static str,
    },
    /// An unsafe set that does not fit the model (its name).
    UnsafeSet(String),
    /// The result has no ball around the nominal to tighten by (the linearised Gaussian set
    /// alone, method.md 8.12).
    NoDeviationBound,
    /// The result's metric could not be factorised (`P` not positive definite in interval
    /// arithmetic).
    Metric,
}

impl std::error::Error for TightenError {}

/// The tightening of `constraints` and the inflation of `unsafe_sets` by the stochastic radii
/// of `prs` (method.md 8.14).
pub fn tighten(
    prs: &Prs,
    constraints: &[Constraint],
    unsafe_sets: &[UnsafeSet],
) -> Result<Tightening, TightenError> {
    let n = prs.n();
    check(constraints, n)?;
    let amounts = amounts(prs, constraints, unsafe_sets)?;
    let steps = prs
        .steps
        .iter()
        .zip(amounts)
        .enumerate()
        .map(|(k, (st, a))| TightStep {
            t: st.t,
            constraints: constraints
                .iter()
                .zip(&a.constraints)
                .map(|(c, s)| tightened(c, s))
                .collect(),
            unsafe_sets: unsafe_sets
                .iter()
                .zip(&a.unsafe_sets)
                .enumerate()
                .map(|(j, (u, s))| {
                    // A moving set is inflated where the result held it still (8.15).
                    inflated(u, prs.swept_unsafe(j, k).unwrap_or(&u.shape), s)
                })
                .collect(),
        })
        .collect();
    Ok(Tightening {
        analysis: prs.analysis.clone(),
        delta: prs.delta,
        guarantee: prs.guarantee,
        validation: prs.validation.clone(),
        steps,
    })
}

/// Refuses constraints that do not fit `n` states.
fn check(constraints: &[Constraint], n: usize) -> Result<(), TightenError> {
    for (index, c) in constraints.iter().enumerate() {
        let bad = |what| Err(TightenError::Malformed { index, what });
        match c {
            Constraint::HalfSpace { normal, bound } => {
                if normal.len() != n {
                    return bad("the normal needs one entry per state");
                }
                if !normal.iter().all(|a| a.is_finite()) || bound.is_nan() {
                    return bad("the normal must be finite and the bound a number");
                }
            }
            Constraint::Box(coords) => {
                for (i, b) in coords {
                    if *i >= n {
                        return bad("a state index is out of range");
                    }
                    if b.lo.is_nan() || b.hi.is_nan() || b.lo > b.hi {
                        return bad("a range must be numbers with lo <= hi");
                    }
                }
            }
        }
    }
    Ok(())
}

/// How much each constraint and unsafe set moves at one report time: one amount for a
/// half-space or a ball, one per listed state for a box.
#[derive(Clone, Debug, Default)]
struct Amounts {
    constraints: Vec<Vec<f64>>,
    unsafe_sets: Vec<Vec<f64>>,
}

impl Amounts {
    /// Per entry, `f` of the two: `f64::max` for a union's pieces, `f64::min` for the metrics
    /// of one event.
    fn join(mut self, other: &Amounts, f: fn(f64, f64) -> f64) -> Amounts {
        for (a, b) in [
            (&mut self.constraints, &other.constraints),
            (&mut self.unsafe_sets, &other.unsafe_sets),
        ] {
            for (x, y) in a.iter_mut().flatten().zip(b.iter().flatten()) {
                *x = f(*x, *y);
            }
        }
        self
    }
}

/// The amounts of each report time of `prs`: the largest over a union's pieces, each the
/// smallest over the result's metrics.
fn amounts(
    prs: &Prs,
    constraints: &[Constraint],
    unsafe_sets: &[UnsafeSet],
) -> Result<Vec<Amounts>, TightenError> {
    if !prs.pieces.is_empty() {
        let mut pieces = prs.pieces.iter();
        let first = pieces
            .next()
            .map_or(Ok(Vec::new()), |p| amounts(p, constraints, unsafe_sets))?;
        return pieces.try_fold(first, |acc, p| {
            let next = amounts(p, constraints, unsafe_sets)?;
            Ok(acc
                .into_iter()
                .zip(&next)
                .map(|(a, b)| a.join(b, f64::max))
                .collect())
        });
    }
    if prs.role != Role::Own {
        return Err(TightenError::NoDeviationBound);
    }
    let own = of_metric(prs, constraints, unsafe_sets)?;
    prs.also
        .iter()
        .filter(|m| m.role == Role::Metric)
        .try_fold(own, |acc, m| {
            let next = of_metric(m, constraints, unsafe_sets)?;
            Ok(acc
                .into_iter()
                .zip(&next)
                .map(|(a, b)| a.join(b, f64::min))
                .collect())
        })
}

/// The amounts of one metric's run: its `r_span` times the dual norm of each direction.
fn of_metric(
    prs: &Prs,
    constraints: &[Constraint],
    unsafe_sets: &[UnsafeSet],
) -> Result<Vec<Amounts>, TightenError> {
    let n = prs.n();
    let metric = &prs.constants.metric;
    let chol = linalg::cholesky(&linalg::to_intervals(metric), n).ok_or(TightenError::Metric)?;
    let p_inv_diag = linalg::inverse_diagonal(&chol, n);
    // Per constraint, the dual norms of its directions (upper bounds).
    let spread = |i: usize| p_inv_diag[i].sqrt().hi();
    let norms: Vec<Vec<f64>> = constraints
        .iter()
        .map(|c| match c {
            Constraint::HalfSpace { normal, .. } => {
                vec![linalg::inv_quad_form(&chol, n, normal).sqrt().hi()]
            }
            Constraint::Box(coords) => coords.iter().map(|&(i, _)| spread(i)).collect(),
        })
        .collect();
    let unsafe_norms: Vec<Vec<f64>> = unsafe_sets
        .iter()
        .map(|u| {
            let check = Check::new(u, n, &chol, &p_inv_diag)
                .map_err(|_| TightenError::UnsafeSet(u.name.clone()))?;
            Ok(match check {
                Check::HalfSpace { dual_norm, .. } => vec![dual_norm],
                Check::Box { coords } => coords.iter().map(|&(_, _, w)| w).collect(),
                Check::Ball { spread, .. } => vec![spread],
            })
        })
        .collect::<Result<_, TightenError>>()?;
    let times = |norms: &Vec<Vec<f64>>, r: f64| -> Vec<Vec<f64>> {
        norms
            .iter()
            .map(|v| {
                v.iter()
                    .map(|&w| (Interval::point(r) * Interval::point(w)).hi())
                    .collect()
            })
            .collect()
    };
    Ok(prs
        .steps
        .iter()
        .map(|st| Amounts {
            constraints: times(&norms, st.r_span),
            unsafe_sets: times(&unsafe_norms, st.r_span),
        })
        .collect())
}

/// `a - s` rounded down and `a + s` rounded up.
fn less(a: f64, s: f64) -> f64 {
    (Interval::point(a) - Interval::point(s)).lo()
}

fn more(a: f64, s: f64) -> f64 {
    (Interval::point(a) + Interval::point(s)).hi()
}

/// `c` moved inwards by the amounts `s`.
fn tightened(c: &Constraint, s: &[f64]) -> Constraint {
    match c {
        Constraint::HalfSpace { normal, bound } => Constraint::HalfSpace {
            normal: normal.clone(),
            bound: less(*bound, s[0]),
        },
        Constraint::Box(coords) => Constraint::Box(
            coords
                .iter()
                .zip(s)
                .map(|(&(i, b), &s)| {
                    (
                        i,
                        Bounds {
                            lo: more(b.lo, s),
                            hi: less(b.hi, s),
                        },
                    )
                })
                .collect(),
        ),
    }
}

/// `u`, at `shape`, moved outwards by the amounts `s`.
fn inflated(u: &UnsafeSet, shape: &UnsafeShape, s: &[f64]) -> UnsafeSet {
    let shape = match shape {
        UnsafeShape::HalfSpace { normal, offset } => UnsafeShape::HalfSpace {
            normal: normal.clone(),
            offset: less(*offset, s[0]),
        },
        UnsafeShape::Box(coords) => UnsafeShape::Box(
            coords
                .iter()
                .zip(s)
                .map(|(&(i, b), &s)| {
                    (
                        i,
                        Bounds {
                            lo: less(b.lo, s),
                            hi: more(b.hi, s),
                        },
                    )
                })
                .collect(),
        ),
        UnsafeShape::Ball {
            states,
            center,
            radius,
        } => UnsafeShape::Ball {
            states: states.clone(),
            center: center.clone(),
            radius: more(*radius, s[0]),
        },
    };
    UnsafeSet {
        name: u.name.clone(),
        shape,
        moving: Vec::new(),
    }
}
