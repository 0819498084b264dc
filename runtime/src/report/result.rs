//! Renderings of a [`Prs`]: JSON (documented in docs/results.md), CSV and a text summary.

use super::probability::{GoalProbabilityJson, Probabilities, ProbabilityJson};
use super::shape::ShapeJson;
use super::{count, csv_field, num, summary_indices, time};
use reachc_core::model::{AutoFit, Guarantee, Method, Rate, Split, TransformSource};
use reachc_core::prs::{
    BallBound, DetSet, GoalMiss, GoalOutcome, GoalVerdict, Hint, Proved, Prs, R1Method, Role, Step,
    TransformUsed, UniformBound, Unproved, UnsafeKind, UnsafeVerdict, Verdict,
};
use reachc_core::Interval;
use serde::Serialize;
use std::borrow::Cow;
use std::fmt::Write as _;
use std::io::{self, Write};

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
        let mut json = Json::of(prs);
        if boxed {
            json.also = prs.also.iter().map(Json::boxed).collect();
        }
        json.safety_probability = probabilities.safety.map(|p| ProbabilityJson::of(prs, p));
        for p in probabilities.goals {
            if let Some(g) = json.goals.get_mut(p.goal) {
                g.probability = Some(GoalProbabilityJson::of(prs, p));
            }
        }
        // Plain data with string keys: serialising cannot fail.
        inline_scalar_arrays(&serde_json::to_string_pretty(&json).expect("a result serialises"))
    };
    // The members' sets dominate such a file: each number in it takes about 20 bytes (the
    // budget is checked on that count before anything is written, rather than on a text of
    // hundreds of megabytes).
    let numbers: usize = prs
        .also
        .iter()
        .flat_map(|m| &m.steps)
        .map(|st| (st.det.generators().len() + 4) * st.det.center().len())
        .sum();
    write(numbers.saturating_mul(BYTES_PER_NUMBER) > budget)
}

/// About what one number takes in a result file (17 significant digits, a separator).
const BYTES_PER_NUMBER: usize = 20;

/// serde_json's pretty output with every array of scalars (numbers, strings, `null`, booleans)
/// on one line: `[\n  1.0,\n  2.0\n]` becomes `[1.0, 2.0]` (half the size of a result file, and
/// one line per vector). serde_json writes each array item on its own line and never a newline
/// inside a string, so a line is an item.
pub(crate) fn inline_scalar_arrays(pretty: &str) -> String {
    let lines: Vec<&str> = pretty.lines().collect();
    let mut out = String::with_capacity(pretty.len());
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.ends_with('[') {
            // The items up to the closing bracket at this line's indentation, if all scalars.
            let indent = line.len() - line.trim_start().len();
            let end = lines[i + 1..].iter().position(|l| {
                let t = l.trim_start();
                l.len() - t.len() == indent && (t == "]" || t == "],")
            });
            if let Some(end) = end {
                let items = &lines[i + 1..i + 1 + end];
                if items.iter().all(|l| scalar(l.trim().trim_end_matches(','))) {
                    out.push_str(line);
                    for (j, item) in items.iter().enumerate() {
                        if j > 0 {
                            out.push(' ');
                        }
                        out.push_str(item.trim());
                    }
                    out.push_str(lines[i + 1 + end].trim_start());
                    out.push('\n');
                    i += end + 2;
                    continue;
                }
            }
        }
        out.push_str(line);
        out.push('\n');
        i += 1;
    }
    out.pop();
    out
}

/// Whether one item of serde_json's output is a scalar (a string, number, `null`, `true` or
/// `false`), not the start of an object or array.
fn scalar(item: &str) -> bool {
    let string = item.len() >= 2 && item.starts_with('"') && item.ends_with('"');
    string || !(item.starts_with('{') || item.starts_with('[') || item.is_empty())
}

/// The JSON document, field for field (the order is the documented one).
#[derive(Serialize)]
struct Json<'a> {
    model: &'a str,
    analysis: &'a str,
    method: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    inclusion: Option<&'static str>,
    delta: f64,
    horizon: f64,
    step: f64,
    integrator: &'static str,
    guarantee: &'static str,
    internal_steps: usize,
    states: &'a [String],
    outputs: &'a [usize],
    rate: RateJson,
    constants: ConstantsJson<'a>,
    radius_rule: RuleJson,
    kappa: f64,
    r1: f64,
    r2: f64,
    r1_how: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    transform: Option<TransformJson<'a>>,
    initial_center: &'a [f64],
    input_center: &'a [f64],
    steps: Vec<StepJson<'a>>,
    unsafe_sets: Vec<UnsafeJson<'a>>,
    /// Per goal set (absent without goals; method.md 8.13).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    goals: Vec<GoalJson<'a>>,
    verdict: VerdictJson<'a>,
    /// The probability of safety (`reachc run --probability` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    safety_probability: Option<ProbabilityJson<'a>>,
    validated: ValidationJson,
    hints: Vec<HintJson<'a>>,
    /// The members of the intersection (the PRS is the intersection:
    /// `steps[..].prs_hull_lo/hi` and the verdicts are the intersection's).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    also: Vec<Json<'a>>,
    /// A member's kind (`metric`, `box`, `first_order`); absent for the result itself.
    #[serde(skip_serializing_if = "Option::is_none")]
    role: Option<&'static str>,
    /// A member written as its PRS's bounding boxes ([`MEMBERS_BUDGET`]); absent otherwise.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    boxed: bool,
    /// The split (absent without one; method.md 8.11): the counts per state, or
    /// `{"auto": {"pieces": N}}` (the budget).
    #[serde(skip_serializing_if = "Option::is_none")]
    split: Option<SplitJson<'a>>,
    /// With a split, each piece in brief (the PRS is their union: `steps[..].prs_hull_lo/hi`
    /// are the union's bounding boxes, the margins and verdicts the union's).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pieces: Vec<PieceJson<'a>>,
}

/// One piece of a split (method.md 8.11), in brief: its initial box, its verdict, and per report
/// time its PRS's bounding box and margins. (Written in full, with their members' zonotopes,
/// the 64 pieces of `specs/vanderpol.sde` made files of 100 to 160 MB.)
#[derive(Serialize)]
struct PieceJson<'a> {
    initial_box: Vec<[f64; 2]>,
    verdict: VerdictJson<'a>,
    steps: Vec<PieceStepJson<'a>>,
}

#[derive(Serialize)]
struct PieceStepJson<'a> {
    t: f64,
    prs_hull_lo: Vec<f64>,
    prs_hull_hi: Vec<f64>,
    margins: &'a [f64],
}

impl<'a> PieceJson<'a> {
    fn of(p: &'a Prs) -> PieceJson<'a> {
        PieceJson {
            initial_box: p
                .initial
                .bounding_box()
                .unwrap_or_default()
                .iter()
                .map(|x| [x.lo, x.hi])
                .collect(),
            verdict: VerdictJson::of(p),
            steps: p
                .steps
                .iter()
                .enumerate()
                .map(|(k, st)| {
                    let (lo, hi) = p
                        .hull_at(k)
                        .unwrap_or_default()
                        .iter()
                        .map(|b| (b.lo, b.hi))
                        .unzip();
                    PieceStepJson {
                        t: st.t,
                        prs_hull_lo: lo,
                        prs_hull_hi: hi,
                        margins: &st.margins,
                    }
                })
                .collect(),
        }
    }
}

/// How the initial box was split.
#[derive(Serialize)]
#[serde(untagged)]
enum SplitJson<'a> {
    /// `split = [..]`.
    Counts(&'a [usize]),
    /// `split = auto(pieces = N, seconds = S)`.
    Auto { auto: AutoJson },
}

#[derive(Serialize)]
struct AutoJson {
    pieces: usize,
    seconds: Option<u64>,
}

#[derive(Serialize)]
struct RateJson {
    kind: &'static str,
    note: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    paths: Option<u64>,
    min_c: f64,
    max_c: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    global_from: Option<f64>,
}

#[derive(Serialize)]
struct ConstantsJson<'a> {
    c: f64,
    sigma: f64,
    rho: f64,
    how: String,
    metric: Vec<&'a [f64]>,
    metric_from: String,
}

