//! What the figures show, in plot coordinates: the sets at the chosen times as polygons, the
//! nominal and the sample paths projected, the unsafe regions, the radii over time. Built from
//! the inputs here, drawn by [`super::figures`], so that the geometry can be tested without
//! pixels.

use super::figures::num;
use super::geometry::{clip, half_planes, Plane, Point, Projected};
use super::input::MovingSet;
use super::regions::Region;
use super::Quantile;
use reachc_runtime::model::{Analysis, ModelInfo};
use reachc_runtime::report::count;
use reachc_runtime::report::schema::{
    Guarantee, Method, RateSource, ResultJson, Role, Shape, StepJson,
};

/// The sets figure: a 2-D projection.
#[derive(Clone, Debug)]
pub struct SetsScene {
    /// Title (model and analysis).
    pub title: String,
    /// Axis labels (the plotted states).
    pub axes: [String; 2],
    /// The sets at the chosen times.
    pub slices: Vec<Slice>,
    /// The PRS at every report time, whose union is filled (empty: not drawn).
    pub envelope: Vec<Vec<Point>>,
    /// A reference trajectory from a table of the spec, with its legend label.
    pub reference: Option<(String, Vec<Point>)>,
    /// The nominal trajectory (or the sets' centres), at every report time.
    pub nominal: Vec<Point>,
    /// What [`SetsScene::nominal`] is, for the legend.
    pub nominal_label: String,
    /// Sample paths, at every report time.
    pub paths: Vec<Vec<Point>>,
    /// How the paths were drawn, for the legend: `Euler-Maruyama`, or a discrete-time model's
    /// `exact map steps`.
    pub paths_by: &'static str,
    /// Unsafe sets by name.
    pub regions: Vec<(String, Region)>,
    /// Goal sets by name: the projections of their parts (the goal's projection lies in
    /// their intersection).
    pub goals: Vec<(String, Vec<Region>)>,
    /// Lines for the legend panel: what is drawn and what is not.
    pub notes: Vec<String>,
}

/// The sets at one report time.
#[derive(Clone, Debug)]
pub struct Slice {
    /// Time.
    pub t: f64,
    /// Boundary of the deterministic set (counter-clockwise; empty when there is none).
    pub det: Vec<Point>,
    /// Boundary of the PRS (empty when there is none; a split result's: the union's box).
    pub prs: Vec<Point>,
    /// A split result's pieces' PRS bounding boxes: the PRS is the union of the pieces' sets.
    pub pieces: Vec<Vec<Point>>,
    /// The sample paths' states at this time.
    pub samples: Vec<Point>,
    /// The nominal state (or the set's centre) at this time.
    pub nominal: Option<Point>,
}

/// The radius figure: radii in the P-norm against time.
#[derive(Clone, Debug)]
pub struct RadiusScene {
    /// Title.
    pub title: String,
    /// Report times.
    pub times: Vec<f64>,
    /// `r_t`.
    pub r_t: Vec<f64>,
    /// The PRS radius.
    pub prs_radius: Vec<f64>,
    /// What the PRS radius is, for the legend.
    pub prs_label: String,
    /// The empirical quantile per report time (`None` where not finite) and its legend label.
    pub quantile: Option<(Vec<Option<f64>>, String)>,
    /// Lines for the legend panel.
    pub notes: Vec<String>,
}

/// The widths figure: per plotted state, the PRS's bounding-box half-width about the nominal
/// and the half-width holding `1 - δ` of the Monte Carlo paths, against time (tightness per
/// coordinate).
#[derive(Clone, Debug)]
pub struct WidthsScene {
    /// Title.
    pub title: String,
    /// Report times.
    pub times: Vec<f64>,
    /// The plotted states' curves.
    pub states: Vec<WidthCurves>,
    /// Lines for the legend panel.
    pub notes: Vec<String>,
}

/// One state's curves in the widths figure.
#[derive(Clone, Debug)]
pub struct WidthCurves {
    /// The PRS's half-widths (`None`: not finite) and their legend label.
    pub prs: Vec<Option<f64>>,
    pub prs_label: String,
    /// The paths' half-widths and their legend label.
    pub paths: Vec<Option<f64>>,
    pub paths_label: String,
}

