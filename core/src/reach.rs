//! [`Reach`]: one analysis of a model, checked once, run from any initial set inside what its
//! constants were certified for.

use crate::engine::{
    self, check_initial, union, BoxMemo, Constraint, Detail, Inputs, Needs, Note, Problem, Run,
    RunError, Setting, Setup, TightenError, Tightening,
};
use crate::interval::Interval;
use crate::model::{
    Analysis, AnalysisSpec, Bounds, Constants, Guarantee, Inclusion, InitialSet, Method, ModelInfo,
    Rate, Split, Time,
};
use crate::prs::{Prs, Role, Verdict};
use crate::system::{Model, System};
use crate::workers::Workers;
use std::time::{Duration, Instant};

/// An analysis of a model, ready to run: its parameters checked, its certified constants
/// checked against the model data (domain, input box, horizon) and kept private, the metric
/// factorised and the unsafe sets prepared, once.
///
/// Through it a caller chooses where the sets start ([`Reach::from_box`], [`Reach::from_set`])
/// and, optionally, a known input signal ([`Reach::from_box_with`]); what the constants were
/// certified for cannot be changed: an initial set outside the spec's domain, or an input plan
/// outside the input box, is an error.
///
/// ```ignore
/// let reach = Reach::new(&Pendulum, pendulum::analysis::CONTRACTION)?;
/// let prs = reach.from_box(&[Bounds::new(-0.1, 0.1), Bounds::new(-0.2, 0.2)])?;
/// let radius_at_1 = prs.at(1.0).unwrap().prs_radius;
/// ```
pub struct Reach<'a> {
    sys: &'a dyn System,
    info: &'a ModelInfo,
    spec: AnalysisSpec,
    setup: Setup<'a>,
    /// The setups of the analysis' further metrics (`metric = auto(states = [..])`).
    also: Vec<Setup<'a>>,
    /// The setups of the metrics run as well, the smallest result kept
    /// ([`Constants::alternatives`](crate::model::Constants::alternatives)).
    alternatives: Vec<Setup<'a>>,
    /// The embedding's boxes of its runs, kept for those that repeat them.
    memo: BoxMemo,
}

impl<'a> Reach<'a> {
    /// The analysis `name` of `model`.
    pub fn new(model: &'a dyn Model, name: &str) -> Result<Reach<'a>, RunError> {
        Reach::named(model, model.info(), name)
    }

    /// The analysis `name` of the system `sys` with the model data `info`: test support
    /// (feature `test-util`), for tests of hand-written systems and data.
    #[cfg(feature = "test-util")]
    #[doc(hidden)]
    pub fn paired(
        sys: &'a dyn System,
        info: &'a ModelInfo,
        name: &str,
    ) -> Result<Reach<'a>, RunError> {
        Reach::named(sys, info, name)
    }

