//! Renderings of a Monte Carlo [`SimReport`]: JSON (documented in docs/results.md) and a text
//! summary.

use super::result::unsafe_kind;
use super::schema::{
    CoverageJson, DtRuleJson, DtStatus, HorizonJson, InputsJson, SafetyJson, SimGoalJson, SimJson,
    SimStateJson, SimStepJson, SimUnsafeJson, TubeJson,
};
use super::{count, summary_indices, time};
use reachc_core::model::Guarantee;
use reachc_core::simulate::{
    DtSource, DtUsed, InitialSampling, InputMode, NoiseKind, SimReport, DT_ACCURACY, DT_RULE,
    MAX_STEPS,
};
use std::fmt::Write as _;

/// Pretty-printed JSON of a report (arrays of scalars on one line, non-finite numbers as
/// `null`).
pub fn to_json(r: &SimReport) -> String {
    SimJson::of(r).to_text()
}

/// What the distances and the outside counts measure.
const COMPARED: &str = "distance |X_t - x*_t|_P with P the analysis' metric and x*_t the \
    result's centre (nominal trajectory; box centre for the interval method), read against the \
    PRS radius (the PRS is the P-ball of that radius for the contraction method; a P-ball \
    containing the PRS for the interval method) and r_t (the stochastic part: equal to the PRS \
    radius when the deterministic set is a point); outside = X_t not in the PRS \
    (engine::contains)";

/// What the tube check of a uniform result checks.
const TUBE_CHECKED: &str = "all times at once: every path's state after every Euler-Maruyama \
    step of each report interval against the PRS over that interval (the result's span), the \
    initial state against the PRS at t = 0, and the state at each report time against that \
    time's PRS; outside_tube counts the paths that left at least once";

impl SimJson {
    fn of(r: &SimReport) -> SimJson {
        SimJson {
            model: r.model.clone(),
            analysis: r.analysis.clone(),
            states: r.states.clone(),
            method: r.method.into(),
            delta: r.delta,
            guarantee: r.guarantee.into(),
            paths: r.paths,
            seed: r.seed,
            dt: r.dt.max,
            dt_min: r.dt.min,
            dt_rule: DtRuleJson {
                source: r.dt.source.into(),
                status: dt_status(&r.dt),
                bound: DT_RULE,
                hl_max: r.dt.hl_max,
                accuracy: DT_ACCURACY,
                bias_max: r.dt.bias_max,
                rule_min: r.dt.rule_min,
                coarse_intervals: r.dt.coarse,
                max_steps: MAX_STEPS,
                warning: dt_warning(&r.dt),
            },
            steps_per_path: r.steps_per_path,
            initial_states: initial_states(r.initial_states).to_string(),
            inputs: InputsJson {
                mode: r.inputs.mode.into(),
                hold: r.inputs.hold,
                description: inputs(r),
            },
            noise: noise(r.noise),
            compared: COMPARED.to_string(),
            quantile_rank: r.quantile_rank,
            confidence: r.confidence,
            steps: r
                .steps
                .iter()
                .map(|s| SimStepJson {
                    t: s.t,
                    r_t: s.r_t,
                    prs_radius: s.prs_radius,
                    quantile: s.quantile,
                    max: s.max,
                    outside: s.outside,
                    fraction: s.fraction,
                    cp_upper: s.cp_upper,
                    left_tube: s.left_tube,
                    states: s
                        .states
                        .iter()
                        .map(|v| SimStateJson {
                            quantile: v.quantile,
                            max: v.max,
                            prs: v.prs,
                            ratio: v.ratio(),
                        })
                        .collect(),
                })
                .collect(),
            horizon: HorizonJson {
                outside_any: r.horizon.outside_any,
                fraction: r.horizon.fraction,
                cp_upper: r.horizon.cp_upper,
            },
            outside_tube: r.tube.as_ref().map(|t| TubeJson {
                count: t.outside,
                fraction: t.fraction,
                cp_upper: t.cp_upper,
                cp_lower: t.cp_lower,
                checks_per_path: t.checks_per_path,
                checked: TUBE_CHECKED.to_string(),
            }),
            unsafe_sets: r
                .unsafe_sets
                .iter()
                .map(|u| SimUnsafeJson {
                    name: u.name.clone(),
                    kind: u.kind.into(),
                    hits: u.hits,
                    fraction: u.fraction,
                    first_hit_t: u.first_hit_t,
                })
                .collect(),
            safety: r.safety.as_ref().map(|c| SafetyJson {
                safe: c.safe,
                fraction: c.fraction,
                cp_upper: c.cp_upper,
                certified: c.certified,
                status: c.certified.map(|_| c.passed.into()),
            }),
            goals: r
                .goals
                .iter()
                .map(|g| SimGoalJson {
                    name: g.name.clone(),
                    reached: g.reached,
                    fraction: g.fraction,
                    cp_upper: g.cp_upper,
                    certified: g.certified,
                    status: g.certified.map(|_| g.passed.into()),
                })
                .collect(),
            left_domain: r.left_domain,
            diverged: r.diverged,
            verdict: CoverageJson {
                status: r.verdict.passed.into(),
                decided_by: r.verdict.decided_by.into(),
                pointwise_status: r.verdict.pointwise_passed.into(),
                alpha: r.verdict.alpha,
                alpha_per_step: r.verdict.alpha_per_step,
                failing_steps: r.verdict.failing_steps,
                worst_step: r.verdict.worst_step,
                worst_t: r.verdict.worst_t,
                worst_outside: r.verdict.worst_outside,
                worst_cp_lower: r.verdict.worst_cp_lower,
            },
        }
    }
}

