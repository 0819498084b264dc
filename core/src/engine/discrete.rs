//! Discrete-time models (method.md 8.16): `X_(k+1) = f(X_k, u_k, t_k) + G(X_k, t_k) w_k` at
//! `t_k = k period`, the `w_k` independent standard normal vectors.
//!
//! The deterministic set `D_k` holds every noise-free state `z_k` (`z_(k+1) = f(z_k, u_k, t_k)`
//! from any initial state and input sequence): a P-ball around a nominal (contraction method)
//! or a box (interval method), each step's map enclosed in interval arithmetic, so there is
//! no integrator and nothing left unvalidated. The deviation `e_k = X_k - z_k` satisfies the
//! averaged-MGF recursion `Psi_(k+1) = L_k^2 Psi_k + s_k^2` with `L_k` a bound of the map's
//! Jacobian in the metric (`|R J R^-1|_2`, `P = R'R`) and `s_k^2` of `lambda_max(R G G' R')`,
//! both on the step's region; `r_k = sqrt(Psi_k kappa(n, delta'))`.
//!
//! Regions: with `guarantee = uniform`, step `k`'s region is the box hull of `D_k (+) B_P(r_k)`
//! and `delta' = delta / K` (the union bound over the `K` steps; method.md 8.16 has why the
//! process never leaves the regions on that event). With `guarantee = pointwise` the region is
//! the model's domain (the whole space without one): the factors hold for every state, so each
//! step's set holds at the full `delta`. An affine map with additive noise has
//! `e_k ~ N(0, Sigma_k)`, `Sigma_(k+1) = A Sigma_k A' + G G'`, whatever the regions: its radius
//! is also `sqrt(q lambda_max(R Sigma_k R'))` with `q` a certified chi-square quantile, and the
//! smaller of the two radii is kept (both hold).

use super::assemble::{
    assemble_with, constants_used, rate_used, span_of, spread, Deterministic, Header, Piece, Radii,
};
use super::contraction::initial_set;
use super::defect::MAX_STEPS;
use super::linalg::{self, lambda_max, product};
use super::radius::{self, BoxRadius};
use super::{r1, Culprit, Detail, Inputs, Problem, Run, RunError, Setting};
use crate::chi2::chi2_quantile_upper;
use crate::interval::Interval;
use crate::model::{Guarantee, Inclusion, Method, RadiusRule};
use crate::prs::{DetSet, GaussianUsed, Proved, Prs, R1Bound, UniformBound};

/// The most states of a model whose covariance is propagated (`n^3` interval products per
/// step), as for continuous time.
const MAX_GAUSSIAN_STATES: usize = 64;

/// Relative tolerance of a horizon or report step that is a whole number of periods.
const WHOLE: f64 = 1e-9;

