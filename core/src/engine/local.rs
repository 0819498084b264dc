//! Local rates on the tube (method.md section 8.3, `rate = local`): per internal step, `c_k`,
//! `sigma_k` and `rho_k` certified over a box `D_k` that holds the deterministic set over the
//! step widened by the time-uniform tube's radius. Up to the first exit from the regions, the
//! pair `(X_t, x_t)` stays in a convex `D_k`, so the proof's contraction step and the
//! supermartingale hold with the local rates; on Ville's event the process is strictly inside
//! the tube, hence inside `D_k`, so it never exits. No global rate and no domain are needed.
//!
//! The regions depend on the tube and the tube on the rates, so each step guesses a region from
//! the previous rates, certifies rates over it, and accepts them only if the tube they give over
//! the step lies strictly inside the region; otherwise it inflates and retries.
//!
//! The certificate over a box, for `P = L L'` (`R = L'`, `|x|_P = |R x|`):
//! `mu_P(J) = lambda_max(sym(R J R^-1))` bounded over the interval Jacobian by the midpoint's
//! verified `lambda_max` plus the spectral radius bound of the radius matrix (or interval
//! Cholesky, whichever is smaller; Gershgorin for large sparse systems);
//! `sigma^2 = lambda_max(R G G' R')` over the interval `G`; `rho` by columns of `R D_u f`
//! scaled by the input box's half-widths. Where the compiler's global constants hold on the
//! region (no domain, or the region inside it), the smaller of the two is used.

use super::assemble::spread;
use super::linalg::{self, lambda_max, product, symmetric_part};
use super::uniform::{Scale, Tube};
use super::{Detail, JacobianEntry, Problem, Run, RunError, Setting};
use crate::interval::Interval;
use crate::model::Bounds;
use crate::prs::RateRegion;
use crate::system::System;

/// Up to this many states the rates use dense interval matrices; above, a diagonal metric and
/// Gershgorin bounds in time proportional to the Jacobian's non-zeros.
pub(crate) const DENSE_MAX: usize = 64;

/// The most Jacobian entries enumerated at their ends (`2^6` vertex matrices per bound).
const VERTEX_ENTRIES: usize = 6;

/// Up to this many states the vertex refinement runs (its cost grows as `2^6 n^3`).
const VERTEX_DIM: usize = 8;

/// Attempts per step to find a region that holds its own tube.
const MAX_TRIES: usize = 12;

/// Each attempt's region exceeds what the current rates need by this factor.
const INFLATE: f64 = 1.25;

/// Passes over the horizon: the tube's epochs are laid out from the previous pass's scale.
const MAX_PASSES: usize = 3;

/// Rates certified over a region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Rates {
    pub(super) c: f64,
    pub(super) sigma: f64,
    pub(super) rho: f64,
}

impl Rates {
    fn max(self, o: Rates) -> Rates {
        Rates {
            c: self.c.max(o.c),
            sigma: self.sigma.max(o.sigma),
            rho: self.rho.max(o.rho),
        }
    }

    fn is_finite(self) -> bool {
        self.c.is_finite() && self.sigma.is_finite() && self.rho.is_finite()
    }
}

/// Certifies [`Rates`] over boxes of states, for the analysis' metric.
pub(super) struct Certifier<'a> {
    sys: &'a dyn System,
    states: &'a [String],
    n: usize,
    /// `R = L'`, upper triangular, and an enclosure of `R^-1` (dense route), or the diagonal
    /// of `R` (sparse route).
    r: Vec<Interval>,
    r_inv: Vec<Interval>,
    dense: bool,
    pattern: Vec<(usize, usize)>,
    inputs: Vec<Interval>,
    half: Vec<Interval>,
    /// The compiler's constants, with the box they hold on (`None`: all of R^n).
    global: Option<(Rates, Option<Vec<Bounds>>)>,
    /// Whether the run may lean on the domain's constants at all (its initial set lies in
    /// the domain), and whether each step's hull (the nominal's) must lie in it too.
    lean_start: bool,
    lean_hull: bool,
    /// The noise level when `G` is the same everywhere and at all times (bounded once).
    constant_noise: Option<f64>,
}

/// Why no rates: the Jacobian entry with the largest magnitude over the region.
pub(super) struct Grew {
    entry: Option<(usize, usize, Interval)>,
}