/// What one step of the paths is: an Euler-Maruyama step, or a step of a discrete-time
/// model's map.
fn step_name(r: &SimReport) -> &'static str {
    match r.dt.source {
        DtSource::Map => "step of the map",
        DtSource::Rule | DtSource::Option => "Euler-Maruyama step",
    }
}

/// Met, capped or coarser.
fn dt_status(dt: &DtUsed) -> DtStatus {
    match (dt.meets_rule(), dt.source) {
        (true, _) => DtStatus::Met,
        (false, DtSource::Rule) => DtStatus::Capped,
        (false, DtSource::Option) => DtStatus::Coarser,
        // (A map's steps are exact: they always meet the rules.)
        (false, DtSource::Map) => DtStatus::Met,
    }
}

/// The steps used, in words: one `dt`, or the smallest and largest.
fn dt_range(dt: &DtUsed) -> String {
    // Equal steps on intervals of equal width differ in their last digits only.
    let (min, max) = (time(dt.min), time(dt.max));
    if min == max {
        format!("dt = {max}")
    } else {
        format!("dt = {min} to {max}")
    }
}

/// A warning when some Euler-Maruyama steps are coarser than the rules `h L_k <= 0.05` and
/// `(h_k / 2) a_k tau_k <= 0.05 w_k` ask (the check may then test the integrator's error, not
/// the PRS); `None` when they all meet them.
pub fn dt_warning(dt: &DtUsed) -> Option<String> {
    let hl = if dt.hl_max.is_finite() {
        format!("h L up to {:.3}", dt.hl_max)
    } else {
        "no finite bound L of the drift's Jacobian over the sets".to_string()
    };
    let bias = if dt.bias_max.is_finite() {
        format!(
            "Euler-Maruyama's bias up to {:.3} of the sets' half-width",
            dt.bias_max
        )
    } else {
        "no finite bound of Euler-Maruyama's bias".to_string()
    };
    let rules = format!("the rules h L <= {DT_RULE} and bias <= {DT_ACCURACY} of the half-width");
    match (dt.meets_rule(), dt.source) {
        (true, _) | (_, DtSource::Map) => None,
        (false, DtSource::Rule) => Some(format!(
            "the Euler-Maruyama step is capped at {MAX_STEPS} steps per report interval on {}, \
             coarser than {rules} ask ({hl}, {bias}): Euler-Maruyama's own error may show as \
             paths outside; a smaller --dt checks more finely",
            count(dt.coarse, "report interval")
        )),
        (false, DtSource::Option) => Some(format!(
            "--dt {} is coarser than {rules} ask on {} ({hl}, {bias}{}): Euler-Maruyama's own \
             error may show as paths outside",
            time(dt.max),
            count(dt.coarse, "report interval"),
            if dt.rule_min > 0.0 {
                format!("; the rules' step: {}", time(dt.rule_min))
            } else {
                String::new()
            }
        )),
    }
}

/// How the initial states were drawn, in words.
fn initial_states(s: InitialSampling) -> &'static str {
    match s {
        InitialSampling::Point => "the initial point (the initial set is a single point)",
        InitialSampling::Box => "uniform in the initial box",
        InitialSampling::Balls => "uniform in the initial ball(s)",
        InitialSampling::BoxAndBalls => "uniform in the initial box and ball(s)",
    }
}

/// How the inputs were drawn, in words.
fn inputs(r: &SimReport) -> String {
    let hold = r.inputs.hold_shown;
    match (r.inputs.any, r.inputs.mode) {
        (false, _) => "none (the model has no inputs)".to_string(),
        (true, InputMode::Centre) => "the centre of the input box".to_string(),
        (true, InputMode::Random) => {
            format!("piecewise constant, uniform in the input box, redrawn every {hold}")
        }
        (true, InputMode::Corners) => {
            format!("piecewise constant, a random corner of the input box, redrawn every {hold}")
        }
    }
}

