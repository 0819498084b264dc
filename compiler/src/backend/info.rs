//! What every backend needs: the Jacobians and the runtime's [`ModelInfo`], with the constants
//! of Assumption 1 derived (and certified) for each analysis.

use reachc_core::model::{Analysis, ModelInfo, ModelParts};

use crate::analysis::{
    constants, constants_without_rate, map_metric, metric_for_result, synthesize_metric,
    synthesize_metric_over, time_range, ConstantsError, Derivatives, Frame, Objective,
};
use crate::diagnostics::Diagnostic;
use crate::ir::Names;

/// Longest expression an "unbounded" message shows, in bytes (then ` ...`).
const MAX_SHOWN: usize = 200;
use crate::model::{self, MetricChoice, Model, Rate};
use reachc_core::interval::Interval;
use reachc_core::model::{
    AnalysisSpec, Constants, ConstantsParts, MetricRegion, NoConstants, Provenance,
};

/// A model ready for code generation or interpretation.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The Jacobians (their expressions live in the model's pool).
    pub derivatives: Derivatives,
    /// The transformed systems of the analyses' coordinate transforms (one per distinct `T`,
    /// indexed by [`Transform::frame`](reachc_core::model::Transform::frame)).
    pub frames: Vec<Frame>,
    /// Sets, analyses and derived constants, as the runtime consumes them.
    pub info: ModelInfo,
    /// Warnings, e.g. an analysis whose constants are unbounded (it cannot run; the model can
    /// still be built).
    pub warnings: Vec<Diagnostic>,
}

/// Differentiates the model and derives each analysis' constants.
///
/// An analysis whose constants cannot be bounded (an unbounded Jacobian entry over the domain)
/// gets `constants: Err` with the reason, and a warning naming the entry; running it is then
/// an error, but the rest of the model is still usable.
pub fn prepare(model: &mut Model) -> Prepared {
    let derivatives = Derivatives::of(model);
    let mut warnings = Vec::new();
    let mut analyses = Vec::new();
    let mut frames: Vec<Frame> = Vec::new();
    for a in model.analyses.clone() {
        let derived = analysis_constants(model, &derivatives, &a.spec);
        let constants = derived.map_err(|e| {
            let (why, help) = explain(model, &derivatives, &e);
            warnings.push(
                Diagnostic::warning(
                    format!("analysis `{}` cannot run: {why}", a.spec.name),
                    a.span.clone(),
                    "its constants are unbounded",
                )
                .with_help(help),
            );
            why
        });
        // One transformed system per distinct `T` (the checker numbered them).
        if let Some(t) = &a.spec.transform {
            if t.frame == frames.len() {
                frames.push(
                    Frame::of(model, t)
                        .expect("the checker accepts only transforms with a finite inverse"),
                );
            }
        }
        analyses.push(Analysis {
            spec: a.spec,
            constants,
        });
    }
    let names = |v: &[model::Variable]| v.iter().map(|x| x.name.clone()).collect();
    let info = ModelInfo::from_parts(ModelParts {
        name: model.name.clone(),
        states: names(&model.states),
        inputs: names(&model.inputs),
        noises: names(&model.noises),
        input_box: model.input_box.clone(),
        initial: model.initial.clone(),
        domain: model.domain.clone(),
        has_domain: model.has_domain,
        affine: is_affine(model, &derivatives),
        constant_diffusion: model
            .diffusion
            .iter()
            .flatten()
            .all(|e| model.pool.vars_of(*e).is_empty()),
        time: model.time,
        unsafe_sets: model.unsafe_sets.clone(),
        goals: model.goals.clone(),
        analyses,
    });
    Prepared {
        derivatives,
        frames,
        info,
        warnings,
    }
}

/// Whether `D_x f` and `G` are constant expressions (no state, input, time or table in them):
/// the model is affine in the state with additive noise (method.md section 8.1); for a
/// discrete-time model, an affine map with additive noise.
fn is_affine(model: &Model, d: &Derivatives) -> bool {
    let constant = |e: &crate::ir::ExprId| model.pool.vars_of(*e).is_empty();
    d.jac_x.iter().flatten().all(constant) && model.diffusion.iter().flatten().all(constant)
}

/// The constants of an analysis: for its metric, or with `metric = auto(states = [..])` one
/// metric per named state, each chosen for that state's extent at `delta / K`, the first's
/// constants holding the others' in [`Constants::also`]. A discrete-time model's are
/// [`map_constants`].
fn analysis_constants(
    model: &Model,
    d: &Derivatives,
    spec: &AnalysisSpec,
) -> Result<Constants, ConstantsError> {
    if model.time.period().is_some() {
        return Ok(map_constants(model, d, spec));
    }
    let MetricChoice::PerState(states) = &spec.metric else {
        return one_metric(model, d, spec, Objective::Volume);
    };
    let metrics = states.len();
    let mut all = states
        .iter()
        .map(|&state| one_metric(model, d, spec, Objective::Extent { state, metrics }))
        .collect::<Result<Vec<_>, _>>()?;
    let mut first = all.remove(0).into_parts();
    first.also = all;
    Ok(Constants::from_parts(first))
}

