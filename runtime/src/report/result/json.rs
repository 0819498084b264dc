//! A result as JSON: a [`Prs`] as the result file's [`ResultJson`], written pretty-printed.

use super::words::{margin_unit, proved, r1_how, rate_note, unproved, ALONE_NOTE};
use crate::report::probability::Probabilities;
use crate::report::schema::{
    AutoJson, ConstantsJson, DetSetJson, GaussianJson, GoalJson, GoalMissJson, GoalProbabilityJson,
    GoalStatus, HintJson, LogNormJson, MetricRef, PieceJson, PieceStepJson, ProbabilityJson,
    RateJson, ResultJson, RuleJson, Shape, ShapeJson, SpanJson, SplitJson, StepJson, TransformJson,
    UnsafeJson, ValidationJson, VerdictJson,
};
use reachc_core::model::{AutoFit, Rate, Split, TransformSource};
use reachc_core::prs::{
    DetSet, GoalMiss, GoalOutcome, GoalVerdict, Hint, Prs, Role, UnsafeVerdict, Verdict,
};
use reachc_core::Interval;

/// The size above which a result file writes the members of its intersection as their
/// bounding boxes ([`to_json_with`]): 32 MiB.
pub const MEMBERS_BUDGET: usize = 32 << 20;

/// Pretty-printed JSON of a result (arrays of numbers or strings on one line). Non-finite
/// numbers (e.g. an infinite margin) are `null`.
pub fn to_json(prs: &Prs) -> String {
    to_json_with(prs, Probabilities::default())
}

/// [`to_json`] with the analysis' certified probabilities (`reachc run --probability`), within
/// [`MEMBERS_BUDGET`] (see [`to_json_within`]).
pub fn to_json_with(prs: &Prs, probabilities: Probabilities<'_>) -> String {
    to_json_within(prs, probabilities, MEMBERS_BUDGET)
}

/// [`to_json_with`] for a size budget of `budget` bytes: where the file would be larger with the
/// members of the intersection written in full (estimated from the count of their numbers;
/// first-order and linearised zonotopes over thousands of report times: a 12-state chain at
/// 5000 report times wrote 235 MB), each member is written as its PRS's bounding box per report
/// time instead (`"boxed": true`; a larger set, so still a PRS; the result's own sets, boxes,
/// margins and verdicts are unchanged).
pub fn to_json_within(prs: &Prs, probabilities: Probabilities<'_>, budget: usize) -> String {
    let write = |boxed: bool| {
        let member = if boxed {
            ResultJson::boxed
        } else {
            ResultJson::of
        };
        let mut json = ResultJson::with(prs, StepJson::of, member);
        json.safety_probability = probabilities.safety.map(|p| ProbabilityJson::of(prs, p));
        for p in probabilities.goals {
            if let Some(g) = json.goals.get_mut(p.goal) {
                g.probability = Some(GoalProbabilityJson::of(prs, p));
            }
        }
        json.to_text()
    };
    // The members' steps dominate such a file (the budget is checked on an estimate before
    // anything is written, rather than on a text of hundreds of megabytes): per step, the set
    // (centre, generators, hull) and the step's other arrays (nominal, spans, hulls: about 8
    // numbers per state), and its scalar fields.
    let bytes: usize = prs
        .also()
        .iter()
        .flat_map(|m| m.steps())
        .map(|st| {
            let numbers = (st.det.generators().len() + 12) * st.det.center().len();
            numbers * BYTES_PER_NUMBER + BYTES_PER_STEP
        })
        .sum();
    write(bytes > budget)
}

/// About what one number of an array takes in a result file (17 significant digits, a
/// separator).
const BYTES_PER_NUMBER: usize = 20;

/// About what a step's scalar fields take (one line each, with their keys and indentation).
const BYTES_PER_STEP: usize = 640;

impl ResultJson {
    /// The result file of `prs`, its members written in full.
    fn of(prs: &Prs) -> ResultJson {
        ResultJson::with(prs, StepJson::of, ResultJson::of)
    }

    /// A member of the intersection written as its PRS's bounding box per report time (see
    /// [`to_json_within`]).
    fn boxed(member: &Prs) -> ResultJson {
        ResultJson {
            boxed: true,
            ..ResultJson::with(member, StepJson::boxed, ResultJson::of)
        }
    }

