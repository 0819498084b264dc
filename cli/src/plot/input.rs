//! What the plots read: the result JSON of `reachc run` (`DIR/<analysis>.json`) and the Monte
//! Carlo report of `reachc simulate` (`DIR/<analysis>.sim.json`), both documented in
//! docs/results.md, as the types the runtime writes them with
//! ([`reachc_runtime::report::schema`]). What the plots draw from is checked for consistency,
//! so a damaged file gives a message instead of a wrong picture.

use std::ops::Deref;
use std::path::Path;

use reachc_runtime::model::{Bounds, UnsafeShape};
use reachc_runtime::report::schema::{DetSetJson, ResultJson, Shape, ShapeJson, SimJson};
use serde::de::DeserializeOwned;

/// A result file that passed [`ResultFile::read`]'s checks; it reads as its [`ResultJson`].
#[derive(Clone, Debug)]
pub struct ResultFile(ResultJson);

impl Deref for ResultFile {
    type Target = ResultJson;

    fn deref(&self) -> &ResultJson {
        &self.0
    }
}

/// A Monte Carlo report file; it reads as its [`SimJson`].
#[derive(Clone, Debug)]
pub struct SimFile(SimJson);

impl Deref for SimFile {
    type Target = SimJson;

    fn deref(&self) -> &SimJson {
        &self.0
    }
}

/// The shape with its states as indices into `states`, or why it does not fit them (or is not
/// finite: a moving set's enclosure that was not).
fn shape(file: &ShapeJson, states: &[String]) -> Result<UnsafeShape, String> {
    let index = |name: &str| {
        states
            .iter()
            .position(|s| s == name)
            .ok_or_else(|| format!("no state `{name}`"))
    };
    Ok(match file {
        ShapeJson::Box { sides } => UnsafeShape::Box(
            sides
                .iter()
                .map(|side| {
                    let [lo, hi] = side.range;
                    Ok((index(&side.state)?, Bounds::new(lo, hi)))
                })
                .collect::<Result<_, String>>()?,
        ),
        ShapeJson::Ball {
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
            if !(center.iter().all(|x| x.is_finite()) && radius.is_finite()) {
                return Err("a ball whose centre or radius is not finite".into());
            }
            UnsafeShape::Ball {
                states: over.iter().map(|s| index(s)).collect::<Result<_, _>>()?,
                center: center.clone(),
                radius: *radius,
            }
        }
        ShapeJson::HalfSpace { normal, offset } => {
            if normal.len() != states.len() {
                return Err(format!(
                    "a half-space normal of {} entries in {} states",
                    normal.len(),
                    states.len()
                ));
            }
            if !offset.is_finite() {
                return Err("a half-space whose offset is not finite".into());
            }
            UnsafeShape::HalfSpace {
                normal: normal.clone(),
                offset: *offset,
            }
        }
    })
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

/// Whether a deterministic set is well formed in `n` states (every number finite; the
/// transform, which a parallelotope needs, is checked by the caller).
fn valid(d: &DetSetJson, n: usize) -> bool {
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    let corners = match (&d.lo, &d.hi) {
        (Some(lo), Some(hi)) => lo.len() == n && hi.len() == n && finite(lo) && finite(hi),
        _ => false,
    };
    let centre = d.center.len() == n && finite(&d.center);
    match d.shape {
        Shape::PBall => centre && d.radius.is_finite(),
        Shape::Box | Shape::Parallelotope => corners,
        Shape::Zonotope => {
            let generators = d
                .generators
                .as_ref()
                .is_some_and(|g| g.iter().all(|g| g.len() == n && finite(g)));
            let remainder = d.remainder.is_some_and(|r| r.is_finite() && r >= 0.0);
            centre && generators && remainder
        }
    }
}

/// Reads a JSON file into `T`; the message names the file.
fn read<T: DeserializeOwned>(path: &Path, what: &str) -> Result<T, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    serde_json::from_str(&text)
        .map_err(|e| format!("{} is not a valid {what}: {e}", path.display()))
}

