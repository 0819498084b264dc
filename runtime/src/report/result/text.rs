//! A result as a readable text summary: the constants, the radius rule, a table at about ten
//! report times, the verdicts and what is not proved.

use super::words::{margin_unit, r1_how, rate_note, unproved, ALONE_NOTE};
use super::{box_columns, unsafe_kind, zonotopes};
use crate::report::{count, num, summary_indices, time};
use reachc_core::model::{AutoFit, Guarantee, Method, Rate, Split, TransformSource};
use reachc_core::prs::{
    GoalMiss, GoalOutcome, GoalVerdict, Hint, Prs, Role, TransformUsed, UniformBound, Verdict,
};
use std::fmt::Write as _;

/// The text line of one goal's verdict.
fn goal_line(prs: &Prs, g: &GoalVerdict) -> String {
    let (lo, hi) = (time(g.window.lo), time(g.window.hi));
    let what = if g.stay {
        format!(
            "reach within [{lo}, {hi}] and stay until {}",
            time(prs.horizon())
        )
    } else {
        format!("reach within [{lo}, {hi}]")
    };
    let status = match &g.outcome {
        GoalOutcome::Reached { t, margin } => {
            let claim = if g.stay {
                let end = time(prs.horizon());
                let avoiding = match prs.unsafe_sets().is_empty() {
                    true => String::new(),
                    false => format!(", avoiding every unsafe set on [0, {end}]"),
                };
                format!(
                    "the state is in it at t = {} and stays in it until t = {end}{avoiding}",
                    time(*t)
                )
            } else if prs.unsafe_sets().is_empty() {
                format!("the state is in it at t = {}", time(*t))
            } else {
                format!(
                    "the state is in it at t = {}, having avoided every unsafe set on [0, {}]",
                    time(*t),
                    time(*t)
                )
            };
            let how = if matches!(prs.rate().rate, Rate::Empirical { .. }) {
                "by the EMPIRICAL estimate (not a guarantee)".to_string()
            } else {
                format!("with probability at least {}", 1.0 - prs.delta())
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
                    prs.unsafe_sets().get(set).map_or("?", |u| &u.name)
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

/// A readable text summary: constants, radius rule and kappa, a table at about ten evenly
/// spaced times plus the final time, and the safety verdicts with margins.
pub fn summary(prs: &Prs) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "analysis `{}` of model `{}` ({} method, delta = {}, {} guarantee)",
        prs.analysis(),
        prs.model(),
        prs.method().name(),
        prs.delta(),
        prs.guarantee().name()
    );
    let _ = writeln!(s, "  {}", guarantee_sentence(prs));
    let k = prs.constants();
    // The linearised Gaussian set alone (method.md 8.12) uses no rate.
    let alone = prs.role() == Role::Linearised;
    match prs.rate().rate {
        _ if alone => {
            let _ = writeln!(
                s,
                "  rates: {ALONE_NOTE}: c_t in [{}, {}]",
                num(prs.rate().min_c),
                num(prs.rate().max_c)
            );
        }
        Rate::Global => {
            let _ = writeln!(
                s,
                "  constants: c = {:.6}, sigma = {:.6}, rho = {:.6} ({})",
                k.c, k.sigma, k.rho, k.provenance
            );
        }
        Rate::Local if prs.period().is_some() => {
            let _ = writeln!(
                s,
                "  discrete time, period {}: map factors L_k in [{}, {}] ({})",
                time(prs.period().unwrap_or(0.0)),
                num(prs.rate().min_c),
                num(prs.rate().max_c),
                k.provenance
            );
        }
        Rate::Local => {
            // (A split result's regions are its pieces'.)
            let sigma = std::iter::once(prs)
                .chain(prs.pieces())
                .flat_map(|p| p.regions())
                .map(|r| r.sigma)
                .fold(0.0, f64::max);
            let _ = writeln!(
                s,
                "  rates: local, c_t in [{}, {}], sigma_t at most {} (global: c = {}, sigma = \
                 {}; {})",
                num(prs.rate().min_c),
                num(prs.rate().max_c),
                num(sigma),
                num(k.c),
                num(k.sigma),
                k.provenance
            );
            if let Some(t) = prs.rate().global_from {
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
                num(prs.rate().max_c),
                k.sigma,
                k.rho,
                k.provenance
            );
        }
    }
    if prs.rate().rate != Rate::Global && !alone && prs.period().is_none() {
        let _ = writeln!(s, "  rate: {}", rate_note(prs.rate().rate));
    }
    let _ = writeln!(
        s,
        "  metric P = [{}] ({})",
        metric_rows(prs),
        k.metric_region
    );
    let rule = match (prs.radius_rule().eps, prs.radius_rule().gaussian) {
        (Some(eps), _) => format!("{} (eps = {eps:.6})", prs.radius_rule().rule.name()),
        (None, Some(g)) => format!(
            "exact Gaussian (affine system: chi2 quantile {:.6}{})",
            g.quantile,
            match g.uniform {
                Some(UniformBound::Mixture) => ", time-uniform by the Gaussian mixture bound",
                Some(UniformBound::AmgfTube) => ", time-uniform by the amgf tube (tighter here)",
                Some(UniformBound::UnionOverSteps) => ", at once over the steps by the union bound",
                None => "",
            },
        ),
        (None, None) => prs.radius_rule().rule.name().to_string(),
    };
    // With several metrics each set is at delta / K.
    let delta_each = prs.delta() / metrics(prs) as f64;
    let _ = writeln!(
        s,
        "  radius rule: {rule}, kappa(n = {}, delta = {}) = {:.6}",
        prs.states().len(),
        delta_each,
        prs.kappa()
    );
    summary_metrics(prs, &mut s);
    if !prs.pieces().is_empty() {
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
    } else if prs.method() == Method::Interval {
        summary_boxes(prs, &mut s);
    } else {
        let _ = writeln!(
            s,
            "  r1 = {:.6} ({}), r2 = {}",
            prs.r1(),
            r1_how(prs),
            prs.r2()
        );
        let _ = writeln!(
            s,
            "  {:>10}  {:>12}  {:>12}  {:>12}  {:>12}",
            "t", "R_t", "r_t", "PRS radius", "pointwise r"
        );
        for i in summary_indices(prs.steps().len()) {
            let st = &prs.steps()[i];
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
    if prs.unsafe_sets().is_empty() {
        let _ = writeln!(s, "  safety: no unsafe sets");
    } else {
        for u in prs.unsafe_sets() {
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
    for g in prs.goals() {
        let _ = writeln!(s, "{}", goal_line(prs, g));
    }
    let verdict = match &prs.verdict() {
        Verdict::Safe if matches!(prs.rate().rate, Rate::Empirical { .. }) => {
            "safe by the EMPIRICAL estimate (every estimated PRS misses every unsafe set; not a \
             guarantee)"
                .to_string()
        }
        Verdict::Safe => match prs.guarantee() {
            Guarantee::Uniform => format!(
                "safe: with probability at least {} the state avoids every unsafe set for all t \
                 in [0, {}] (every PRS over every interval misses every unsafe set)",
                1.0 - prs.delta(),
                prs.horizon()
            ),
            Guarantee::Pointwise => format!(
                "safe at each time separately: for every t in [0, {}], the state is in no \
                 unsafe set with probability at least {} (every PRS misses every unsafe set)",
                prs.horizon(),
                1.0 - prs.delta()
            ),
        },
        Verdict::NoUnsafeSets => "no unsafe sets to check".to_string(),
        Verdict::NotShownSafe { t, set, .. } => format!(
            "not shown safe: the PRS over the interval ending at t = {} meets `{}` (this \
             does not prove a violation)",
            time(*t),
            prs.unsafe_sets()[*set].name
        ),
    };
    let _ = writeln!(s, "  verdict: {verdict}");
    if prs.validation().conditional_on_domain {
        let _ = writeln!(
            s,
            "  condition: the constants hold only in the domain; the result assumes the state \
             does not leave it"
        );
    }
    let not_validated: Vec<String> = prs
        .validation()
        .not_validated
        .iter()
        .map(unproved)
        .collect();
    let not_validated = if not_validated.is_empty() {
        "nothing (every bound above is proved)".to_string()
    } else {
        not_validated.join("; ")
    };
    let _ = writeln!(s, "  not validated: {not_validated}");
    for hint in prs.hints() {
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
        .transform()
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
                prs.states()[state],
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
            prs.states()[state],
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
    match prs.guarantee() {
        Guarantee::Uniform => format!(
            "guarantee: one event of probability at least {}: X_t lies in the tube for all t in \
             [0, {}] at once",
            1.0 - prs.delta(),
            prs.horizon()
        ),
        Guarantee::Pointwise => format!(
            "guarantee: for each t separately, X_t lies in its PRS with probability at least {} \
             (not uniformly in time)",
            1.0 - prs.delta()
        ),
    }
}

/// The number of metrics of a result: its own and its members that are further metrics (the
/// others are the interval boxes and first-order zonotopes it is cut by).
fn metrics(prs: &Prs) -> usize {
    1 + prs
        .also()
        .iter()
        .filter(|m| m.role() == Role::Metric)
        .count()
}

/// The further metrics of an intersection result, and its bounding boxes.
fn summary_metrics(prs: &Prs, s: &mut String) {
    if prs.also().is_empty() {
        return;
    }
    let k = metrics(prs);
    if k > 1 {
        let _ = writeln!(
            s,
            "  several metrics: the PRS is the intersection of the sets of {k} metrics, each at \
             delta / {k} = {:e} (the tables below the first metric's; the boxes, margins and \
             verdicts the intersection's)",
            prs.delta() / k as f64
        );
    }
    let boxes = prs.also().iter().filter(|m| m.role() == Role::Box).count();
    if boxes > 0 {
        let _ = writeln!(
            s,
            "  cut by the interval box: the PRS is the intersection of each metric's ball with \
             the interval method's box of the same run, widened by the same r_t, at the same \
             delta ({boxes} box{}; the boxes, margins and verdicts below are the intersection's)",
            if boxes == 1 { "" } else { "es" }
        );
    }
    for m in prs.also().iter().filter(|m| m.role() == Role::FirstOrder) {
        let last = m.steps().last();
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
    for m in prs.also().iter().filter(|m| m.role() == Role::Linearised) {
        let _ = writeln!(
            s,
            "  cut by the linearised Gaussian set (delta = {} of it; the other sets at the \
             rest): the PRS also lies in a zonotope holding the initial box under the flow's \
             linearisation, the linearisation's error and its Gaussian part, for all t at once \
             (P-radius {} at the horizon); the boxes, margins and verdicts below are the \
             intersection's",
            num(m.delta()),
            num(m.steps().last().map_or(f64::NAN, |st| st.det.radius()))
        );
    }
    for (j, m) in prs
        .also()
        .iter()
        .filter(|m| m.role() == Role::Metric)
        .enumerate()
    {
        let last = m.steps().last().map_or(f64::NAN, |st| st.prs_radius);
        let _ = writeln!(
            s,
            "  metric {}: P = [{}], c = {:.6}, sigma = {:.6}; PRS radius at the horizon {}",
            j + 2,
            metric_rows(m),
            m.constants().c,
            m.constants().sigma,
            num(last)
        );
    }
    hull_table(prs, s);
}

/// A result's metric `P`, row by row: `[p11, p12], [p21, p22]`.
fn metric_rows(prs: &Prs) -> String {
    let rows: Vec<String> = prs
        .constants()
        .metric
        .chunks(prs.n().max(1))
        .map(|r| {
            let cells: Vec<String> = r.iter().map(|v| format!("{v:.6}")).collect();
            format!("[{}]", cells.join(", "))
        })
        .collect();
    rows.join(", ")
}

/// The table of the PRS's bounding boxes (of an intersection or a union) per report time.
fn hull_table(prs: &Prs, s: &mut String) {
    let names: Vec<String> = prs
        .states()
        .iter()
        .map(|x| format!("{x} [lo, hi]"))
        .collect();
    let header: Vec<String> = names.iter().map(|x| format!("{x:>28}")).collect();
    let _ = writeln!(s, "  {:>10}  {}", "t", header.join("  "));
    for i in summary_indices(prs.steps().len()) {
        let Some(hull) = prs.hull_at(i) else {
            continue;
        };
        let cells: Vec<String> = hull
            .iter()
            .map(|b| format!("[{:>12}, {:>12}]", num(b.lo), num(b.hi)))
            .collect();
        let _ = writeln!(s, "  {:>10.4}  {}", prs.steps()[i].t, cells.join("  "));
    }
}

/// A split result (method.md 8.11) in words: the pieces, the union's bounding boxes, and which
/// pieces are not shown safe.
fn summary_split(prs: &Prs, s: &mut String) {
    let how = match prs.split() {
        Split::Counts(k) => {
            let counts: Vec<String> = k.iter().map(|k| k.to_string()).collect();
            format!(
                "cut into {} = {} pieces",
                counts.join(" x "),
                prs.pieces().len()
            )
        }
        Split::Auto { pieces, seconds } => format!(
            "cut automatically into {} pieces (at most {pieces}{}: the pieces with the largest \
             sets halved along their widest state, while that shrank them)",
            prs.pieces().len(),
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
        prs.delta(),
        1.0 - prs.delta()
    );
    let cut: usize = prs.pieces().iter().filter(|p| !p.also().is_empty()).count();
    if cut > 0 {
        let _ = writeln!(
            s,
            "  pieces cut by further sets of their own run (interval box, first-order or \
             linearised sets): {cut} of {}",
            prs.pieces().len()
        );
    }
    hull_table(prs, s);
    let unsafe_pieces: Vec<(usize, &Prs)> = prs
        .pieces()
        .iter()
        .enumerate()
        .filter(|(_, p)| matches!(p.verdict(), Verdict::NotShownSafe { .. }))
        .collect();
    if let Some((j, p)) = unsafe_pieces.first() {
        let range: Vec<String> = p
            .initial()
            .bounding_box()
            .unwrap_or_default()
            .iter()
            .zip(prs.states())
            .map(|(b, x)| format!("{x} in [{}, {}]", num(b.lo), num(b.hi)))
            .collect();
        let _ = writeln!(
            s,
            "  pieces not shown safe: {} of {} (the first, piece {}: {})",
            unsafe_pieces.len(),
            prs.pieces().len(),
            j + 1,
            range.join(", ")
        );
    }
}

/// The deterministic sets of an interval result (boxes or parallelotopes) in words, and their
/// table.
fn summary_boxes(prs: &Prs, s: &mut String) {
    let inclusion = prs.inclusion().map_or("?", |i| i.name());
    match &prs.transform() {
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
    let Some(first) = prs.steps().first() else {
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
    for k in summary_indices(prs.steps().len()) {
        let st = &prs.steps()[k];
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
