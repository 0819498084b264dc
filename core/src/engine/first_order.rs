//! First-order deterministic sets (method.md 8.8): the initial box's image under the flow's
//! linearisation along the validated nominal, a zonotope, plus a P-ball bounding everything
//! the linearisation leaves out.
//!
//! With the validated nominal `p` (a cubic per step, defect `d = p' - f(p, u*)` bounded in the
//! P-norm) and a matrix curve `M` (`M(0) = I`), every noise-free solution from `x0 + xi` (`xi`
//! in the initial box minus its centre) under inputs in the box is compared with
//! `y = p + M xi`. On a step, `M(s) = exp(A (s - t_k)) M_k` with a point matrix `A` (the
//! Jacobian at the step's middle), so `M' = A M` exactly, and
//!
//! ```text
//! y' - f(y, u) = d + (A - J) M xi - (f(y, u) - f(y, u*)),   J in [D_x f](H)
//! ```
//!
//! (`H` the box holding `p + M xi` over the step), whose P-norm is at most
//! `|d|_P + |(A - [J](H)) [M] Xi|_P + rho r2`: second order in the box's size, since
//! `[J](H) - A` shrinks with it. With `c` certified on a region holding `y` and the solution
//! (H widened by the a-priori remainder), `e = x - y` obeys `D+ |e|_P <= c |e|_P + forcing`,
//! the remainder ODE of the contraction method. Each node replaces `exp(A h) M_k` by its
//! floating-point midpoint `M_(k+1)`; the jump `(exp(A h) M_k - M_(k+1)) xi` is added to the
//! remainder there.

use super::assemble::{assemble_with, spread, Deterministic, Header, Piece, Radii};
use super::defect::NominalStep;
use super::linalg::{product, product_point};
use super::linearised::{sliced_jacobian, StepData, Tracker};
use super::local::Certifier;
use super::radius::{expm1_over, BoxRadius};
use super::Run;
use crate::interval::Interval;
use crate::model::{AnalysisSpec, Guarantee, InitialSet, Integrator, ModelInfo, Time};
use crate::prs::{DetSet, Proved, Prs, Role, Span};
use crate::sets::zonotope;

/// The most terms of the Taylor series of `exp(A tau)` before the remainder bound.
const TAYLOR_TERMS: usize = 12;

/// Fewer terms where the remainder bound is already below this (the entries of `exp(A tau)`
/// are of order 1 on a step, so this is below their rounding): a short step of a slow flow
/// needs 5 or 6 terms, each an `n^3` interval product.
const TAYLOR_TAIL: f64 = 1e-18;

/// Attempts per step to find an a-priori remainder that holds its own bound.
const MAX_TRIES: usize = 12;

/// The largest model that gets first-order sets: each step multiplies `n x n` interval
/// matrices (up to `2 * TAYLOR_TERMS + 2` products, `n^3` each), which beyond this costs far more
/// than the rest of the run (the 1000-state chain would take hours).
pub const MAX_FIRST_ORDER_STATES: usize = 32;

/// Whether `run` gets first-order sets: asked for (`first_order = on`, the default), a
/// validated run, a box initial set, at most [`MAX_FIRST_ORDER_STATES`] states.
pub(super) fn wanted(run: &Run) -> bool {
    wanted_for(run.spec, run.initial, run.setup.n)
}

fn wanted_for(spec: &AnalysisSpec, initial: &InitialSet, n: usize) -> bool {
    spec.first_order
        && spec.integrator == Integrator::Validated
        && initial.balls.is_empty()
        && n <= MAX_FIRST_ORDER_STATES
}

