//! What the plots read: the result JSON of `reachc run` (`DIR/<analysis>.json`) and the Monte
//! Carlo report of `reachc simulate` (`DIR/<analysis>.sim.json`), both documented in
//! docs/results.md. Only the fields the plots use are read, and checked for consistency, so a
//! damaged file gives a message instead of a wrong picture.

use std::path::Path;

use serde::Deserialize;

/// The parts of an analysis result the plots use.
#[derive(Clone, Debug, Deserialize)]
pub struct ResultFile {
    /// `model NAME`.
    pub model: String,
    /// The analysis' name (also the output file names).
    pub analysis: String,
    /// How the deterministic sets were computed.
    pub method: Method,
    /// Probability level.
    pub delta: f64,
    /// What `delta` is about: all times at once, or each time separately (results written
    /// before time-uniform tubes are pointwise).
    #[serde(default)]
    pub guarantee: Guarantee,
    /// State names.
    pub states: Vec<String>,
    /// Indices of the output states.
    pub outputs: Vec<usize>,
    /// The constants (the metric `P`).
    pub constants: Constants,
    /// The coordinate transform of an interval analysis.
    #[serde(default)]
    pub transform: Option<Transform>,
    /// Centre of the initial set (where `simulate` evaluates a constant diffusion).
    pub initial_center: Vec<f64>,
    /// Where the rates come from (results written before local rates have none).
    #[serde(default)]
    pub rate: Option<RateKind>,
    /// One record per report time.
    pub steps: Vec<Step>,
    /// The analysis' further metrics' results (the PRS is the intersection of all sets).
    #[serde(default)]
    pub also: Vec<ResultFile>,
}

/// The guarantee of a result (`"uniform"` or `"pointwise"`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Guarantee {
    /// One event for the whole horizon.
    Uniform,
    /// Each time separately.
    #[default]
    Pointwise,
}

/// The method of a result (`"contraction"` or `"interval"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// P-balls around the nominal trajectory.
    Contraction,
    /// Boxes (or parallelotopes) of an embedding system.
    Interval,
}

/// The shape of a deterministic set (`"p_ball"`, `"box"` or `"parallelotope"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// `{x : |x - center|_P <= radius}`.
    PBall,
    /// `{x : lo <= x <= hi}`.
    Box,
    /// `{x : lo <= T x <= hi}`.
    Parallelotope,
}

/// Where a result's rates come from.
#[derive(Clone, Debug, Deserialize)]
pub struct RateKind {
    /// Local, global or empirical.
    pub kind: RateSource,
    /// Local rates: when the domain's global constants took over.
    #[serde(default)]
    pub global_from: Option<f64>,
}

/// The kind of a result's rates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RateSource {
    /// Certified on regions holding the tube.
    Local,
    /// The compiler's constants.
    Global,
    /// Estimated from sample paths (not a guarantee).
    Empirical,
}

impl RateSource {
    /// The name used in specs and result files.
    pub fn name(self) -> &'static str {
        match self {
            RateSource::Local => "local",
            RateSource::Global => "global",
            RateSource::Empirical => "empirical",
        }
    }
}

/// The constants of a result (only the metric is drawn).
#[derive(Clone, Debug, Deserialize)]
pub struct Constants {
    /// `P`, by rows.
    pub metric: Vec<Vec<f64>>,
}

/// A coordinate transform `y = T x`.
#[derive(Clone, Debug, Deserialize)]
pub struct Transform {
    /// `T^-1` (floating point, within `inverse_error` of the exact inverse: far below a pixel).
    pub inverse: Vec<Vec<f64>>,
}

/// The sets at one report time.
#[derive(Clone, Debug, Deserialize)]
pub struct Step {
    /// Time.
    pub t: f64,
    /// Nominal state (interval method: the centre of the set).
    pub nominal: Vec<f64>,
    /// The deterministic set.
    pub det_set: DetSet,
    /// Stochastic radius.
    pub r_t: f64,
    /// PRS radius (interval method: a P-ball containing the PRS).
    pub prs_radius: f64,
    /// The largest contraction rate over the report interval ending here (`null`: unbounded).
    #[serde(default)]
    pub c: Option<f64>,
    /// The largest noise level over the same.
    #[serde(default)]
    pub sigma: Option<f64>,
}

/// A deterministic set: `p_ball`, `box` or `parallelotope` (see docs/results.md).
#[derive(Clone, Debug, Deserialize)]
pub struct DetSet {
    /// Its shape.
    pub shape: Shape,
    /// Centre of the P-ball (`p_ball`).
    pub center: Vec<f64>,
    /// Radius `R_t` of the P-ball.
    pub radius: f64,
    /// Lower corner (`box`: in `x`; `parallelotope`: in `y = T x`).
    #[serde(default)]
    pub lo: Option<Vec<f64>>,
    /// Upper corner.
    #[serde(default)]
    pub hi: Option<Vec<f64>>,
}