impl<'a> Certifier<'a> {
    /// The certifier of a run: its metric, input box and the compiler's constants.
    pub(super) fn new(run: &Run<'a>) -> Result<Certifier<'a>, RunError> {
        let (sys, n, consts) = (run.sys, run.setup.n, run.setup.consts);
        let chol = linalg::cholesky(&linalg::to_intervals(&consts.metric), n).ok_or_else(|| {
            RunError::Invalid(
                Detail::from(Problem::LocalMetricIndefinite).at_setting(Setting::Metric),
            )
        })?;
        let diagonal = (0..n).all(|i| (0..n).all(|j| i == j || consts.metric[i * n + j] == 0.0));
        let dense = n <= DENSE_MAX;
        if !dense && !diagonal {
            return Err(RunError::Unsupported(
                Detail::from(Problem::LocalRatesNeedDiagonal { max: DENSE_MAX })
                    .at_setting(Setting::Rate),
            ));
        }
        let (r, r_inv) = if dense {
            let mut r = vec![Interval::ZERO; n * n];
            let mut r_inv = vec![Interval::ZERO; n * n];
            for j in 0..n {
                let mut e = vec![Interval::ZERO; n];
                e[j] = Interval::ONE;
                // Column j of L^-1 is row j of R^-1 = (L^-1)'.
                let col = linalg::forward_solve(&chol, n, &e);
                for i in 0..n {
                    r[i * n + j] = chol[j * n + i];
                    r_inv[j * n + i] = col[i];
                }
            }
            (r, r_inv)
        } else {
            let d: Vec<Interval> = (0..n).map(|i| chol[i * n + i]).collect();
            let inv = d.iter().map(|x| x.recip()).collect();
            (d, inv)
        };
        let inputs = super::input_intervals(run.info);
        let half = inputs.iter().map(|u| Interval::point(u.rad())).collect();
        let global = Rates {
            c: consts.c,
            sigma: consts.sigma,
            rho: consts.rho,
        };
        let domain = run.info.has_domain.then(|| run.info.domain.clone());
        // Leaning on the domain's constants (conditional on staying in it) takes what
        // `rate = global` takes: an initial set in the domain, and for the contraction method
        // a nominal in it.
        let lean_start = domain.as_ref().is_some_and(|d| {
            run.initial.bounding_box().is_ok_and(|b| {
                b.iter()
                    .zip(d)
                    .all(|(x, dom)| x.lo >= dom.lo && x.hi <= dom.hi)
            })
        });
        let mut cert = Certifier {
            sys,
            states: &run.info.states,
            n,
            r,
            r_inv,
            dense,
            pattern: if dense {
                Vec::new()
            } else {
                sys.jac_x_pattern()
            },
            inputs: inputs
                .iter()
                .map(|u| Interval::new(u.lo(), u.hi()))
                .collect(),
            half,
            global: Some((global, domain)),
            lean_start,
            lean_hull: run.spec.method == crate::model::Method::Contraction,
            constant_noise: None,
        };
        // A diffusion whose enclosure over all states and times is a point (up to rounding) is
        // constant: its noise level, bounded once over everything, holds on every region.
        let (m, everywhere) = (sys.m(), vec![Interval::ENTIRE; n]);
        let mut g = vec![Interval::ZERO; n * m];
        let all_times = Interval::new(0.0, run.spec.horizon);
        sys.diffusion_interval(&everywhere, all_times, &mut g);
        if g.iter()
            .all(|v| v.is_bounded() && v.width() <= 1e-12 * v.mag())
        {
            // Bounded over all times too: "constant" allows rounding-level variation in t.
            cert.constant_noise = Some(cert.noise(&everywhere, all_times));
        }
        Ok(cert)
    }

    /// Rates over the box `x` of states, inputs in the input box, times in `t`, and whether
    /// they lean on the domain: where the box leaves the spec's domain and the compiler's
    /// constants are smaller than the box's own, those are used, conditional on the process
    /// staying in the domain (the semantics of `rate = global`), so local rates are never
    /// above the global ones.
    ///
    /// `lean`: whether the step may lean on the domain ([`Certifier::may_lean`]).
    pub(super) fn rates(
        &self,
        x: &[Interval],
        t: Interval,
        lean: bool,
    ) -> Result<(Rates, bool), Grew> {
        let (global, inside) = match &self.global {
            Some((g, domain)) if g.is_finite() => {
                let inside = domain.as_ref().is_none_or(|d| within(x, d));
                (Some(*g).filter(|_| inside || lean), inside)
            }
            _ => (None, false),
        };
        let sigma = match self.constant_noise {
            Some(sigma) => sigma,
            None => self.noise(x, t),
        };
        let cap = global.filter(|_| inside).map(|g| g.c);
        let local = match self.rate(x, t, cap) {
            Ok(c) => Rates {
                c,
                sigma,
                rho: self.gain(x, t),
            },
            // Unbounded on the box: the domain's constants if there are any.
            Err(grew) => match global {
                Some(g) => return Ok((g, !inside)),
                None => return Err(grew),
            },
        };
        Ok(match global {
            Some(g) => {
                let min = Rates {
                    c: local.c.min(g.c),
                    sigma: local.sigma.min(g.sigma),
                    rho: local.rho.min(g.rho),
                };
                (min, !inside && min != local)
            }
            None => (local, false),
        })
    }

    /// Whether a step whose deterministic hull is `[lo, hi]` may lean on the domain's constants:
    /// what `rate = global` requires of a run (see `lean_start`, `lean_hull`).
    pub(super) fn may_lean(&self, lo: &[f64], hi: &[f64], w: &[f64]) -> bool {
        let Some((_, Some(domain))) = &self.global else {
            return false;
        };
        self.lean_start && (!self.lean_hull || within(&widen(lo, hi, 0.0, w), domain))
    }

    /// An upper bound of `mu_P(D_x f)` over the box; `cap`, a rate known to hold there, spares
    /// the vertex refinement when the direct bound cannot beat it.
    fn rate(&self, x: &[Interval], t: Interval, cap: Option<f64>) -> Result<f64, Grew> {
        let n = self.n;
        if self.dense {
            let mut j = vec![Interval::ZERO; n * n];
            self.sys.jac_x_interval(x, &self.inputs, t, &mut j);
            if let Some(k) = j.iter().position(|v| !v.is_bounded()) {
                return Err(Grew {
                    entry: Some((k / n, k % n, j[k])),
                });
            }
            let b = product(&product(&self.r, &j, n, n, n), &self.r_inv, n, n, n);
            let mut rate = lambda_max(&symmetric_part(&b, n), n);
            if n <= VERTEX_DIM && cap.is_none_or(|cap| rate < cap) {
                rate = rate.min(self.vertex_rate(&j));
            }
            if rate.is_finite() {
                Ok(rate)
            } else {
                Err(Grew {
                    entry: largest(&j, n),
                })
            }
        } else {
            let mut j = vec![Interval::ZERO; self.pattern.len()];
            self.sys.jac_x_sparse_interval(x, &self.inputs, t, &mut j);
            // Gershgorin on sym(D J D^-1): row i gets the diagonal's upper end and half the
            // magnitudes of (i, j) and (j, i).
            let mut row = vec![Interval::ZERO; n];
            for (&(i, k), &v) in self.pattern.iter().zip(&j) {
                if !v.is_bounded() {
                    return Err(Grew {
                        entry: Some((i, k, v)),
                    });
                }
                let b = self.r[i] * v * self.r_inv[k];
                if i == k {
                    row[i] += Interval::point(b.hi());
                } else {
                    let half = Interval::point(b.mag()) * Interval::point(0.5);
                    row[i] += half;
                    row[k] += half;
                }
            }
            Ok(row.iter().map(|v| v.hi()).fold(f64::NEG_INFINITY, f64::max))
        }
    }

    /// An upper bound of `lambda_max(sym(R J R^-1))` over the interval matrix `j` (dense). The
    /// bound is convex in `J`, so its supremum over the widest entries' ranges is attained at
    /// their ends: those entries are enumerated at their ends (the others stay intervals).
    fn vertex_rate(&self, j: &[Interval]) -> f64 {
        let n = self.n;
        let mut wide: Vec<usize> = (0..n * n).filter(|&k| j[k].width() > 0.0).collect();
        wide.sort_by(|&a, &b| j[b].width().total_cmp(&j[a].width()));
        wide.truncate(VERTEX_ENTRIES);
        let mut vertex = j.to_vec();
        let mut worst = f64::NEG_INFINITY;
        for mask in 0..1usize << wide.len() {
            for (bit, &k) in wide.iter().enumerate() {
                let end = if mask >> bit & 1 == 1 {
                    j[k].hi()
                } else {
                    j[k].lo()
                };
                vertex[k] = Interval::point(end);
            }
            let b = product(&product(&self.r, &vertex, n, n, n), &self.r_inv, n, n, n);
            worst = worst.max(lambda_max(&symmetric_part(&b, n), n));
        }
        worst
    }

    /// An upper bound of `sqrt(lambda_max(R G G' R'))` over the box (infinite if unbounded).
    fn noise(&self, x: &[Interval], t: Interval) -> f64 {
        let (n, m) = (self.n, self.sys.m());
        if m == 0 {
            return 0.0;
        }
        let mut g = vec![Interval::ZERO; n * m];
        self.sys.diffusion_interval(x, t, &mut g);
        if self.dense {
            let rg = product(&self.r, &g, n, n, m);
            let mut w = vec![Interval::ZERO; n * n];
            for i in 0..n {
                for k in 0..=i {
                    let mut s = Interval::ZERO;
                    for l in 0..m {
                        s += rg[i * m + l] * rg[k * m + l];
                    }
                    w[i * n + k] = s;
                    w[k * n + i] = s;
                }
            }
            lambda_max(&w, n).max(0.0).sqrt().next_up()
        } else {
            // ||M||_2 <= sqrt(||M||_1 ||M||_inf) on the magnitudes of M = R G.
            let (mut rows, mut cols) = (vec![Interval::ZERO; n], vec![Interval::ZERO; m]);
            for i in 0..n {
                for l in 0..m {
                    let v = Interval::point((self.r[i] * g[i * m + l]).mag());
                    rows[i] += v;
                    cols[l] += v;
                }
            }
            let top = |v: &[Interval]| v.iter().map(|x| x.hi()).fold(0.0, f64::max);
            (Interval::point(top(&rows)) * Interval::point(top(&cols)))
                .sqrt()
                .hi()
        }
    }

    /// An upper bound of `sup |D_u f v|_P` over `|v|_U <= 1` (the sum of the column norms of
    /// `R D_u f diag(h)`).
    fn gain(&self, x: &[Interval], t: Interval) -> f64 {
        let (n, p) = (self.n, self.sys.p());
        if p == 0 {
            return 0.0;
        }
        let mut ju = vec![Interval::ZERO; n * p];
        self.sys.jac_u_interval(x, &self.inputs, t, &mut ju);
        let m = if self.dense {
            product(&self.r, &ju, n, n, p)
        } else {
            (0..n * p).map(|k| self.r[k / p] * ju[k]).collect()
        };
        let mut total = Interval::ZERO;
        for j in 0..p {
            let mut s = Interval::ZERO;
            for i in 0..n {
                s += Interval::point(m[i * p + j].mag()).sqr();
            }
            total += s.sqrt() * self.half[j];
        }
        total.hi()
    }

    /// The diagnostic for a region whose rates cannot be bounded or do not settle.
    fn explain(&self, t0: f64, x: &[Interval], grew: Option<Grew>) -> RunError {
        let region = self.states.iter().cloned().zip(x.iter().copied()).collect();
        let entry = grew
            .and_then(|g| g.entry)
            .or_else(|| {
                let mut j = vec![Interval::ZERO; self.n * self.n];
                self.sys
                    .jac_x_interval(x, &self.inputs, Interval::point(t0), &mut j);
                largest(&j, self.n)
            })
            .map(|(i, k, v)| JacobianEntry {
                row: self.states[i].clone(),
                col: self.states[k].clone(),
                value: v,
            });
        RunError::NonFinite(
            Detail::from(Problem::LocalRates {
                t: t0,
                region,
                entry,
            })
            .at_setting(Setting::Horizon),
        )
    }
}

/// The entry of largest magnitude (non-finite first).
fn largest(j: &[Interval], n: usize) -> Option<(usize, usize, Interval)> {
    let k = (0..j.len()).max_by(|&a, &b| {
        let key = |v: Interval| {
            if v.is_bounded() {
                v.mag()
            } else {
                f64::INFINITY
            }
        };
        key(j[a]).total_cmp(&key(j[b]))
    })?;
    Some((k / n, k % n, j[k]))
}

/// Steps along the horizon, certifying each step's rates on a region holding its tube.
pub(super) struct Stepper<'a> {
    cert: &'a Certifier<'a>,
    /// The tube the regions must hold; `None` in the first pass (the deterministic set only:
    /// an estimate of the scale for laying out the epochs).
    tube: Option<&'a Tube>,
    /// `B_P(r)` lies in the box `|d_i| <= r w_i`.
    w: &'a [f64],
    pub(super) scale: Scale,
    pub(super) regions: Vec<RateRegion>,
    /// The last accepted rates (the next step's first guess).
    last: Option<Rates>,
    /// Where the local rates could not be closed and the domain's global constants took over
    /// (the result is conditional on the domain from then on).
    pub(super) global_from: Option<f64>,
}