/// The PRS of a run of a discrete-time model with sampling period `period`.
pub(super) fn run(run: &Run, period: f64) -> Result<Prs, RunError> {
    let spec = run.spec;
    let n = run.setup.n;
    let steps = whole_periods(spec.horizon, period, Setting::Horizon)?;
    // (Each step keeps its sets: as many as a continuous run's internal steps at most.)
    if steps > MAX_STEPS {
        return Err(RunError::Invalid(
            Detail::from(Problem::TooManyMapSteps {
                steps,
                max: MAX_STEPS,
            })
            .at_setting(Setting::Horizon),
        ));
    }
    let stride = whole_periods(spec.step, period, Setting::Step)?;
    let uniform = spec.guarantee == Guarantee::Uniform;
    if spec.radius != RadiusRule::Amgf {
        return Err(RunError::Unsupported(
            Detail::from(Problem::DiscreteSetting(Setting::Radius)).at_setting(Setting::Radius),
        ));
    }
    let metric = &run.setup.consts.metric;
    let whitening = Whitening::new(metric, n).ok_or_else(|| {
        RunError::Invalid(Detail::from(Problem::MetricIndefinite).at_setting(Setting::Metric))
    })?;
    // The union bound over the steps (uniform), rounded down so the shares sum to at most delta.
    let delta = if uniform {
        (spec.delta / steps as f64).next_down()
    } else {
        spec.delta
    };
    let kappa = crate::kappa::kappa(n, delta, RadiusRule::Amgf);
    let gaussian = Gaussian::of(run, delta);
    let (x0, half) = radius::initial_center_and_halfwidths(run.initial, n)
        .map_err(|e| RunError::Invalid(Problem::InitialSet(e).into()))?;
    let mut stepper = Stepper {
        run,
        whitening,
        period,
        kappa: Interval::point(kappa),
        psi: Interval::ZERO,
        r: 0.0,
        w: spread(run),
        gaussian,
        box_inputs: (
            super::input_intervals(run.info),
            run.nominal_inputs(&[0.0]).0.remove(0),
        ),
    };
    let (start, r1, r1_bound, pieces) = match spec.method {
        Method::Contraction => {
            let (r1, r1_bound) = r1::bound(metric, run.initial, &half);
            let pieces = stepper.balls(&x0, r1, steps, stride)?;
            (initial_set(run, &x0, r1), r1, r1_bound, pieces)
        }
        Method::Interval => {
            let bounds = run
                .initial
                .bounding_box()
                .map_err(|e| RunError::Invalid(Problem::InitialSet(e).into()))?;
            let x: Vec<Interval> = bounds.iter().map(|b| Interval::new(b.lo, b.hi)).collect();
            let (r1, r1_bound) = r1::bound(metric, run.initial, &half);
            let pieces = stepper.boxes(x.clone(), steps, stride)?;
            let bound = R1Bound {
                reported_only: true,
                ..r1_bound
            };
            (box_set(&x, &BoxRadius::new(metric, n)), r1, bound, pieces)
        }
    };
    let used = stepper.gaussian.as_ref().map(|g| GaussianUsed {
        quantile: g.quantile,
        uniform: uniform.then_some(UniformBound::UnionOverSteps),
    });
    let (pieces, at): (Vec<Piece>, Vec<(f64, f64)>) = pieces.into_iter().unzip();
    let radii = Radii::discrete(&pieces, &at, uniform.then_some(steps), used);
    let det = Deterministic {
        start,
        pieces,
        frame: None,
        tube: None,
    };
    let mut rigorous = vec![Proved::MapFactors {
        steps,
        metric: run.setup.consts.metric_region,
        over_domain: !uniform,
    }];
    if spec.method == Method::Interval {
        rigorous.push(Proved::Inclusion(spec.inclusion));
    }
    rigorous.extend([
        Proved::Kappa,
        Proved::Psi,
        match spec.method {
            Method::Contraction => Proved::Radii,
            Method::Interval => Proved::StochasticRadius,
        },
        Proved::Margins { given: spec.method },
    ]);
    let input_center = stepper.inputs(0).1;
    let header = Header {
        method: spec.method,
        inclusion: (spec.method == Method::Interval).then_some(spec.inclusion),
        rate: rate_used(spec.rate, &det.pieces, None),
        constants: constants_used(run, run.setup.consts.rho),
        radius_rule: radius::stochastic_factor(n, spec).1,
        kappa,
        r1,
        r2: run.input_radius(),
        r1_bound,
        transform: None,
        initial_center: x0,
        input_center,
        rigorous,
        not_validated: Vec::new(),
    };
    let mut prs = assemble_with(run, det, header, None, radii);
    // Over the domain (pointwise), the factors hold only there.
    prs.validation.conditional_on_domain = !uniform && run.info.has_domain;
    Ok(prs)
}

/// `value / period` as a whole number of steps, at least 1 (within [`WHOLE`]).
fn whole_periods(value: f64, period: f64, setting: Setting) -> Result<usize, RunError> {
    let k = (value / period).round();
    if (1.0..=1e8).contains(&k) && (k * period - value).abs() <= WHOLE * value {
        return Ok(k as usize);
    }
    Err(RunError::Invalid(
        Detail::from(Problem::NotWholePeriods {
            setting,
            value,
            period,
        })
        .at_setting(setting),
    ))
}