/// How the noise was applied, in words.
fn noise(kind: NoiseKind) -> String {
    match kind {
        NoiseKind::AdditiveDiagonal => "additive (constant diagonal G, evaluated once)".into(),
        NoiseKind::Additive { entries } => {
            format!("additive (constant G with {entries} non-zero entries, evaluated once)")
        }
        NoiseKind::StateDependent { entries } => format!(
            "state-dependent (G evaluated at every step; {entries} entries not identically zero)"
        ),
    }
}

/// States shown in the text's tightness table (the JSON has them all).
const TIGHTNESS_STATES: usize = 6;

/// The tightness table: at the summary's report times, per state, the PRS's bounding-box
/// half-width about the nominal over the half-width holding `1 - delta` of the paths.
fn tightness(s: &mut String, r: &SimReport) {
    let n = r.states.len().min(TIGHTNESS_STATES);
    if n == 0 {
        return;
    }
    let more = if r.states.len() > n {
        format!(
            " (the first {n} of {} states; the JSON has all)",
            r.states.len()
        )
    } else {
        String::new()
    };
    let _ = writeln!(
        s,
        "  per state, the PRS's bounding box about x*_t against the paths: half-width / the \
         half-width holding 1 - delta of the paths about x*_t{more}"
    );
    let _ = write!(s, "  {:>9}", "t");
    for name in &r.states[..n] {
        let _ = write!(s, "  {name:>22}");
    }
    s.push('\n');
    for k in summary_indices(r.steps.len()) {
        let st = &r.steps[k];
        let _ = write!(s, "  {:>9.4}", st.t);
        for v in st.states.iter().take(n) {
            let ratio = v.ratio();
            let cell = if ratio.is_finite() {
                format!("{:.4}/{:.4} = {ratio:.2}x", v.prs, v.quantile)
            } else {
                format!("{:.4}/{:.4}", v.prs, v.quantile)
            };
            let _ = write!(s, "  {cell:>22}");
        }
        s.push('\n');
    }
}