#[derive(Serialize)]
struct RuleJson {
    rule: &'static str,
    eps: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    gaussian: Option<GaussianJson>,
}

#[derive(Serialize)]
struct GaussianJson {
    chi2_quantile: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    uniform: Option<&'static str>,
}

#[derive(Serialize)]
struct TransformJson<'a> {
    matrix: Vec<&'a [f64]>,
    inverse: Vec<&'a [f64]>,
    inverse_error: f64,
    source: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    log_norm_inf: Option<LogNormJson>,
}

#[derive(Serialize)]
struct LogNormJson {
    chosen: f64,
    identity: f64,
}

#[derive(Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
enum HintJson<'a> {
    Wrapping {
        t: f64,
        state: &'a str,
        half_width: f64,
        ball_half_width: f64,
        c: f64,
    },
    LeavesDomain {
        t: f64,
        state: &'a str,
        range: [f64; 2],
        domain: [f64; 2],
    },
    FirstOrderLoose {
        t: f64,
        remainder: f64,
        linear: f64,
    },
    FirstOrderUnbounded,
    LinearisedAlone {
        why: String,
    },
}

#[derive(Serialize)]
struct StepJson<'a> {
    t: f64,
    nominal: &'a [f64],
    det_set: DetSetJson<'a>,
    r_t: f64,
    r_pointwise: f64,
    psi: f64,
    c: f64,
    sigma: f64,
    prs_radius: f64,
    prs_hull_lo: Vec<f64>,
    prs_hull_hi: Vec<f64>,
    span: SpanJson<'a>,
    margins: &'a [f64],
}

#[derive(Serialize)]
struct SpanJson<'a> {
    lo: &'a [f64],
    hi: &'a [f64],
    radius: f64,
}

#[derive(Serialize)]
struct DetSetJson<'a> {
    shape: &'static str,
    center: Cow<'a, [f64]>,
    radius: f64,
    metric: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    lo: Option<Cow<'a, [f64]>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    hi: Option<Cow<'a, [f64]>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    hull_lo: Option<&'a [f64]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    hull_hi: Option<&'a [f64]>,
    /// A zonotope's generators, one array each.
    #[serde(skip_serializing_if = "Option::is_none")]
    generators: Option<Vec<&'a [f64]>>,
    /// A zonotope's remainder (the P-radius of the ball added to it).
    #[serde(skip_serializing_if = "Option::is_none")]
    remainder: Option<f64>,
}

#[derive(Serialize)]
struct UnsafeJson<'a> {
    name: &'a str,
    kind: &'static str,
    safe: bool,
    min_margin: f64,
    min_margin_t: f64,
    first_not_safe_t: Option<f64>,
    margin_unit: &'static str,
    /// A moving set (method.md 8.15): per report time, the fixed set that held it over the
    /// report interval ending there; absent for a fixed set.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    swept: Vec<ShapeJson<'a>>,
}

/// One goal's verdict: `reached` with its time and margin, or `why` not.
#[derive(Serialize)]
struct GoalJson<'a> {
    name: &'a str,
    window: [f64; 2],
    stay: bool,
    status: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    t: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    margin: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    why: Option<GoalMissJson<'a>>,
    /// The certified probability of reaching it (`reachc run --probability`).
    #[serde(skip_serializing_if = "Option::is_none")]
    probability: Option<GoalProbabilityJson<'a>>,
    margins: &'a [f64],
    /// A moving goal (method.md 8.15): per report time, its parts as they are then; absent for a
    /// fixed goal.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    swept: Vec<Vec<ShapeJson<'a>>>,
}

/// Why a goal is not shown reached (a goal's `why`, and the limit of its probability).
#[derive(Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub(super) enum GoalMissJson<'a> {
    NoReportTime,
    Unsafe { t: f64, set: &'a str },
    NotInside { t: f64, margin: f64 },
    Leaves { t: f64 },
}

impl<'a> GoalMissJson<'a> {
    pub(super) fn of(prs: &'a Prs, miss: &GoalMiss) -> GoalMissJson<'a> {
        match *miss {
            GoalMiss::NoReportTime => GoalMissJson::NoReportTime,
            GoalMiss::Unsafe { t, set } => GoalMissJson::Unsafe {
                t,
                set: prs.unsafe_sets.get(set).map_or("?", |u| &u.name),
            },
            GoalMiss::NotInside { t, margin } => GoalMissJson::NotInside { t, margin },
            GoalMiss::Leaves { t } => GoalMissJson::Leaves { t },
        }
    }
}

impl<'a> GoalJson<'a> {
    fn of(prs: &'a Prs, g: &'a GoalVerdict) -> GoalJson<'a> {
        let (status, t, margin, why) = match &g.outcome {
            GoalOutcome::Reached { t, margin } => ("reached", Some(*t), Some(*margin), None),
            GoalOutcome::NeedsUniform => ("needs_uniform", None, None, None),
            GoalOutcome::NotShown(miss) => {
                ("not_shown", None, None, Some(GoalMissJson::of(prs, miss)))
            }
        };
        GoalJson {
            name: &g.name,
            window: [g.window.lo, g.window.hi],
            stay: g.stay,
            status,
            t,
            margin,
            why,
            probability: None,
            margins: &g.margins,
            swept: g
                .swept
                .iter()
                .map(|parts| {
                    parts
                        .iter()
                        .map(|p| ShapeJson::of(&prs.states, p))
                        .collect()
                })
                .collect(),
        }
    }
}

/// The text line of one goal's verdict.
fn goal_line(prs: &Prs, g: &GoalVerdict) -> String {
    let (lo, hi) = (time(g.window.lo), time(g.window.hi));
    let what = if g.stay {
        format!(
            "reach within [{lo}, {hi}] and stay until {}",
            time(prs.horizon)
        )
    } else {
        format!("reach within [{lo}, {hi}]")
    };
    let status = match &g.outcome {
        GoalOutcome::Reached { t, margin } => {
            let claim = if g.stay {
                let end = time(prs.horizon);
                let avoiding = match prs.unsafe_sets.is_empty() {
                    true => String::new(),
                    false => format!(", avoiding every unsafe set on [0, {end}]"),
                };
                format!(
                    "the state is in it at t = {} and stays in it until t = {end}{avoiding}",
                    time(*t)
                )
            } else if prs.unsafe_sets.is_empty() {
                format!("the state is in it at t = {}", time(*t))
            } else {
                format!(
                    "the state is in it at t = {}, having avoided every unsafe set on [0, {}]",
                    time(*t),
                    time(*t)
                )
            };
            let how = if matches!(prs.rate.rate, Rate::Empirical { .. }) {
                "by the EMPIRICAL estimate (not a guarantee)".to_string()
            } else {
                format!("with probability at least {}", 1.0 - prs.delta)
            };
            format!("reached: {how} {claim}; margin {}", num(*margin))
        }
        GoalOutcome::NeedsUniform => "not assessed: reaching needs `guarantee = uniform` (a \
                                      pointwise PRS bounds each time separately, not the path)"
            .to_string(),
        GoalOutcome::NotShown(miss) => {
            let why = match *miss {
                GoalMiss::NoReportTime => "no report time lies in the window".to_string(),
                GoalMiss::Unsafe { t, set } => format!(
                    "the PRS over the interval ending at t = {} meets unsafe set `{}` first",
                    time(t),
                    prs.unsafe_sets.get(set).map_or("?", |u| &u.name)
                ),
                GoalMiss::NotInside { t, margin } => format!(
                    "the PRS is not inside it at any report time in the window (largest margin \
                     {} at t = {})",
                    num(margin),
                    time(t)
                ),
                GoalMiss::Leaves { t } => format!(
                    "the PRS over the interval ending at t = {} is not shown inside it",
                    time(t)
                ),
            };
            format!("NOT SHOWN REACHED: {why} (this does not prove that it is missed)")
        }
    };
    format!("  goal `{}` ({what}): {status}", g.name)
}