/// The interval hull box `x` as a deterministic set, with its P-radius around its centre.
fn box_set(x: &[Interval], radius: &BoxRadius) -> DetSet {
    let center: Vec<f64> = x.iter().map(|v| v.mid()).collect();
    let half: Vec<f64> = x
        .iter()
        .zip(&center)
        .map(|(v, &c)| {
            let c = Interval::point(c);
            (Interval::point(v.hi()) - c)
                .hi()
                .max((c - Interval::point(v.lo())).hi())
        })
        .collect();
    DetSet::Box {
        lo: x.iter().map(|v| v.lo()).collect(),
        hi: x.iter().map(|v| v.hi()).collect(),
        radius: radius.bound(&half),
        center,
    }
}

/// The metric's factor: `P = L L'`, so `|v|_P = |L' v|` and `R = L'`, with `L^-1` enclosed.
struct Whitening {
    n: usize,
    /// `L`, lower triangular, row-major.
    l: Vec<Interval>,
    /// `L^-1`, row-major.
    l_inv: Vec<Interval>,
}

impl Whitening {
    fn new(p: &[f64], n: usize) -> Option<Whitening> {
        let l = linalg::cholesky(&linalg::to_intervals(p), n)?;
        let mut l_inv = vec![Interval::ZERO; n * n];
        for j in 0..n {
            let mut e = vec![Interval::ZERO; n];
            e[j] = Interval::ONE;
            for (i, v) in linalg::forward_solve(&l, n, &e).into_iter().enumerate() {
                l_inv[i * n + j] = v;
            }
        }
        Some(Whitening { n, l, l_inv })
    }

    /// `L' A` for an `n x c` interval matrix `A`.
    fn apply(&self, a: &[Interval], c: usize) -> Vec<Interval> {
        let n = self.n;
        let mut out = vec![Interval::ZERO; n * c];
        for i in 0..n {
            for k in i..n {
                let lki = self.l[k * n + i];
                if lki == Interval::ZERO {
                    continue;
                }
                for j in 0..c {
                    out[i * c + j] += lki * a[k * c + j];
                }
            }
        }
        out
    }

    /// Upper bound of `|v|_P` over the box `v`.
    fn norm(&self, v: &[Interval]) -> f64 {
        let w = self.apply(v, 1);
        w.iter()
            .fold(Interval::ZERO, |s, x| s + x.sqr())
            .sqrt()
            .hi()
    }

    /// Upper bound of `|R J R^-1|_2 = |L' J L^-T|_2` over the interval matrix `j`: the larger
    /// eigenvalue of `[[0, M'], [M, 0]]` (verified), or `sqrt(|M|_1 |M|_inf)` where smaller.
    fn factor(&self, j: &[Interval]) -> f64 {
        let n = self.n;
        let a = self.apply(j, n);
        let l_inv_t: Vec<Interval> = (0..n * n)
            .map(|k| self.l_inv[(k % n) * n + k / n])
            .collect();
        let m = product(&a, &l_inv_t, n, n, n);
        let mut block = vec![Interval::ZERO; 4 * n * n];
        for r in 0..n {
            for c in 0..n {
                block[r * 2 * n + n + c] = m[c * n + r];
                block[(n + r) * 2 * n + c] = m[r * n + c];
            }
        }
        let (mut rows, mut cols) = (vec![Interval::ZERO; n], vec![Interval::ZERO; n]);
        for r in 0..n {
            for c in 0..n {
                let v = Interval::point(m[r * n + c].mag());
                rows[r] += v;
                cols[c] += v;
            }
        }
        let top = |v: &[Interval]| v.iter().fold(0.0f64, |a, x| a.max(x.hi()));
        let norms = (Interval::point(top(&rows)) * Interval::point(top(&cols)))
            .sqrt()
            .hi();
        lambda_max(&block, 2 * n).max(0.0).min(norms)
    }

    /// Upper bound of `sqrt(lambda_max(L' G G' L))` over the `n x m` interval matrix `g`.
    fn noise(&self, g: &[Interval], m: usize) -> f64 {
        if m == 0 {
            return 0.0;
        }
        let rg = self.apply(g, m);
        Interval::point(self.covariance(&rg, m).max(0.0))
            .sqrt()
            .hi()
    }

    /// Upper bound of `lambda_max(B B')` for an `n x m` interval matrix `B`.
    fn covariance(&self, b: &[Interval], m: usize) -> f64 {
        let n = self.n;
        let mut s = vec![Interval::ZERO; n * n];
        for i in 0..n {
            for j in 0..=i {
                let v = (0..m).fold(Interval::ZERO, |acc, k| {
                    acc + if i == j {
                        b[i * m + k].sqr()
                    } else {
                        b[i * m + k] * b[j * m + k]
                    }
                });
                s[i * n + j] = v;
                s[j * n + i] = v;
            }
        }
        lambda_max(&s, n)
    }
}