impl<'a> Stepper<'a> {
    pub(super) fn new(cert: &'a Certifier<'a>, tube: Option<&'a Tube>, w: &'a [f64]) -> Self {
        Stepper {
            cert,
            tube,
            w,
            scale: Scale::new(std::iter::empty()),
            regions: Vec::new(),
            last: None,
            global_from: None,
        }
    }

    /// The rates of the step `[t0, t1]` whose deterministic set lies in the box `[lo, hi]`
    /// widened by the P-radius `det(rates)` (which may depend on the rates: `R_t` of the
    /// contraction method). Where a region leans on the domain's constants, or no region closes
    /// and the spec has a domain with finite constants (then those hold for the step), the
    /// result becomes conditional on the domain from that step on, as with `rate = global`;
    /// otherwise a step that does not close is an error that says where and why.
    pub(super) fn step(
        &mut self,
        lo: &[f64],
        hi: &[f64],
        (t0, t1): (f64, f64),
        det: impl Fn(Rates) -> f64,
    ) -> Result<Rates, RunError> {
        let h = Interval::point(t1) - Interval::point(t0);
        let (rates, region) = match self.close(lo, hi, (t0, t1), h, &det) {
            Ok((rates, region, conditional)) => {
                if conditional {
                    self.global_from.get_or_insert(t0);
                }
                (rates, region)
            }
            Err(why) => {
                // The same semantics as `rate = global` from here on: the constants hold on
                // the domain, and the result is conditional on the process staying in it.
                let lean = self.cert.may_lean(lo, hi, self.w);
                let fallback = self.cert.global.as_ref().and_then(|(g, domain)| {
                    let domain = domain.as_ref()?;
                    (lean && g.is_finite()).then(|| {
                        let region = domain.iter().map(|b| Interval::new(b.lo, b.hi)).collect();
                        (*g, region)
                    })
                });
                match (fallback, why) {
                    (Some(found), _) => {
                        self.global_from.get_or_insert(t0);
                        found
                    }
                    (None, Some(why)) => return Err(why),
                    (None, None) => {
                        return Err(self.cert.explain(t0, &widen(lo, hi, 0.0, self.w), None))
                    }
                }
            }
        };
        self.scale.push(h, rates.c, rates.sigma);
        self.regions.push(RateRegion {
            t0,
            t1,
            lo: region.iter().map(|v: &Interval| v.lo()).collect(),
            hi: region.iter().map(|v| v.hi()).collect(),
            c: rates.c,
            sigma: rates.sigma,
            rho: rates.rho,
        });
        self.last = Some(rates);
        Ok(rates)
    }

