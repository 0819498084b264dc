//! The names result files and Monte Carlo reports write for closed sets of choices (a method, a
//! shape, a status), as serde enums: `"contraction"`, `"p_ball"`, `"pass"`. Each is made from
//! the core's type it names (the same names as its `name()`).

use reachc_core::model;
use reachc_core::prs;
use reachc_core::simulate;
use serde::{Deserialize, Serialize};

/// How the deterministic sets were computed (`"contraction"` or `"interval"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// P-balls around the nominal trajectory.
    Contraction,
    /// Boxes (or parallelotopes) of an embedding system.
    Interval,
}

/// The interval method's inclusion function of the drift.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Inclusion {
    /// Natural inclusion.
    Natural,
    /// Jacobian-based (mean-value) inclusion.
    Jacobian,
    /// Mixed Jacobian, one column at a time.
    Mixed,
}

/// How the deterministic part is integrated in time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Validated steps.
    Validated,
    /// Classical Runge-Kutta of order 4, taken as exact.
    Rk4,
    /// Forward Euler, taken as exact.
    Euler,
}

/// Where a result's rates come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RateSource {
    /// Certified on regions holding the tube.
    Local,
    /// The compiler's constants.
    Global,
    /// Estimated from sample paths (not a guarantee).
    Empirical,
}

/// The stochastic radius rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Rule {
    /// The averaged-MGF bound.
    Amgf,
    /// Theorem 1 with a given eps.
    Paper,
    /// Theorem 1 with eps minimising the radius.
    PaperOptimal,
}

/// The time-uniform bound of a Gaussian result (`"amgf_tube"` or `"gaussian_mixture"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UniformBound {
    /// The AMGF tube.
    AmgfTube,
    /// The method-of-mixtures bound.
    GaussianMixture,
    /// The union bound over a discrete-time model's steps.
    UnionOverSteps,
}

/// Where a coordinate transform comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TransformSource {
    /// Written in the spec.
    Given,
    /// Chosen by the compiler.
    Auto,
}

/// The shape of a deterministic set (`"p_ball"`, `"box"`, `"parallelotope"` or
/// `"zonotope"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
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

/// The kind of an unsafe set (`"half_space"`, `"box"` or `"ball"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnsafeKind {
    /// `{x : a.x >= b}`.
    HalfSpace,
    /// A box.
    Box,
    /// A Euclidean ball.
    Ball,
}

/// What is shown of a goal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GoalStatus {
    /// Reached (and held, with `stay`).
    Reached,
    /// Not shown: it needs a time-uniform result.
    NeedsUniform,
    /// Not shown (`why` says why).
    NotShown,
}

/// Where the Euler-Maruyama steps of a Monte Carlo check came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DtSource {
    /// The rule (no `--dt`).
    Rule,
    /// The `--dt` option.
    Option,
    /// A discrete-time model's map, one step per step.
    Map,
}

/// How the Euler-Maruyama steps compare with the rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DtStatus {
    /// They meet it.
    Met,
    /// The rule's cap of steps per report interval bound.
    Capped,
    /// The `--dt` is coarser than the rule asks.
    Coarser,
}

/// How the inputs of the sample paths were drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InputMode {
    /// Uniform in the input box.
    Random,
    /// A random corner of the input box.
    Corners,
    /// The centre of the input box.
    Centre,
}

/// The outcome of a check (`"pass"` or `"fail"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Passed.
    Pass,
    /// Failed.
    Fail,
}

/// What the probability level of a PRS is about (`"uniform"` or `"pointwise"`; results written
/// before time-uniform tubes have none, and are pointwise).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Guarantee {
    /// One event for the whole horizon.
    Uniform,
    /// Each time separately.
    #[default]
    Pointwise,
}

/// What a result is within an intersection (`"metric"`, `"box"`, `"first_order"`,
/// `"linearised"`; none is written for the result itself).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// The analysis' own result.
    #[default]
    Own,
    /// A further metric's result, of the same method, at `delta / K`.
    Metric,
    /// The interval method's box of a contraction run.
    Box,
    /// The first-order sets (zonotopes plus a remainder ball).
    FirstOrder,
    /// The linearised Gaussian sets (zonotopes holding the stochastic part too).
    Linearised,
}

impl Role {
    /// The result itself (written without a `role`).
    pub fn is_own(&self) -> bool {
        *self == Role::Own
    }
}

/// The metric a deterministic set's radius is measured in: always the result's
/// (`"constants.metric"`; files may leave it out).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum MetricRef {
    /// `constants.metric`.
    #[default]
    #[serde(rename = "constants.metric")]
    Constants,
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

/// `From` impls of names: `$from => $to` for each variant.
macro_rules! from {
    ($($from:ty => $to:ident { $($pat:pat => $variant:ident),+ $(,)? })+) => {$(
        impl From<$from> for $to {
            fn from(v: $from) -> $to {
                match v { $($pat => $to::$variant),+ }
            }
        }
    )+};
}