/// A readable summary: what was simulated, a table at about ten report times plus the last, the
/// horizon-wide count, the tube's (uniform results: what was checked, paths that left it), the
/// unsafe-set counts, and the verdict (the uniform one for a uniform result, with the
/// per-report-time figures alongside).
pub fn summary(r: &SimReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Monte Carlo check of analysis `{}` of model `{}` ({} method, delta = {}, {} guarantee)",
        r.analysis,
        r.model,
        r.method.name(),
        r.delta,
        r.guarantee.name()
    );
    // dt is a quotient (step / substeps): show it without its last-digit noise.
    let how = match r.dt.source {
        DtSource::Rule => Some(format!(
            "chosen by the rules h L <= {DT_RULE} and bias <= {DT_ACCURACY} of the half-width"
        )),
        DtSource::Option => Some("--dt".to_string()),
        DtSource::Map => None,
    };
    let _ = match how {
        Some(how) => writeln!(
            s,
            "  {} (seed {}), Euler-Maruyama with {} ({} per path; {how})",
            count(r.paths, "path"),
            r.seed,
            dt_range(&r.dt),
            count(r.steps_per_path, "step"),
        ),
        None => writeln!(
            s,
            "  {} (seed {}), the map's exact recursion, period {} ({} per path)",
            count(r.paths, "path"),
            r.seed,
            time(r.dt.max),
            count(r.steps_per_path, "step"),
        ),
    };
    if let Some(w) = dt_warning(&r.dt) {
        let _ = writeln!(s, "  warning: {w}");
    }
    let _ = writeln!(s, "  initial states: {}", initial_states(r.initial_states));
    let _ = writeln!(s, "  inputs: {}", inputs(r));
    let _ = writeln!(s, "  noise: {}", noise(r.noise));
    let _ = writeln!(s, "  compared: {COMPARED}");
    let _ = writeln!(
        s,
        "  {:>9}  {:>11}  {:>11}  {:>11}  {:>7}  {:>8}  {:>10}  {:>10}",
        "t", "r_t", "PRS radius", "quantile", "q/PRS", "outside", "fraction", "CP upper"
    );
    for k in summary_indices(r.steps.len()) {
        let st = &r.steps[k];
        let _ = writeln!(
            s,
            "  {:>9.4}  {:>11.5e}  {:>11.5e}  {:>11.5e}  {:>7.4}  {:>8}  {:>10.3e}  {:>10.3e}",
            st.t,
            st.r_t,
            st.prs_radius,
            st.quantile,
            // 0 / 0 at t = 0 for a point initial set.
            if st.prs_radius > 0.0 {
                st.quantile / st.prs_radius
            } else {
                0.0
            },
            st.outside,
            st.fraction,
            st.cp_upper
        );
    }
    tightness(&mut s, r);
    let _ = write!(
        s,
        "  over the horizon: {} ({:.3e}) outside the PRS at some report time (CP upper \
         {:.3e})",
        count(r.horizon.outside_any, "path"),
        r.horizon.fraction,
        r.horizon.cp_upper
    );
    if r.guarantee == Guarantee::Pointwise {
        s.push_str("; the PRS bounds each time separately, not uniformly in time");
    }
    s.push('\n');
    if let Some(t) = &r.tube {
        let _ = writeln!(
            s,
            "  tube, all times at once: {} ({:.3e}) left it at some time (Clopper-Pearson \
             bounds [{:.3e}, {:.3e}] at confidence {}); checked at every {} ({} \
             states per path) against the PRS over its report interval, and at each report time \
             against that time's PRS",
            count(t.outside, "path"),
            t.fraction,
            t.cp_lower,
            t.cp_upper,
            r.confidence,
            step_name(r),
            t.checks_per_path
        );
    }
    for u in &r.unsafe_sets {
        let first = u
            .first_hit_t
            .map_or(String::new(), |t| format!(", first at t = {}", time(t)));
        let _ = writeln!(
            s,
            "  unsafe set `{}` ({}): entered by {} ({:.3e}){first}",
            u.name,
            unsafe_kind(u.kind),
            count(u.hits, "path"),
            u.fraction
        );
    }
    if let Some(c) = &r.safety {
        let check = (c.safe, c.fraction, c.cp_upper, c.certified, c.passed);
        let what = format!("entered no unsafe set at any {}", step_name(r));
        s.push_str(&check_line(r, "probability of safety", &what, check));
    }
    for g in &r.goals {
        let check = (g.reached, g.fraction, g.cp_upper, g.certified, g.passed);
        let steps = match r.dt.source {
            DtSource::Map => "steps of the map",
            DtSource::Rule | DtSource::Option => "Euler-Maruyama steps",
        };
        let what = format!("reached it as the goal set asks, at the {steps}");
        s.push_str(&check_line(r, &format!("goal `{}`", g.name), &what, check));
    }
    if let Some(left) = r.left_domain {
        let _ = writeln!(
            s,
            "  left the domain: {} (the PRS holds only while the state stays in it)",
            count(left, "path")
        );
    }
    if r.diverged > 0 {
        let _ = writeln!(
            s,
            "  diverged (non-finite state): {}",
            count(r.diverged, "path")
        );
    }
    let v = &r.verdict;
    let verdict = if v.passed { "PASS" } else { "FAIL" };
    let per_time = format!(
        "{} of {} report times with a Clopper-Pearson lower bound above delta at level 1 - \
         {:.1e}; worst t = {}: {} outside, lower bound {:.3e}",
        v.failing_steps,
        r.steps.len(),
        v.alpha_per_step,
        time(v.worst_t),
        v.worst_outside,
        v.worst_cp_lower
    );
    match &r.tube {
        Some(t) => {
            let _ = writeln!(
                s,
                "  coverage: {verdict} (uniform: the fraction of paths leaving the tube has a \
                 Clopper-Pearson lower bound of {:.3e} at level 1 - {:.1e}, {} delta = {}; per \
                 report time, reported only: {per_time})",
                t.cp_lower,
                v.alpha,
                if t.cp_lower > r.delta {
                    "above"
                } else {
                    "not above"
                },
                r.delta
            );
        }
        None => {
            let _ = writeln!(s, "  coverage: {verdict} ({per_time})");
        }
    }
    s
}

/// A probability check's line: `label`, the paths that did `what` (`counted`, their
/// `fraction` and its Clopper-Pearson upper bound), and the certified lower bound against it.
fn check_line(
    r: &SimReport,
    label: &str,
    what: &str,
    (counted, fraction, cp_upper, certified, passed): (u64, f64, f64, Option<f64>, bool),
) -> String {
    let verdict = match certified {
        Some(b) if passed => format!("; the certified lower bound {b} is not above it: PASS"),
        Some(b) => {
            format!("; the certified lower bound {b} is above it: FAIL (the bound is too high)")
        }
        None => String::new(),
    };
    format!(
        "  {label}: {} of {} ({fraction:.6}) {what} (Clopper-Pearson upper bound {cp_upper:.6} at \
         confidence {}){verdict}\n",
        count(counted, "path"),
        r.paths,
        r.confidence
    )
}
