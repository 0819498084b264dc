//! The linearised Gaussian set alone (method.md 8.12): the PRS of a run whose contraction ball
//! (or interval box) cannot be bounded, where the set of method.md 8.10 still can. That set
//! holds its stochastic part itself, on an event of its own, so at the full delta it is a
//! delta-PRS without any other set: no contraction rate, no domain, no tube region.

use super::assemble::{assemble_with, constants_used, rate_used, Header, Radii};
use super::{contraction, first_order, nominal, r1, radius, Problem, Run, RunError};
use crate::model::Method;
use crate::prs::{Hint, Proved, Prs, Role};

/// The PRS of `run` that is the linearised Gaussian set at the run's whole delta, or `None`
/// when that set does not apply (state-dependent noise, a pointwise guarantee, a ball initial
/// set, an unvalidated nominal) or cannot be bounded over the horizon. `failed` is what
/// stopped the analysis' own sets (the result's hint).
pub(super) fn run(run: &Run, failed: &RunError) -> Result<Option<Prs>, RunError> {
    let (spec, n) = (run.spec, run.setup.n);
    if !first_order::gaussian_wanted(run.info, spec, run.initial, n) {
        return Ok(None);
    }
    let metric = &run.setup.consts.metric;
    let (x0, half) = radius::initial_center_and_halfwidths(run.initial, n)
        .map_err(|e| RunError::Invalid(Problem::InitialSet(e).into()))?;
    let (r1, r1_bound) = r1::bound(metric, run.initial, &half);
    let grid = nominal::time_grid(spec.horizon, spec.step);
    let (inputs, r2) = run.nominal_inputs(&grid);
    let (kappa, radius_rule) = radius::stochastic_factor(n, spec);
    let steps = contraction::nominal_steps(run, &x0, r1, &grid, &inputs)?;
    let first = first_order::deterministic(
        run,
        &steps,
        &x0,
        &grid,
        &inputs,
        r2,
        first_order::Linearised::Alone(spec.delta),
    );
    let Some((det, epochs)) = first.and_then(|f| f.gaussian) else {
        return Ok(None);
    };
    let header = Header {
        method: spec.method,
        inclusion: None,
        // (The rates certified on the set's own regions, for the record: the set does not
        // use them.)
        rate: rate_used(spec.rate, &det.pieces, None),
        constants: constants_used(run, run.setup.consts.rho),
        radius_rule,
        kappa,
        r1,
        r2,
        r1_bound,
        transform: None,
        initial_center: x0,
        input_center: inputs.first().cloned().unwrap_or_default(),
        rigorous: vec![
            Proved::ValidatedNominal {
                steps: steps.len(),
                ros2: steps.iter().filter(|(s, _)| s.ros2).count(),
            },
            Proved::LinearisedGaussian { epochs },
            Proved::Margins {
                given: Method::Contraction,
            },
        ],
        not_validated: Vec::new(),
    };
    let reports = det.pieces.iter().filter(|p| p.end.is_some()).count();
    let mut prs = assemble_with(run, det, header, None, Radii::inside(reports));
    prs.hints.push(Hint::LinearisedAlone {
        failed: failed.clone(),
    });
    Ok(Some(prs.with_role(Role::Linearised)))
}