/// The constants of an analysis for one metric: given, or chosen by the compiler for
/// `objective`. An empirical rate needs only sigma and rho from here; local rates need only a
/// metric (the global constants, where bounded, tighten them where they hold).
fn one_metric(
    model: &Model,
    d: &Derivatives,
    spec: &AnalysisSpec,
    objective: Objective,
) -> Result<Constants, ConstantsError> {
    let metric = || match given_metric(spec, model.states.len()) {
        Some(p) => Ok(p),
        None => {
            synthesize_metric(model, d).map(|p| metric_for_result(model, d, spec, p, objective))
        }
    };
    let region = match spec.metric {
        MetricChoice::Auto | MetricChoice::PerState(_) => MetricRegion::Domain,
        _ => MetricRegion::Given,
    };
    let derived = match spec.rate {
        Rate::Global => metric().and_then(|p| constants(model, d, &p)),
        Rate::Empirical { .. } => metric().and_then(|p| constants_without_rate(model, d, &p)),
        Rate::Local => return local_constants(model, d, spec, objective),
    };
    derived.map(|c| {
        Constants::from_parts(ConstantsParts {
            metric_region: region,
            ..c.into_parts()
        })
    })
}

/// The constants of a local-rate analysis: its metric (given; or synthesised over the domain
/// when the compiler can bound the rate there, so that the local rates are never above the
/// global ones; else over the initial set during the first report step), and the global
/// constants for that metric where the compiler can bound them (infinite otherwise).
fn local_constants(
    model: &Model,
    d: &Derivatives,
    spec: &AnalysisSpec,
    objective: Objective,
) -> Result<Constants, ConstantsError> {
    let n = model.states.len();
    let (metric, region) = match given_metric(spec, n) {
        Some(p) => (p, MetricRegion::Given),
        None => {
            let global = synthesize_metric(model, d)
                .map(|p| metric_for_result(model, d, spec, p, objective))
                .and_then(|p| constants(model, d, &p));
            match global {
                Ok(c) if c.c().is_finite() => {
                    return Ok(Constants::from_parts(ConstantsParts {
                        metric_region: MetricRegion::Domain,
                        ..c.into_parts()
                    }))
                }
                _ => (
                    initial_metric(model, d, spec.step),
                    MetricRegion::InitialSet,
                ),
            }
        }
    };
    let mut chosen = for_metric(model, d, metric, region)?.into_parts();
    // Constants over the initial set predict the PRS at the horizon too poorly to compare
    // metrics by: the engine runs the identity as well and keeps the smaller result.
    if region == MetricRegion::InitialSet && chosen.metric != identity(n) {
        let id = for_metric(model, d, identity(n), MetricRegion::IdentityAtRun)?;
        chosen.alternatives.push(id);
    }
    Ok(Constants::from_parts(chosen))
}

/// The constants of a local-rate analysis for `metric`: the compiler's global ones where it can
/// bound them, else infinite (the engine certifies local rates only).
fn for_metric(
    model: &Model,
    d: &Derivatives,
    metric: Vec<f64>,
    region: MetricRegion,
) -> Result<Constants, ConstantsError> {
    match constants(model, d, &metric) {
        Ok(c) => Ok(Constants::from_parts(ConstantsParts {
            metric_region: region,
            ..c.into_parts()
        })),
        Err(e @ ConstantsError::Unbounded { .. }) => {
            let time = time_range(model);
            Ok(Constants::from_parts(ConstantsParts {
                metric,
                metric_region: region,
                c: f64::INFINITY,
                sigma: f64::INFINITY,
                rho: f64::INFINITY,
                provenance: Provenance::Unbounded {
                    why: explain(model, d, &e).0.to_string(),
                },
                also: Vec::new(),
                alternatives: Vec::new(),
                region: reachc_core::model::Region {
                    domain: model.domain.clone(),
                    input_box: model.input_box.clone(),
                    time: reachc_core::model::Bounds::new(time.lo(), time.hi()),
                },
            }))
        }
        Err(e) => Err(e),
    }
}

/// A metric synthesised for the Jacobian over the initial set's bounding box and
/// `t in [0, step]` (the identity if that fails). Not compared by the PRS predicted at the
/// horizon (constants over the initial set predict it too poorly): the engine runs the identity
/// as well and keeps the smaller result.
fn initial_metric(model: &Model, d: &Derivatives, step: f64) -> Vec<f64> {
    let n = model.states.len();
    let Ok(start) = model.initial.bounding_box() else {
        return identity(n);
    };
    let mut at_start = model.clone();
    at_start.domain = start;
    synthesize_metric_over(&at_start, d, Interval::new(0.0, step)).unwrap_or_else(|_| identity(n))
}