    /// `analysis` (built by hand) of the system `sys` with the model data `info`: test support
    /// (feature `test-util`).
    #[cfg(feature = "test-util")]
    #[doc(hidden)]
    pub fn for_analysis(
        sys: &'a dyn System,
        info: &'a ModelInfo,
        analysis: &'a Analysis,
    ) -> Result<Reach<'a>, RunError> {
        Reach::of(sys, info, analysis)
    }

    /// The analysis `name` of `info`, run with `sys`.
    fn named(sys: &'a dyn System, info: &'a ModelInfo, name: &str) -> Result<Reach<'a>, RunError> {
        let analysis = info
            .analysis(name)
            .ok_or_else(|| RunError::UnknownAnalysis {
                name: name.to_string(),
                available: info.analyses.iter().map(|a| a.spec.name.clone()).collect(),
            })?;
        Reach::of(sys, info, analysis)
    }

    /// `analysis` of `info`, run with `sys`.
    fn of(
        sys: &'a dyn System,
        info: &'a ModelInfo,
        analysis: &'a Analysis,
    ) -> Result<Reach<'a>, RunError> {
        let spec = &analysis.spec;
        let needs = match (spec.method, spec.rate) {
            // A discrete-time model's factors are bounded at run time, for either guarantee.
            _ if info.time() != Time::Continuous => Needs {
                c: false,
                sigma: false,
                rho: false,
            },
            (_, Rate::Local) if spec.guarantee != Guarantee::Uniform => {
                return Err(RunError::Unsupported(
                    Detail::from(Problem::LocalPointwise).at_setting(Setting::Rate),
                ))
            }
            (_, Rate::Local) => Needs {
                c: false,
                sigma: false,
                rho: false,
            },
            (Method::Interval, Rate::Global) => Needs {
                c: true,
                sigma: true,
                rho: false,
            },
            (Method::Interval, rate) => {
                return Err(RunError::Unsupported(
                    Detail::from(Problem::IntervalRate(rate)).at_setting(Setting::Rate),
                ))
            }
            (Method::Contraction, Rate::Global) => Needs {
                c: true,
                sigma: true,
                rho: true,
            },
            (Method::Contraction, Rate::Empirical { .. }) => Needs {
                c: false,
                sigma: true,
                rho: true,
            },
        };
        let setup = Setup::new(sys, info, spec, &analysis.constants, needs)?;
        let setups = |of: fn(&Constants) -> &Vec<Constants>| match &analysis.constants {
            Ok(c) => of(c)
                .iter()
                .map(|k| Setup::with(sys, info, spec, k, needs))
                .collect::<Result<Vec<_>, _>>(),
            Err(_) => Ok(Vec::new()),
        };
        Ok(Reach {
            sys,
            info,
            spec: spec.clone(),
            setup,
            also: setups(|c| &c.also)?,
            alternatives: setups(|c| &c.alternatives)?,
            memo: BoxMemo::default(),
        })
    }

    /// The constraints a nominal plan must meet, per report interval, for the stochastic
    /// system to meet `constraints` and avoid the model's unsafe sets with probability at least
    /// `1 - delta` (method.md 8.14), from `prs`, a result of this analysis (from the start the
    /// plan starts at, or an initial set holding it).
    pub fn tighten(
        &self,
        prs: &Prs,
        constraints: &[Constraint],
    ) -> Result<Tightening, TightenError> {
        engine::tighten(prs, constraints, &self.info.unsafe_sets)
    }

    /// The same analysis at another probability level `delta` in `(0, 1)` (the constants do
    /// not depend on it).
    pub fn with_delta(mut self, delta: f64) -> Result<Reach<'a>, RunError> {
        self.spec.delta = delta;
        engine::validate(self.info, &self.spec, self.setup.n, self.setup.p)?;
        Ok(self)
    }

    /// The same analysis with another inclusion function (interval method; the constants do
    /// not depend on it).
    pub fn with_inclusion(mut self, inclusion: Inclusion) -> Reach<'a> {
        self.spec.inclusion = inclusion;
        self
    }

    /// The analysis as it runs.
    pub fn analysis(&self) -> &AnalysisSpec {
        &self.spec
    }

    /// The model.
    pub fn model(&self) -> &ModelInfo {
        self.info
    }

    /// The PRS from the spec's initial set, for any input in the input box.
    pub fn run(&self) -> Result<Prs, RunError> {
        self.from_set(&self.info.initial)
    }

    /// The PRS from the initial box `x0` (one range per state), for any input in the input box.
    pub fn from_box(&self, x0: &[Bounds]) -> Result<Prs, RunError> {
        self.from_set(&self.initial_box(x0)?)
    }

    /// The PRS from the initial box `x0` under the known input signal `plan`.
    pub fn from_box_with(&self, x0: &[Bounds], plan: &InputPlan) -> Result<Prs, RunError> {
        self.from_set_with(&self.initial_box(x0)?, plan)
    }

    /// The PRS from the initial set `x0`, for any input in the input box.
    pub fn from_set(&self, x0: &InitialSet) -> Result<Prs, RunError> {
        self.run_from(x0, Inputs::Box)
    }

    /// The PRS from the initial set `x0` under the known input signal `plan`.
    pub fn from_set_with(&self, x0: &InitialSet, plan: &InputPlan) -> Result<Prs, RunError> {
        plan.check(&self.info.input_box)?;
        if let Rate::Empirical { .. } = self.spec.rate {
            return Err(RunError::Unsupported(
                Detail::from(Problem::PlanWithEmpiricalRate).at_setting(Setting::Rate),
            ));
        }
        self.run_from(x0, Inputs::Plan(plan))
    }

    fn initial_box(&self, x0: &[Bounds]) -> Result<InitialSet, RunError> {
        if x0.len() != self.setup.n {
            return Err(RunError::Invalid(
                Problem::InitialBoxSize {
                    ranges: x0.len(),
                    n: self.setup.n,
                }
                .into(),
            ));
        }
        Ok(InitialSet::from_box(x0))
    }

    fn run_from(&self, initial: &InitialSet, inputs: Inputs) -> Result<Prs, RunError> {
        self.run_spec(&self.spec, initial, inputs)
    }

    /// The PRS of the spec's initial set and input box at another `delta` in `(0, 1)` (see
    /// [`Reach::with_delta`]).
    pub(crate) fn run_at(&self, delta: f64) -> Result<Prs, RunError> {
        let spec = AnalysisSpec {
            delta,
            ..self.spec.clone()
        };
        engine::validate(self.info, &spec, self.setup.n, self.setup.p)?;
        self.run_spec(&spec, &self.info.initial, Inputs::Box)
    }

    /// The result of `own` from `initial` with its goal verdicts (method.md 8.13), read off
    /// the finished result (the union of a split, the intersection of members).
    fn run_spec(
        &self,
        own: &AnalysisSpec,
        initial: &InitialSet,
        inputs: Inputs,
    ) -> Result<Prs, RunError> {
        let mut prs = self.run_sets(own, initial, inputs)?;
        let numbers = |t| crate::sweep::numbers(self.sys, self.info, t);
        prs.goals = engine::goals::assess(&self.info.goals, &prs, &numbers);
        Ok(prs)
    }

    fn run_sets(
        &self,
        own: &AnalysisSpec,
        initial: &InitialSet,
        inputs: Inputs,
    ) -> Result<Prs, RunError> {
        if own.split.pieces() == 1 {
            return self.run_piece(own, initial, inputs);
        }
        // Splitting (method.md 8.11): the initial box in pieces, each run at the full delta in
        // parallel, the PRS their union.
        let bounds = match initial.bounding_box() {
            Ok(b) if initial.balls.is_empty() => b,
            _ => {
                return Err(RunError::Unsupported(
                    Detail::from(Problem::SplitNotABox).at_setting(Setting::Split),
                ))
            }
        };
        let workers =
            Workers::new(None).map_err(|e| RunError::Invalid(Problem::Threads(e).into()))?;
        // A piece's failure says which piece.
        let run = |b: &[Bounds]| {
            self.run_piece(own, &InitialSet::from_box(b), inputs)
                .map_err(|e| {
                    let ranges = self.info.states.iter().cloned().zip(b.iter().copied());
                    e.in_piece(ranges.collect())
                })
        };
        let (split, pieces) = match &own.split {
            Split::Counts(counts) => {
                // A range of no width is not cut (its pieces would all be the same).
                let counts: Vec<usize> = counts
                    .iter()
                    .zip(&bounds)
                    .map(|(&k, b)| if b.lo < b.hi { k } else { 1 })
                    .collect();
                let results = workers.map(union::pieces(&bounds, &counts), |b| run(&b));
                (
                    Split::Counts(counts),
                    results.into_iter().collect::<Result<_, _>>()?,
                )
            }
            Split::Auto { pieces, seconds } => {
                let deadline = seconds.map(|s| Instant::now() + Duration::from_secs(s));
                let found = self.refine(bounds, (*pieces, deadline), &workers, &run)?;
                (own.split.clone(), found)
            }
            Split::Off => unreachable!("one piece"),
        };
        Ok(union::union(
            self.info,
            &self.setup.checks,
            initial,
            split,
            pieces,
        ))
    }

    /// `split = auto` (method.md 8.11): from the whole box, round after round, the worse half
    /// of the pieces still worth cutting (by the size of their sets, [`log_volume_sum`];
    /// pieces that cannot run first) are bisected along their widest state in the metric
    /// (`h_i sqrt(P_ii)`), within `budget` pieces and no round starting after the deadline (the
    /// time budget; the whole box always runs); a piece whose halves did not shrink its sets
    /// by [`AUTO_GAIN`] per report time is not cut again. The first piece that still cannot run
    /// when the budget is spent is the analysis' error. Every decision depends on earlier
    /// results only (deterministic, whatever the number of threads), except where the deadline
    /// ends the refinement.
    fn refine(
        &self,
        whole: Vec<Bounds>,
        (budget, deadline): (usize, Option<Instant>),
        workers: &Workers,
        run: &(dyn Fn(&[Bounds]) -> Result<Prs, RunError> + Sync),
    ) -> Result<Vec<Prs>, RunError> {
        let metric = &self.setup.consts.metric;
        let n = whole.len();
        let first = run(&whole);
        // (box, result, worth cutting): a piece that cannot run is cut like one whose sets are
        // infinite, and the analysis fails only if one is left when the budget is spent.
        let mut pieces = vec![(whole, first, true)];
        loop {
            let room = budget.saturating_sub(pieces.len());
            let mut order: Vec<usize> = (0..pieces.len())
                .filter(|&j| pieces[j].2 && pieces[j].0.iter().any(|b| b.lo < b.hi))
                .collect();
            if room == 0 || order.is_empty() || deadline.is_some_and(|d| Instant::now() >= d) {
                break;
            }
            let size: Vec<f64> = pieces
                .iter()
                .map(|p| p.1.as_ref().map_or(f64::INFINITY, log_volume_sum))
                .collect();
            order.sort_by(|&a, &b| size[b].total_cmp(&size[a]).then(a.cmp(&b)));
            order.truncate(order.len().div_ceil(2).min(room));
            order.sort_unstable();
            let halves: Vec<Vec<Bounds>> = order
                .iter()
                .flat_map(|&j| {
                    let b = &pieces[j].0;
                    // The widest state in the metric.
                    let i = (0..n)
                        .filter(|&i| b[i].lo < b[i].hi)
                        .max_by(|&x, &y| {
                            let w = |i: usize| (b[i].hi - b[i].lo) * metric[i * n + i].sqrt();
                            w(x).total_cmp(&w(y)).then(y.cmp(&x))
                        })
                        .expect("a piece worth cutting has width");
                    union::pieces(
                        b,
                        &(0..n).map(|s| 1 + usize::from(s == i)).collect::<Vec<_>>(),
                    )
                })
                .collect();
            let mut results = workers
                .map(halves, |b| {
                    let r = run(&b);
                    (b, r)
                })
                .into_iter();
            let mut next = Vec::with_capacity(pieces.len() + order.len());
            for (j, parent) in pieces.into_iter().enumerate() {
                if order.binary_search(&j).is_err() {
                    next.push(parent);
                    continue;
                }
                let (a, b) = (results.next().unwrap(), results.next().unwrap());
                // Halves that both run are worth cutting again while they shrank the sets;
                // a half that cannot run always is.
                let shrunk = match (&a.1, &b.1) {
                    (Ok(x), Ok(y)) => {
                        let steps = x.steps.len().saturating_sub(1).max(1) as f64;
                        log_volume_sum(x).max(log_volume_sum(y)) < size[j] - AUTO_GAIN.ln() * steps
                    }
                    _ => true,
                };
                next.push((a.0, a.1, shrunk));
                next.push((b.0, b.1, shrunk));
            }
            pieces = next;
        }
        pieces.into_iter().map(|(_, p, _)| p).collect()
    }

    /// The result of one piece of the initial set (the whole of it without a split).
    fn run_piece(
        &self,
        own: &AnalysisSpec,
        initial: &InitialSet,
        inputs: Inputs,
    ) -> Result<Prs, RunError> {
        // Local rates hold wherever the tube goes: the domain does not constrain them.
        check_initial(self.info, initial, own.rate != Rate::Local)?;
        // K metrics: each set at delta / K, the PRS their intersection (union bound).
        let k = 1 + self.also.len();
        let run_with = |setup: &Setup, spec: &AnalysisSpec, gaussian: Option<f64>| {
            engine::run_engine(&Run {
                sys: self.sys,
                info: self.info,
                spec,
                setup,
                initial,
                inputs,
                memo: &self.memo,
                gaussian,
            })
        };
        // With the linearised Gaussian sets (method.md 8.10) they take one more share of delta;
        // of that and the plain run, the better (a choice made from the results alone, both
        // being valid at delta).
        let gaussian = engine::gaussian_wanted(self.info, own, initial, self.setup.n);
        if k > 1 {
            let several = |shares: usize, with_gaussian: bool| -> Result<Prs, RunError> {
                // Rounded down, so that the shares sum to at most delta.
                let spec = AnalysisSpec {
                    delta: (own.delta / shares as f64).next_down(),
                    ..own.clone()
                };
                let first = run_with(&self.setup, &spec, with_gaussian.then_some(spec.delta))?;
                let others = self
                    .also
                    .iter()
                    .map(|s| run_with(s, &spec, None).map(|p| p.with_role(Role::Metric)))
                    .collect::<Result<_, _>>()?;
                Ok(engine::intersect(
                    self.info,
                    &self.setup.checks,
                    own.delta,
                    first,
                    others,
                ))
            };
            let plain = several(k, false);
            return match gaussian {
                true => pick(plain, several(k + 1, true), own.delta),
                false => plain,
            };
        }
        let one = |setup: &Setup| {
            let plain = run_with(setup, own, None);
            if !gaussian {
                return plain;
            }
            let half = AnalysisSpec {
                delta: (own.delta / 2.0).next_down(),
                ..own.clone()
            };
            let best = pick(plain, run_with(setup, &half, Some(half.delta)), own.delta);
            let Err(failed) = best else {
                return best;
            };
            // Where the analysis' own sets cannot be bounded, the linearised set alone.
            let alone = engine::run_alone(
                &Run {
                    sys: self.sys,
                    info: self.info,
                    spec: own,
                    setup,
                    initial,
                    inputs,
                    memo: &self.memo,
                    gaussian: Some(own.delta),
                },
                &failed,
            );
            match alone {
                Ok(Some(prs)) => Ok(prs),
                Ok(None) => Err(failed.noted(Note::AloneFailed)),
                Err(_) => Err(failed),
            }
        };
        // Alternatives: the result with the smallest box at the horizon (where one fails, the
        // others still stand).
        let size = |p: &Prs| p.hull(p.horizon).map_or(f64::INFINITY, |h| log_volume(&h));
        let mut best = one(&self.setup);
        for other in self.alternatives.iter().filter_map(|s| one(s).ok()) {
            if best.as_ref().map_or(true, |b| size(&other) < size(b)) {
                best = Ok(other);
            }
        }
        best
    }
}