/// The parts of a Monte Carlo report the plots use.
#[derive(Clone, Debug, Deserialize)]
pub struct SimFile {
    /// `model NAME`.
    pub model: String,
    /// The analysis checked.
    pub analysis: String,
    /// The PRS's probability level (the quantile's level is `1 - delta`).
    pub delta: f64,
    /// Number of paths.
    pub paths: u64,
    /// Per report time.
    pub steps: Vec<SimStep>,
}

/// One report time of a Monte Carlo report.
#[derive(Clone, Debug, Deserialize)]
pub struct SimStep {
    /// Time.
    pub t: f64,
    /// Empirical `(1 - delta)` quantile of `|X_t - x*_t|_P` (`null` when not finite).
    pub quantile: Option<f64>,
}

/// Reads a JSON file into `T`; the message names the file.
fn read<T: for<'de> Deserialize<'de>>(path: &Path, what: &str) -> Result<T, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    serde_json::from_str(&text)
        .map_err(|e| format!("{} is not a valid {what}: {e}", path.display()))
}

impl ResultFile {
    /// Reads and checks a result file.
    pub fn read(path: &Path) -> Result<ResultFile, String> {
        let r: ResultFile = read(path, "result of `reachc run`")?;
        r.check()
            .map_err(|e| format!("{} is not a consistent result: {e}", path.display()))?;
        Ok(r)
    }

    /// Dimensions, shapes and times agree, every number is finite.
    fn check(&self) -> Result<(), String> {
        let n = self.states.len();
        let square = |m: &[Vec<f64>]| m.len() == n && m.iter().all(|r| r.len() == n);
        if n == 0 || self.steps.is_empty() {
            return Err("no states or no report times".into());
        }
        if !square(&self.constants.metric) {
            return Err(format!("the metric is not {n} x {n}"));
        }
        if let Some(&i) = self.outputs.iter().find(|&&i| i >= n) {
            return Err(format!("output index {i} is not a state"));
        }
        if let Some(t) = &self.transform {
            if !square(&t.inverse) {
                return Err(format!("the transform's inverse is not {n} x {n}"));
            }
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        for (k, s) in self.steps.iter().enumerate() {
            let d = &s.det_set;
            let corners = match (&d.lo, &d.hi) {
                (Some(lo), Some(hi)) => lo.len() == n && hi.len() == n && finite(lo) && finite(hi),
                _ => false,
            };
            let shape_ok = match d.shape {
                Shape::PBall => d.center.len() == n && finite(&d.center) && d.radius.is_finite(),
                Shape::Box => corners,
                Shape::Parallelotope => corners && self.transform.is_some(),
            };
            if !shape_ok {
                return Err(format!("step {k}: malformed {:?} set", d.shape));
            }
            if s.nominal.len() != n || !finite(&s.nominal) {
                return Err(format!(
                    "step {k}: the nominal state has the wrong dimension"
                ));
            }
            if !(s.t.is_finite() && s.r_t.is_finite() && s.prs_radius.is_finite()) {
                return Err(format!("step {k}: non-finite time or radius"));
            }
            if k > 0 && s.t <= self.steps[k - 1].t {
                return Err(format!("step {k}: the times do not increase"));
            }
        }
        if !finite(&self.constants.metric.concat()) {
            return Err("the metric has non-finite entries".into());
        }
        Ok(())
    }

    /// The report times.
    pub fn times(&self) -> Vec<f64> {
        self.steps.iter().map(|s| s.t).collect()
    }
}

impl SimFile {
    /// Reads a Monte Carlo report.
    pub fn read(path: &Path) -> Result<SimFile, String> {
        read(path, "report of `reachc simulate`")
    }

    /// Why it does not belong to `result` (another model, analysis or delta, other report
    /// times), or `None` if it does.
    pub fn mismatch(&self, result: &ResultFile) -> Option<String> {
        let same_times = self.steps.len() == result.steps.len()
            && self
                .steps
                .iter()
                .zip(&result.steps)
                .all(|(a, b)| (a.t - b.t).abs() <= 1e-9 * b.t.abs().max(1.0));
        if self.model != result.model || self.analysis != result.analysis {
            Some(format!(
                "it checks `{}` / `{}`, not `{}` / `{}`",
                self.model, self.analysis, result.model, result.analysis
            ))
        } else if self.delta != result.delta {
            Some(format!(
                "it was simulated at delta = {}, the result has delta = {}",
                self.delta, result.delta
            ))
        } else if !same_times {
            Some("its report times differ from the result's".into())
        } else {
            None
        }
    }
}
