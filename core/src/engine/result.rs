//! The result of an analysis and its renderings (JSON, CSV, text summary).

use serde::Serialize;
use std::fmt::Write as _;
use std::io::{self, Write};

/// Everything an analysis computed, ready to be serialised.
///
/// Non-finite numbers (e.g. an infinite margin) appear as `null` in the JSON.
#[derive(Clone, Debug, Serialize)]
pub struct AnalysisResult {
    /// `model NAME`.
    pub model: String,
    /// The analysis' name.
    pub analysis: String,
    /// Deterministic-set method (`"contraction"` or `"interval"`).
    pub method: String,
    /// Inclusion function of the interval method (`"natural"` or `"jacobian"`); absent (not
    /// serialised) for the contraction method.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inclusion: Option<String>,
    /// Probability level: each PRS holds `X_t` with probability `>= 1 - delta`.
    pub delta: f64,
    /// Final time.
    pub horizon: f64,
    /// Nominal report step (the last step may be shorter).
    pub step: f64,
    /// Integrator of the nominal trajectory (`"rk4"` or `"euler"`).
    pub integrator: String,
    /// All state names (the order of `nominal` and `center`).
    pub states: Vec<String>,
    /// Indices of the states the CSV and the summary report.
    pub outputs: Vec<usize>,
    /// Where the contraction rate came from.
    pub rate: RateReport,
    /// The constants of Assumption 1 used.
    pub constants: ConstantsReport,
    /// The stochastic radius rule.
    pub radius_rule: RadiusRuleReport,
    /// `kappa(n, delta)` of the rule: `r_t = sqrt(Psi_t kappa)`.
    pub kappa: f64,
    /// Upper bound of `|x0 - x*_0|_P` over the initial set.
    pub r1: f64,
    /// Radius of the input box in the input norm (1; 0 without inputs).
    pub r2: f64,
    /// How `r1` was bounded.
    pub r1_how: String,
    /// The coordinate transform of an interval analysis (absent otherwise). The boxes
    /// (`det_set.lo`, `det_set.hi`) are then in the coordinates `y = T x`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub transform: Option<TransformReport>,
    /// Centre of the initial set (the nominal's start).
    pub initial_center: Vec<f64>,
    /// Centre of the input box (the nominal's input).
    pub input_center: Vec<f64>,
    /// One record per report time.
    pub steps: Vec<StepRecord>,
    /// Per unsafe set, its verdict over the whole horizon.
    pub unsafe_sets: Vec<UnsafeReport>,
    /// The overall verdict.
    pub verdict: Verdict,
    /// Which parts are rigorous and which are not.
    pub validated: Validation,
}

/// The constants of Assumption 1, as used.
#[derive(Clone, Debug, Serialize)]
pub struct ConstantsReport {
    /// Contraction rate.
    pub c: f64,
    /// Noise level.
    pub sigma: f64,
    /// Input gain (0 without inputs).
    pub rho: f64,
    /// How the compiler obtained them.
    pub how: String,
    /// The metric `P`, by rows.
    pub metric: Vec<Vec<f64>>,
}

/// Where the contraction rate `c_t` came from (see [`Rate`](crate::system::Rate)).
#[derive(Clone, Debug, Serialize)]
pub struct RateReport {
    /// `"certified"` or `"empirical"`.
    pub kind: String,
    /// One sentence for the reader; an empirical rate says plainly that it is no guarantee.
    pub note: String,
    /// Number of sample paths of the estimate (empirical rates).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub paths: Option<u64>,
    /// The largest rate used on any step (the certified `c` for a certified rate).
    pub max_c: f64,
}

/// A coordinate transform `y = T x`, as used.
#[derive(Clone, Debug, Serialize)]
pub struct TransformReport {
    /// `T`, by rows.
    pub matrix: Vec<Vec<f64>>,
    /// `T^-1` computed in floating point, by rows (`x = T^-1 y`).
    pub inverse: Vec<Vec<f64>>,
    /// A rigorous bound of `|(T^-1)_ij - inverse_ij|` over all entries (0 when exact).
    pub inverse_error: f64,
}

/// The stochastic radius rule used.
#[derive(Clone, Debug, Serialize)]
pub struct RadiusRuleReport {
    /// `"amgf"`, `"paper"` or `"paper_optimal"`.
    pub rule: String,
    /// `eps` of Theorem 1 (the given one, or the minimiser), for the paper rules.
    pub eps: Option<f64>,
}