/// Of the plain result of an analysis and the one `split` with the linearised Gaussian sets
/// (method.md 8.10; both valid at `delta`), the [`better`]; the plain one when the split run
/// fails or has no such set (it fails or cuts nowhere).
fn pick(
    plain: Result<Prs, RunError>,
    split: Result<Prs, RunError>,
    delta: f64,
) -> Result<Prs, RunError> {
    match split {
        Ok(mut split) if split.also.iter().any(|m| m.role == Role::Linearised) => {
            split.delta = delta;
            match plain {
                Ok(plain) if !better(&split, &plain) => Ok(plain),
                _ => Ok(split),
            }
        }
        _ => plain,
    }
}

/// Whether `a` is the better of two results of one analysis: shown safe where `b` is not, or
/// else bounding boxes of less volume summed (in logarithms) over the report times.
fn better(a: &Prs, b: &Prs) -> bool {
    let safe = |p: &Prs| matches!(p.verdict, Verdict::Safe);
    if safe(a) != safe(b) {
        return safe(a);
    }
    log_volume_sum(a) < log_volume_sum(b)
}

/// The size of a result's sets: the sum over the report times after 0 of the logarithm of its
/// bounding box's volume (half-widths, at least `1e-300`; infinite without a bounding box).
fn log_volume_sum(p: &Prs) -> f64 {
    (1..p.steps.len())
        .map(|k| {
            p.hull_at(k).map_or(f64::INFINITY, |h| {
                h.iter()
                    .map(|x| (0.5 * (x.hi - x.lo)).max(1e-300).ln())
                    .sum()
            })
        })
        .sum()
}