/// The widths figure of the `plotted` states of a result, from a Monte Carlo report with
/// per-state spreads (`None` without them).
pub fn widths_scene(
    result: &ResultJson,
    plotted: [usize; 2],
    quantile: &Quantile,
) -> Option<WidthsScene> {
    if quantile.states.len() != result.states.len() {
        return None;
    }
    let mut picked = plotted.to_vec();
    picked.dedup();
    let times = result.times();
    let mut notes = vec![
        format!(
            "half-widths about the nominal x*_t: of the PRS's bounding box (solid) and of the \
             smallest interval holding 1-δ of {} (dashed), δ = {}",
            count(quantile.paths, "path"),
            result.delta
        ),
        format!("paths: {}", quantile.source),
    ];
    let states = picked
        .iter()
        .map(|&i| {
            let w = &quantile.states[i];
            let name = &result.states[i];
            // The ratio at the last report time where both are finite and positive.
            let last =
                w.prs
                    .iter()
                    .zip(&w.quantile)
                    .zip(&times)
                    .rev()
                    .find_map(|((p, q), t)| match (p, q) {
                        (Some(p), Some(q)) if *q > 0.0 => Some((p / q, *t)),
                        _ => None,
                    });
            if let Some((ratio, t)) = last {
                notes.push(format!(
                    "{name}: the PRS is {ratio:.2} times the paths' half-width at t = {t}"
                ));
            }
            WidthCurves {
                prs: w.prs.clone(),
                prs_label: format!("{name}: PRS"),
                paths: w.quantile.clone(),
                paths_label: format!("{name}: paths (1-δ)"),
            }
        })
        .collect();
    Some(WidthsScene {
        title: format!(
            "{} / {}: half-widths per state",
            result.model, result.analysis
        ),
        times,
        states,
        notes,
    })
}

/// The rates figure of a result whose rates vary in time (`rate = local` or `empirical`):
/// `c_t` against time.
#[derive(Clone, Debug)]
pub struct RatesScene {
    /// Title.
    pub title: String,
    /// Report times after 0 (each rate holds on the report interval ending there).
    pub times: Vec<f64>,
    /// `c_t`, the largest over each report interval (`None`: not finite).
    pub c: Vec<Option<f64>>,
    /// The rate's name on the axis and in the legend: `c_t`, or a map's factor `L_k`.
    pub label: &'static str,
    /// Lines for the legend panel.
    pub notes: Vec<String>,
}

/// The rates figure of a result with time-varying rates, `None` for one global rate.
pub fn rates_scene(result: &ResultJson) -> Option<RatesScene> {
    let rate = result
        .rate
        .as_ref()
        .filter(|r| r.kind != RateSource::Global)?;
    let steps = result.steps.get(1..).unwrap_or_default();
    let sigma = steps.iter().map(|s| s.sigma).filter(|v| v.is_finite());
    let (lo, hi) = sigma.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let map = result.period.is_some();
    let mut notes = vec![if map {
        "discrete time: L_k is the map's factor |R J R^-1|_2 (the largest over each report \
         interval)"
            .to_string()
    } else {
        format!(
            "{} rates: c_t is the largest contraction rate (mu_P of the Jacobian) over each \
             report interval",
            rate.kind.name()
        )
    }];
    if lo <= hi {
        notes.push(format!("noise level sigma_t in [{lo:.4}, {hi:.4}]"));
    }
    match rate.kind {
        RateSource::Local if map => notes.push(
            "bounded on boxes holding the tube at each step: where L_k > 1 the tube grows".into(),
        ),
        RateSource::Local => notes.push(
            "certified on boxes holding the tube over each internal step: where c_t > 0 the \
             tube grows"
                .into(),
        ),
        _ => notes.push("EMPIRICAL: estimated from sample paths, not a guarantee".into()),
    }
    if let Some(t) = rate.global_from {
        notes.push(format!(
            "from t = {t}: the domain's global constants (no local region closed)"
        ));
    }
    Some(RatesScene {
        title: format!(
            "{} / {}: {}",
            result.model,
            result.analysis,
            if map {
                "map factor"
            } else {
                "contraction rate"
            }
        ),
        label: if map { "L_k" } else { "c_t" },
        times: steps.iter().map(|s| s.t).collect(),
        c: steps
            .iter()
            .map(|s| Some(s.c).filter(|v| v.is_finite()))
            .collect(),
        notes,
    })
}