    /// Guess, verify, inflate: rates certified over a region that holds the tube they give.
    fn close(
        &self,
        lo: &[f64],
        hi: &[f64],
        (t0, t1): (f64, f64),
        h: Interval,
        det: &impl Fn(Rates) -> f64,
    ) -> Result<(Rates, Vec<Interval>, bool), Option<RunError>> {
        let time = Interval::new(t0, t1);
        let last = self.scale.psi.len() - 1;
        let (psi0, s0) = (self.scale.psi[last], self.scale.s[last]);
        // The P-radius the region must hold with these rates: the deterministic set's and the
        // tube's largest over the step.
        let need = |r: Rates| -> f64 {
            let tube = self.tube.map_or(0.0, |tube| {
                let (psi1, s1) = self.scale.next(h, r.c, r.sigma);
                tube.radius(psi0.hull(psi1), s0.hull(s1))
            });
            (Interval::point(det(r)) + Interval::point(tube)).hi()
        };
        // Absolute floor of the region's margin, so a zero-width tube still gets a region.
        let floor = 1e-9 * lo.iter().chain(hi).fold(1.0f64, |m, v| m.max(v.abs()));
        let mut tried = widen(lo, hi, floor, self.w);
        let lean = self.cert.may_lean(lo, hi, self.w);
        let certify = |region: &[Interval]| {
            self.cert
                .rates(region, time, lean)
                .map_err(|grew| Some(self.cert.explain(t0, region, Some(grew))))
        };
        let mut guess = match self.last {
            Some(prev) => prev,
            None => certify(&tried)?.0,
        };
        for _ in 0..MAX_TRIES {
            let g = need(guess) * INFLATE + floor;
            if !g.is_finite() {
                break;
            }
            tried = widen(lo, hi, g, self.w);
            // `conditional`: the rates lean on the domain (see `Certifier::rates`).
            let (rates, conditional) = certify(&tried)?;
            if !rates.is_finite() {
                break;
            }
            if need(rates) < g {
                return Ok((rates, tried, conditional));
            }
            guess = guess.max(rates);
        }
        Err(Some(self.cert.explain(t0, &tried, None)))
    }
}

