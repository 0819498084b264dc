//! The result of a Monte Carlo validation and its renderings (JSON, text summary).

use super::inputs::InputMode;
use serde::Serialize;
use std::fmt::Write as _;

/// Everything a simulation measured, ready to be serialised. The same seed and options give the
/// same report (and JSON) whatever the number of threads.
#[derive(Clone, Debug, Serialize)]
pub struct SimReport {
    /// `model NAME`.
    pub model: String,
    /// The analysis whose PRS is checked.
    pub analysis: String,
    /// Its method (`"contraction"`, `"interval"`).
    pub method: String,
    /// The PRS's probability level: each PRS should hold `X_t` with probability `>= 1 - delta`.
    pub delta: f64,
    /// Number of sample paths.
    pub paths: u64,
    /// Random seed.
    pub seed: u64,
    /// Largest Euler-Maruyama step used (each report interval is split into equal steps).
    pub dt: f64,
    /// Euler-Maruyama steps per path.
    pub steps_per_path: u64,
    /// How initial states were drawn.
    pub initial_states: String,
    /// How inputs were drawn.
    pub inputs: InputsReport,
    /// How the noise was applied (additive or state-dependent).
    pub noise: String,
    /// What the distances and the outside counts measure.
    pub compared: String,
    /// The quantile is the `quantile_rank`-th largest distance of the `paths` at each step (the
    /// `ceil((1 - delta) paths)`-th smallest).
    pub quantile_rank: u64,
    /// Confidence level of the Clopper-Pearson bounds.
    pub confidence: f64,
    /// One record per report time.
    pub steps: Vec<SimStep>,
    /// Violations over the whole horizon.
    pub horizon: HorizonReport,
    /// Per unsafe set, the paths that entered it.
    pub unsafe_sets: Vec<UnsafeHits>,
    /// Paths that left the spec's domain at some Euler step (`None` without a domain).
    pub left_domain: Option<u64>,
    /// Paths whose state became non-finite (counted outside from then on).
    pub diverged: u64,
    /// The coverage check.
    pub verdict: Coverage,
}

/// The inputs of the paths.
#[derive(Clone, Debug, Serialize)]
pub struct InputsReport {
    /// `"random"`, `"corners"` or `"centre"`.
    pub mode: InputMode,
    /// Hold time of the piecewise-constant inputs (`None` without inputs or for `centre`).
    pub hold: Option<f64>,
    /// In words.
    pub description: String,
}

/// Statistics at one report time.
#[derive(Clone, Debug, Serialize)]
pub struct SimStep {
    /// Time.
    pub t: f64,
    /// The analysis' stochastic radius `r_t`.
    pub r_t: f64,
    /// The analysis' PRS radius (see [`SimReport::compared`]).
    pub prs_radius: f64,
    /// Empirical `(1 - delta)` quantile of `|X_t - x*_t|_P`.
    pub quantile: f64,
    /// Largest `|X_t - x*_t|_P`.
    pub max: f64,
    /// Paths outside the PRS.
    pub outside: u64,
    /// `outside / paths`.
    pub fraction: f64,
    /// One-sided Clopper-Pearson upper bound of the violation probability at `confidence`.
    pub cp_upper: f64,
}

/// Paths outside the PRS at one report time at least. The PRS bounds the probability at each
/// time, not uniformly in time, so this may exceed `delta` without contradicting it.
#[derive(Clone, Debug, Serialize)]
pub struct HorizonReport {
    /// Paths outside at one report time or more.
    pub outside_any: u64,
    /// `outside_any / paths`.
    pub fraction: f64,
    /// One-sided Clopper-Pearson upper bound at `confidence`.
    pub cp_upper: f64,
}

/// One unsafe set's hits.
#[derive(Clone, Debug, Serialize)]
pub struct UnsafeHits {
    /// Its name.
    pub name: String,
    /// `"box"`, `"ball"` or `"half_space"`.
    pub kind: String,
    /// Paths that entered it at some Euler step.
    pub hits: u64,
    /// `hits / paths`.
    pub fraction: f64,
    /// Earliest entry over all paths.
    pub first_hit_t: Option<f64>,
}