    /// The result file of `prs`, report step `k` written by `step(prs, k)` and each member of
    /// the intersection by `member`.
    fn with(
        prs: &Prs,
        step: fn(&Prs, usize) -> StepJson,
        member: fn(&Prs) -> ResultJson,
    ) -> ResultJson {
        let n = prs.n();
        let rows =
            |m: &[f64]| -> Vec<Vec<f64>> { m.chunks(n.max(1)).map(<[f64]>::to_vec).collect() };
        ResultJson {
            model: prs.model().to_string(),
            analysis: prs.analysis().to_string(),
            method: prs.method().into(),
            inclusion: prs.inclusion().map(Into::into),
            delta: prs.delta(),
            horizon: prs.horizon(),
            step: prs.step(),
            integrator: prs.integrator().into(),
            period: prs.period(),
            guarantee: prs.guarantee().into(),
            internal_steps: prs.internal_steps(),
            states: prs.states().to_vec(),
            outputs: prs.outputs().to_vec(),
            rate: Some(RateJson {
                kind: prs.rate().rate.into(),
                note: match prs.role() {
                    Role::Linearised => ALONE_NOTE.to_string(),
                    _ => rate_note(prs.rate().rate),
                },
                paths: match prs.rate().rate {
                    Rate::Empirical { paths } => Some(paths),
                    Rate::Local | Rate::Global => None,
                },
                min_c: prs.rate().min_c,
                max_c: prs.rate().max_c,
                global_from: prs.rate().global_from,
            }),
            constants: ConstantsJson {
                c: prs.constants().c,
                sigma: prs.constants().sigma,
                rho: prs.constants().rho,
                how: prs.constants().provenance.to_string(),
                metric: rows(&prs.constants().metric),
                metric_from: prs.constants().metric_region.to_string(),
            },
            radius_rule: RuleJson {
                rule: prs.radius_rule().rule.into(),
                eps: prs.radius_rule().eps,
                gaussian: prs.radius_rule().gaussian.map(|g| GaussianJson {
                    chi2_quantile: g.quantile,
                    uniform: g.uniform.map(Into::into),
                }),
            },
            kappa: prs.kappa(),
            r1: prs.r1(),
            r2: prs.r2(),
            r1_how: r1_how(prs),
            transform: prs.transform().map(|tr| TransformJson {
                matrix: rows(&tr.matrix),
                inverse: rows(&tr.inverse),
                inverse_error: tr.inverse_error,
                source: tr.source.into(),
                log_norm_inf: match tr.source {
                    TransformSource::Auto(AutoFit::LogNorm { chosen, identity }) => {
                        Some(LogNormJson { chosen, identity })
                    }
                    TransformSource::Given | TransformSource::Auto(AutoFit::NonFiniteJacobian) => {
                        None
                    }
                },
            }),
            initial_center: prs.initial_center().to_vec(),
            input_center: prs.input_center().to_vec(),
            steps: (0..prs.steps().len()).map(|k| step(prs, k)).collect(),
            unsafe_sets: prs
                .unsafe_sets()
                .iter()
                .map(|u| UnsafeJson::of(prs.states(), u))
                .collect(),
            goals: prs.goals().iter().map(|g| GoalJson::of(prs, g)).collect(),
            verdict: VerdictJson::of(prs),
            safety_probability: None,
            validated: ValidationJson {
                rigorous: prs.validation().rigorous.iter().map(proved).collect(),
                not_validated: prs
                    .validation()
                    .not_validated
                    .iter()
                    .map(unproved)
                    .collect(),
                conditional_on_domain: prs.validation().conditional_on_domain,
            },
            hints: prs.hints().iter().map(|h| HintJson::of(prs, h)).collect(),
            also: prs.also().iter().map(member).collect(),
            role: prs.role().into(),
            boxed: false,
            split: match prs.split() {
                Split::Off => None,
                Split::Counts(k) => Some(SplitJson::Counts(k.clone())),
                Split::Auto { pieces, seconds } => Some(SplitJson::Auto {
                    auto: AutoJson {
                        pieces: *pieces,
                        seconds: *seconds,
                    },
                }),
            },
            pieces: prs.pieces().iter().map(PieceJson::of).collect(),
        }
    }
}