/// The deterministic set of a step in the plane.
fn det_set(result: &ResultJson, plane: &Plane, step: &StepJson) -> Projected {
    let d = &step.det_set;
    // ResultFile::read checked the shapes: lo and hi exist for boxes and parallelotopes, the
    // generators and the remainder for zonotopes.
    let corners = || {
        (
            d.lo.as_deref().unwrap_or(&[]),
            d.hi.as_deref().unwrap_or(&[]),
        )
    };
    match (d.shape, &result.transform) {
        (Shape::Box, _) => {
            let (lo, hi) = corners();
            plane.boxed(lo, hi)
        }
        (Shape::Parallelotope, Some(t)) => {
            let (lo, hi) = corners();
            plane.parallelotope(lo, hi, &t.inverse)
        }
        (Shape::Zonotope, _) => plane.zonotope(
            &d.center,
            d.generators.as_deref().unwrap_or(&[]),
            d.remainder.unwrap_or(0.0),
        ),
        _ => plane.p_ball(&d.center, d.radius),
    }
}

/// Whether a result's own sets are first-order zonotopes (a member of role
/// [`Role::FirstOrder`] or [`Role::Linearised`]; its set at `t = 0` is the initial box).
fn zonotopes(result: &ResultJson) -> bool {
    matches!(result.role, Role::FirstOrder | Role::Linearised)
}

/// The projected PRS `poly` of report step `k` clipped by the projected PRS of each further
/// metric of the result (its polygon contains the set, so the clipped polygon contains the
/// projection of the intersection).
fn intersected(result: &ResultJson, plane: &Plane, k: usize, poly: Vec<Point>) -> Vec<Point> {
    result.also.iter().fold(poly, |poly, m| {
        let (Some(mp), Some(step)) = (
            Plane::new(plane.states, &m.constants.metric),
            m.steps.get(k),
        ) else {
            return poly;
        };
        let other = det_set(m, &mp, step)
            .plus_ellipse(mp.shape, step.r_t)
            .polygon();
        clip(&poly, &half_planes(&other))
    })
}

/// Projects each path (flat, `n` per report time) onto the plane.
fn project_paths(plane: &Plane, n: usize, paths: &[Vec<f64>]) -> Vec<Vec<Point>> {
    paths
        .iter()
        .map(|p| p.chunks_exact(n).map(|x| plane.point(x)).collect())
        .collect()
}

/// The states of the paths at report step `k`, where finite.
fn samples_at(paths: &[Vec<Point>], k: usize) -> Vec<Point> {
    paths
        .iter()
        .filter_map(|p| p.get(k).copied())
        .filter(|z| z[0].is_finite() && z[1].is_finite())
        .collect()
}

/// The PRS of every report step of a result, as polygons (their union is the set of states the
/// PRS hold at some time of the horizon).
pub fn envelope(result: &ResultJson, plane: &Plane) -> Vec<Vec<Point>> {
    result
        .steps
        .iter()
        .map(|step| {
            det_set(result, plane, step)
                .plus_ellipse(plane.shape, step.r_t)
                .polygon()
        })
        .filter(|p| p.len() >= 3)
        .collect()
}

/// How sample paths are drawn for a model of this period (`None`: continuous time).
fn paths_by(period: Option<f64>) -> &'static str {
    match period {
        Some(_) => "exact map steps",
        None => "Euler-Maruyama",
    }
}