/// The sets at one report time.
#[derive(Clone, Debug, Serialize)]
pub struct StepRecord {
    /// Time.
    pub t: f64,
    /// Nominal state `x*_t` (all states). Interval method: the centre of the box.
    pub nominal: Vec<f64>,
    /// Deterministic reachable set `Rbar_t`.
    pub det_set: DetSet,
    /// Stochastic radius `r_t` (in `|.|_P`).
    pub r_t: f64,
    /// `Psi_t` (upper bound).
    pub psi: f64,
    /// Contraction rate on the step ending here.
    pub c: f64,
    /// Noise level on the step ending here.
    pub sigma: f64,
    /// Radius of the PRS `B_P(x*_t, R_t + r_t)`. Interval method: radius of a P-ball around the
    /// box centre containing the PRS `box (+) B_P(r_t)` (coarser than the PRS).
    pub prs_radius: f64,
    /// Safety margin per unsafe set (same order as `unsafe_sets`; `> 0` means shown safe).
    pub margins: Vec<f64>,
}

/// A deterministic reachable set.
#[derive(Clone, Debug, Serialize)]
pub struct DetSet {
    /// `"p_ball"`: `{x : |x - center|_P <= radius}`; `"box"`: `{x : lo <= x <= hi}` (interval
    /// method), with `center`, `radius` a P-ball containing the box; `"parallelotope"`:
    /// `{x : lo <= T x <= hi}` (interval method with the transform `T` of
    /// [`AnalysisResult::transform`]), with its interval hull `hull_lo`, `hull_hi` in `x` and
    /// `center`, `radius` a P-ball containing the hull.
    pub shape: &'static str,
    /// Centre.
    pub center: Vec<f64>,
    /// Radius `R_t` (upper bound); for a box, an upper bound of its P-radius around `center`.
    pub radius: f64,
    /// Where the metric is: `"constants.metric"`.
    pub metric: &'static str,
    /// Lower corner of the box (shapes `"box"` and `"parallelotope"`, where it is in `y`; not
    /// serialised otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lo: Option<Vec<f64>>,
    /// Upper corner of the box (shapes `"box"` and `"parallelotope"`; not serialised
    /// otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hi: Option<Vec<f64>>,
    /// Lower corner of the parallelotope's interval hull in `x` (shape `"parallelotope"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hull_lo: Option<Vec<f64>>,
    /// Upper corner of the parallelotope's interval hull in `x` (shape `"parallelotope"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hull_hi: Option<Vec<f64>>,
}

/// One unsafe set's verdict.
#[derive(Clone, Debug, Serialize)]
pub struct UnsafeReport {
    /// Its name.
    pub name: String,
    /// `"half_space"`, `"box"` or `"ball"`.
    pub kind: String,
    /// Shown safe at every report time.
    pub safe: bool,
    /// Smallest margin over the report times.
    pub min_margin: f64,
    /// Time of the smallest margin.
    pub min_margin_t: f64,
    /// First report time at which safety was not shown.
    pub first_not_safe_t: Option<f64>,
    /// What the margin measures.
    pub margin_unit: String,
}

/// The overall verdict. A PRS touching an unsafe set does not prove a violation, hence "not
/// shown safe" rather than "unsafe".
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Verdict {
    /// Every PRS is disjoint from every unsafe set.
    Safe,
    /// The spec has no unsafe sets.
    NoUnsafeSets,
    /// The first report time and set for which safety was not shown.
    NotShownSafe {
        /// Time.
        t: f64,
        /// Step index.
        step: usize,
        /// The unsafe set's name.
        set: String,
    },
}

/// Which parts of the result are rigorous.
#[derive(Clone, Debug, Serialize)]
pub struct Validation {
    /// Rigorous parts (outward-rounded, or certified by the compiler).
    pub rigorous: Vec<String>,
    /// Parts that are not validated.
    pub not_validated: Vec<String>,
    /// The result holds only while the state stays in the spec's domain.
    pub conditional_on_domain: bool,
}

impl AnalysisResult {
    /// Pretty-printed JSON.
    pub fn to_json(&self) -> String {
        // Serialising plain data with string keys cannot fail.
        serde_json::to_string_pretty(self).expect("AnalysisResult serialises")
    }

    /// State indices the CSV and the summary show: `outputs`, or all states if it is empty.
    fn shown_states(&self) -> Vec<usize> {
        if self.outputs.is_empty() {
            (0..self.states.len()).collect()
        } else {
            self.outputs.clone()
        }
    }

    /// Whether the deterministic sets are boxes (interval method).
    fn has_boxes(&self) -> bool {
        self.steps.first().is_some_and(|s| s.det_set.lo.is_some())
    }