/// Whether the box `x` lies in the box `d`.
fn within(x: &[Interval], d: &[Bounds]) -> bool {
    x.iter()
        .zip(d)
        .all(|(v, b)| v.lo() >= b.lo && v.hi() <= b.hi)
}

/// The box `[lo, hi]` widened by the P-ball of radius `g` (rounded outward).
fn widen(lo: &[f64], hi: &[f64], g: f64, w: &[f64]) -> Vec<Interval> {
    lo.iter()
        .zip(hi)
        .zip(w)
        .map(|((&a, &b), &w)| {
            let d = Interval::point(g) * Interval::point(w);
            Interval::new((Interval::point(a) - d).lo(), (Interval::point(b) + d).hi())
        })
        .collect()
}

/// A run's local rates: the passes' last result, the tube it holds and its regions.
pub(super) struct Local<T> {
    pub(super) result: T,
    pub(super) tube: Tube,
    pub(super) regions: Vec<RateRegion>,
    /// When the domain's global constants took over (see [`Stepper::step`]).
    pub(super) global_from: Option<f64>,
}

/// What a run's result keeps of its local rates.
pub(super) struct Found {
    pub(super) tube: Tube,
    pub(super) regions: Vec<RateRegion>,
    pub(super) global_from: Option<f64>,
}