/// The sets figure of a result: the sets at report steps `picked`, the nominal, the sample
/// paths (flat states at every report time of the result) and the unsafe regions.
pub fn sets_scene(
    result: &ResultJson,
    plane: &Plane,
    picked: &[usize],
    paths: &[Vec<f64>],
    regions: Vec<(String, Region)>,
) -> SetsScene {
    let n = result.states.len();
    let paths = project_paths(plane, n, paths);
    let slices = picked
        .iter()
        .map(|&k| {
            let step = &result.steps[k];
            let det = det_set(result, plane, step);
            let prs = det.plus_ellipse(plane.shape, step.r_t);
            // A point deterministic set (a point initial set at t = 0) has no boundary.
            let degenerate = det.support([1.0, 0.0]) + det.support([-1.0, 0.0]) <= 0.0
                && det.support([0.0, 1.0]) + det.support([0.0, -1.0]) <= 0.0;
            Slice {
                t: step.t,
                // (A union has no one deterministic set: its pieces are drawn instead.)
                det: if degenerate || !result.pieces.is_empty() {
                    Vec::new()
                } else {
                    det.polygon()
                },
                prs: intersected(result, plane, k, prs.polygon()),
                pieces: result
                    .pieces
                    .iter()
                    .filter_map(|p| {
                        let st = p.steps.get(k)?;
                        Some(plane.boxed(&st.prs_hull_lo, &st.prs_hull_hi).polygon())
                    })
                    .filter(|poly| poly.len() >= 3)
                    .collect(),
                samples: samples_at(&paths, k),
                nominal: Some(plane.point(&step.nominal)),
            }
        })
        .collect();
    let contraction = result.method == Method::Contraction;
    let [a, b] = plane.states;
    let shape = match result.transform {
        _ if zonotopes(result) => "zonotope + B_P(remainder)",
        Some(_) => "parallelotope",
        None if contraction => "P-ball",
        None => "box",
    };
    let holds = match result.guarantee {
        Guarantee::Uniform => "holds X_t for all t at once with probability ≥ 1 - δ",
        Guarantee::Pointwise => "holds X_t with probability ≥ 1 - δ at each t",
    };
    let mut notes = vec![
        format!(
            "PRS (solid) = deterministic {shape} (dashed) + B_P(r_t): {holds}, δ = {}",
            result.delta
        ),
        "projections onto the plotted states: exact".into(),
    ];
    if !result.pieces.is_empty() {
        notes[0] = format!(
            "PRS (solid) = the union of the PRS of {} pieces of the initial box (thin: each \
             piece's bounding box), each at δ = {}: {holds}",
            result.pieces.len(),
            result.delta
        );
        notes[1] = "solid: the union's bounding box; projections onto the plotted states".into();
    }
    if !result.also.is_empty() {
        let of = |role: Role| result.also.iter().filter(|m| m.role == role).count();
        let k = 1 + of(Role::Metric);
        let mut parts = Vec::new();
        if k > 1 {
            parts.push(format!("the sets of {k} metrics, each at δ / {k}"));
        } else {
            parts.push("its set".to_string());
        }
        if of(Role::Box) > 0 {
            parts.push("the interval box".to_string());
        }
        if of(Role::FirstOrder) > 0 {
            parts.push("the first-order zonotope + B_P(remainder + r_t)".to_string());
        }
        if of(Role::Linearised) > 0 {
            parts.push("the linearised Gaussian zonotope".to_string());
        }
        notes[1] = format!(
            "PRS: the intersection of {} (dashed: the first deterministic set); drawn: the \
             intersection of their projections",
            parts.join(" and ")
        );
    }
    SetsScene {
        title: format!("{} / {}: δ-PRS", result.model, result.analysis),
        axes: [result.states[a].clone(), result.states[b].clone()],
        slices,
        envelope: Vec::new(),
        reference: None,
        nominal: result
            .steps
            .iter()
            .map(|s| plane.point(&s.nominal))
            .collect(),
        nominal_label: if contraction {
            "nominal x*_t".into()
        } else {
            "centre of the deterministic set".into()
        },
        paths_by: paths_by(result.period),
        paths,
        regions,
        goals: Vec::new(),
        notes,
    }
}

/// The note for a set (`what`: "unsafe set" or "goal") that does not constrain the plotted
/// states (it projects to the whole plane).
pub(super) fn not_drawn(what: &str, name: &str) -> String {
    format!("{what} `{name}` does not constrain the plotted states: not drawn")
}

/// Moving sets in the plane: unsafe sets as regions, goals as their parts' regions, each
/// labelled with its name and the time it is drawn at.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MovingRegions {
    /// Unsafe sets: `(NAME at t = T, region)`.
    pub unsafe_sets: Vec<(String, Region)>,
    /// Goals: `(NAME at t = T, the projections of its parts)`.
    pub goals: Vec<(String, Vec<Region>)>,
}