/// Whether a run of `spec` from `initial` may get the linearised Gaussian sets (method.md
/// 8.10): first-order sets [`wanted`], constant noise, a time-uniform guarantee and continuous
/// time (a map has no linearised flow: its runs never take the Gaussian share of delta nor
/// fall back on the set alone of 8.12).
pub(crate) fn gaussian_wanted(
    info: &ModelInfo,
    spec: &AnalysisSpec,
    initial: &InitialSet,
    n: usize,
) -> bool {
    wanted_for(spec, initial, n)
        && info.constant_diffusion
        && spec.guarantee == Guarantee::Uniform
        && info.time == Time::Continuous
}

/// The first-order sets of a run, and with `gaussian = Some(delta')` (additive noise, a
/// time-uniform guarantee) the linearised Gaussian sets at `delta'` (method.md 8.10) with their
/// number of epochs.
pub(super) struct FirstOrder {
    /// The first-order deterministic sets (8.8).
    pub(super) det: Deterministic,
    /// The linearised Gaussian sets (8.10), the stochastic part inside their zonotopes, and the
    /// Gaussian bound's number of epochs; `None` when not asked for or a step cannot be bounded.
    pub(super) gaussian: Option<(Deterministic, usize)>,
}

/// The first-order sets keep the flow's shape while their remainder is at most this part of
/// their linear part ([`FirstOrder::keeps_shape`]).
const SHAPE_KEPT: f64 = 0.1;

impl FirstOrder {
    /// Whether the first-order sets keep the flow's shape over the whole horizon: at every
    /// report time a linear part (not a point start) and a remainder at most [`SHAPE_KEPT`] of
    /// it ([`linear_and_remainder`]). Then a box cannot do much better than they do (the
    /// contraction run computes none, method.md 8.7); a larger remainder leaves room for a box
    /// (the logistic flow's, about a third of its linear part, is cut to 3% by one).
    pub(super) fn keeps_shape(&self) -> bool {
        self.det
            .pieces
            .iter()
            .filter_map(|p| p.end.as_ref())
            .all(|set| {
                linear_and_remainder(set)
                    .is_some_and(|(linear, rem)| linear > 0.0 && rem <= SHAPE_KEPT * linear)
            })
    }
}

/// A first-order set's linear part and remainder, as P-radii: the zonotope's (the set's radius
/// less its remainder) and the remainder's; `None` for another shape.
pub(super) fn linear_and_remainder(set: &DetSet) -> Option<(f64, f64)> {
    match *set {
        DetSet::Zonotope {
            remainder, radius, ..
        } => Some(((radius - remainder).max(0.0), remainder)),
        _ => None,
    }
}

/// Which linearised Gaussian sets (method.md 8.10) a run of [`deterministic`] computes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Linearised {
    /// None.
    Off,
    /// Beside the first-order sets, at this share of delta.
    Member(f64),
    /// Alone, at this delta (method.md 8.12): the first-order sets' remainder, which needs the
    /// contraction rates, is not computed, and a step the linearised sets cannot bound ends
    /// the run.
    Alone(f64),
}

impl Linearised {
    /// The member at a run's share `gaussian`, if any.
    pub(super) fn member(gaussian: Option<f64>) -> Linearised {
        gaussian.map_or(Linearised::Off, Linearised::Member)
    }
}

