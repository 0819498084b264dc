//! The sentences a result's JSON and its text summary share: where the rate, the constants and
//! `r1` came from, what is proved and what is not, what a margin measures.

use reachc_core::model::{Method, Rate};
use reachc_core::prs::{BallBound, Proved, Prs, R1Method, Unproved, UnsafeKind};

use crate::report::count;

/// What an unsafe set's margins measure, by its kind.
pub(super) fn margin_unit(kind: UnsafeKind) -> &'static str {
    match kind {
        UnsafeKind::Box => "largest per-coordinate gap between the PRS's bounding box and the box",
        UnsafeKind::HalfSpace | UnsafeKind::Ball => "Euclidean distance",
    }
}

/// An unsafe set's kind in reports.
pub(crate) fn unsafe_kind(kind: UnsafeKind) -> &'static str {
    match kind {
        UnsafeKind::HalfSpace => "half_space",
        UnsafeKind::Box => "box",
        UnsafeKind::Ball => "ball",
    }
}

/// The rate note of the linearised Gaussian set alone (method.md 8.12).
pub(super) const ALONE_NOTE: &str =
    "none used: the PRS is the linearised Gaussian set alone (method.md \
     8.12), at the full delta; min_c and max_c are the rates certified on its own spans, for the \
     record";

/// One sentence on where the rate came from; an empirical rate says plainly that it is no
/// guarantee.
pub(super) fn rate_note(rate: Rate) -> String {
    match rate {
        Rate::Local => "c_t, sigma_t and rho_t certified on each internal step over a box \
             holding the deterministic set and the time-uniform tube on that step (interval \
             Jacobian, verified eigenvalue bounds): no global rate and no domain needed"
            .into(),
        Rate::Global => {
            "one rate c for the whole horizon, certified by the compiler over the domain".into()
        }
        Rate::Empirical { paths } => format!(
            "EMPIRICAL: c_t estimated from {paths} sample paths (largest one-sided Lipschitz \
             quotient between a sampled state and the nominal), not certified: the PRS is an \
             estimate, not a guarantee"
        ),
    }
}

/// How `r1` was bounded, in words.
pub(super) fn r1_how(prs: &Prs) -> String {
    let b = prs.r1_bound();
    let how = match b.balls {
        BallBound::NoBalls => r1_over_box(b.boxes, "the initial box"),
        BallBound::BoundingBoxes => format!(
            "{}; balls replaced by their bounding boxes (conservative: the balls' own bound was \
             not smaller)",
            r1_over_box(b.boxes, "the initial box")
        ),
        BallBound::Joint { balls } => r1_joint(balls, b.boxes),
        BallBound::Separate { balls } => format!(
            "|b|_P + |y|_P, the box part b and the ball part y bounded separately: {}; {}",
            r1_over_box(b.boxes, "the box part"),
            match balls {
                1 => "the initial ball by r sqrt(lambda_max(P, M)), exact for the ball alone"
                    .to_string(),
                m => format!("the {m} initial balls by the S-procedure (not exact in general)"),
            }
        ),
    };
    match (b.reported_only, b.balls) {
        (false, _) => how,
        (true, BallBound::NoBalls) => "P-radius of the initial box around its centre (reported \
                                       only: the interval method propagates the box itself)"
            .to_string(),
        (true, _) => format!(
            "{how} (reported only: the interval method propagates the initial set's bounding box)"
        ),
    }
}

/// The bound of `r1` over a box part, in words.
fn r1_over_box(boxes: R1Method, what: &str) -> String {
    match boxes {
        R1Method::Vertices { active } => format!(
            "max of |x0 - x*_0|_P over the vertices of {what} ({active} non-degenerate \
             coordinates)"
        ),
        R1Method::AbsoluteSum => format!(
            "sum_ij |P_ij| h_i h_j over {what} (more than {} coordinates)",
            reachc_core::engine::MAX_VERTEX_COORDS
        ),
    }
}

/// The bound of `r1` over balls jointly with the box part's vertices, in words.
fn r1_joint(balls: usize, boxes: R1Method) -> String {
    let vertices = match boxes {
        R1Method::Vertices { active: 0 } => String::new(),
        R1Method::Vertices { active } => {
            format!(" and the vertices of the box part ({active} non-degenerate coordinates)")
        }
        R1Method::AbsoluteSum => " and the box part".to_string(),
    };
    match (balls, boxes) {
        (1, R1Method::Vertices { active: 0 }) => "max of |x0 - x*_0|_P over the initial ball, \
                                                  exact: r sqrt(lambda_max(P, M)), certified by \
                                                  interval Cholesky"
            .to_string(),
        (1, _) => format!(
            "max of |x0 - x*_0|_P over the initial ball{vertices}, exact (S-lemma, one \
             multiplier per vertex, interval arithmetic)"
        ),
        (m, _) => format!(
            "upper bound of |x0 - x*_0|_P over the {m} initial balls{vertices} by the \
             S-procedure (one multiplier per ball; not exact in general)"
        ),
    }
}