/// The `moving` sets of `result` (method.md 8.15) in the plane of states `plane`, each at the
/// report steps `at`: an unsafe set as the fixed set that held it over the report interval
/// ending there (its margins' set), a goal as its parts then. A set that does not constrain
/// the plotted states is listed in `notes` instead, and a note says what is drawn.
pub fn moving_regions(
    result: &ResultJson,
    moving: &[MovingSet],
    plane: [usize; 2],
    at: &[usize],
    notes: &mut Vec<String>,
) -> MovingRegions {
    let mut drawn = MovingRegions::default();
    for set in moving {
        // A set's shape keeps its kind and states as it moves: it constrains the plane at
        // every time or at none.
        let mut constrains = false;
        for &k in at {
            let (Some(parts), Some(step)) = (set.at.get(k), result.steps.get(k)) else {
                continue;
            };
            let regions: Vec<Region> = parts.iter().filter_map(|p| Region::of(p, plane)).collect();
            if regions.is_empty() {
                continue;
            }
            constrains = true;
            let label = format!("{} at t = {}", set.name, num(step.t));
            if set.goal {
                drawn.goals.push((label, regions));
            } else {
                // (An unsafe set has one part.)
                drawn
                    .unsafe_sets
                    .extend(regions.into_iter().map(|r| (label.clone(), r)));
            }
        }
        if !constrains {
            let what = if set.goal { "goal" } else { "unsafe set" };
            notes.push(not_drawn(what, &set.name));
        }
    }
    if !(drawn.unsafe_sets.is_empty() && drawn.goals.is_empty()) {
        let times: Vec<String> = at
            .iter()
            .filter_map(|&k| result.steps.get(k))
            .map(|s| num(s.t))
            .collect();
        notes.push(format!(
            "moving sets drawn at t = {}: an unsafe set as the fixed set holding it over the \
             report interval ending then (its margins are computed against it), a goal as it \
             is then",
            times.join(", ")
        ));
    }
    drawn
}

/// The sets figure of an analysis that has no PRS (its constants could not be bounded): the
/// sample paths (flat states at the report times `times`) with their states at report steps
/// `picked`, and the unsafe regions.
pub fn paths_scene(
    info: &ModelInfo,
    analysis: &Analysis,
    plane: &Plane,
    (times, picked): (&[f64], &[usize]),
    paths: &[Vec<f64>],
    regions: Vec<(String, Region)>,
) -> SetsScene {
    let paths = project_paths(plane, info.states().len(), paths);
    let [a, b] = plane.states;
    // The reason can be a long Jacobian entry: the warning printed with the spec shows it.
    let why = match analysis.constants.as_ref().err() {
        Some(e) if e.to_string().chars().count() <= 160 => e.to_string(),
        _ => "the analysis' constants (c, sigma, rho) could not be bounded (see the warning)"
            .to_string(),
    };
    SetsScene {
        title: format!("{} / {}: sample paths", info.name(), analysis.spec.name),
        axes: [info.states()[a].clone(), info.states()[b].clone()],
        slices: picked
            .iter()
            .map(|&k| Slice {
                t: times[k],
                det: Vec::new(),
                prs: Vec::new(),
                pieces: Vec::new(),
                samples: samples_at(&paths, k),
                nominal: None,
            })
            .collect(),
        envelope: Vec::new(),
        reference: None,
        nominal: Vec::new(),
        nominal_label: String::new(),
        paths_by: paths_by(info.time().period()),
        paths,
        regions,
        goals: Vec::new(),
        notes: vec![format!("no PRS: {why}")],
    }
}