#[derive(Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
enum VerdictJson<'a> {
    Safe,
    NoUnsafeSets,
    NotShownSafe { t: f64, step: usize, set: &'a str },
}

impl<'a> VerdictJson<'a> {
    fn of(prs: &'a Prs) -> VerdictJson<'a> {
        match prs.verdict {
            Verdict::Safe => VerdictJson::Safe,
            Verdict::NoUnsafeSets => VerdictJson::NoUnsafeSets,
            Verdict::NotShownSafe { t, step, set } => VerdictJson::NotShownSafe {
                t,
                step,
                set: &prs.unsafe_sets[set].name,
            },
        }
    }
}

#[derive(Serialize)]
struct ValidationJson {
    rigorous: Vec<String>,
    not_validated: Vec<String>,
    conditional_on_domain: bool,
}

impl<'a> Json<'a> {
    fn of(prs: &'a Prs) -> Json<'a> {
        let n = prs.n();
        let rows = |m: &'a [f64]| -> Vec<&'a [f64]> { m.chunks(n.max(1)).collect() };
        Json {
            model: &prs.model,
            analysis: &prs.analysis,
            method: prs.method.name(),
            inclusion: prs.inclusion.map(|i| i.name()),
            delta: prs.delta,
            horizon: prs.horizon,
            step: prs.step,
            integrator: prs.integrator.name(),
            guarantee: prs.guarantee.name(),
            internal_steps: prs.internal_steps,
            states: &prs.states,
            outputs: &prs.outputs,
            rate: RateJson {
                kind: prs.rate.rate.name(),
                note: match prs.role {
                    Role::Linearised => ALONE_NOTE.to_string(),
                    _ => rate_note(prs.rate.rate),
                },
                paths: match prs.rate.rate {
                    Rate::Empirical { paths } => Some(paths),
                    Rate::Local | Rate::Global => None,
                },
                min_c: prs.rate.min_c,
                max_c: prs.rate.max_c,
                global_from: prs.rate.global_from,
            },
            constants: ConstantsJson {
                c: prs.constants.c,
                sigma: prs.constants.sigma,
                rho: prs.constants.rho,
                how: prs.constants.provenance.to_string(),
                metric: rows(&prs.constants.metric),
                metric_from: prs.constants.metric_region.to_string(),
            },
            radius_rule: RuleJson {
                rule: prs.radius_rule.rule.name(),
                eps: prs.radius_rule.eps,
                gaussian: prs.radius_rule.gaussian.map(|g| GaussianJson {
                    chi2_quantile: g.quantile,
                    uniform: g.uniform.map(uniform_name),
                }),
            },
            kappa: prs.kappa,
            r1: prs.r1,
            r2: prs.r2,
            r1_how: r1_how(prs),
            transform: prs.transform.as_ref().map(|tr| TransformJson {
                matrix: rows(&tr.matrix),
                inverse: rows(&tr.inverse),
                inverse_error: tr.inverse_error,
                source: match tr.source {
                    TransformSource::Given => "given",
                    TransformSource::Auto(_) => "auto",
                },
                log_norm_inf: match tr.source {
                    TransformSource::Auto(AutoFit::LogNorm { chosen, identity }) => {
                        Some(LogNormJson { chosen, identity })
                    }
                    TransformSource::Given | TransformSource::Auto(AutoFit::NonFiniteJacobian) => {
                        None
                    }
                },
            }),
            initial_center: &prs.initial_center,
            input_center: &prs.input_center,
            steps: (0..prs.steps.len()).map(|k| StepJson::of(prs, k)).collect(),
            unsafe_sets: prs
                .unsafe_sets
                .iter()
                .map(|u| UnsafeJson::of(&prs.states, u))
                .collect(),
            goals: prs.goals.iter().map(|g| GoalJson::of(prs, g)).collect(),
            verdict: VerdictJson::of(prs),
            safety_probability: None,
            validated: ValidationJson {
                rigorous: prs.validation.rigorous.iter().map(proved).collect(),
                not_validated: prs.validation.not_validated.iter().map(unproved).collect(),
                conditional_on_domain: prs.validation.conditional_on_domain,
            },
            hints: prs.hints.iter().map(|h| HintJson::of(prs, h)).collect(),
            also: prs.also.iter().map(Json::of).collect(),
            role: (prs.role != Role::Own).then(|| prs.role.name()),
            boxed: false,
            split: match &prs.split {
                Split::Off => None,
                Split::Counts(k) => Some(SplitJson::Counts(k)),
                Split::Auto { pieces, seconds } => Some(SplitJson::Auto {
                    auto: AutoJson {
                        pieces: *pieces,
                        seconds: *seconds,
                    },
                }),
            },
            pieces: prs.pieces.iter().map(PieceJson::of).collect(),
        }
    }
}

impl<'a> Json<'a> {
    /// A member of the intersection written as its PRS's bounding box per report time (see
    /// [`to_json_with`]).
    fn boxed(member: &'a Prs) -> Json<'a> {
        Json {
            steps: (0..member.steps.len())
                .map(|k| StepJson::boxed(member, k))
                .collect(),
            boxed: true,
            ..Json::of(member)
        }
    }
}

impl<'a> HintJson<'a> {
    fn of(prs: &'a Prs, hint: &'a Hint) -> HintJson<'a> {
        match *hint {
            Hint::Wrapping {
                t,
                state,
                half_width,
                ball_half_width,
                c,
            } => HintJson::Wrapping {
                t,
                state: &prs.states[state],
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
                state: &prs.states[state],
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

impl<'a> StepJson<'a> {
    /// Report step `k` of a member written as its PRS's bounding box: a `"box"` (its centre the
    /// box's midpoint, its radius an upper bound of the box's P-radius about it) with
    /// `r_t = r_pointwise = 0` (the box holds the stochastic part too), the rest as
    /// [`StepJson::of`] writes it.
    fn boxed(member: &'a Prs, k: usize) -> StepJson<'a> {
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
        let p = &member.constants.metric;
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
                shape: "box",
                center: center.into(),
                radius,
                metric: "constants.metric",
                lo: Some(lo.into()),
                hi: Some(hi.into()),
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

    fn of(prs: &'a Prs, k: usize) -> StepJson<'a> {
        let st = &prs.steps[k];
        let (prs_lo, prs_hi) = prs
            .hull_at(k)
            .unwrap_or_default()
            .into_iter()
            .map(|b| (b.lo, b.hi))
            .unzip();
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
            nominal: st.nominal(),
            det_set: DetSetJson {
                shape: st.det.shape(),
                center: st.det.center().into(),
                radius: st.det.radius(),
                metric: "constants.metric",
                lo: lo.map(Cow::from),
                hi: hi.map(Cow::from),
                hull_lo,
                hull_hi,
                generators: zonotope.then(|| st.det.generators()),
                remainder: zonotope.then(|| st.det.ball_added()),
            },
            r_t: st.r_t,
            r_pointwise: st.r_pointwise,
            psi: st.psi,
            c: st.c,
            sigma: st.sigma,
            prs_radius: st.prs_radius,
            prs_hull_lo: prs_lo,
            prs_hull_hi: prs_hi,
            span: SpanJson {
                lo: &st.span.lo,
                hi: &st.span.hi,
                radius: st.span.radius,
            },
            margins: &st.margins,
        }
    }
}

impl<'a> UnsafeJson<'a> {
    /// The verdict `u` of a result in the states `states`.
    fn of(states: &'a [String], u: &'a UnsafeVerdict) -> UnsafeJson<'a> {
        UnsafeJson {
            name: &u.name,
            kind: unsafe_kind(u.kind),
            safe: u.safe,
            min_margin: u.min_margin,
            min_margin_t: u.min_margin_t,
            first_not_safe_t: u.first_not_safe_t,
            margin_unit: margin_unit(u.kind),
            swept: u.swept.iter().map(|s| ShapeJson::of(states, s)).collect(),
        }
    }
}

/// What an unsafe set's margins measure, by its kind.
fn margin_unit(kind: UnsafeKind) -> &'static str {
    match kind {
        UnsafeKind::Box => "largest per-coordinate gap between the PRS's bounding box and the box",
        UnsafeKind::HalfSpace | UnsafeKind::Ball => "Euclidean distance",
    }
}

/// An unsafe set's kind in reports.
pub(crate) fn unsafe_kind(kind: UnsafeKind) -> &'static str {
    match kind {
        UnsafeKind::HalfSpace => "half_space",
        UnsafeKind::Box => "box",
        UnsafeKind::Ball => "ball",
    }
}

/// One sentence on where the rate came from; an empirical rate says plainly that it is no
/// guarantee.
/// The rate note of the linearised Gaussian set alone (method.md 8.12).
const ALONE_NOTE: &str = "none used: the PRS is the linearised Gaussian set alone (method.md \
     8.12), at the full delta; min_c and max_c are the rates certified on its own spans, for the \
     record";

fn rate_note(rate: Rate) -> String {
    match rate {
        Rate::Local => "c_t, sigma_t and rho_t certified on each internal step over a box \
             holding the deterministic set and the time-uniform tube on that step (interval \
             Jacobian, verified eigenvalue bounds): no global rate and no domain needed"
            .into(),
        Rate::Global => {
            "one rate c for the whole horizon, certified by the compiler over the domain".into()
        }
        Rate::Empirical { paths } => format!(
            "EMPIRICAL: c_t estimated from {paths} sample paths (largest one-sided Lipschitz \
             quotient between a sampled state and the nominal), not certified: the PRS is an \
             estimate, not a guarantee"
        ),
    }
}

/// How `r1` was bounded, in words.
fn r1_how(prs: &Prs) -> String {
    let b = prs.r1_bound;
    let how = match b.balls {
        BallBound::NoBalls => r1_over_box(b.boxes, "the initial box"),
        BallBound::BoundingBoxes => format!(
            "{}; balls replaced by their bounding boxes (conservative: the balls' own bound was \
             not smaller)",
            r1_over_box(b.boxes, "the initial box")
        ),
        BallBound::Joint { balls } => r1_joint(balls, b.boxes),
        BallBound::Separate { balls } => format!(
            "|b|_P + |y|_P, the box part b and the ball part y bounded separately: {}; {}",
            r1_over_box(b.boxes, "the box part"),
            match balls {
                1 => "the initial ball by r sqrt(lambda_max(P, M)), exact for the ball alone"
                    .to_string(),
                m => format!("the {m} initial balls by the S-procedure (not exact in general)"),
            }
        ),
    };
    match (b.reported_only, b.balls) {
        (false, _) => how,
        (true, BallBound::NoBalls) => "P-radius of the initial box around its centre (reported \
                                       only: the interval method propagates the box itself)"
            .to_string(),
        (true, _) => format!(
            "{how} (reported only: the interval method propagates the initial set's bounding box)"
        ),
    }
}

/// The bound of `r1` over a box part, in words.
fn r1_over_box(boxes: R1Method, what: &str) -> String {
    match boxes {
        R1Method::Vertices { active } => format!(
            "max of |x0 - x*_0|_P over the vertices of {what} ({active} non-degenerate \
             coordinates)"
        ),
        R1Method::AbsoluteSum => format!(
            "sum_ij |P_ij| h_i h_j over {what} (more than {} coordinates)",
            reachc_core::engine::MAX_VERTEX_COORDS
        ),
    }
}

/// The bound of `r1` over balls jointly with the box part's vertices, in words.
fn r1_joint(balls: usize, boxes: R1Method) -> String {
    let vertices = match boxes {
        R1Method::Vertices { active: 0 } => String::new(),
        R1Method::Vertices { active } => {
            format!(" and the vertices of the box part ({active} non-degenerate coordinates)")
        }
        R1Method::AbsoluteSum => " and the box part".to_string(),
    };
    match (balls, boxes) {
        (1, R1Method::Vertices { active: 0 }) => "max of |x0 - x*_0|_P over the initial ball, \
                                                  exact: r sqrt(lambda_max(P, M)), certified by \
                                                  interval Cholesky"
            .to_string(),
        (1, _) => format!(
            "max of |x0 - x*_0|_P over the initial ball{vertices}, exact (S-lemma, one \
             multiplier per vertex, interval arithmetic)"
        ),
        (m, _) => format!(
            "upper bound of |x0 - x*_0|_P over the {m} initial balls{vertices} by the \
             S-procedure (one multiplier per ball; not exact in general)"
        ),
    }
}

/// A proved part, in words.
fn proved(p: &Proved) -> String {
    match p {
        Proved::Constants { c, rho, provenance } => {
            let mut names = Vec::new();
            if *c {
                names.push("c");
            }
            names.push("sigma");
            if *rho {
                names.push("rho");
            }
            format!("constants {} ({provenance})", names.join(", "))
        }
        Proved::Inclusion(inclusion) => format!(
            "{} inclusion function of the drift on each face (outward-rounded interval \
             arithmetic)",
            inclusion.name()
        ),
        Proved::Kappa => "kappa (rounded up)".into(),
        Proved::Psi => {
            "Psi_t (exact per-step integration in interval arithmetic, upper end)".into()
        }
        Proved::Radii => "radii r1, R_t, r_t, PRS radius (interval arithmetic, rounded up)".into(),
        Proved::StochasticRadius => "r_t (interval arithmetic, rounded up)".into(),
        Proved::Margins { given } => format!(
            "safety margins given the {} (P^-1 enclosed by interval Cholesky, rounded down)",
            match given {
                Method::Contraction => "nominal",
                Method::Interval => "box",
            }
        ),
        Proved::TransformMaps { inverse_error } => format!(
            "the transformed drift T f(T^-1 y) (exact T^-1, coefficients folded without \
             rounding), the initial box in y = T x (interval hull of T X0) and the map back to x \
             (T^-1 enclosed entry-wise within {inverse_error:.1e} of the floating-point inverse)"
        ),
        Proved::ValidatedNominal { steps } => format!(
            "nominal trajectory on {steps} validated steps (a cubic through RK4 nodes, its \
             defect bounded in interval arithmetic on each step and added to R_t through the \
             contraction rate): the sets hold over whole steps, not only at report times"
        ),
        Proved::ValidatedEmbedding { steps } => format!(
            "embedding system on {} (the comparison principle on each \
             step's hull, time as an interval): the boxes hold over whole steps, not only at \
             report times",
            count(*steps as u64, "validated step")
        ),
        Proved::LocalRates { regions, metric } => format!(
            "local rates on {}, each holding the tube over its step, so the process never \
             leaves them on the tube's event (metric {metric})",
            count(*regions as u64, "region")
        ),
        Proved::UniformTube { epochs } => format!(
            "time-uniform tube: Ville's inequality on the averaged-MGF supermartingale over \
             {epochs} epochs at delta / {epochs} each: one event, of probability at least \
             1 - delta, for all t in [0, horizon]"
        ),
        Proved::ExactGaussian => "exact Gaussian: the system is affine with additive noise, so \
             X_t - x_t ~ N(0, Sigma_t); Sigma_t enclosed in interval arithmetic (Taylor series \
             with remainder), the chi-square quantile rounded up"
            .to_string(),
        Proved::GaussianMixture { epochs } => format!(
            "time-uniform Gaussian bound: Ville's inequality on the method-of-mixtures \
             martingale over {epochs} epochs at delta / {epochs} each (tighter here than the \
             averaged-MGF tube): one event, of probability at least 1 - delta, for all t in \
             [0, horizon]"
        ),
        Proved::LinearisedGaussian { epochs } => format!(
            "linearised Gaussian sets: the covariance of the linearisation along the nominal \
             (enclosed), the reflection principle for each coordinate's Gaussian martingale \
             over {epochs} epochs (one per internal step) at their share of delta, and the \
             linearisation's error bounded path by path on that event (interval Jacobians and \
             input Jacobians on a box holding the state, propagated by the linear flow)"
        ),
    }
}

/// The name of a time-uniform bound in result files.
fn uniform_name(bound: UniformBound) -> &'static str {
    match bound {
        UniformBound::AmgfTube => "amgf_tube",
        UniformBound::Mixture => "gaussian_mixture",
    }
}

/// A part that is not proved, in words.
fn unproved(u: &Unproved) -> String {
    match u {
        Unproved::EmpiricalRate { paths } => rate_note(Rate::Empirical { paths: *paths }),
        Unproved::Nominal { integrator, step } => format!(
            "nominal trajectory x*_t (numerical {} integration, step {step}; taken as exact)",
            integrator.name()
        ),
        Unproved::Embedding { integrator, step } => format!(
            "time discretisation of the embedding system (numerical {} integration, step \
             {step}, no remainder bound): the box encloses the deterministic reachable set only \
             up to the integration error",
            integrator.name()
        ),
    }
}

/// State indices the CSV and the summary show: the outputs, or all states if there are none.
fn shown_states(prs: &Prs) -> Vec<usize> {
    if prs.outputs.is_empty() {
        (0..prs.states.len()).collect()
    } else {
        prs.outputs.clone()
    }
}

/// Whether a result's own sets are first-order zonotopes (a member of role
/// [`Role::FirstOrder`] or [`Role::Linearised`]; its set at `t = 0` is the initial box).
fn zonotopes(prs: &Prs) -> bool {
    matches!(prs.role, Role::FirstOrder | Role::Linearised)
}

/// CSV with header `t,<output state names...>,det_radius,r_t,psi,c,sigma,prs_radius` and one
/// row per report time (the nominal state in the state columns). For the interval method (box
/// sets) the header is `t,<state>_lo,<state>_hi,...,r_t,psi` instead; with a coordinate
/// transform, `t,y1_lo,y1_hi,...,yn_lo,yn_hi,<state>_lo,<state>_hi,...,r_t,psi` (the box in
/// `y = T x`, then the parallelotope's interval hull in the output states). For first-order
/// zonotopes, `t,<state>_lo,<state>_hi,...,remainder,r_t,psi`: the zonotope's interval hull and
/// the P-radius of the ball added to it (the PRS is `Z (+) B_P(remainder + r_t)`).
pub fn write_csv(prs: &Prs, w: &mut dyn Write) -> io::Result<()> {
    let shown = shown_states(prs);
    let zonotopes = zonotopes(prs);
    if prs.method == Method::Interval || zonotopes {
        let mut header = String::from("t");
        if let Some(first) = prs.steps.first() {
            for (label, _, _) in box_columns(prs, first) {
                let _ = write!(
                    header,
                    ",{},{}",
                    csv_field(&format!("{label}_lo")),
                    csv_field(&format!("{label}_hi"))
                );
            }
        }
        if zonotopes {
            header.push_str(",remainder");
        }
        header.push_str(",r_t,psi");
        writeln!(w, "{header}")?;
        for s in &prs.steps {
            let mut row = format!("{}", s.t);
            for (_, a, b) in box_columns(prs, s) {
                let _ = write!(row, ",{a},{b}");
            }
            if zonotopes {
                let _ = write!(row, ",{}", s.det.ball_added());
            }
            let _ = write!(row, ",{},{}", s.r_t, s.psi);
            writeln!(w, "{row}")?;
        }
        return Ok(());
    }
    let mut header = String::from("t");
    for &i in &shown {
        header.push(',');
        header.push_str(&csv_field(&prs.states[i]));
    }
    header.push_str(",det_radius,r_t,psi,c,sigma,prs_radius");
    // Several metrics: the radii are the first metric's; the PRS is the intersection, whose
    // bounding box follows.
    let boxes = !prs.also.is_empty();
    if boxes {
        for &i in &shown {
            let name = &prs.states[i];
            let _ = write!(
                header,
                ",{},{}",
                csv_field(&format!("prs_{name}_lo")),
                csv_field(&format!("prs_{name}_hi"))
            );
        }
    }
    writeln!(w, "{header}")?;
    for (k, s) in prs.steps.iter().enumerate() {
        let mut row = format!("{}", s.t);
        for &i in &shown {
            let _ = write!(row, ",{}", s.nominal()[i]);
        }
        let _ = write!(
            row,
            ",{},{},{},{},{},{}",
            s.det.radius(),
            s.r_t,
            s.psi,
            s.c,
            s.sigma,
            s.prs_radius
        );
        if let (true, Some(hull)) = (boxes, prs.hull_at(k)) {
            for &i in &shown {
                let _ = write!(row, ",{},{}", hull[i].lo, hull[i].hi);
            }
        }
        writeln!(w, "{row}")?;
    }
    Ok(())
}

/// The ranges shown for a box step, `(label, lo, hi)`: the box over the shown states, or with a
/// transform the box in `y` (`y1`, `y2`, ...) and then the parallelotope's interval hull over
/// the shown states.
fn box_columns(prs: &Prs, st: &Step) -> Vec<(String, f64, f64)> {
    let at = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(f64::NAN);
    let shown = shown_states(prs).into_iter();
    match &st.det {
        DetSet::Parallelotope {
            lo,
            hi,
            hull_lo,
            hull_hi,
            ..
        } => {
            let ys = (0..prs.states.len()).map(|i| (format!("y{}", i + 1), at(lo, i), at(hi, i)));
            ys.chain(shown.map(|i| (prs.states[i].clone(), at(hull_lo, i), at(hull_hi, i))))
                .collect()
        }
        DetSet::Box { lo, hi, .. }
        | DetSet::Zonotope {
            hull_lo: lo,
            hull_hi: hi,
            ..
        } => shown
            .map(|i| (prs.states[i].clone(), at(lo, i), at(hi, i)))
            .collect(),
        DetSet::Ball { .. } => Vec::new(),
    }
}

/// A readable text summary: constants, radius rule and kappa, a table at about ten evenly
/// spaced times plus the final time, and the safety verdicts with margins.
pub fn summary(prs: &Prs) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "analysis `{}` of model `{}` ({} method, delta = {}, {} guarantee)",
        prs.analysis,
        prs.model,
        prs.method.name(),
        prs.delta,
        prs.guarantee.name()
    );
    let _ = writeln!(s, "  {}", guarantee_sentence(prs));
    let k = &prs.constants;
    // The linearised Gaussian set alone (method.md 8.12) uses no rate.
    let alone = prs.role == Role::Linearised;
    match prs.rate.rate {
        _ if alone => {
            let _ = writeln!(
                s,
                "  rates: {ALONE_NOTE}: c_t in [{}, {}]",
                num(prs.rate.min_c),
                num(prs.rate.max_c)
            );
        }
        Rate::Global => {
            let _ = writeln!(
                s,
                "  constants: c = {:.6}, sigma = {:.6}, rho = {:.6} ({})",
                k.c, k.sigma, k.rho, k.provenance
            );
        }
        Rate::Local => {
            // (A split result's regions are its pieces'.)
            let sigma = std::iter::once(prs)
                .chain(&prs.pieces)
                .flat_map(|p| &p.regions)
                .map(|r| r.sigma)
                .fold(0.0, f64::max);
            let _ = writeln!(
                s,
                "  rates: local, c_t in [{}, {}], sigma_t at most {} (global: c = {}, sigma = \
                 {}; {})",
                num(prs.rate.min_c),
                num(prs.rate.max_c),
                num(sigma),
                num(k.c),
                num(k.sigma),
                k.provenance
            );
            if let Some(t) = prs.rate.global_from {
                let _ = writeln!(
                    s,
                    "  from t = {}, no region around the tube closed: the global constants over \
                     the domain took over (the result is conditional on the domain)",
                    time(t)
                );
            }
        }
        rate => {
            let _ = writeln!(
                s,
                "  constants: c = c_t ({} rate, at most {}), sigma = {:.6}, rho = {:.6} ({})",
                rate.name(),
                num(prs.rate.max_c),
                k.sigma,
                k.rho,
                k.provenance
            );
        }
    }
    if prs.rate.rate != Rate::Global && !alone {
        let _ = writeln!(s, "  rate: {}", rate_note(prs.rate.rate));
    }
    let n = prs.n().max(1);
    let rows: Vec<String> = k
        .metric
        .chunks(n)
        .map(|r| {
            let cells: Vec<String> = r.iter().map(|v| format!("{v:.6}")).collect();
            format!("[{}]", cells.join(", "))
        })
        .collect();
    let _ = writeln!(
        s,
        "  metric P = [{}] ({})",
        rows.join(", "),
        k.metric_region
    );
    let rule = match (prs.radius_rule.eps, prs.radius_rule.gaussian) {
        (Some(eps), _) => format!("{} (eps = {eps:.6})", prs.radius_rule.rule.name()),
        (None, Some(g)) => format!(
            "exact Gaussian (affine system: chi2 quantile {:.6}{})",
            g.quantile,
            match g.uniform {
                Some(UniformBound::Mixture) => ", time-uniform by the Gaussian mixture bound",
                Some(UniformBound::AmgfTube) => ", time-uniform by the amgf tube (tighter here)",
                None => "",
            },
        ),
        (None, None) => prs.radius_rule.rule.name().to_string(),
    };
    // With several metrics each set is at delta / K.
    let delta_each = prs.delta / metrics(prs) as f64;
    let _ = writeln!(
        s,
        "  radius rule: {rule}, kappa(n = {}, delta = {}) = {:.6}",
        prs.states.len(),
        delta_each,
        prs.kappa
    );
    summary_metrics(prs, &mut s);
    if !prs.pieces.is_empty() {
        summary_split(prs, &mut s);
    } else if alone {
        let _ = writeln!(
            s,
            "  sets: linearised Gaussian zonotopes (the initial box under the flow's \
             linearisation along the nominal, the Gaussian part's box and the linearisation's \
             error, method.md 8.10), which hold the stochastic part themselves (r_t = 0; the \
             remainder is a millionth of the radius); columns: the zonotope's hull"
        );
        box_table(prs, &mut s);
    } else if zonotopes(prs) {
        let _ = writeln!(
            s,
            "  deterministic sets: first-order zonotopes (the initial box under the flow's \
             linearisation along the nominal) plus a P-ball bounding the linearisation's \
             remainder; PRS = zonotope (+) B_P(remainder + r_t); columns: the zonotope's hull"
        );
        box_table(prs, &mut s);
    } else if prs.method == Method::Interval {
        summary_boxes(prs, &mut s);
    } else {
        let _ = writeln!(s, "  r1 = {:.6} ({}), r2 = {}", prs.r1, r1_how(prs), prs.r2);
        let _ = writeln!(
            s,
            "  {:>10}  {:>12}  {:>12}  {:>12}  {:>12}",
            "t", "R_t", "r_t", "PRS radius", "pointwise r"
        );
        for i in summary_indices(prs.steps.len()) {
            let st = &prs.steps[i];
            let _ = writeln!(
                s,
                "  {:>10.4}  {:>12}  {:>12}  {:>12}  {:>12}",
                st.t,
                num(st.det.radius()),
                num(st.r_t),
                num(st.prs_radius),
                num(st.r_pointwise)
            );
        }
    }
    if prs.unsafe_sets.is_empty() {
        let _ = writeln!(s, "  safety: no unsafe sets");
    } else {
        for u in &prs.unsafe_sets {
            let status = if u.safe {
                "safe".to_string()
            } else {
                format!(
                    "NOT SHOWN SAFE (first at t = {})",
                    time(u.first_not_safe_t.unwrap_or(f64::NAN))
                )
            };
            let unit = margin_unit(u.kind);
            let _ = writeln!(
                s,
                "  unsafe set `{}` ({}): {status}; min margin {} at t = {} ({unit})",
                u.name,
                unsafe_kind(u.kind),
                num(u.min_margin),
                time(u.min_margin_t),
            );
        }
    }
    for g in &prs.goals {
        let _ = writeln!(s, "{}", goal_line(prs, g));
    }
    let verdict = match &prs.verdict {
        Verdict::Safe if matches!(prs.rate.rate, Rate::Empirical { .. }) => {
            "safe by the EMPIRICAL estimate (every estimated PRS misses every unsafe set; not a \
             guarantee)"
                .to_string()
        }
        Verdict::Safe => match prs.guarantee {
            Guarantee::Uniform => format!(
                "safe: with probability at least {} the state avoids every unsafe set for all t \
                 in [0, {}] (every PRS over every interval misses every unsafe set)",
                1.0 - prs.delta,
                prs.horizon
            ),
            Guarantee::Pointwise => format!(
                "safe at each time separately: for every t in [0, {}], the state is in no \
                 unsafe set with probability at least {} (every PRS misses every unsafe set)",
                prs.horizon,
                1.0 - prs.delta
            ),
        },
        Verdict::NoUnsafeSets => "no unsafe sets to check".to_string(),
        Verdict::NotShownSafe { t, set, .. } => format!(
            "not shown safe: the PRS over the interval ending at t = {} meets `{}` (this \
             does not prove a violation)",
            time(*t),
            prs.unsafe_sets[*set].name
        ),
    };
    let _ = writeln!(s, "  verdict: {verdict}");
    if prs.validation.conditional_on_domain {
        let _ = writeln!(
            s,
            "  condition: the constants hold only in the domain; the result assumes the state \
             does not leave it"
        );
    }
    let not_validated: Vec<String> = prs.validation.not_validated.iter().map(unproved).collect();
    let not_validated = if not_validated.is_empty() {
        "nothing (every bound above is proved)".to_string()
    } else {
        not_validated.join("; ")
    };
    let _ = writeln!(s, "  not validated: {not_validated}");
    for hint in &prs.hints {
        let _ = writeln!(s, "  hint: {}", hint_sentence(prs, hint));
    }
    s
}

/// Where a transform comes from, as a parenthesis after it (nothing for a given one).
fn transform_source(tr: &TransformUsed) -> String {
    let fit = match tr.source {
        TransformSource::Given => return String::new(),
        TransformSource::Auto(fit) => fit,
    };
    let how = match fit {
        AutoFit::LogNorm { chosen, identity } if chosen < identity => format!(
            "mu_inf(T A T^-1) = {} against mu_inf(A) = {} for the identity",
            num(chosen),
            num(identity)
        ),
        AutoFit::LogNorm { identity, .. } => {
            format!("nothing beats the identity: mu_inf(A) = {}", num(identity))
        }
        AutoFit::NonFiniteJacobian => "A is not finite: the identity".to_string(),
    };
    format!(
        " (chosen automatically from A, the drift's Jacobian at the initial set's centre: {how})"
    )
}

/// A hint, in words, with what to try.
fn hint_sentence(prs: &Prs, hint: &Hint) -> String {
    let already_auto = prs
        .transform
        .as_ref()
        .is_some_and(|tr| matches!(tr.source, TransformSource::Auto(_)));
    let try_this = if already_auto {
        "try `method = contraction`"
    } else {
        "try `transform = auto` (or `method = contraction`)"
    };
    match *hint {
        Hint::Wrapping {
            t,
            state,
            half_width,
            ball_half_width,
            c,
        } => {
            let ball = if c < 0.0 { "shrinks" } else { "bounds" };
            format!(
                "the box grows (wrapping): the PRS's half-width in `{}` is {} by t = {} while \
                 the contraction rate c = {} {ball} P-balls (half-width {} from the same initial \
                 set and r_t): {try_this}",
                prs.states[state],
                num(half_width),
                time(t),
                num(c),
                num(ball_half_width)
            )
        }
        Hint::LeavesDomain {
            t,
            state,
            range,
            domain,
        } => format!(
            "the box leaves the domain in `{}` at t = {} ([{}, {}] is not in [{}, {}]; the \
             constants hold only in the domain): {try_this}",
            prs.states[state],
            time(t),
            num(range.lo),
            num(range.hi),
            num(domain.lo),
            num(domain.hi)
        ),
        Hint::FirstOrderLoose {
            t,
            remainder,
            linear,
        } => format!(
            "the first-order sets (the flow's linearisation, method.md 8.8) lose their shape \
             from t = {}: their second-order remainder (P-radius {}) is larger than their linear \
             part ({}), so the initial set (or the input box) is too wide for one linearisation \
             over the horizon; the \
             remainder shrinks with the square of their widths: split the initial set \
             (`split = [..]` in the analysis, one count per state)",
            time(t),
            num(remainder),
            num(linear)
        ),
        Hint::FirstOrderUnbounded => "the first-order sets (the flow's linearisation, method.md \
             8.8) could not be bounded on some internal step (the linearisation's remainder \
             did not hold its own a-priori bound), so the result has none; the remainder \
             shrinks with the square of the initial set's width: split the initial set \
             (`split = [..]` in the analysis, one count per state)"
            .to_string(),
        Hint::LinearisedAlone { ref failed } => format!(
            "the analysis' own sets could not be bounded ({failed}); the PRS is the linearised \
             Gaussian set alone (method.md 8.12), at the full delta, which needs no contraction \
             rate: a smaller initial set (`split = [..]`) or less noise keeps its second-order \
             error small"
        ),
    }
}

/// What the probability level is about, in words.
fn guarantee_sentence(prs: &Prs) -> String {
    match prs.guarantee {
        Guarantee::Uniform => format!(
            "guarantee: one event of probability at least {}: X_t lies in the tube for all t in \
             [0, {}] at once",
            1.0 - prs.delta,
            prs.horizon
        ),
        Guarantee::Pointwise => format!(
            "guarantee: for each t separately, X_t lies in its PRS with probability at least {} \
             (not uniformly in time)",
            1.0 - prs.delta
        ),
    }
}

/// The number of metrics of a result: its own and its members that are further metrics (the
/// others are the interval boxes and first-order zonotopes it is cut by).
fn metrics(prs: &Prs) -> usize {
    1 + prs.also.iter().filter(|m| m.role == Role::Metric).count()
}

/// The further metrics of an intersection result, and its bounding boxes.
fn summary_metrics(prs: &Prs, s: &mut String) {
    if prs.also.is_empty() {
        return;
    }
    let k = metrics(prs);
    if k > 1 {
        let _ = writeln!(
            s,
            "  several metrics: the PRS is the intersection of the sets of {k} metrics, each at \
             delta / {k} = {:e} (the tables below the first metric's; the boxes, margins and \
             verdicts the intersection's)",
            prs.delta / k as f64
        );
    }
    let boxes = prs.also.iter().filter(|m| m.role == Role::Box).count();
    if boxes > 0 {
        let _ = writeln!(
            s,
            "  cut by the interval box: the PRS is the intersection of each metric's ball with \
             the interval method's box of the same run, widened by the same r_t, at the same \
             delta ({boxes} box{}; the boxes, margins and verdicts below are the intersection's)",
            if boxes == 1 { "" } else { "es" }
        );
    }
    for m in prs.also.iter().filter(|m| m.role == Role::FirstOrder) {
        let last = m.steps.last();
        let _ = writeln!(
            s,
            "  cut by the first-order zonotope: the PRS also lies in Z_t (+) B_P(remainder_t + \
             r_t), Z_t the initial box under the flow's linearisation along the nominal \
             ({}), the remainder bounding the linearisation's error ({} at the horizon; P-radius \
             of the set {}); the boxes, margins and verdicts below are the intersection's",
            count(
                last.map_or(0, |st| st.det.generators().len()) as u64,
                "generator"
            ),
            num(last.map_or(f64::NAN, |st| st.det.ball_added())),
            num(last.map_or(f64::NAN, |st| st.det.radius()))
        );
    }
    for m in prs.also.iter().filter(|m| m.role == Role::Linearised) {
        let _ = writeln!(
            s,
            "  cut by the linearised Gaussian set (delta = {} of it; the other sets at the \
             rest): the PRS also lies in a zonotope holding the initial box under the flow's \
             linearisation, the linearisation's error and its Gaussian part, for all t at once \
             (P-radius {} at the horizon); the boxes, margins and verdicts below are the \
             intersection's",
            num(m.delta),
            num(m.steps.last().map_or(f64::NAN, |st| st.det.radius()))
        );
    }
    for (j, m) in prs
        .also
        .iter()
        .filter(|m| m.role == Role::Metric)
        .enumerate()
    {
        let n = m.n().max(1);
        let rows: Vec<String> = m
            .constants
            .metric
            .chunks(n)
            .map(|r| {
                let cells: Vec<String> = r.iter().map(|v| format!("{v:.6}")).collect();
                format!("[{}]", cells.join(", "))
            })
            .collect();
        let last = m.steps.last().map_or(f64::NAN, |st| st.prs_radius);
        let _ = writeln!(
            s,
            "  metric {}: P = [{}], c = {:.6}, sigma = {:.6}; PRS radius at the horizon {}",
            j + 2,
            rows.join(", "),
            m.constants.c,
            m.constants.sigma,
            num(last)
        );
    }
    hull_table(prs, s);
}

/// The table of the PRS's bounding boxes (of an intersection or a union) per report time.
fn hull_table(prs: &Prs, s: &mut String) {
    let names: Vec<String> = prs.states.iter().map(|x| format!("{x} [lo, hi]")).collect();
    let header: Vec<String> = names.iter().map(|x| format!("{x:>28}")).collect();
    let _ = writeln!(s, "  {:>10}  {}", "t", header.join("  "));
    for i in summary_indices(prs.steps.len()) {
        let Some(hull) = prs.hull_at(i) else {
            continue;
        };
        let cells: Vec<String> = hull
            .iter()
            .map(|b| format!("[{:>12}, {:>12}]", num(b.lo), num(b.hi)))
            .collect();
        let _ = writeln!(s, "  {:>10.4}  {}", prs.steps[i].t, cells.join("  "));
    }
}

/// A split result (method.md 8.11) in words: the pieces, the union's bounding boxes, and which
/// pieces are not shown safe.
fn summary_split(prs: &Prs, s: &mut String) {
    let how = match &prs.split {
        Split::Counts(k) => {
            let counts: Vec<String> = k.iter().map(|k| k.to_string()).collect();
            format!(
                "cut into {} = {} pieces",
                counts.join(" x "),
                prs.pieces.len()
            )
        }
        Split::Auto { pieces, seconds } => format!(
            "cut automatically into {} pieces (at most {pieces}{}: the pieces with the largest \
             sets halved along their widest state, while that shrank them)",
            prs.pieces.len(),
            seconds.map_or(String::new(), |s| format!(", no round started after {s} s"))
        ),
        Split::Off => String::new(),
    };
    let _ = writeln!(
        s,
        "  split: the initial box {how}, each run at delta = {} (method.md 8.11); the PRS is \
         their union (a path starts in one piece and stays in that piece's PRS with probability \
         at least {}); the boxes below are the union's bounding boxes, the margins and verdicts \
         the union's",
        prs.delta,
        1.0 - prs.delta
    );
    let cut: usize = prs.pieces.iter().filter(|p| !p.also.is_empty()).count();
    if cut > 0 {
        let _ = writeln!(
            s,
            "  pieces cut by further sets of their own run (interval box, first-order or \
             linearised sets): {cut} of {}",
            prs.pieces.len()
        );
    }
    hull_table(prs, s);
    let unsafe_pieces: Vec<(usize, &Prs)> = prs
        .pieces
        .iter()
        .enumerate()
        .filter(|(_, p)| matches!(p.verdict, Verdict::NotShownSafe { .. }))
        .collect();
    if let Some((j, p)) = unsafe_pieces.first() {
        let range: Vec<String> = p
            .initial
            .bounding_box()
            .unwrap_or_default()
            .iter()
            .zip(&prs.states)
            .map(|(b, x)| format!("{x} in [{}, {}]", num(b.lo), num(b.hi)))
            .collect();
        let _ = writeln!(
            s,
            "  pieces not shown safe: {} of {} (the first, piece {}: {})",
            unsafe_pieces.len(),
            prs.pieces.len(),
            j + 1,
            range.join(", ")
        );
    }
}

/// The deterministic sets of an interval result (boxes or parallelotopes) in words, and their
/// table.
fn summary_boxes(prs: &Prs, s: &mut String) {
    let inclusion = prs.inclusion.map_or("?", |i| i.name());
    match &prs.transform {
        None => {
            let _ = writeln!(
                s,
                "  deterministic sets: boxes of the embedding system ({inclusion} inclusion); \
                 PRS = box (+) B_P(r_t)"
            );
        }
        Some(tr) => {
            let n = prs.n().max(1);
            let rows: Vec<String> = tr.matrix.chunks(n).map(|r| format!("{r:?}")).collect();
            let _ = writeln!(
                s,
                "  deterministic sets: parallelotopes {{x : T x in box}}, T = [{}]{}, box of the \
                 embedding system in y = T x ({inclusion} inclusion); PRS = parallelotope (+) \
                 B_P(r_t); columns: the box in y, then the parallelotope's hull in x",
                rows.join(", "),
                transform_source(tr)
            );
        }
    }
    box_table(prs, s);
}

/// The table of the summary for sets with a box hull: per column of [`box_columns`] the range
/// `[lo, hi]`, the remainder of first-order zonotopes, and `r_t`.
fn box_table(prs: &Prs, s: &mut String) {
    let Some(first) = prs.steps.first() else {
        return;
    };
    let zonotopes = zonotopes(prs);
    let mut head = format!("  {:>10}", "t");
    for (label, _, _) in box_columns(prs, first) {
        let _ = write!(head, "  {:>27}", format!("{label} [lo, hi]"));
    }
    if zonotopes {
        let _ = write!(head, "  {:>12}", "remainder");
    }
    let _ = write!(head, "  {:>12}", "r_t");
    let _ = writeln!(s, "{head}");
    for k in summary_indices(prs.steps.len()) {
        let st = &prs.steps[k];
        let mut row = format!("  {:>10.4}", st.t);
        for (_, a, b) in box_columns(prs, st) {
            let _ = write!(row, "  [{a:>12.6}, {b:>12.6}]");
        }
        if zonotopes {
            let _ = write!(row, "  {:>12.6}", st.det.ball_added());
        }
        let _ = write!(row, "  {:>12.6}", st.r_t);
        let _ = writeln!(s, "{row}");
    }
}

#[cfg(test)]
mod tests {
    use super::inline_scalar_arrays;