/// The exact covariance of an affine map with additive noise: `A` and `W = G G'` enclosed,
/// `Sigma_k` propagated, and the certified quantile.
struct Gaussian {
    a: Vec<Interval>,
    w: Vec<Interval>,
    sigma: Vec<Interval>,
    quantile: f64,
}

impl Gaussian {
    /// The route for an affine model of at most [`MAX_GAUSSIAN_STATES`] states, at `delta`.
    fn of(run: &Run, delta: f64) -> Option<Gaussian> {
        let (n, m) = (run.setup.n, run.sys.m());
        if !run.info.affine || n > MAX_GAUSSIAN_STATES {
            return None;
        }
        let x: Vec<Interval> = vec![Interval::ZERO; n];
        let u: Vec<Interval> = run
            .info
            .input_box
            .iter()
            .map(|b| Interval::point(Interval::new(b.lo, b.hi).mid()))
            .collect();
        let mut a = vec![Interval::ZERO; n * n];
        run.sys.jac_x_interval(&x, &u, Interval::ZERO, &mut a);
        let mut g = vec![Interval::ZERO; n * m];
        run.sys.diffusion_interval(&x, Interval::ZERO, &mut g);
        let g_t: Vec<Interval> = (0..m * n).map(|k| g[(k % n) * m + k / n]).collect();
        let w = product(&g, &g_t, n, m, n);
        let bounded = |v: &[Interval]| v.iter().all(|x| x.is_bounded());
        (bounded(&a) && bounded(&w)).then(|| Gaussian {
            a,
            w,
            sigma: vec![Interval::ZERO; n * n],
            quantile: chi2_quantile_upper(n, delta),
        })
    }

    /// `Sigma_(k+1) = A Sigma_k A' + W`, and the radius `sqrt(q lambda_max(L' Sigma L))`.
    fn advance(&mut self, whitening: &Whitening) -> f64 {
        let n = whitening.n;
        let a_t: Vec<Interval> = (0..n * n).map(|k| self.a[(k % n) * n + k / n]).collect();
        let next = product(&product(&self.a, &self.sigma, n, n, n), &a_t, n, n, n);
        for i in 0..n {
            for j in 0..n {
                // Symmetric: both triangles from the lower one (the same set of matrices).
                let (r, c) = if j <= i { (i, j) } else { (j, i) };
                self.sigma[i * n + j] = next[r * n + c] + self.w[r * n + c];
            }
        }
        let rs = whitening.apply(&self.sigma, n);
        let rs_t: Vec<Interval> = (0..n * n).map(|k| rs[(k % n) * n + k / n]).collect();
        let form = whitening.apply(&rs_t, n);
        let top = lambda_max(&linalg::symmetric_part(&form, n), n).max(0.0);
        (Interval::point(self.quantile) * Interval::point(top))
            .sqrt()
            .hi()
    }
}

/// The recursion along the steps: `Psi`, the stochastic radius and the factors.
struct Stepper<'a> {
    run: &'a Run<'a>,
    whitening: Whitening,
    period: f64,
    kappa: Interval,
    /// `Psi_k` (upper bound).
    psi: Interval,
    /// `r_k`, the radius at the current step.
    r: f64,
    /// Upper bounds of `sqrt((P^-1)_ii)`.
    w: Vec<f64>,
    gaussian: Option<Gaussian>,
    /// The input box as intervals and its centre (the nominal's input), for inputs anywhere in
    /// the box.
    box_inputs: (Vec<Interval>, Vec<f64>),
}

/// A step's piece and the stochastic radius at its end with `Psi` there.
type Stepped = (Piece, (f64, f64));