/// The radius figure of a result, with the Monte Carlo quantile if given (`(values per report
/// time, number of paths, where they come from)`).
pub fn radius_scene(
    result: &ResultJson,
    quantile: Option<(Vec<Option<f64>>, u64, &str)>,
) -> RadiusScene {
    let contraction = result.method == Method::Contraction;
    let mut notes = vec![
        format!(
            "radii in the P-norm |v|_P = sqrt(v' P v), δ = {}",
            result.delta
        ),
        "r_t = sqrt(Ψ_t κ(n, δ)): the stochastic part".into(),
    ];
    let quantile = quantile.map(|(values, paths, source)| {
        notes.push(format!("quantile: {source}"));
        (
            values,
            format!(
                "empirical (1-δ) quantile of |X_t - x*_t|_P ({})",
                count(paths, "path")
            ),
        )
    });
    if quantile.is_none() {
        notes.push(
            "no empirical quantile: run `reachc simulate` with -o into the result's directory"
                .into(),
        );
    }
    if zonotopes(result) {
        notes.push(
            "first-order sets: the PRS is a zonotope + B_P(remainder + r_t); its P-radius \
             bounds it coarsely, so the quantile is only indicative"
                .into(),
        );
    } else if !contraction {
        notes.push(
            "interval method: the PRS is a box or parallelotope + B_P(r_t); its P-radius \
             bounds it coarsely, so the quantile is only indicative"
                .into(),
        );
    }
    RadiusScene {
        title: format!("{} / {}: radii", result.model, result.analysis),
        times: result.times(),
        r_t: result.steps.iter().map(|s| s.r_t).collect(),
        prs_radius: result.steps.iter().map(|s| s.prs_radius).collect(),
        prs_label: if contraction {
            "PRS radius R_t + r_t".into()
        } else {
            "P-radius of a ball containing the PRS".into()
        },
        quantile,
        notes,
    }
}

#[cfg(test)]
mod tests {
    use super::super::input::tests::result as sample;
    use super::*;
    use reachc_runtime::model::{Bounds, UnsafeShape};
    use reachc_runtime::report::schema::{
        DetSetJson, MetricRef, PieceJson, PieceStepJson, VerdictJson,
    };

    const P: [[f64; 2]; 2] = [[2.0, 0.5], [0.5, 1.0]];
    /// `P^-1`.
    const S: [[f64; 2]; 2] = [[1.0 / 1.75, -0.5 / 1.75], [-0.5 / 1.75, 2.0 / 1.75]];
    const CENTER: [f64; 2] = [1.0, 0.0];
    const GENS: [[f64; 2]; 3] = [[0.3, 0.1], [-0.1, 0.4], [0.2, -0.2]];

    /// A deterministic set of `shape` about [`CENTER`] of `radius`, without corners or
    /// generators.
    fn set_about(shape: Shape, radius: f64) -> DetSetJson {
        DetSetJson {
            shape,
            center: CENTER.to_vec(),
            radius,
            metric: MetricRef::Constants,
            lo: None,
            hi: None,
            hull_lo: None,
            hull_hi: None,
            generators: None,
            remainder: None,
        }
    }

    /// The zonotope of [`GENS`] around [`CENTER`] plus `B_P(remainder)`.
    fn zonotope(remainder: f64) -> DetSetJson {
        DetSetJson {
            generators: Some(GENS.iter().map(|g| g.to_vec()).collect()),
            remainder: Some(remainder),
            ..set_about(Shape::Zonotope, 2.0)
        }
    }

    /// A result in two states with one report time holding `det` and `r_t`, and `also`.
    fn result(method: Method, det: DetSetJson, r_t: f64, also: Vec<ResultJson>) -> ResultJson {
        let ball = serde_json::to_value(p_ball(1.0)).unwrap();
        let mut r: ResultJson =
            serde_json::from_value(sample(ball, serde_json::json!([]))).unwrap();
        r.method = method;
        r.guarantee = Guarantee::Uniform;
        r.constants.metric = P.iter().map(|r| r.to_vec()).collect();
        r.initial_center = CENTER.to_vec();
        let step = &mut r.steps[0];
        (step.t, step.nominal, step.det_set) = (1.0, CENTER.to_vec(), det);
        (step.r_t, step.prs_radius) = (r_t, 2.0);
        r.also = also;
        r
    }

    /// The P-ball of `radius` about [`CENTER`].
    fn p_ball(radius: f64) -> DetSetJson {
        set_about(Shape::PBall, radius)
    }

    /// `sqrt(d' P^-1 d)`: the support of `B_P(1)`.
    fn dual(d: [f64; 2]) -> f64 {
        (S[0][0] * d[0] * d[0] + 2.0 * S[0][1] * d[0] * d[1] + S[1][1] * d[1] * d[1]).sqrt()
    }

    /// `c . d + sum_j |g_j . d| + r sqrt(d' P^-1 d)`: the support of the zonotope plus
    /// `B_P(r)`.
    fn support(d: [f64; 2], r: f64) -> f64 {
        let dot = |a: [f64; 2]| a[0] * d[0] + a[1] * d[1];
        dot(CENTER) + GENS.iter().map(|&g| dot(g).abs()).sum::<f64>() + r * dual(d)
    }