/// The coverage check: it fails when some report time's violation probability is, with
/// confidence, above `delta`.
#[derive(Clone, Debug, Serialize)]
pub struct Coverage {
    /// `"pass"` or `"fail"`.
    pub status: &'static str,
    /// `1 - confidence`: the probability of a false failure when every PRS is valid.
    pub alpha: f64,
    /// `alpha / (report times)`: the level of each step's lower bound (Bonferroni).
    pub alpha_per_step: f64,
    /// Report times whose lower bound exceeds `delta`.
    pub failing_steps: usize,
    /// The step with the most paths outside (the earliest of equals).
    pub worst_step: usize,
    /// Its time.
    pub worst_t: f64,
    /// Its paths outside.
    pub worst_outside: u64,
    /// Its one-sided Clopper-Pearson lower bound at `1 - alpha_per_step`.
    pub worst_cp_lower: f64,
}

impl SimReport {
    /// Whether the coverage check passed.
    pub fn passed(&self) -> bool {
        self.verdict.status == "pass"
    }

    /// Pretty-printed JSON (non-finite numbers as `null`).
    pub fn to_json(&self) -> String {
        // Plain data with string keys: serialising cannot fail.
        serde_json::to_string_pretty(self).expect("SimReport serialises")
    }

    /// A readable summary: what was simulated, a table at about ten report times plus the last,
    /// the horizon-wide and unsafe-set counts, and the verdict.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "Monte Carlo check of analysis `{}` of model `{}` ({} method, delta = {})",
            self.analysis, self.model, self.method, self.delta
        );
        // dt is a quotient (step / substeps): show it without its last-digit noise.
        let dt: f64 = format!("{:.10e}", self.dt).parse().unwrap_or(self.dt);
        let _ = writeln!(
            s,
            "  {} paths (seed {}), Euler-Maruyama with dt = {dt} ({} steps per path)",
            self.paths, self.seed, self.steps_per_path
        );
        let _ = writeln!(s, "  initial states: {}", self.initial_states);
        let _ = writeln!(s, "  inputs: {}", self.inputs.description);
        let _ = writeln!(s, "  noise: {}", self.noise);
        let _ = writeln!(s, "  compared: {}", self.compared);
        let _ = writeln!(
            s,
            "  {:>9}  {:>11}  {:>11}  {:>11}  {:>7}  {:>8}  {:>10}  {:>10}",
            "t", "r_t", "PRS radius", "quantile", "q/PRS", "outside", "fraction", "CP upper"
        );
        // About ten evenly spaced report times, the first and the last included.
        let last = self.steps.len().saturating_sub(1);
        let mut rows: Vec<usize> = (0..=10).map(|i| i * last / 10).collect();
        rows.dedup();
        for &k in rows.iter().filter(|&&k| k < self.steps.len()) {
            let st = &self.steps[k];
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
        let _ = writeln!(
            s,
            "  over the horizon: {} paths ({:.3e}) outside the PRS at some report time (CP upper \
             {:.3e}); the PRS bounds each time separately, not uniformly in time",
            self.horizon.outside_any, self.horizon.fraction, self.horizon.cp_upper
        );
        for u in &self.unsafe_sets {
            let first = u
                .first_hit_t
                .map_or(String::new(), |t| format!(", first at t = {t:.4}"));
            let _ = writeln!(
                s,
                "  unsafe set `{}` ({}): entered by {} paths ({:.3e}){first}",
                u.name, u.kind, u.hits, u.fraction
            );
        }
        if let Some(left) = self.left_domain {
            let _ = writeln!(
                s,
                "  left the domain: {left} paths (the PRS holds only while the state stays in it)"
            );
        }
        if self.diverged > 0 {
            let _ = writeln!(s, "  diverged (non-finite state): {} paths", self.diverged);
        }
        let v = &self.verdict;
        let _ = writeln!(
            s,
            "  coverage: {} ({} of {} report times with a Clopper-Pearson lower bound above \
             delta at level 1 - {:.1e}; worst t = {:.4}: {} outside, lower bound {:.3e})",
            if self.passed() { "PASS" } else { "FAIL" },
            v.failing_steps,
            self.steps.len(),
            v.alpha_per_step,
            v.worst_t,
            v.worst_outside,
            v.worst_cp_lower
        );
        s
    }
}