/// The first-order sets of a run on the validated nominal's `steps` (each with its report
/// interval), from the initial box `[x0 - half, x0 + half]`, inputs `inputs[k]` held by the
/// nominal on report interval `k` and `r2` the input uncertainty; `None` when the run is not
/// [`wanted`] or a step cannot be bounded (the result then goes without these sets). With
/// `linearised`, also the linearised Gaussian sets where they apply ([`Linearised`]).
pub(super) fn deterministic(
    run: &Run,
    steps: &[(NominalStep, usize)],
    x0: &[f64],
    grid: &[f64],
    inputs: &[Vec<f64>],
    r2: f64,
    linearised: Linearised,
) -> Option<FirstOrder> {
    if !wanted(run) {
        return None;
    }
    let (gaussian, alone) = match linearised {
        Linearised::Off => (None, false),
        Linearised::Member(delta) => (Some(delta), false),
        Linearised::Alone(delta) => (Some(delta), true),
    };

    let n = run.setup.n;
    let sys = run.sys;
    let metric = &run.setup.consts.metric;
    let cert = Certifier::new(run).ok()?;
    let norm = BoxRadius::new(metric, n);
    let w = spread(run);
    // Generator j of the initial box: h_j e_j, h_j >= |x - x0_j| over the box.
    let bounds = run.initial.bounding_box().ok()?;
    let h: Vec<f64> = bounds
        .iter()
        .zip(x0)
        .map(|(b, &c)| {
            let c = Interval::point(c);
            (Interval::point(b.hi) - c)
                .hi()
                .max((c - Interval::point(b.lo)).hi())
        })
        .collect();
    let xi: Vec<Interval> = h.iter().map(|&v| Interval::new(-v, v)).collect();
    let mut tracker = gaussian.and_then(|delta| Tracker::new(run, steps.len(), delta, &h));
    let mut gauss_pieces = Vec::new();
    let zonotope_at = |center: &[f64], m: &[f64], remainder: f64| {
        // g_j = M_(., j) h_j.
        let h = &h;
        let gens: Vec<f64> = (0..n)
            .flat_map(|j| (0..n).map(move |i| m[i * n + j] * h[j]))
            .collect();
        let (hull_lo, hull_hi) = zonotope::hull(center, &gens);
        let radius = (Interval::point(zonotope::p_radius(metric, n, &gens))
            + Interval::point(remainder))
        .hi();
        DetSet::Zonotope {
            center: center.to_vec(),
            generators: gens,
            remainder,
            hull_lo,
            hull_hi,
            radius,
        }
    };
    let mut m: Vec<f64> = (0..n * n)
        .map(|k| if k / n == k % n { 1.0 } else { 0.0 })
        .collect();
    // At t = 0 the initial box itself (the zonotope with M = I, as a box: exact membership).
    let start = DetSet::Box {
        lo: bounds.iter().map(|b| b.lo).collect(),
        hi: bounds.iter().map(|b| b.hi).collect(),
        center: x0.to_vec(),
        radius: zonotope_at(x0, &m, 0.0).radius(),
    };
    let mut rho = Interval::ZERO;
    let mut x = x0.to_vec();
    let mut t0 = 0.0;
    // The remainder's growth over the previous step: the next step's first guess.
    let mut grew = 0.0f64;
    let mut pieces = Vec::with_capacity(steps.len());
    let mut jac = vec![Interval::ZERO; n * n];
    for (step, k) in steps {
        let (t1, u) = (step.t1, &inputs[*k]);
        let span = Interval::point(t1) - Interval::point(t0);
        let times = Interval::new(t0, t1);
        // A: the Jacobian at the middle of the step's nodes.
        let mid: Vec<f64> = x.iter().zip(&step.x1).map(|(a, b)| 0.5 * (a + b)).collect();
        let mut a = vec![0.0; n * n];
        sys.jac_x(&mid, u, 0.5 * (t0 + t1), &mut a);
        let exp_h = exp_enclosure(&a, n, span)?;
        let exp_over = exp_enclosure(&a, n, Interval::new(0.0, span.hi()))?;
        let next = product_point(&exp_h, &m, n, n, n);
        let m_over = product_point(&exp_over, &m, n, n, n);
        // V = [M] Xi over the step, and H = p([t0, t1]) + V.
        let v: Vec<Interval> = (0..n)
            .map(|i| (0..n).fold(Interval::ZERO, |acc, j| acc + m_over[i * n + j] * xi[j]))
            .collect();
        let hbox: Vec<Interval> = (0..n)
            .map(|i| Interval::new(step.lo[i], step.hi[i]) + v[i])
            .collect();
        let ui: Vec<Interval> = u.iter().map(|&x| Interval::point(x)).collect();
        let hull: Vec<Interval> = (0..n)
            .map(|i| Interval::new(step.lo[i], step.hi[i]))
            .collect();
        // The remainder over the step (not computed alone: the linearised Gaussian sets go
        // without it).
        let remainder = 'rem: {
            if alone {
                break 'rem None;
            }
            sliced_jacobian(sys, &hull, &v, &ui, times, &mut jac);
            // |(A - [J](H)) V|_P.
            let lin: Vec<f64> = (0..n)
                .map(|i| {
                    (0..n)
                        .fold(Interval::ZERO, |acc, j| {
                            acc + (Interval::point(a[i * n + j]) - jac[i * n + j]) * v[j]
                        })
                        .mag()
                })
                .collect();
            let forcing = Interval::point(step.defect) + Interval::point(norm.bound(&lin));
            // The remainder over the step, on a region that must hold it (a-priori guess `cap`).
            let mut cap = 1.25 * (rho.hi() + grew) + f64::MIN_POSITIVE;
            let mut accepted = None;
            for _ in 0..MAX_TRIES {
                let region: Vec<Interval> = hbox
                    .iter()
                    .zip(&w)
                    .map(|(b, &wi)| {
                        let d = Interval::point(cap) * Interval::point(wi);
                        Interval::new(
                            (Interval::point(b.lo()) - d).lo(),
                            (Interval::point(b.hi()) + d).hi(),
                        )
                    })
                    .collect();
                let (lo, hi): (Vec<f64>, Vec<f64>) =
                    region.iter().map(|r| (r.lo(), r.hi())).unzip();
                let lean = cert.may_lean(&lo, &hi, &w);
                let Ok((rates, _)) = cert.rates(&region, times, lean) else {
                    break 'rem None;
                };
                if !(rates.c.is_finite() && rates.rho.is_finite()) {
                    break 'rem None;
                }
                let f = forcing + Interval::point(rates.rho) * Interval::point(r2);
                let end =
                    rho * (Interval::point(rates.c) * span).exp() + f * expm1_over(rates.c, span);
                let top = rho.hi().max(end.hi());
                if top < cap {
                    accepted = Some((end, rates));
                    break;
                }
                cap = (2.0 * cap).max(1.25 * top);
            }
            accepted
        };
        if remainder.is_none() && !alone {
            return None;
        }
        // The node: M_(k+1) the midpoint of exp(A h) M_k, the jump into the remainder.
        let m_next: Vec<f64> = next.iter().map(|e| e.mid()).collect();
        let jump: Vec<f64> = (0..n)
            .map(|i| {
                (0..n)
                    .fold(Interval::ZERO, |acc, j| {
                        acc + (next[i * n + j] - Interval::point(m_next[i * n + j])) * xi[j]
                    })
                    .mag()
            })
            .collect();
        if m_next.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let report = t1 == grid[k + 1];
        // The first-order set's remainder at the node.
        let after = remainder.map(|(end, rates)| {
            (
                Interval::point(end.hi()) + Interval::point(norm.bound(&jump)),
                end,
                rates,
            )
        });
        if after
            .as_ref()
            .is_some_and(|(after, ..)| !after.hi().is_finite())
        {
            return None;
        }
        if let Some(tr) = tracker.as_mut() {
            let hull: Vec<Interval> = (0..n)
                .map(|i| Interval::new(step.lo[i], step.hi[i]))
                .collect();
            let data = StepData {
                a: &a,
                exp_h: &exp_h,
                exp_over: &exp_over,
                span,
                times,
                hull: &hull,
                v: &v,
                u,
                defect: step.defect,
                jump: &jump,
                x1: &step.x1,
                m_next: &m_next,
                half: &h,
                report,
            };
            // Alone, the rates shown are those certified on the region the set spans (the
            // set does not use them; infinite where they cannot be certified).
            let rates = after
                .as_ref()
                .map_or((0.0, 0.0), |(_, _, r)| (r.c, r.sigma));
            match tr.step(&data, rates) {
                Some(mut piece) if alone => {
                    let region: Vec<Interval> = piece
                        .over
                        .lo
                        .iter()
                        .zip(&piece.over.hi)
                        .map(|(&lo, &hi)| Interval::new(lo, hi))
                        .collect();
                    piece.rates = cert
                        .rates(&region, times, false)
                        .map_or((f64::INFINITY, f64::INFINITY), |(r, _)| (r.c, r.sigma));
                    gauss_pieces.push(piece);
                }
                Some(piece) => gauss_pieces.push(piece),
                None if alone => return None,
                None => tracker = None,
            }
        }
        if let Some((after, end, rates)) = after {
            grew = (after.hi() - rho.hi()).max(0.0);
            pieces.push(Piece {
                t1,
                rates: (rates.c, rates.sigma),
                over: Span {
                    lo: hbox.iter().map(|b| b.lo()).collect(),
                    hi: hbox.iter().map(|b| b.hi()).collect(),
                    radius: rho.hi().max(end.hi()),
                },
                end: report.then(|| zonotope_at(&step.x1, &m_next, after.hi())),
            });
            rho = Interval::point(after.hi());
        }
        m = m_next;
        x.clone_from(&step.x1);
        t0 = t1;
    }
    let gaussian = tracker.map(|tr| {
        let det = Deterministic {
            start: start.clone(),
            pieces: gauss_pieces,
            frame: None,
            tube: None,
        };
        (det, tr.epochs())
    });
    Some(FirstOrder {
        det: Deterministic {
            start,
            pieces,
            frame: None,
            tube: None,
        },
        gaussian,
    })
}