    /// CSV with header `t,<output state names...>,det_radius,r_t,psi,c,sigma,prs_radius` and one
    /// row per report time (the nominal state in the state columns). For the interval method
    /// (box sets) the header is `t,<state>_lo,<state>_hi,...,r_t,psi` instead; with a coordinate
    /// transform, `t,y1_lo,y1_hi,...,yn_lo,yn_hi,<state>_lo,<state>_hi,...,r_t,psi` (the box in
    /// `y = T x`, then the parallelotope's interval hull in the output states).
    pub fn write_csv(&self, w: &mut dyn Write) -> io::Result<()> {
        let shown = self.shown_states();
        if self.has_boxes() {
            let mut header = String::from("t");
            if let Some(first) = self.steps.first() {
                for (label, _, _) in self.box_columns(first) {
                    let _ = write!(
                        header,
                        ",{},{}",
                        csv_field(&format!("{label}_lo")),
                        csv_field(&format!("{label}_hi"))
                    );
                }
            }
            header.push_str(",r_t,psi");
            writeln!(w, "{header}")?;
            for s in &self.steps {
                let mut row = format!("{}", s.t);
                for (_, a, b) in self.box_columns(s) {
                    let _ = write!(row, ",{a},{b}");
                }
                let _ = write!(row, ",{},{}", s.r_t, s.psi);
                writeln!(w, "{row}")?;
            }
            return Ok(());
        }
        let mut header = String::from("t");
        for &i in &shown {
            header.push(',');
            header.push_str(&csv_field(&self.states[i]));
        }
        header.push_str(",det_radius,r_t,psi,c,sigma,prs_radius");
        writeln!(w, "{header}")?;
        for s in &self.steps {
            let mut row = format!("{}", s.t);
            for &i in &shown {
                let _ = write!(row, ",{}", s.nominal[i]);
            }
            let _ = write!(
                row,
                ",{},{},{},{},{},{}",
                s.det_set.radius, s.r_t, s.psi, s.c, s.sigma, s.prs_radius
            );
            writeln!(w, "{row}")?;
        }
        Ok(())
    }

    /// A readable text summary: constants, radius rule and kappa, a table at about ten evenly
    /// spaced times plus the final time, and the safety verdicts with margins.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "analysis `{}` of model `{}` ({} method, delta = {})",
            self.analysis, self.model, self.method, self.delta
        );
        let k = &self.constants;
        let c = if self.rate.kind == "certified" {
            format!("{:.6}", k.c)
        } else {
            format!(
                "c_t ({} rate, at most {})",
                self.rate.kind,
                num(self.rate.max_c)
            )
        };
        let _ = writeln!(
            s,
            "  constants: c = {c}, sigma = {:.6}, rho = {:.6} ({})",
            k.sigma, k.rho, k.how
        );
        if self.rate.kind != "certified" {
            let _ = writeln!(s, "  rate: {}", self.rate.note);
        }
        let rows: Vec<String> = k
            .metric
            .iter()
            .map(|r| {
                let cells: Vec<String> = r.iter().map(|v| format!("{v:.6}")).collect();
                format!("[{}]", cells.join(", "))
            })
            .collect();
        let _ = writeln!(s, "  metric P = [{}]", rows.join(", "));
        let rule = match self.radius_rule.eps {
            Some(eps) => format!("{} (eps = {eps:.6})", self.radius_rule.rule),
            None => self.radius_rule.rule.clone(),
        };
        let _ = writeln!(
            s,
            "  radius rule: {rule}, kappa(n = {}, delta = {}) = {:.6}",
            self.states.len(),
            self.delta,
            self.kappa
        );
        if self.has_boxes() {
            self.summary_boxes(&mut s);
        } else {
            let _ = writeln!(
                s,
                "  r1 = {:.6} ({}), r2 = {}",
                self.r1, self.r1_how, self.r2
            );
            let _ = writeln!(
                s,
                "  {:>10}  {:>12}  {:>12}  {:>12}",
                "t", "R_t", "r_t", "PRS radius"
            );
            for i in summary_indices(self.steps.len()) {
                let st = &self.steps[i];
                let _ = writeln!(
                    s,
                    "  {:>10.4}  {:>12}  {:>12}  {:>12}",
                    st.t,
                    num(st.det_set.radius),
                    num(st.r_t),
                    num(st.prs_radius)
                );
            }
        }
        if self.unsafe_sets.is_empty() {
            let _ = writeln!(s, "  safety: no unsafe sets");
        } else {
            for u in &self.unsafe_sets {
                let status = if u.safe {
                    "safe".to_string()
                } else {
                    format!(
                        "NOT SHOWN SAFE (first at t = {:.4})",
                        u.first_not_safe_t.unwrap_or(f64::NAN)
                    )
                };
                let _ = writeln!(
                    s,
                    "  unsafe set `{}` ({}): {status}; min margin {} at t = {:.4} ({})",
                    u.name,
                    u.kind,
                    num(u.min_margin),
                    u.min_margin_t,
                    u.margin_unit
                );
            }
        }
        let verdict = match &self.verdict {
            Verdict::Safe if self.rate.kind == "empirical" => {
                "safe by the EMPIRICAL estimate (every estimated PRS misses every unsafe set; \
                 not a guarantee)"
                    .to_string()
            }
            Verdict::Safe => "safe (every PRS misses every unsafe set)".to_string(),
            Verdict::NoUnsafeSets => "no unsafe sets to check".to_string(),
            Verdict::NotShownSafe { t, set, .. } => format!(
                "not shown safe: the PRS at t = {t:.4} meets `{set}` (this does not prove a violation)"
            ),
        };
        let _ = writeln!(s, "  verdict: {verdict}");
        let _ = writeln!(
            s,
            "  not validated: {}",
            self.validated.not_validated.join("; ")
        );
        s
    }
}