impl Stepper<'_> {
    /// `t_k`, enclosed.
    fn time(&self, k: usize) -> Interval {
        Interval::point(k as f64) * Interval::point(self.period)
    }

    /// The inputs over step `k`: the box (or the plan's value), and the nominal's.
    fn inputs(&self, k: usize) -> (Vec<Interval>, Vec<f64>) {
        match self.run.inputs {
            Inputs::Box => self.box_inputs.clone(),
            Inputs::Plan(plan) => {
                // (At the step's time as the report prints it.)
                let u = plan.at(k as f64 * self.period).to_vec();
                (u.iter().map(|&v| Interval::point(v)).collect(), u)
            }
        }
    }

    /// The region of a step whose deterministic set lies in the box `set`: the box widened by
    /// the stochastic radius (uniform), or the domain (pointwise).
    fn region(&self, set: &[Interval]) -> Vec<Interval> {
        if self.run.spec.guarantee == Guarantee::Pointwise {
            return self
                .run
                .info
                .domain
                .iter()
                .map(|b| Interval::new(b.lo, b.hi))
                .collect();
        }
        set.iter()
            .zip(&self.w)
            .map(|(v, &w)| {
                let d = Interval::point(self.r) * Interval::point(w);
                Interval::new(
                    (Interval::point(v.lo()) - d).lo(),
                    (Interval::point(v.hi()) + d).hi(),
                )
            })
            .collect()
    }

    /// The factor `L_k` and noise level `s_k` on `region` at step `k` with inputs `u`; an error
    /// where either is not finite.
    fn factors(
        &self,
        k: usize,
        region: &[Interval],
        u: &[Interval],
    ) -> Result<(f64, f64), RunError> {
        let (sys, n, m) = (self.run.sys, self.run.setup.n, self.run.sys.m());
        let t = self.time(k);
        let mut j = vec![Interval::ZERO; n * n];
        sys.jac_x_interval(region, u, t, &mut j);
        let factor = self.whitening.factor(&j);
        let mut g = vec![Interval::ZERO; n * m];
        sys.diffusion_interval(region, t, &mut g);
        let noise = self.whitening.noise(&g, m);
        if factor.is_finite() && noise.is_finite() {
            return Ok((factor, noise));
        }
        let states = &self.run.info.states;
        let culprit = (0..n * n)
            .find(|&e| !j[e].is_bounded())
            .map(|e| Culprit::State(e % n));
        let detail = Detail::from(Problem::MapFactor {
            t: t.hi(),
            region: states.iter().cloned().zip(region.iter().copied()).collect(),
            pointwise: self.run.spec.guarantee == Guarantee::Pointwise,
        });
        Err(RunError::NonFinite(match culprit {
            Some(c) => detail.at(c),
            None => detail.at_setting(Setting::Guarantee),
        }))
    }

    /// `Psi` and the radius after a step with factor `l` and noise level `s`.
    fn advance(&mut self, l: f64, s: f64) -> (f64, f64) {
        self.psi =
            Interval::point((Interval::point(l).sqr() * self.psi + Interval::point(s).sqr()).hi());
        let mut r = (self.psi * self.kappa).sqrt().hi();
        if let Some(g) = self.gaussian.as_mut() {
            r = r.min(g.advance(&self.whitening));
        }
        self.r = r;
        (self.psi.hi(), r)
    }

    /// The contraction method: the nominal from `x0`, `R_(k+1) = L_k R_k + gamma_k + eps_k`
    /// (the inputs' effect and the nominal's rounding, in the metric).
    fn balls(
        &mut self,
        x0: &[f64],
        r1: f64,
        steps: usize,
        stride: usize,
    ) -> Result<Vec<Stepped>, RunError> {
        let (sys, n) = (self.run.sys, self.run.setup.n);
        let mut z = x0.to_vec();
        let mut big_r = Interval::point(r1);
        let mut pieces = Vec::with_capacity(steps);
        for k in 0..steps {
            let t = self.time(k);
            let (u_box, u_nom) = self.inputs(k);
            let zi: Vec<Interval> = z.iter().map(|&v| Interval::point(v)).collect();
            let hull: Vec<Interval> = zi
                .iter()
                .zip(&self.w)
                .map(|(v, &w)| {
                    let d = big_r * Interval::point(w);
                    Interval::new((*v - d).lo(), (*v + d).hi())
                })
                .collect();
            let region = self.region(&hull);
            let (l, s) = self.factors(k, &region, &u_box)?;
            let ui: Vec<Interval> = u_nom.iter().map(|&v| Interval::point(v)).collect();
            let mut fz = vec![Interval::ZERO; n];
            sys.drift_interval(&zi, &ui, t, &mut fz);
            let next: Vec<f64> = fz.iter().map(|v| v.mid()).collect();
            let eps: Vec<Interval> = fz
                .iter()
                .zip(&next)
                .map(|(v, &c)| *v - Interval::point(c))
                .collect();
            let mut gamma = 0.0;
            if matches!(self.run.inputs, Inputs::Box) && self.run.setup.p > 0 {
                let mut fu = vec![Interval::ZERO; n];
                sys.drift_interval(&zi, &u_box, t, &mut fu);
                let d: Vec<Interval> = fu.iter().zip(&fz).map(|(a, b)| *a - *b).collect();
                gamma = self.whitening.norm(&d);
            }
            big_r = Interval::point(
                (Interval::point(l) * big_r
                    + Interval::point(gamma)
                    + Interval::point(self.whitening.norm(&eps)))
                .hi(),
            );
            let radii = self.advance(l, s);
            let set = DetSet::Ball {
                center: next.clone(),
                radius: big_r.hi(),
            };
            pieces.push(self.piece(k, steps, stride, set, (l, s), radii));
            z = next;
        }
        Ok(pieces)
    }

    /// The interval method: `X_(k+1) = F(X_k, U, t_k)`, the natural inclusion, intersected
    /// with the mean-value form `f(m, U) + J(X_k, U) (X_k - m)` for `inclusion = jacobian`.
    fn boxes(
        &mut self,
        mut x: Vec<Interval>,
        steps: usize,
        stride: usize,
    ) -> Result<Vec<Stepped>, RunError> {
        let (sys, n) = (self.run.sys, self.run.setup.n);
        let metric = &self.run.setup.consts.metric;
        let radius = BoxRadius::new(metric, n);
        let mut pieces = Vec::with_capacity(steps);
        for k in 0..steps {
            let t = self.time(k);
            let (u_box, _) = self.inputs(k);
            let region = self.region(&x);
            let (l, s) = self.factors(k, &region, &u_box)?;
            let mut next = vec![Interval::ZERO; n];
            sys.drift_interval(&x, &u_box, t, &mut next);
            if self.run.spec.inclusion != Inclusion::Natural {
                let m: Vec<Interval> = x.iter().map(|v| Interval::point(v.mid())).collect();
                let mut fm = vec![Interval::ZERO; n];
                sys.drift_interval(&m, &u_box, t, &mut fm);
                let mut j = vec![Interval::ZERO; n * n];
                sys.jac_x_interval(&x, &u_box, t, &mut j);
                for i in 0..n {
                    let mv = (0..n).fold(fm[i], |acc, c| acc + j[i * n + c] * (x[c] - m[c]));
                    // Both hold every image: their intersection does (never empty in exact
                    // arithmetic; outward rounding keeps it so).
                    next[i] = next[i].intersect(mv).unwrap_or(next[i]);
                }
            }
            if let Some(i) = (0..n).find(|&i| !next[i].is_bounded()) {
                return Err(RunError::NonFinite(
                    Detail::from(Problem::MapNotFinite {
                        t: self.time(k + 1).hi(),
                    })
                    .at(Culprit::State(i)),
                ));
            }
            let radii = self.advance(l, s);
            let set = box_set(&next, &radius);
            pieces.push(self.piece(k, steps, stride, set, (l, s), radii));
            x = next;
        }
        Ok(pieces)
    }

    /// The piece of step `k` (to `t_(k+1)`), its set reported where `k + 1` is a report step.
    fn piece(
        &self,
        k: usize,
        steps: usize,
        stride: usize,
        set: DetSet,
        rates: (f64, f64),
        radii: (f64, f64),
    ) -> Stepped {
        let end = k + 1;
        let t1 = if end == steps {
            self.run.spec.horizon
        } else {
            end as f64 * self.period
        };
        let piece = Piece {
            t1,
            rates,
            // (The stochastic radius is added by the assembly, the largest of the interval's.)
            over: span_of(&set, 0.0),
            end: (end.is_multiple_of(stride) || end == steps).then_some(set),
        };
        (piece, radii)
    }
}
