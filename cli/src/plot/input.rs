//! What the plots read: the result JSON of `reachc run` (`DIR/<analysis>.json`) and the Monte
//! Carlo report of `reachc simulate` (`DIR/<analysis>.sim.json`), both documented in
//! docs/results.md. Only the fields the plots use are read, and checked for consistency, so a
//! damaged file gives a message instead of a wrong picture.

use std::path::Path;

use reachc_runtime::model::{Bounds, UnsafeShape};
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
    /// The members of the intersection (the PRS is the intersection of all sets).
    #[serde(default)]
    pub also: Vec<ResultFile>,
    /// A member's kind; [`Role::Own`] for the result itself (no `role` in the file).
    #[serde(default)]
    pub role: Role,
    /// A split result's pieces (the PRS is their union; `steps` hold its bounding boxes).
    #[serde(default)]
    pub pieces: Vec<PieceFile>,
    /// The unsafe sets' verdicts (only their names and where moving ones were are read).
    #[serde(default)]
    pub unsafe_sets: Vec<UnsafeEntry>,
    /// The goals' verdicts (the same).
    #[serde(default)]
    pub goals: Vec<GoalEntry>,
}

/// An unsafe set of a result: its name and, for a moving set (method.md 8.15), per report time
/// the fixed set that held it over the report interval ending there (empty for a fixed set).
#[derive(Clone, Debug, Deserialize)]
pub struct UnsafeEntry {
    /// Its name.
    pub name: String,
    /// Its positions, one per report time.
    #[serde(default)]
    pub swept: Vec<ShapeFile>,
}

/// A goal of a result: its name and, for a moving goal, per report time its parts as they are
/// then (empty for a fixed goal).
#[derive(Clone, Debug, Deserialize)]
pub struct GoalEntry {
    /// Its name.
    pub name: String,
    /// Its parts, one list per report time.
    #[serde(default)]
    pub swept: Vec<Vec<ShapeFile>>,
}

/// A set's shape as result files write it (the form of `reachc inspect --json`: states by
/// name, an infinite end of a range `null`).
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ShapeFile {
    /// A box: the ranges of the states it constrains.
    Box {
        /// One range per constrained state.
        sides: Vec<SideFile>,
    },
    /// A ball over some states.
    Ball {
        /// Its states, in the order of `center`.
        over: Vec<String>,
        /// Its centre.
        center: Vec<f64>,
        /// Its radius.
        radius: f64,
    },
    /// `{x : normal . x >= offset}`.
    #[serde(rename = "halfspace")]
    HalfSpace {
        /// One coefficient per state.
        normal: Vec<f64>,
        /// The offset.
        offset: f64,
    },
}

/// One side of a box.
#[derive(Clone, Debug, Deserialize)]
pub struct SideFile {
    /// The state's name.
    pub state: String,
    /// Its range (`null`: unbounded on that side).
    pub range: [Option<f64>; 2],
}

impl ShapeFile {
    /// The shape with its states as indices into `states`, or why it does not fit them.
    fn shape(&self, states: &[String]) -> Result<UnsafeShape, String> {
        let index = |name: &str| {
            states
                .iter()
                .position(|s| s == name)
                .ok_or_else(|| format!("no state `{name}`"))
        };
        Ok(match self {
            ShapeFile::Box { sides } => UnsafeShape::Box(
                sides
                    .iter()
                    .map(|side| {
                        let [lo, hi] = side.range;
                        let range = Bounds::new(
                            lo.unwrap_or(f64::NEG_INFINITY),
                            hi.unwrap_or(f64::INFINITY),
                        );
                        Ok((index(&side.state)?, range))
                    })
                    .collect::<Result<_, String>>()?,
            ),
            ShapeFile::Ball {
                over,
                center,
                radius,
            } => {
                if over.len() != center.len() {
                    return Err(format!(
                        "a ball over {} states with a centre of {}",
                        over.len(),
                        center.len()
                    ));
                }
                UnsafeShape::Ball {
                    states: over.iter().map(|s| index(s)).collect::<Result<_, _>>()?,
                    center: center.clone(),
                    radius: *radius,
                }
            }
            ShapeFile::HalfSpace { normal, offset } => {
                if normal.len() != states.len() {
                    return Err(format!(
                        "a half-space normal of {} entries in {} states",
                        normal.len(),
                        states.len()
                    ));
                }
                UnsafeShape::HalfSpace {
                    normal: normal.clone(),
                    offset: *offset,
                }
            }
        })
    }
}

/// A moving unsafe or goal set of a result (method.md 8.15), its shapes in state indices.
#[derive(Clone, Debug, PartialEq)]
pub struct MovingSet {
    /// Its name.
    pub name: String,
    /// A goal (else an unsafe set).
    pub goal: bool,
    /// Per report time its parts (an unsafe set has one): for an unsafe set the fixed set that
    /// held it over the report interval ending there, for a goal its parts at that time.
    pub at: Vec<Vec<UnsafeShape>>,
}