    /// The largest `d . v` over the polygon's vertices.
    fn reach(poly: &[Point], d: [f64; 2]) -> f64 {
        poly.iter()
            .map(|v| v[0] * d[0] + v[1] * d[1])
            .fold(f64::NEG_INFINITY, f64::max)
    }

    fn directions() -> impl Iterator<Item = [f64; 2]> {
        (0..360).map(|k| {
            let a = std::f64::consts::TAU * (f64::from(k) + 0.29) / 360.0;
            [a.cos(), a.sin()]
        })
    }

    /// A zonotope result: the dashed set is the zonogon plus `B_P(remainder)`, the PRS the
    /// zonogon plus `B_P(remainder + r_t)`, each polygon's support within the angular
    /// spacing above the exact one; the legend and the radius figure say what they are.
    #[test]
    fn zonotopes_are_drawn_as_zonogons_plus_their_balls() {
        let (remainder, r_t) = (0.05, 0.1);
        let mut r = result(Method::Interval, zonotope(remainder), r_t, vec![]);
        r.role = Role::FirstOrder;
        let plane = Plane::new([0, 1], &r.constants.metric).unwrap();
        let scene = sets_scene(&r, &plane, &[0], &[], vec![]);
        let slice = &scene.slices[0];
        for d in directions() {
            let (det, prs) = (support(d, remainder), support(d, remainder + r_t));
            assert!((det..det + 1e-4 * remainder).contains(&reach(&slice.det, d)));
            assert!((prs..prs + 1e-4 * (remainder + r_t)).contains(&reach(&slice.prs, d)));
        }
        assert!(
            scene.notes[0].starts_with("PRS (solid) = deterministic zonotope + B_P(remainder)"),
            "{:?}",
            scene.notes
        );
        let radius = radius_scene(&r, None);
        assert!(radius
            .notes
            .iter()
            .any(|n| n.starts_with("first-order sets")));
    }