/// The constants of an analysis of a discrete-time model: its metric only, nothing certified
/// (a logarithmic norm of a map's Jacobian bounds nothing; the engine bounds the map's factors
/// on each step's region at run time), over the domain, the input box and `[0, horizon]`. The
/// metric is given (`identity`, a matrix) or, for `auto`, the Stein solution for the map's
/// Jacobian at the initial set's centre ([`map_metric`]; the identity when there is none).
fn map_constants(model: &Model, d: &Derivatives, spec: &AnalysisSpec) -> Constants {
    let n = model.states.len();
    let (metric, metric_region) = match given_metric(spec, n) {
        Some(p) => (p, MetricRegion::Given),
        None => map_metric(model, d, map_steps(model, spec)).map_or_else(
            || (identity(n), MetricRegion::Given),
            |p| (p, MetricRegion::Map),
        ),
    };
    Constants::from_parts(ConstantsParts {
        metric,
        metric_region,
        c: f64::INFINITY,
        sigma: f64::INFINITY,
        rho: f64::INFINITY,
        provenance: Provenance::Map,
        region: reachc_core::model::Region {
            domain: model.domain.clone(),
            input_box: model.input_box.clone(),
            time: reachc_core::model::Bounds::new(0.0, spec.horizon),
        },
        also: Vec::new(),
        alternatives: Vec::new(),
    })
}

/// The number of steps of a discrete-time analysis (its horizon in periods).
fn map_steps(model: &Model, spec: &AnalysisSpec) -> usize {
    model
        .time
        .period()
        .map_or(0, |period| (spec.horizon / period).round() as usize)
}

/// The metric the spec gives (`identity` or a matrix); `None` for the compiler to choose.
fn given_metric(spec: &AnalysisSpec, n: usize) -> Option<Vec<f64>> {
    match &spec.metric {
        MetricChoice::Identity => Some(identity(n)),
        MetricChoice::Matrix(m) => Some(m.clone()),
        MetricChoice::Auto | MetricChoice::PerState(_) => None,
    }
}

fn identity(n: usize) -> Vec<f64> {
    (0..n * n)
        .map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 })
        .collect()
}

/// A constants error with its entry named, and the help for it.
fn explain(model: &Model, d: &Derivatives, e: &ConstantsError) -> (NoConstants, String) {
    let metric_help = || "check the analysis' metric".to_string();
    let (matrix, row, column) = match e {
        ConstantsError::Unbounded {
            matrix,
            row,
            column,
        } => (*matrix, *row, *column),
        ConstantsError::BadMetric { reason } => {
            let reason = reason.clone();
            return (NoConstants::BadMetric { reason }, metric_help());
        }
        ConstantsError::NotCertified { constant } => {
            let constant = constant.to_string();
            return (NoConstants::NotCertified { constant }, metric_help());
        }
    };
    let names = |v: &[model::Variable]| v.iter().map(|x| x.name.clone()).collect::<Vec<_>>();
    let (states, inputs, noises) = (
        names(&model.states),
        names(&model.inputs),
        names(&model.noises),
    );
    let sde = Names {
        states: &states,
        inputs: &inputs,
        noises: &noises,
        tables: &model.tables,
    };
    let (what, expr) = match matrix {
        "D_u f" => (
            format!("d f[{}] / d {}", states[row], inputs[column]),
            d.jac_u[row][column],
        ),
        "G" => (
            format!("the diffusion entry G[{}, {}]", states[row], noises[column]),
            model.diffusion[row][column],
        ),
        _ => (
            format!("d f[{}] / d {}", states[row], states[column]),
            d.jac_x[row][column],
        ),
    };
    // A prefix: printed as a tree, an entry over shared lets can be millions of characters.
    let mut shown = model.pool.to_sde_prefix(expr, &sde, MAX_SHOWN);
    if shown.len() > MAX_SHOWN {
        let cut = (0..=MAX_SHOWN).rev().find(|&i| shown.is_char_boundary(i));
        shown.truncate(cut.unwrap_or(0));
        shown.push_str(" ...");
    }

    let vars: Vec<String> = model
        .pool
        .vars_of(expr)
        .into_iter()
        .filter_map(|v| match v {
            crate::ir::Var::State(i) => Some(states[i as usize].clone()),
            _ => None,
        })
        .collect();
    let help = if vars.is_empty() {
        "the entry is unbounded in time or in the inputs; bound them".to_string()
    } else {
        let example: Vec<String> = vars.iter().map(|v| format!("{v} in [LO, HI]")).collect();
        format!(
            "add a domain box for the states it depends on: `domain {{ {} }}`",
            example.join("  ")
        )
    };
    let why = NoConstants::Unbounded {
        entry: what,
        expression: shown,
    };
    (why, help)
}

#[cfg(test)]
mod tests;