/// One piece of a split, in brief: per report time its PRS's bounding box.
#[derive(Clone, Debug, Deserialize)]
pub struct PieceFile {
    /// One record per report time.
    pub steps: Vec<PieceStep>,
}

/// A piece's PRS at one report time.
#[derive(Clone, Debug, Deserialize)]
pub struct PieceStep {
    /// Time.
    pub t: f64,
    /// Lower corner of the PRS's bounding box.
    pub prs_hull_lo: Vec<f64>,
    /// Upper corner.
    pub prs_hull_hi: Vec<f64>,
}

/// What a result is within an intersection (`"metric"`, `"box"`, `"first_order"`,
/// `"linearised"`; none for
/// the result itself).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// The analysis' own result.
    #[default]
    Own,
    /// A further metric's result, of the same method, at `δ / K`.
    Metric,
    /// The interval method's box of a contraction run.
    Box,
    /// The first-order sets (zonotopes plus a remainder ball).
    FirstOrder,
    /// The linearised Gaussian sets (zonotopes holding the stochastic part too).
    Linearised,
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

/// The shape of a deterministic set (`"p_ball"`, `"box"`, `"parallelotope"` or `"zonotope"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// `{x : |x - center|_P <= radius}`.
    PBall,
    /// `{x : lo <= x <= hi}`.
    Box,
    /// `{x : lo <= T x <= hi}`.
    Parallelotope,
    /// `{center + sum_j xi_j g_j : |xi_j| <= 1} (+) B_P(remainder)`.
    Zonotope,
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

/// A deterministic set: `p_ball`, `box`, `parallelotope` or `zonotope` (see docs/results.md).
#[derive(Clone, Debug, Deserialize)]
pub struct DetSet {
    /// Its shape.
    pub shape: Shape,
    /// Centre of the P-ball (`p_ball`) or of the zonotope.
    pub center: Vec<f64>,
    /// Radius `R_t` of the P-ball.
    pub radius: f64,
    /// Lower corner (`box`: in `x`; `parallelotope`: in `y = T x`).
    #[serde(default)]
    pub lo: Option<Vec<f64>>,
    /// Upper corner.
    #[serde(default)]
    pub hi: Option<Vec<f64>>,
    /// A zonotope's generators, one array of `n` values each.
    #[serde(default)]
    pub generators: Option<Vec<Vec<f64>>>,
    /// The P-radius of the ball added to a zonotope.
    #[serde(default)]
    pub remainder: Option<f64>,
}

impl DetSet {
    /// Whether the set is well formed in `n` states (every number finite; the transform, which
    /// a parallelotope needs, is checked by the caller).
    fn valid(&self, n: usize) -> bool {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let corners = match (&self.lo, &self.hi) {
            (Some(lo), Some(hi)) => lo.len() == n && hi.len() == n && finite(lo) && finite(hi),
            _ => false,
        };
        let centre = self.center.len() == n && finite(&self.center);
        match self.shape {
            Shape::PBall => centre && self.radius.is_finite(),
            Shape::Box | Shape::Parallelotope => corners,
            Shape::Zonotope => {
                let generators = self
                    .generators
                    .as_ref()
                    .is_some_and(|g| g.iter().all(|g| g.len() == n && finite(g)));
                let remainder = self.remainder.is_some_and(|r| r.is_finite() && r >= 0.0);
                centre && generators && remainder
            }
        }
    }
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
    /// The state names (absent from reports of older versions).
    #[serde(default)]
    pub states: Vec<String>,
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
    /// Per state (absent from reports of older versions).
    #[serde(default)]
    pub states: Vec<SimState>,
}

/// One state at one report time of a Monte Carlo report.
#[derive(Clone, Debug, Deserialize)]
pub struct SimState {
    /// The half-width about `x*_t,i` holding `1 - delta` of the paths (`null`: not finite).
    pub quantile: Option<f64>,
    /// The PRS's bounding-box half-width about `x*_t,i` (`null`: not finite).
    pub prs: Option<f64>,
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