/// A proved part, in words.
pub(super) fn proved(p: &Proved) -> String {
    match p {
        Proved::Constants { c, rho, provenance } => {
            let mut names = Vec::new();
            if *c {
                names.push("c");
            }
            names.push("sigma");
            if *rho {
                names.push("rho");
            }
            format!("constants {} ({provenance})", names.join(", "))
        }
        Proved::Inclusion(inclusion) => format!(
            "{} inclusion function of the drift on each face (outward-rounded interval \
             arithmetic)",
            inclusion.name()
        ),
        Proved::Kappa => "kappa (rounded up)".into(),
        Proved::Psi => {
            "Psi_t (exact per-step integration in interval arithmetic, upper end)".into()
        }
        Proved::Radii => "radii r1, R_t, r_t, PRS radius (interval arithmetic, rounded up)".into(),
        Proved::StochasticRadius => "r_t (interval arithmetic, rounded up)".into(),
        Proved::Margins { given } => format!(
            "safety margins given the {} (P^-1 enclosed by interval Cholesky, rounded down)",
            match given {
                Method::Contraction => "nominal",
                Method::Interval => "box",
            }
        ),
        Proved::TransformMaps { inverse_error } => format!(
            "the transformed drift T f(T^-1 y) (exact T^-1, coefficients folded without \
             rounding), the initial box in y = T x (interval hull of T X0) and the map back to x \
             (T^-1 enclosed entry-wise within {inverse_error:.1e} of the floating-point inverse)"
        ),
        Proved::ValidatedNominal { steps, ros2 } => format!(
            "nominal trajectory on {steps} validated steps (a cubic through RK4 nodes{}, its \
             defect bounded in interval arithmetic on each step and added to R_t through the \
             contraction rate): the sets hold over whole steps, not only at report times",
            match ros2 {
                0 => String::new(),
                k => format!(", ROS2 nodes on {k} steps where the model is stiff"),
            }
        ),
        Proved::ValidatedEmbedding { steps } => format!(
            "embedding system on {} (the comparison principle on each \
             step's hull, time as an interval): the boxes hold over whole steps, not only at \
             report times",
            count(*steps as u64, "validated step")
        ),
        Proved::LocalRates { regions, metric } => format!(
            "local rates on {}, each holding the tube over its step, so the process never \
             leaves them on the tube's event (metric {metric})",
            count(*regions as u64, "region")
        ),
        Proved::MapFactors {
            steps,
            metric,
            over_domain,
        } => format!(
            "discrete time: the map's image enclosed in interval arithmetic on each of {}, its \
             factor |R J R^-1|_2 and noise level bounded by verified eigenvalues on {} \
             (metric {metric})",
            count(*steps as u64, "step"),
            if *over_domain {
                "the domain (every state)"
            } else {
                "each step's box holding the tube, so the process never leaves them on the \
                 tube's event"
            }
        ),
        Proved::UnionOverSteps { steps } => format!(
            "at once over the steps: the union bound over {steps} steps at delta / {steps} \
             each: one event, of probability at least 1 - delta, for every step in [0, horizon]"
        ),
        Proved::UniformTube { epochs } => format!(
            "time-uniform tube: Ville's inequality on the averaged-MGF supermartingale over \
             {epochs} epochs at delta / {epochs} each: one event, of probability at least \
             1 - delta, for all t in [0, horizon]"
        ),
        Proved::ExactGaussian => "exact Gaussian: the system is affine with additive noise, so \
             X_t - x_t ~ N(0, Sigma_t); Sigma_t enclosed in interval arithmetic (Taylor series \
             with remainder), the chi-square quantile rounded up"
            .to_string(),
        Proved::GaussianMixture { epochs } => format!(
            "time-uniform Gaussian bound: Ville's inequality on the method-of-mixtures \
             martingale over {epochs} epochs at delta / {epochs} each (tighter here than the \
             averaged-MGF tube): one event, of probability at least 1 - delta, for all t in \
             [0, horizon]"
        ),
        Proved::LinearisedGaussian { epochs } => format!(
            "linearised Gaussian sets: the covariance of the linearisation along the nominal \
             (enclosed), the reflection principle for each coordinate's Gaussian martingale \
             over {epochs} epochs (one per internal step) at their share of delta, and the \
             linearisation's error bounded path by path on that event (interval Jacobians and \
             input Jacobians on a box holding the state, propagated by the linear flow)"
        ),
    }
}

/// A part that is not proved, in words.
pub(super) fn unproved(u: &Unproved) -> String {
    match u {
        Unproved::EmpiricalRate { paths } => rate_note(Rate::Empirical { paths: *paths }),
        Unproved::Nominal { integrator, step } => format!(
            "nominal trajectory x*_t (numerical {} integration, step {step}; taken as exact)",
            integrator.name()
        ),
        Unproved::Embedding { integrator, step } => format!(
            "time discretisation of the embedding system (numerical {} integration, step \
             {step}, no remainder bound): the box encloses the deterministic reachable set only \
             up to the integration error",
            integrator.name()
        ),
    }
}
