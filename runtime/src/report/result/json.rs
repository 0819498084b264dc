//! A result as JSON, field for field in the order docs/results.md documents.

use super::unsafe_kind;
use super::words::{margin_unit, proved, r1_how, rate_note, unproved, ALONE_NOTE};
use crate::report::probability::{GoalProbabilityJson, Probabilities, ProbabilityJson};
use crate::report::shape::ShapeJson;
use reachc_core::model::{AutoFit, Rate, Split, TransformSource};
use reachc_core::prs::{
    DetSet, GoalMiss, GoalOutcome, GoalVerdict, Hint, Prs, Role, UniformBound, UnsafeVerdict,
    Verdict,
};
use reachc_core::Interval;
use serde::Serialize;
use std::borrow::Cow;

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
            json.also = prs.also().iter().map(Json::boxed).collect();
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
        .also()
        .iter()
        .flat_map(|m| m.steps())
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
            // The items up to the closing bracket at this line's indentation, if all scalars:
            // the search stops at the first item that is not one (an array of objects or
            // arrays is left as it is without reading it to its end, so a file is read once).
            let indent = line.len() - line.trim_start().len();
            let end = lines[i + 1..]
                .iter()
                .map(|l| {
                    let t = l.trim_start();
                    let close = l.len() - t.len() == indent && (t == "]" || t == "],");
                    (close, close || scalar(t.trim_end().trim_end_matches(',')))
                })
                .take_while(|&(_, scalar)| scalar)
                .position(|(close, _)| close);
            if let Some(end) = end {
                out.push_str(line);
                for (j, item) in lines[i + 1..i + 1 + end].iter().enumerate() {
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
pub(crate) enum GoalMissJson<'a> {
    NoReportTime,
    Unsafe { t: f64, set: &'a str },
    NotInside { t: f64, margin: f64 },
    Leaves { t: f64 },
}

impl<'a> GoalMissJson<'a> {
    pub(crate) fn of(prs: &'a Prs, miss: &GoalMiss) -> GoalMissJson<'a> {
        match *miss {
            GoalMiss::NoReportTime => GoalMissJson::NoReportTime,
            GoalMiss::Unsafe { t, set } => GoalMissJson::Unsafe {
                t,
                set: prs.unsafe_sets().get(set).map_or("?", |u| &u.name),
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
                        .map(|p| ShapeJson::of(prs.states(), p))
                        .collect()
                })
                .collect(),
        }
    }
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
        match prs.verdict() {
            Verdict::Safe => VerdictJson::Safe,
            Verdict::NoUnsafeSets => VerdictJson::NoUnsafeSets,
            Verdict::NotShownSafe { t, step, set } => VerdictJson::NotShownSafe {
                t,
                step,
                set: &prs.unsafe_sets()[set].name,
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
            model: prs.model(),
            analysis: prs.analysis(),
            method: prs.method().name(),
            inclusion: prs.inclusion().map(|i| i.name()),
            delta: prs.delta(),
            horizon: prs.horizon(),
            step: prs.step(),
            integrator: prs.integrator().name(),
            guarantee: prs.guarantee().name(),
            internal_steps: prs.internal_steps(),
            states: prs.states(),
            outputs: prs.outputs(),
            rate: RateJson {
                kind: prs.rate().rate.name(),
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
            },
            constants: ConstantsJson {
                c: prs.constants().c,
                sigma: prs.constants().sigma,
                rho: prs.constants().rho,
                how: prs.constants().provenance.to_string(),
                metric: rows(&prs.constants().metric),
                metric_from: prs.constants().metric_region.to_string(),
            },
            radius_rule: RuleJson {
                rule: prs.radius_rule().rule.name(),
                eps: prs.radius_rule().eps,
                gaussian: prs.radius_rule().gaussian.map(|g| GaussianJson {
                    chi2_quantile: g.quantile,
                    uniform: g.uniform.map(uniform_name),
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
            initial_center: prs.initial_center(),
            input_center: prs.input_center(),
            steps: (0..prs.steps().len())
                .map(|k| StepJson::of(prs, k))
                .collect(),
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
            also: prs.also().iter().map(Json::of).collect(),
            role: (prs.role() != Role::Own).then(|| prs.role().name()),
            boxed: false,
            split: match prs.split() {
                Split::Off => None,
                Split::Counts(k) => Some(SplitJson::Counts(k)),
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

impl<'a> Json<'a> {
    /// A member of the intersection written as its PRS's bounding box per report time (see
    /// [`to_json_with`]).
    fn boxed(member: &'a Prs) -> Json<'a> {
        Json {
            steps: (0..member.steps().len())
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
                state: &prs.states()[state],
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
                state: &prs.states()[state],
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
        let st = &prs.steps()[k];
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

/// The name of a time-uniform bound in result files.
fn uniform_name(bound: UniformBound) -> &'static str {
    match bound {
        UniformBound::AmgfTube => "amgf_tube",
        UniformBound::Mixture => "gaussian_mixture",
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