    /// Dimensions, shapes and times agree, every number is finite; and so for the members of
    /// an intersection and the pieces of a split, on the same report times, and for the
    /// positions of moving sets.
    fn check(&self) -> Result<(), String> {
        self.check_own()?;
        self.moving_sets()?;
        for (j, m) in self.also.iter().enumerate() {
            let times = m.steps.len() == self.steps.len()
                && m.steps.iter().zip(&self.steps).all(|(a, b)| a.t == b.t);
            m.check_own()
                .and_then(|()| {
                    (m.states.len() == self.states.len() && times)
                        .then_some(())
                        .ok_or_else(|| "other states or report times".to_string())
                })
                .map_err(|e| format!("member {} of the intersection: {e}", j + 1))?;
        }
        let n = self.states.len();
        for (j, p) in self.pieces.iter().enumerate() {
            let fits = p.steps.len() == self.steps.len()
                && p.steps.iter().zip(&self.steps).all(|(a, b)| {
                    a.t == b.t
                        && a.prs_hull_lo.len() == n
                        && a.prs_hull_hi.len() == n
                        && a.prs_hull_lo
                            .iter()
                            .zip(&a.prs_hull_hi)
                            .all(|(l, h)| l.is_finite() && h.is_finite() && l <= h)
                });
            if !fits {
                return Err(format!(
                    "piece {} of the split: other states or report times, or a box that is \
                     not finite",
                    j + 1
                ));
            }
        }
        Ok(())
    }