impl PieceJson {
    fn of(p: &Prs) -> PieceJson {
        PieceJson {
            initial_box: p
                .initial()
                .bounding_box()
                .unwrap_or_default()
                .iter()
                .map(|x| [x.lo, x.hi])
                .collect(),
            verdict: VerdictJson::of(p),
            steps: p
                .steps()
                .iter()
                .enumerate()
                .map(|(k, st)| {
                    let (prs_hull_lo, prs_hull_hi) = hull(p, k);
                    PieceStepJson {
                        t: st.t,
                        prs_hull_lo,
                        prs_hull_hi,
                        margins: st.margins.clone(),
                    }
                })
                .collect(),
        }
    }
}

/// The corners of the bounding box of `prs`'s PRS at report step `k` (empty without one).
fn hull(prs: &Prs, k: usize) -> (Vec<f64>, Vec<f64>) {
    prs.hull_at(k)
        .unwrap_or_default()
        .iter()
        .map(|b| (b.lo, b.hi))
        .unzip()
}

impl GoalMissJson {
    pub(crate) fn of(prs: &Prs, miss: &GoalMiss) -> GoalMissJson {
        match *miss {
            GoalMiss::NoReportTime => GoalMissJson::NoReportTime,
            GoalMiss::Unsafe { t, set } => GoalMissJson::Unsafe {
                t,
                set: prs
                    .unsafe_sets()
                    .get(set)
                    .map_or("?", |u| &u.name)
                    .to_string(),
            },
            GoalMiss::NotInside { t, margin } => GoalMissJson::NotInside { t, margin },
            GoalMiss::Leaves { t } => GoalMissJson::Leaves { t },
        }
    }
}

impl GoalJson {
    fn of(prs: &Prs, g: &GoalVerdict) -> GoalJson {
        let (status, t, margin, why) = match &g.outcome {
            GoalOutcome::Reached { t, margin } => {
                (GoalStatus::Reached, Some(*t), Some(*margin), None)
            }
            GoalOutcome::NeedsUniform => (GoalStatus::NeedsUniform, None, None, None),
            GoalOutcome::NotShown(miss) => (
                GoalStatus::NotShown,
                None,
                None,
                Some(GoalMissJson::of(prs, miss)),
            ),
        };
        GoalJson {
            name: g.name.clone(),
            window: [g.window.lo, g.window.hi],
            stay: g.stay,
            status,
            t,
            margin,
            why,
            probability: None,
            margins: g.margins.clone(),
            swept: g
                .swept
                .iter()
                .map(|parts| {
                    parts
                        .iter()
                        .map(|p| ShapeJson::of(prs.states(), p))
                        .collect()
                })
                .collect(),
        }
    }
}

impl VerdictJson {
    fn of(prs: &Prs) -> VerdictJson {
        match prs.verdict() {
            Verdict::Safe => VerdictJson::Safe,
            Verdict::NoUnsafeSets => VerdictJson::NoUnsafeSets,
            Verdict::NotShownSafe { t, step, set } => VerdictJson::NotShownSafe {
                t,
                step,
                set: prs.unsafe_sets()[set].name.clone(),
            },
        }
    }
}

impl HintJson {
    fn of(prs: &Prs, hint: &Hint) -> HintJson {
        match *hint {
            Hint::Wrapping {
                t,
                state,
                half_width,
                ball_half_width,
                c,
            } => HintJson::Wrapping {
                t,
                state: prs.states()[state].clone(),
                half_width,
                ball_half_width,
                c,
            },
            Hint::LeavesDomain {
                t,
                state,
                range,
                domain,
            } => HintJson::LeavesDomain {
                t,
                state: prs.states()[state].clone(),
                range: [range.lo, range.hi],
                domain: [domain.lo, domain.hi],
            },
            Hint::FirstOrderLoose {
                t,
                remainder,
                linear,
            } => HintJson::FirstOrderLoose {
                t,
                remainder,
                linear,
            },
            Hint::FirstOrderUnbounded => HintJson::FirstOrderUnbounded,
            Hint::LinearisedAlone { ref failed } => HintJson::LinearisedAlone {
                why: failed.to_string(),
            },
        }
    }
}