impl ResultFile {
    /// Reads and checks a result file.
    pub fn read(path: &Path) -> Result<ResultFile, String> {
        let r: ResultJson = read(path, "result of `reachc run`")?;
        check(&r).map_err(|e| format!("{} is not a consistent result: {e}", path.display()))?;
        Ok(ResultFile(r))
    }

    /// The moving unsafe sets and goals, in the file's order (unsafe sets first), each with
    /// one position per report time.
    pub fn moving_sets(&self) -> Result<Vec<MovingSet>, String> {
        moving_sets(self)
    }
}

/// Dimensions, shapes and times agree, every number is finite; and so for the members of
/// an intersection and the pieces of a split, on the same report times, and for the
/// positions of moving sets.
fn check(r: &ResultJson) -> Result<(), String> {
    check_own(r)?;
    moving_sets(r)?;
    for (j, m) in r.also.iter().enumerate() {
        let times =
            m.steps.len() == r.steps.len() && m.steps.iter().zip(&r.steps).all(|(a, b)| a.t == b.t);
        check_own(m)
            .and_then(|()| {
                (m.states.len() == r.states.len() && times)
                    .then_some(())
                    .ok_or_else(|| "other states or report times".to_string())
            })
            .map_err(|e| format!("member {} of the intersection: {e}", j + 1))?;
    }
    let n = r.states.len();
    for (j, p) in r.pieces.iter().enumerate() {
        let fits = p.steps.len() == r.steps.len()
            && p.steps.iter().zip(&r.steps).all(|(a, b)| {
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

/// [`check`] of a result's own sets.
fn check_own(r: &ResultJson) -> Result<(), String> {
    let n = r.states.len();
    let square = |m: &[Vec<f64>]| m.len() == n && m.iter().all(|r| r.len() == n);
    if n == 0 || r.steps.is_empty() {
        return Err("no states or no report times".into());
    }
    if !square(&r.constants.metric) {
        return Err(format!("the metric is not {n} x {n}"));
    }
    if let Some(&i) = r.outputs.iter().find(|&&i| i >= n) {
        return Err(format!("output index {i} is not a state"));
    }
    if let Some(t) = &r.transform {
        if !square(&t.inverse) {
            return Err(format!("the transform's inverse is not {n} x {n}"));
        }
    }
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    for (k, s) in r.steps.iter().enumerate() {
        let d = &s.det_set;
        let shape_ok = valid(d, n) && (d.shape != Shape::Parallelotope || r.transform.is_some());
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
        if k > 0 && s.t <= r.steps[k - 1].t {
            return Err(format!("step {k}: the times do not increase"));
        }
    }
    if !finite(&r.constants.metric.concat()) {
        return Err("the metric has non-finite entries".into());
    }
    Ok(())
}

/// The moving unsafe sets and goals of `r`, in the file's order (unsafe sets first), each with
/// one position per report time; or why their positions do not fit the result.
fn moving_sets(r: &ResultJson) -> Result<Vec<MovingSet>, String> {
    let unsafe_sets = r
        .unsafe_sets
        .iter()
        .map(|u| (&u.name, false, u.swept.chunks(1).collect::<Vec<_>>()));
    let goals = r
        .goals
        .iter()
        .map(|g| (&g.name, true, g.swept.iter().map(Vec::as_slice).collect()));
    let mut moving = Vec::new();
    for (name, goal, steps) in unsafe_sets.chain(goals) {
        if steps.is_empty() {
            continue;
        }
        let what = if goal { "goal" } else { "unsafe set" };
        if steps.len() != r.steps.len() {
            return Err(format!(
                "{what} `{name}`: {} positions for {} report times",
                steps.len(),
                r.steps.len()
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
                    .map(|p| shape(p, &r.states))
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

impl SimFile {
    /// Reads a Monte Carlo report.
    pub fn read(path: &Path) -> Result<SimFile, String> {
        read(path, "report of `reachc simulate`").map(SimFile)
    }

    /// Why it does not belong to `result` (another model, analysis or delta, other report
    /// times), or `None` if it does.
    pub fn mismatch(&self, result: &ResultJson) -> Option<String> {
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
pub(crate) mod tests {
    use super::*;
    use reachc_runtime::report::schema::Role;
    use serde_json::json;

    /// A result in two states whose one report time holds `det_set`, with `also`.
    pub(crate) fn result(det_set: serde_json::Value, also: serde_json::Value) -> serde_json::Value {
        json!({
            "model": "m", "analysis": "a", "method": "contraction", "delta": 0.01,
            "horizon": 1.0, "step": 1.0, "integrator": "validated", "internal_steps": 1,
            "states": ["x", "y"], "outputs": [0, 1],
            "constants": {"c": -1.0, "sigma": 0.1, "rho": 0.0, "how": "given",
                          "metric": [[2.0, 0.5], [0.5, 1.0]], "metric_from": "the domain"},
            "radius_rule": {"rule": "amgf", "eps": null},
            "kappa": 1.0, "r1": 0.0, "r2": 0.0, "r1_how": "a point",
            "initial_center": [0.0, 0.0], "input_center": [],
            "steps": [{"t": 0.0, "nominal": [1.0, 0.0], "det_set": det_set, "r_t": 0.1,
                       "r_pointwise": 0.1, "psi": 0.0, "prs_radius": 1.0,
                       "prs_hull_lo": [0.0, -1.0], "prs_hull_hi": [2.0, 1.0],
                       "span": {"lo": [0.0, -1.0], "hi": [2.0, 1.0], "radius": 1.0},
                       "margins": []}],
            "verdict": {"status": "no_unsafe_sets"},
            "validated": {"rigorous": [], "not_validated": [], "conditional_on_domain": false},
            "hints": [],
            "also": also,
        })
    }

    fn zonotope(generators: serde_json::Value, remainder: serde_json::Value) -> serde_json::Value {
        json!({"shape": "zonotope", "center": [1.0, 0.0], "radius": 0.9,
               "hull_lo": [0.5, -0.5], "hull_hi": [1.5, 0.5],
               "generators": generators, "remainder": remainder})
    }

    fn check(v: serde_json::Value) -> Result<(), String> {
        super::check(&serde_json::from_value::<ResultJson>(v).map_err(|e| e.to_string())?)
    }

    /// Zonotopes are read with their generators and remainder, as the main sets or a member's;
    /// generators of the wrong length or not finite (null), a missing or negative remainder,
    /// and a member on other report times are refused.
    #[test]
    fn zonotopes_are_read_and_checked() {
        let good = zonotope(json!([[0.3, 0.1], [-0.1, 0.4]]), json!(0.05));
        let ball = json!({"shape": "p_ball", "center": [1.0, 0.0], "radius": 0.5});
        let r: ResultJson = serde_json::from_value(result(good.clone(), json!([]))).unwrap();
        super::check(&r).unwrap();
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
        let cut: ResultJson =
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
        // An unsafe set's or a goal's verdict, with its positions `swept` if any.
        let verdict = |name: &str, swept: serde_json::Value| {
            let mut v = json!({"name": name, "kind": "box", "safe": true, "min_margin": null,
                               "min_margin_t": 0.0, "first_not_safe_t": null,
                               "margin_unit": "gap"});
            if !swept.is_null() {
                v["swept"] = swept;
            }
            v
        };
        let goal = |name: &str, swept: serde_json::Value| {
            json!({"name": name, "window": [0.0, null], "stay": false, "status": "needs_uniform",
                   "margins": [null], "swept": swept})
        };
        r["unsafe_sets"] = json!([
            verdict("fixed", json!(null)),
            verdict(
                "gate",
                json!([{"kind": "box", "sides": [
                {"state": "y", "range": [0.5, null]}, {"state": "x", "range": [-1.0, 2.0]}]}])
            ),
        ]);
        r["goals"] = json!([goal(
            "dock",
            json!([[
                {"kind": "halfspace", "normal": [1.0, -1.0], "offset": 0.25},
                {"kind": "ball", "over": ["y"], "center": [3.0], "radius": 0.75},
            ]])
        )]);
        let file: ResultJson = serde_json::from_value(r.clone()).unwrap();
        super::check(&file).unwrap();
        let moving = moving_sets(&file).unwrap();
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