/// A number for the summary: 6 decimals, or scientific notation where that would be long.
fn num(v: f64) -> String {
    if v.is_finite() && v.abs() >= 1e6 {
        format!("{v:.6e}")
    } else {
        format!("{v:.6}")
    }
}

impl AnalysisResult {
    /// The table of the summary for box sets: per column of [`Self::box_columns`] the range
    /// `[lo, hi]`, and `r_t`.
    fn summary_boxes(&self, s: &mut String) {
        let inclusion = self.inclusion.as_deref().unwrap_or("?");
        match &self.transform {
            None => {
                let _ = writeln!(
                    s,
                    "  deterministic sets: boxes of the embedding system ({inclusion} \
                     inclusion); PRS = box (+) B_P(r_t)"
                );
            }
            Some(tr) => {
                let rows: Vec<String> = tr.matrix.iter().map(|r| format!("{r:?}")).collect();
                let _ = writeln!(
                    s,
                    "  deterministic sets: parallelotopes {{x : T x in box}}, T = [{}], box of the \
                     embedding system in y = T x ({inclusion} inclusion); PRS = parallelotope \
                     (+) B_P(r_t); columns: the box in y, then the parallelotope's hull in x",
                    rows.join(", ")
                );
            }
        }
        let Some(first) = self.steps.first() else {
            return;
        };
        let mut head = format!("  {:>10}", "t");
        for (label, _, _) in self.box_columns(first) {
            let _ = write!(head, "  {:>27}", format!("{label} [lo, hi]"));
        }
        let _ = write!(head, "  {:>12}", "r_t");
        let _ = writeln!(s, "{head}");
        for k in summary_indices(self.steps.len()) {
            let st = &self.steps[k];
            let mut row = format!("  {:>10.4}", st.t);
            for (_, a, b) in self.box_columns(st) {
                let _ = write!(row, "  [{a:>12.6}, {b:>12.6}]");
            }
            let _ = write!(row, "  {:>12.6}", st.r_t);
            let _ = writeln!(s, "{row}");
        }
    }

    /// The ranges shown for a box step, `(label, lo, hi)`: the box over the shown states, or
    /// with a transform the box in `y` (`y1`, `y2`, ...) and then the parallelotope's interval
    /// hull over the shown states.
    fn box_columns(&self, st: &StepRecord) -> Vec<(String, f64, f64)> {
        let at = |v: &Option<Vec<f64>>, i: usize| {
            v.as_deref()
                .and_then(|v| v.get(i).copied())
                .unwrap_or(f64::NAN)
        };
        let d = &st.det_set;
        let shown = self.shown_states().into_iter();
        if self.transform.is_some() {
            let ys =
                (0..self.states.len()).map(|i| (format!("y{}", i + 1), at(&d.lo, i), at(&d.hi, i)));
            ys.chain(shown.map(|i| (self.states[i].clone(), at(&d.hull_lo, i), at(&d.hull_hi, i))))
                .collect()
        } else {
            shown
                .map(|i| (self.states[i].clone(), at(&d.lo, i), at(&d.hi, i)))
                .collect()
        }
    }
}

/// About ten evenly spaced step indices, always including the first and the last.
fn summary_indices(len: usize) -> Vec<usize> {
    if len == 0 {
        return Vec::new();
    }
    let last = len - 1;
    let mut idx: Vec<usize> = (0..10).map(|k| k * last / 10).collect();
    idx.push(last);
    idx.dedup();
    idx
}

/// Quotes a CSV field when it needs it (state names are identifiers, possibly `x[3]`).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