impl Found {
    pub(super) fn of<T>(local: &Local<T>) -> Found {
        Found {
            tube: local.tube.clone(),
            regions: local.regions.clone(),
            global_from: local.global_from,
        }
    }
}

/// The first pass of [`passes`] (no tube yet) alone, for its error: a run whose first report
/// interval's rates cannot be certified stops there with the error the whole run's first pass
/// would give, the regions and steps being the same up to that point.
pub(super) fn pilot<T>(
    run: &Run,
    mut pass: impl FnMut(&mut Stepper) -> Result<(T, usize), RunError>,
) -> Result<(), RunError> {
    let cert = Certifier::new(run)?;
    let w = spread(run);
    pass(&mut Stepper::new(&cert, None, &w)).map(|_| ())
}

/// Runs `pass` (one sweep of the horizon with a [`Stepper`]; returns its result and the index
/// into the scale of the first report time) until the tube's epochs fit the scale: the first
/// pass without a tube, then with the epochs of the previous pass's scale.
pub(super) fn passes<T>(
    run: &Run,
    mut pass: impl FnMut(&mut Stepper) -> Result<(T, usize), RunError>,
) -> Result<Local<T>, RunError> {
    let cert = Certifier::new(run)?;
    let w = spread(run);
    let (n, delta) = (run.setup.n, run.spec.delta);
    let mut stepper = Stepper::new(&cert, None, &w);
    let (_, first) = pass(&mut stepper)?;
    let mut tube = Tube::for_scale(n, delta, &stepper.scale, first);
    let mut passes = 1;
    loop {
        let (result, first, scale, regions, global_from) = {
            let mut stepper = Stepper::new(&cert, Some(&tube), &w);
            let (result, first) = pass(&mut stepper)?;
            (
                result,
                first,
                stepper.scale,
                stepper.regions,
                stepper.global_from,
            )
        };
        passes += 1;
        let s_last = scale.s.last().map_or(0.0, |s| s.hi());
        // Accepted when the epochs reach the horizon's S (any epochs are sound; these are
        // tight), or after the last pass.
        if s_last <= tube.s_last() * (1.0 + 1e-6) || passes >= MAX_PASSES {
            return Ok(Local {
                result,
                tube,
                regions,
                global_from,
            });
        }
        tube = Tube::for_scale(n, delta, &scale, first);
    }
}