from! {
    model::Method => Method {
        model::Method::Contraction => Contraction,
        model::Method::Interval => Interval,
    }
    model::Inclusion => Inclusion {
        model::Inclusion::Natural => Natural,
        model::Inclusion::Jacobian => Jacobian,
        model::Inclusion::Mixed => Mixed,
    }
    model::Integrator => Integrator {
        model::Integrator::Validated => Validated,
        model::Integrator::Rk4 => Rk4,
        model::Integrator::Euler => Euler,
    }
    model::Guarantee => Guarantee {
        model::Guarantee::Uniform => Uniform,
        model::Guarantee::Pointwise => Pointwise,
    }
    model::Rate => RateSource {
        model::Rate::Local => Local,
        model::Rate::Global => Global,
        model::Rate::Empirical { .. } => Empirical,
    }
    model::RadiusRule => Rule {
        model::RadiusRule::Amgf => Amgf,
        model::RadiusRule::Paper(_) => Paper,
        model::RadiusRule::PaperOptimal => PaperOptimal,
    }
    prs::UniformBound => UniformBound {
        prs::UniformBound::AmgfTube => AmgfTube,
        prs::UniformBound::Mixture => GaussianMixture,
        prs::UniformBound::UnionOverSteps => UnionOverSteps,
    }
    model::TransformSource => TransformSource {
        model::TransformSource::Given => Given,
        model::TransformSource::Auto(_) => Auto,
    }
    &prs::DetSet => Shape {
        prs::DetSet::Ball { .. } => PBall,
        prs::DetSet::Box { .. } => Box,
        prs::DetSet::Parallelotope { .. } => Parallelotope,
        prs::DetSet::Zonotope { .. } => Zonotope,
    }
    prs::UnsafeKind => UnsafeKind {
        prs::UnsafeKind::HalfSpace => HalfSpace,
        prs::UnsafeKind::Box => Box,
        prs::UnsafeKind::Ball => Ball,
    }
    prs::Role => Role {
        prs::Role::Own => Own,
        prs::Role::Metric => Metric,
        prs::Role::Box => Box,
        prs::Role::FirstOrder => FirstOrder,
        prs::Role::Linearised => Linearised,
    }
    simulate::DtSource => DtSource {
        simulate::DtSource::Rule => Rule,
        simulate::DtSource::Option => Option,
        simulate::DtSource::Map => Map,
    }
    simulate::InputMode => InputMode {
        simulate::InputMode::Random => Random,
        simulate::InputMode::Corners => Corners,
        simulate::InputMode::Centre => Centre,
    }
}

impl From<bool> for Status {
    /// `pass` if `passed`, else `fail`.
    fn from(passed: bool) -> Status {
        if passed {
            Status::Pass
        } else {
            Status::Fail
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{json, to_value};

    /// Each of `cases` is written as its core name `name`.
    fn written_as<C: Copy, S: From<C> + Serialize>(cases: &[C], name: fn(C) -> &'static str) {
        for &c in cases {
            assert_eq!(to_value(S::from(c)).unwrap(), json!(name(c)));
        }
    }

    /// Each name is the core's own (`name()`), so the files read as they always did.
    #[test]
    fn names_are_the_cores() {
        use model::{Guarantee as G, Inclusion as I, Integrator as N, RadiusRule as R, Rate};
        use simulate::{DtSource as D, InputMode as M};
        written_as::<_, Method>(
            &[model::Method::Contraction, model::Method::Interval],
            model::Method::name,
        );
        written_as::<_, Inclusion>(&[I::Natural, I::Jacobian, I::Mixed], I::name);
        written_as::<_, Integrator>(&[N::Validated, N::Rk4, N::Euler], N::name);
        written_as::<_, Guarantee>(&[G::Uniform, G::Pointwise], G::name);
        let rates = [Rate::Local, Rate::Global, Rate::Empirical { paths: 3 }];
        written_as::<_, RateSource>(&rates, Rate::name);
        for r in rates {
            assert_eq!(RateSource::from(r).name(), r.name());
        }
        written_as::<_, Rule>(&[R::Amgf, R::Paper(0.5), R::PaperOptimal], R::name);
        let roles = [
            prs::Role::Own,
            prs::Role::Metric,
            prs::Role::Box,
            prs::Role::FirstOrder,
            prs::Role::Linearised,
        ];
        written_as::<_, Role>(&roles, prs::Role::name);
        let kinds = [
            prs::UnsafeKind::HalfSpace,
            prs::UnsafeKind::Box,
            prs::UnsafeKind::Ball,
        ];
        written_as::<_, UnsafeKind>(&kinds, crate::report::result::unsafe_kind);
        written_as::<_, DtSource>(&[D::Rule, D::Option, D::Map], D::name);
        written_as::<_, InputMode>(&[M::Random, M::Corners, M::Centre], M::name);
        assert_eq!(
            to_value(MetricRef::Constants).unwrap(),
            json!("constants.metric")
        );
    }
}