    /// [`ResultFile::check`] of the result's own sets.
    fn check_own(&self) -> Result<(), String> {
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
            let shape_ok =
                d.valid(n) && (d.shape != Shape::Parallelotope || self.transform.is_some());
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

    /// The moving unsafe sets and goals, in the file's order (unsafe sets first), each with
    /// one position per report time; or why their positions do not fit the result.
    pub fn moving_sets(&self) -> Result<Vec<MovingSet>, String> {
        let unsafe_sets = self
            .unsafe_sets
            .iter()
            .map(|u| (&u.name, false, u.swept.chunks(1).collect::<Vec<_>>()));
        let goals = self
            .goals
            .iter()
            .map(|g| (&g.name, true, g.swept.iter().map(Vec::as_slice).collect()));
        let mut moving = Vec::new();
        for (name, goal, steps) in unsafe_sets.chain(goals) {
            if steps.is_empty() {
                continue;
            }
            let what = if goal { "goal" } else { "unsafe set" };
            if steps.len() != self.steps.len() {
                return Err(format!(
                    "{what} `{name}`: {} positions for {} report times",
                    steps.len(),
                    self.steps.len()
                ));
            }
            let at = steps
                .iter()
                .enumerate()
                .map(|(k, parts)| {
                    if parts.is_empty() {
                        return Err(format!("{what} `{name}`: step {k}: no parts"));
                    }
                    parts
                        .iter()
                        .map(|p| p.shape(&self.states))
                        .collect::<Result<Vec<_>, _>>()
                        .map_err(|e| format!("{what} `{name}`: step {k}: {e}"))
                })
                .collect::<Result<_, _>>()?;
            moving.push(MovingSet {
                name: name.clone(),
                goal,
                at,
            });
        }
        Ok(moving)
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

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// A result in two states whose one report time holds `det_set`, with `also`.
    fn result(det_set: serde_json::Value, also: serde_json::Value) -> serde_json::Value {
        json!({
            "model": "m", "analysis": "a", "method": "contraction", "delta": 0.01,
            "states": ["x", "y"], "outputs": [0, 1],
            "constants": {"metric": [[2.0, 0.5], [0.5, 1.0]]},
            "initial_center": [0.0, 0.0],
            "steps": [{"t": 0.0, "nominal": [1.0, 0.0], "det_set": det_set, "r_t": 0.1,
                       "prs_radius": 1.0}],
            "also": also,
        })
    }

    fn zonotope(generators: serde_json::Value, remainder: serde_json::Value) -> serde_json::Value {
        json!({"shape": "zonotope", "center": [1.0, 0.0], "radius": 0.9,
               "hull_lo": [0.5, -0.5], "hull_hi": [1.5, 0.5],
               "generators": generators, "remainder": remainder})
    }

    fn check(v: serde_json::Value) -> Result<(), String> {
        serde_json::from_value::<ResultFile>(v)
            .map_err(|e| e.to_string())?
            .check()
    }

    /// Zonotopes are read with their generators and remainder, as the main sets or a member's;
    /// generators of the wrong length or not finite (null), a missing or negative remainder,
    /// and a member on other report times are refused.
    #[test]
    fn zonotopes_are_read_and_checked() {
        let good = zonotope(json!([[0.3, 0.1], [-0.1, 0.4]]), json!(0.05));
        let ball = json!({"shape": "p_ball", "center": [1.0, 0.0], "radius": 0.5});
        let r: ResultFile = serde_json::from_value(result(good.clone(), json!([]))).unwrap();
        r.check().unwrap();
        let d = &r.steps[0].det_set;
        assert_eq!(d.shape, Shape::Zonotope);
        assert_eq!(d.generators, Some(vec![vec![0.3, 0.1], vec![-0.1, 0.4]]));
        assert_eq!(d.remainder, Some(0.05));
        check(result(
            ball.clone(),
            json!([result(good.clone(), json!([]))]),
        ))
        .unwrap();
        // A member's role, as the engine set it; the result itself has none.
        let mut member = result(good.clone(), json!([]));
        member["role"] = json!("first_order");
        let cut: ResultFile =
            serde_json::from_value(result(ball.clone(), json!([member]))).unwrap();
        assert_eq!((cut.role, cut.also[0].role), (Role::Own, Role::FirstOrder));
        for bad in [
            zonotope(json!([[0.3, 0.1, 0.0]]), json!(0.05)),
            zonotope(json!([[0.3, 0.1]]), json!(-1.0)),
            zonotope(json!([[0.3, 0.1]]), json!(null)),
        ] {
            let e = check(result(bad.clone(), json!([]))).unwrap_err();
            assert!(e.contains("malformed Zonotope set"), "{e}");
            let e = check(result(ball.clone(), json!([result(bad, json!([]))]))).unwrap_err();
            assert!(e.contains("member 1 of the intersection: step 0"), "{e}");
        }
        // A generator that was not finite (written as null) is not a number.
        let null = zonotope(json!([[0.3, null]]), json!(0.05));
        let e = check(result(null, json!([]))).unwrap_err();
        assert!(e.contains("invalid type: null"), "{e}");
        let mut later = result(good, json!([]));
        later["steps"][0]["t"] = json!(1.0);
        let e = check(result(ball, json!([later]))).unwrap_err();
        assert!(e.contains("other states or report times"), "{e}");
    }

    /// The positions of moving sets are read in state indices (an infinite end written as
    /// `null`, a goal's parts per report time); a fixed set has none; positions on other
    /// report times, unknown states and shapes of the wrong dimension are refused, naming the
    /// set and the step.
    #[test]
    fn moving_sets_are_read_and_checked() {
        let ball = json!({"shape": "p_ball", "center": [1.0, 0.0], "radius": 0.5});
        let mut r = result(ball, json!([]));
        r["unsafe_sets"] = json!([
            {"name": "fixed", "kind": "box"},
            {"name": "gate", "swept": [{"kind": "box", "sides": [
                {"state": "y", "range": [0.5, null]}, {"state": "x", "range": [-1.0, 2.0]}]}]},
        ]);
        r["goals"] = json!([{"name": "dock", "swept": [[
            {"kind": "halfspace", "normal": [1.0, -1.0], "offset": 0.25},
            {"kind": "ball", "over": ["y"], "center": [3.0], "radius": 0.75},
        ]]}]);
        let file: ResultFile = serde_json::from_value(r.clone()).unwrap();
        file.check().unwrap();
        let moving = file.moving_sets().unwrap();
        let gate = UnsafeShape::Box(vec![
            (1, Bounds::new(0.5, f64::INFINITY)),
            (0, Bounds::new(-1.0, 2.0)),
        ]);
        let dock = vec![
            UnsafeShape::HalfSpace {
                normal: vec![1.0, -1.0],
                offset: 0.25,
            },
            UnsafeShape::Ball {
                states: vec![1],
                center: vec![3.0],
                radius: 0.75,
            },
        ];
        assert_eq!(
            moving,
            [
                MovingSet {
                    name: "gate".into(),
                    goal: false,
                    at: vec![vec![gate]],
                },
                MovingSet {
                    name: "dock".into(),
                    goal: true,
                    at: vec![dock],
                },
            ]
        );
        let refused = |path: &[&str], value: serde_json::Value, message: &str| {
            let mut bad = r.clone();
            let mut at = &mut bad;
            for key in path {
                at = match key.parse::<usize>() {
                    Ok(i) => &mut at[i],
                    Err(_) => &mut at[*key],
                };
            }
            *at = value;
            let e = check(bad).unwrap_err();
            assert!(e.contains(message), "{e}");
        };
        let wall = json!({"kind": "halfspace", "normal": [1.0, 0.0], "offset": 0.0});
        refused(
            &["unsafe_sets", "1", "swept"],
            json!([wall, wall]),
            "unsafe set `gate`: 2 positions for 1 report times",
        );
        refused(
            &["unsafe_sets", "1", "swept", "0", "sides", "0", "state"],
            json!("z"),
            "unsafe set `gate`: step 0: no state `z`",
        );
        refused(
            &["goals", "0", "swept", "0", "0", "normal"],
            json!([1.0]),
            "goal `dock`: step 0: a half-space normal of 1 entries in 2 states",
        );
        refused(
            &["goals", "0", "swept", "0", "1", "center"],
            json!([3.0, 1.0]),
            "goal `dock`: step 0: a ball over 1 states with a centre of 2",
        );
        refused(
            &["goals", "0", "swept", "0"],
            json!([]),
            "goal `dock`: step 0: no parts",
        );
    }
}