/// The members a run's first-order sets give (method.md 8.8, 8.10): the zonotopes widened by
/// the run's stochastic radii, and the linearised Gaussian sets, which hold their stochastic
/// part themselves.
pub(super) fn members(run: &Run, first: FirstOrder, header: Header, radii: Radii) -> Vec<Prs> {
    let mut out = vec![
        assemble_with(run, first.det, header.clone(), None, radii).with_role(Role::FirstOrder)
    ];
    if let Some((det, epochs)) = first.gaussian {
        let reports = det.pieces.iter().filter(|p| p.end.is_some()).count();
        let mut prs = assemble_with(run, det, header, None, Radii::inside(reports));
        prs.validation
            .rigorous
            .push(Proved::LinearisedGaussian { epochs });
        if let Some(delta) = run.gaussian {
            prs.delta = delta;
        }
        out.push(prs.with_role(Role::Linearised));
    }
    out
}

/// An enclosure of `exp(A tau)` for every `tau` in `tau` (`tau >= 0`): the Taylor polynomial
/// of degree `q` (at most [`TAYLOR_TERMS`], the first whose next term is below
/// [`TAYLOR_TAIL`]) in interval arithmetic plus the remainder
/// `a^(q+1) / (q+1)! / (1 - a / (q+2))` on every entry, `a = |A|_inf tau_max` (the remainder
/// matrix's infinity norm bounds each of its entries). `None` if `a >= q + 2` or the entries
/// are not finite.
pub(super) fn exp_enclosure(a: &[f64], n: usize, tau: Interval) -> Option<Vec<Interval>> {
    let norm = (0..n)
        .map(|i| {
            (0..n).fold(Interval::ZERO, |acc, j| {
                acc + Interval::point(a[i * n + j].abs())
            })
        })
        .fold(Interval::ZERO, |m, r| Interval::point(m.hi().max(r.hi())));
    let big = norm * Interval::point(tau.hi());
    // The degree: the first whose next term is below TAYLOR_TAIL (any degree is sound: the
    // remainder below is bounded for the one chosen).
    let (mut q, mut next) = (1, big.hi() * big.hi() / 2.0);
    while q < TAYLOR_TERMS && next.partial_cmp(&TAYLOR_TAIL) != Some(std::cmp::Ordering::Less) {
        q += 1;
        next *= big.hi() / (q + 1) as f64;
    }
    let qi = Interval::point((q + 2) as f64);
    if big.hi().partial_cmp(&qi.lo()) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    let mut fact = Interval::ONE;
    for j in 1..=q + 1 {
        fact *= Interval::point(j as f64);
    }
    let rem = (big.powi(q as i32 + 1) / fact / (Interval::ONE - big / qi)).hi();
    // Horner: I + A tau (I + A tau / 2 (I + ... (I + A tau / q))).
    let at: Vec<Interval> = a.iter().map(|&v| Interval::point(v) * tau).collect();
    let eye = |m: &mut Vec<Interval>| {
        for i in 0..n {
            m[i * n + i] += Interval::ONE;
        }
    };
    let mut s = vec![Interval::ZERO; n * n];
    eye(&mut s);
    for j in (1..=q).rev() {
        // `A tau / j` as `A tau` times an enclosure of `1 / j`: a product per entry, not a
        // quotient.
        let inv = Interval::ONE / Interval::point(j as f64);
        let scaled: Vec<Interval> = at.iter().map(|&v| v * inv).collect();
        s = product(&scaled, &s, n, n, n);
        eye(&mut s);
    }
    let r = Interval::new(-rem, rem);
    let out: Vec<Interval> = s.into_iter().map(|v| v + r).collect();
    out.iter()
        .all(|v| v.lo().is_finite() && v.hi().is_finite())
        .then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The linearised Gaussian sets are wanted for a continuous model with additive noise, a
    /// uniform guarantee and first-order sets, and never for a map with the same data.
    #[test]
    fn maps_want_no_linearised_sets() {
        let base = crate::test_support::models::model("m", &["x"], &["w"], &[(0.0, 1.0)]);
        let spec = AnalysisSpec {
            first_order: true,
            guarantee: Guarantee::Uniform,
            ..AnalysisSpec::default()
        };
        for (time, wanted) in [
            (Time::Continuous, true),
            (Time::Discrete { period: 0.1 }, false),
        ] {
            let info = ModelInfo::from_parts(crate::model::ModelParts {
                constant_diffusion: true,
                time,
                ..base.clone().into_parts()
            });
            let initial = info.initial.clone();
            assert_eq!(
                gaussian_wanted(&info, &spec, &initial, 1),
                wanted,
                "{time:?}"
            );
        }
    }

    #[test]
    fn exp_enclosure_holds_the_closed_form() {
        // A = [[0, 1], [-1, 0]]: exp(A t) is the rotation by -t... [[cos, sin], [-sin, cos]].
        let a = [0.0, 1.0, -1.0, 0.0];
        for t in [0.0, 0.01, 0.3, 1.0] {
            let e = exp_enclosure(&a, 2, Interval::point(t)).unwrap();
            let want = [t.cos(), t.sin(), -t.sin(), t.cos()];
            for (iv, w) in e.iter().zip(want) {
                assert!(iv.lo() <= w && w <= iv.hi(), "t = {t}: {iv:?} vs {w}");
                // The remainder bound 1 / 13! / (1 - 1 / 14) at t = 1, rounding below.
                assert!(iv.width() < 1e-12f64.max(4e-10 * t), "t = {t}: {iv:?}");
            }
        }
        // Over tau in [0, 0.5]: every sampled time's value inside.
        let e = exp_enclosure(&a, 2, Interval::new(0.0, 0.5)).unwrap();
        for k in 0..=50 {
            let t = 0.01 * k as f64;
            let want = [t.cos(), t.sin(), -t.sin(), t.cos()];
            for (iv, w) in e.iter().zip(want) {
                assert!(iv.lo() <= w && w <= iv.hi());
            }
        }
        // A stiff matrix with a too long step: no enclosure rather than a wrong one.
        assert!(exp_enclosure(&[-100.0], 1, Interval::point(1.0)).is_none());
    }
}