    /// A split result: each piece's bounding box is drawn, inside the union's box (the solid
    /// outline), no dashed deterministic set, and the legend says so.
    #[test]
    fn the_pieces_of_a_split_are_drawn() {
        let hull = DetSetJson {
            lo: Some(vec![-1.0, -1.0]),
            hi: Some(vec![2.0, 2.0]),
            ..set_about(Shape::Box, 3.0)
        };
        let mut union = result(Method::Contraction, hull, 0.0, vec![]);
        let piece = |lo: [f64; 2], hi: [f64; 2]| PieceJson {
            initial_box: vec![[0.0, 1.0]; 2],
            verdict: VerdictJson::NoUnsafeSets,
            steps: vec![PieceStepJson {
                t: 1.0,
                prs_hull_lo: lo.to_vec(),
                prs_hull_hi: hi.to_vec(),
                margins: Vec::new(),
            }],
        };
        union.pieces = vec![
            piece([-1.0, -1.0], [0.5, 2.0]),
            piece([0.0, -0.5], [2.0, 1.0]),
        ];
        let plane = Plane::new([0, 1], &union.constants.metric).unwrap();
        let scene = sets_scene(&union, &plane, &[0], &[], vec![]);
        let slice = &scene.slices[0];
        assert_eq!(slice.pieces.len(), 2);
        assert!(slice.det.is_empty());
        let sides = |poly: &[Point]| {
            [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]].map(|d| reach(poly, d))
        };
        // (The projection rounds: within 1e-12 of the boxes' sides.)
        let close = |a: [f64; 4], b: [f64; 4]| a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12);
        assert!(close(sides(&slice.pieces[0]), [0.5, 1.0, 2.0, 1.0]));
        assert!(close(sides(&slice.pieces[1]), [2.0, 0.0, 1.0, 0.5]));
        assert!(close(sides(&slice.prs), [2.0, 1.0, 2.0, 1.0]));
        assert!(
            scene.notes[0].contains("union of the PRS of 2 pieces"),
            "{:?}",
            scene.notes
        );
    }

    /// A P-ball cut by a zonotope member: the drawn PRS lies in both projections, and is the
    /// zonotope's where that is the smaller (the ball's radius is larger than the zonotope's
    /// reach in every direction here); the legend names the zonotope.
    #[test]
    fn a_zonotope_member_cuts_the_drawn_prs() {
        let (remainder, r_t) = (0.05, 0.1);
        let mut member = result(Method::Contraction, zonotope(remainder), r_t, vec![]);
        member.role = Role::FirstOrder;
        let ball = p_ball(1.2);
        let r = result(Method::Contraction, ball, r_t, vec![member]);
        let plane = Plane::new([0, 1], &r.constants.metric).unwrap();
        let scene = sets_scene(&r, &plane, &[0], &[], vec![]);
        let prs = &scene.slices[0].prs;
        for d in directions() {
            let ball = CENTER[0] * d[0] + CENTER[1] * d[1] + (1.2 + r_t) * dual(d);
            let zonotope = support(d, remainder + r_t);
            assert!(zonotope < ball, "{d:?}");
            let got = reach(prs, d);
            assert!(
                (zonotope - 1e-9..zonotope + 1e-4 * (remainder + r_t)).contains(&got),
                "{d:?}: {got} vs {zonotope}"
            );
        }
        assert!(
            scene.notes[1].contains("its set and the first-order zonotope"),
            "{:?}",
            scene.notes
        );
    }

    /// Moving sets are drawn at the given report steps where they are then, labelled with the
    /// time: a box that moved by 2 in x between t = 0 and t = 1 is two rectangles 2 apart, a
    /// goal's parts move with it; a set over a state off the plane is noted, not drawn.
    #[test]
    fn moving_sets_are_drawn_where_they_are_at_each_time() {
        let mut r = result(Method::Contraction, p_ball(1.0), 0.1, vec![]);
        r.steps = (0..3)
            .map(|k| StepJson {
                t: 0.5 * f64::from(k),
                ..r.steps[0].clone()
            })
            .collect();
        let gate = |k: usize| {
            let x = k as f64;
            vec![UnsafeShape::Box(vec![
                (0, Bounds::new(x, x + 1.0)),
                (1, Bounds::new(0.0, 1.0)),
            ])]
        };
        let dock = |k: usize| {
            vec![
                UnsafeShape::HalfSpace {
                    normal: vec![1.0, 0.0],
                    offset: 0.5 * k as f64,
                },
                UnsafeShape::Box(vec![(1, Bounds::new(-1.0, 1.0))]),
            ]
        };
        let moving = [
            MovingSet {
                name: "gate".into(),
                goal: false,
                at: (0..3).map(gate).collect(),
            },
            MovingSet {
                name: "far".into(),
                goal: false,
                at: (0..3)
                    .map(|_| vec![UnsafeShape::Box(vec![(2, Bounds::new(0.0, 1.0))])])
                    .collect(),
            },
            MovingSet {
                name: "dock".into(),
                goal: true,
                at: (0..3).map(dock).collect(),
            },
        ];
        let mut notes = Vec::new();
        let drawn = moving_regions(&r, &moving, [0, 1], &[0, 2], &mut notes);
        let rect = |x: (f64, f64), y: (f64, f64)| Region::Rect { x, y };
        assert_eq!(
            drawn.unsafe_sets,
            [
                ("gate at t = 0".to_string(), rect((0.0, 1.0), (0.0, 1.0))),
                ("gate at t = 1".to_string(), rect((2.0, 3.0), (0.0, 1.0))),
            ]
        );
        let band = rect((f64::NEG_INFINITY, f64::INFINITY), (-1.0, 1.0));
        let half = |offset: f64| Region::HalfPlane {
            normal: [1.0, 0.0],
            offset,
        };
        assert_eq!(
            drawn.goals,
            [
                ("dock at t = 0".to_string(), vec![half(0.0), band.clone()]),
                ("dock at t = 1".to_string(), vec![half(1.0), band]),
            ]
        );
        assert_eq!(
            notes[0],
            "unsafe set `far` does not constrain the plotted states: not drawn"
        );
        assert!(
            notes[1].starts_with("moving sets drawn at t = 0, 1: "),
            "{notes:?}"
        );
        // Nothing moves: nothing drawn, nothing said.
        let mut notes = Vec::new();
        assert_eq!(
            moving_regions(&r, &[], [0, 1], &[0, 2], &mut notes),
            MovingRegions::default()
        );
        assert!(notes.is_empty());
    }
}
