//! The contraction-based deterministic part (Proposition 2): `Rbar_t = B_P(x*_t, R_t)`, a
//! P-ball around the nominal trajectory `x*_t`, with `R_t = e^(ct) r1 + rho/c (e^(ct) - 1) r2`
//! (or the per-step recursion of an empirical rate).

use super::assemble::{assemble, Deterministic, Header};
use super::{nominal, radius, rates, Run, RunError};
use crate::model::{Method, Rate};
use crate::prs::{ConstantsUsed, DetSet, Proved, Prs, R1Bound, R1Method, RateUsed, Unproved};

/// The contraction PRS of a run.
pub(super) fn run(run: &Run) -> Result<Prs, RunError> {
    let (spec, consts, n) = (run.spec, run.setup.consts, run.setup.n);
    let metric = &consts.metric;

    // Initial set and inputs.
    let (x0, half) =
        radius::initial_center_and_halfwidths(run.initial, n).map_err(RunError::Invalid)?;
    let r1 = radius::r1_bound(metric, &half);
    let active = half.iter().filter(|&&h| h > 0.0).count();
    let r1_bound = R1Bound {
        how: if active <= radius::MAX_VERTEX_COORDS {
            R1Method::Vertices { active }
        } else {
            R1Method::AbsoluteSum
        },
        balls_as_boxes: !run.initial.balls.is_empty(),
    };
    let grid = nominal::time_grid(spec.horizon, spec.step);
    let (inputs, r2) = run.nominal_inputs(&grid);
    let rho = if run.setup.p == 0 { 0.0 } else { consts.rho };
    let (kappa, radius_rule) = radius::stochastic_factor(n, spec);

    // Nominal trajectory (not validated).
    let traj = nominal::integrate(run.sys, &x0, &inputs, &grid, spec.integrator).map_err(|k| {
        RunError::NonFinite(format!(
            "the nominal trajectory is not finite at t = {}",
            grid[k]
        ))
    })?;

    // Per-step rates (None: the certified constant on every step).
    let empirical = match spec.rate {
        Rate::Certified => None,
        Rate::Empirical { paths } => {
            Some(rates::empirical(run, metric, &grid, &traj, &inputs, paths)?)
        }
    };
    let det_radii = match &empirical {
        Some(c) => rates::det_radii(c, &grid, rho, r1, r2),
        None => grid
            .iter()
            .map(|&t| radius::det_radius(consts.c, rho, r1, r2, t))
            .collect(),
    };
    let c_at = |k: usize| empirical.as_ref().map_or(consts.c, |c| c[k]);
    let det = Deterministic {
        rates: (0..grid.len()).map(|k| (c_at(k), consts.sigma)).collect(),
        sets: traj
            .into_iter()
            .zip(det_radii)
            .map(|(center, radius)| DetSet::Ball { center, radius })
            .collect(),
        grid,
        frame: None,
    };

    let max_c = empirical.as_ref().map_or(consts.c, |r| {
        r.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    });
    let certified = spec.rate == Rate::Certified;
    let mut not_validated = vec![Unproved::Nominal {
        integrator: spec.integrator,
        step: spec.step,
    }];
    if let Rate::Empirical { paths } = spec.rate {
        not_validated.insert(0, Unproved::EmpiricalRate { paths });
    }
    let header = Header {
        method: Method::Contraction,
        inclusion: None,
        rate: RateUsed {
            rate: spec.rate,
            max_c,
        },
        constants: ConstantsUsed {
            c: consts.c,
            sigma: consts.sigma,
            rho,
            provenance: consts.provenance.clone(),
            metric: metric.clone(),
        },
        radius_rule,
        kappa,
        r1,
        r2,
        r1_bound,
        transform: None,
        initial_center: x0,
        input_center: inputs.first().cloned().unwrap_or_default(),
        rigorous: vec![
            Proved::Constants {
                c: certified,
                rho: true,
                provenance: consts.provenance.clone(),
            },
            Proved::Kappa,
            Proved::Psi,
            Proved::Radii,
            Proved::Margins {
                given: Method::Contraction,
            },
        ],
        not_validated,
    };
    Ok(assemble(run, det, header))
}