    /// Arrays of scalars go on one line, other arrays keep one item per line, and the text
    /// parses back to the same value (strings holding brackets, commas and escapes included).
    #[test]
    fn scalar_arrays_inline() {
        let v = serde_json::json!({
            "states": ["x[1]", "y, [z]", "q\"[", ""],
            "lo": [1.0, -2.5e-300, null],
            "empty": [],
            "nested": [[1, 2], [3]],
            "objects": [{"a": [true, false]}, {"b": {}}],
            "mixed": [1, [2], {"c": 3}],
        });
        let pretty = serde_json::to_string_pretty(&v).unwrap();
        let inline = inline_scalar_arrays(&pretty);
        let back: serde_json::Value = serde_json::from_str(&inline).unwrap();
        assert_eq!(back, v);
        assert!(
            inline.contains(r#""states": ["x[1]", "y, [z]", "q\"[", ""]"#),
            "{inline}"
        );
        assert!(
            inline.contains(r#""lo": [1.0, -2.5e-300, null],"#),
            "{inline}"
        );
        assert!(inline.contains("\"empty\": [],"), "{inline}");
        assert!(inline.contains("    [1, 2],\n    [3]\n"), "{inline}");
        assert!(inline.contains("\"a\": [true, false]"), "{inline}");
        assert!(
            inline.contains("\"mixed\": [\n    1,\n    [2],\n"),
            "{inline}"
        );
        assert!(inline.len() < pretty.len());
    }
}