impl StepJson {
    /// Report step `k` of a member written as its PRS's bounding box: a `"box"` (its centre the
    /// box's midpoint, its radius an upper bound of the box's P-radius about it) with
    /// `r_t = r_pointwise = 0` (the box holds the stochastic part too), the rest as
    /// [`StepJson::of`] writes it.
    fn boxed(member: &Prs, k: usize) -> StepJson {
        let full = StepJson::of(member, k);
        let (lo, hi) = (full.prs_hull_lo.clone(), full.prs_hull_hi.clone());
        let (center, half): (Vec<f64>, Vec<Interval>) = lo
            .iter()
            .zip(&hi)
            .map(|(&l, &h)| {
                let m = 0.5 * l + 0.5 * h;
                let half = (Interval::point(h) - Interval::point(m))
                    .hi()
                    .max((Interval::point(m) - Interval::point(l)).hi());
                (m, Interval::point(half))
            })
            .unzip();
        // |d|_P^2 <= sum_ij |P_ij| |d_i| |d_j| over the box, rounded up.
        let p = &member.constants().metric;
        let n = half.len();
        let mut q = Interval::ZERO;
        if p.len() == n * n {
            for i in 0..n {
                for j in 0..n {
                    q += Interval::point(p[i * n + j].abs()) * half[i] * half[j];
                }
            }
        } else {
            q = Interval::point(f64::INFINITY);
        }
        let radius = q.sqrt().hi();
        StepJson {
            det_set: DetSetJson {
                shape: Shape::Box,
                center,
                radius,
                metric: MetricRef::Constants,
                lo: Some(lo),
                hi: Some(hi),
                hull_lo: None,
                hull_hi: None,
                generators: None,
                remainder: None,
            },
            r_t: 0.0,
            r_pointwise: 0.0,
            prs_radius: radius,
            ..full
        }
    }

    fn of(prs: &Prs, k: usize) -> StepJson {
        let st = &prs.steps()[k];
        let (prs_hull_lo, prs_hull_hi) = hull(prs, k);
        let (lo, hi) = st.det.corners().unzip();
        // A box is its own hull.
        let (hull_lo, hull_hi) = match st.det {
            DetSet::Box { .. } => None,
            _ => st.det.box_hull(),
        }
        .unzip();
        let zonotope = matches!(st.det, DetSet::Zonotope { .. });
        StepJson {
            t: st.t,
            nominal: st.nominal().to_vec(),
            det_set: DetSetJson {
                shape: (&st.det).into(),
                center: st.det.center().to_vec(),
                radius: st.det.radius(),
                metric: MetricRef::Constants,
                lo: lo.map(<[f64]>::to_vec),
                hi: hi.map(<[f64]>::to_vec),
                hull_lo: hull_lo.map(<[f64]>::to_vec),
                hull_hi: hull_hi.map(<[f64]>::to_vec),
                generators: zonotope.then(|| {
                    st.det
                        .generators()
                        .into_iter()
                        .map(<[f64]>::to_vec)
                        .collect()
                }),
                remainder: zonotope.then(|| st.det.ball_added()),
            },
            r_t: st.r_t,
            r_pointwise: st.r_pointwise,
            psi: st.psi,
            c: st.c,
            sigma: st.sigma,
            prs_radius: st.prs_radius,
            prs_hull_lo,
            prs_hull_hi,
            span: SpanJson {
                lo: st.span.lo.clone(),
                hi: st.span.hi.clone(),
                radius: st.span.radius,
            },
            margins: st.margins.clone(),
        }
    }
}

impl UnsafeJson {
    /// The verdict `u` of a result in the states `states`.
    fn of(states: &[String], u: &UnsafeVerdict) -> UnsafeJson {
        UnsafeJson {
            name: u.name.clone(),
            kind: u.kind.into(),
            safe: u.safe,
            min_margin: u.min_margin,
            min_margin_t: u.min_margin_t,
            first_not_safe_t: u.first_not_safe_t,
            margin_unit: margin_unit(u.kind).to_string(),
            swept: u.swept.iter().map(|s| ShapeJson::of(states, s)).collect(),
        }
    }
}