/// `split = auto` cuts a piece again only if cutting it shrank its sets by this factor per
/// report time (in volume; see [`Reach::refine`]).
const AUTO_GAIN: f64 = 1.1;

/// A known input signal: piecewise constant on the analysis' report steps, `u(t) = f(t_k)` on
/// `[t_k, t_(k+1))`. With a plan the sets cover the trajectories under exactly that input (no
/// input uncertainty, `r2 = 0`); its values must lie in the spec's input box, where the
/// constants hold.
#[derive(Clone, Debug, PartialEq)]
pub struct InputPlan {
    /// Switching times, increasing, the first 0.
    times: Vec<f64>,
    /// The input from each switching time on.
    values: Vec<Vec<f64>>,
}

impl InputPlan {
    /// The same input `u` at all times.
    pub fn constant(u: &[f64]) -> InputPlan {
        InputPlan {
            times: vec![0.0],
            values: vec![u.to_vec()],
        }
    }

    /// The input `values[k]` from `times[k]` on (until `times[k + 1]`); `times` increasing,
    /// starting at 0. The engines hold the value in force at the start of each report step for
    /// the whole step.
    pub fn steps(times: Vec<f64>, values: Vec<Vec<f64>>) -> Result<InputPlan, RunError> {
        let increasing = times.windows(2).all(|w| w[0] < w[1]);
        if times.first() != Some(&0.0) || !increasing || times.len() != values.len() {
            return Err(RunError::Invalid(Problem::PlanTimes.into()));
        }
        Ok(InputPlan { times, values })
    }

    /// The input at time `t >= 0`.
    pub fn at(&self, t: f64) -> &[f64] {
        let k = self.times.partition_point(|&s| s <= t).saturating_sub(1);
        &self.values[k]
    }

    /// Checks the values against the input box.
    fn check(&self, input_box: &[Bounds]) -> Result<(), RunError> {
        for u in &self.values {
            if u.len() != input_box.len() {
                return Err(RunError::Invalid(
                    Problem::PlanValueSize {
                        entries: u.len(),
                        p: input_box.len(),
                    }
                    .into(),
                ));
            }
            let inside = u
                .iter()
                .zip(input_box)
                .all(|(&v, b)| Interval::try_new(b.lo, b.hi).is_some_and(|iv| iv.contains(v)));
            if !inside {
                return Err(RunError::Invalid(
                    Problem::PlanValueOutside(u.clone()).into(),
                ));
            }
        }
        Ok(())
    }
}

/// The sum of the logs of a box's half-widths (`-inf` for a degenerate box).
fn log_volume(b: &[Bounds]) -> f64 {
    b.iter().map(|x| (0.5 * (x.hi - x.lo)).ln()).sum()
}
