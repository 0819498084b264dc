//! Runtime for `reachc`-generated crates: the core (`reachc-core`: intervals, the [`System`]
//! trait, the data model, the engines and their typed results, Monte Carlo) re-exported, plus
//! the renderings of results (feature `report`: JSON, CSV, text), parallel Monte Carlo (feature
//! `simulate`) and the `main` of generated binaries (feature `app`).
//!
//! A generated model is a type implementing [`System`] and [`Model`], whose
//! [`Model::info`] is its [`ModelInfo`] (sets, analyses and the constants the compiler
//! certified). [`Reach`] runs one of its analyses from any initial set inside what the
//! constants were certified for, and returns a typed [`Prs`]:
//!
//! ```
//! use reachc_runtime::{Bounds, Reach};
//! # use reachc_runtime::model::*;
//! # use reachc_runtime::{Interval, Model, ModelInfo, System};
//! # // What `reachc build` generates for `dx = -x dt + 0.5 dW` (by hand here, with constants
//! # // given by hand instead of certified by the compiler).
//! # struct Decay;
//! # impl System for Decay {
//! #     fn n(&self) -> usize { 1 }
//! #     fn p(&self) -> usize { 0 }
//! #     fn m(&self) -> usize { 1 }
//! #     fn drift(&self, x: &[f64], _: &[f64], _: f64, out: &mut [f64]) { out[0] = -x[0] }
//! #     fn drift_interval(&self, x: &[Interval], _: &[Interval], _: Interval, out: &mut [Interval]) { out[0] = -x[0] }
//! #     fn jac_x(&self, _: &[f64], _: &[f64], _: f64, out: &mut [f64]) { out[0] = -1.0 }
//! #     fn jac_x_interval(&self, _: &[Interval], _: &[Interval], _: Interval, out: &mut [Interval]) { out[0] = Interval::point(-1.0) }
//! #     fn jac_u(&self, _: &[f64], _: &[f64], _: f64, _: &mut [f64]) {}
//! #     fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, _: &mut [Interval]) {}
//! #     fn diffusion(&self, _: &[f64], _: f64, out: &mut [f64]) { out[0] = 0.5 }
//! #     fn diffusion_interval(&self, _: &[Interval], _: Interval, out: &mut [Interval]) { out[0] = Interval::point(0.5) }
//! # }
//! # fn info() -> ModelInfo {
//! #     let parts = ModelParts {
//! #         name: "decay".into(), states: vec!["x".into()], inputs: vec![], noises: vec!["w".into()],
//! #         input_box: vec![], initial: InitialSet::from_box(&[Bounds::new(0.9, 1.1)]),
//! #         domain: vec![Bounds::ENTIRE], has_domain: false, affine: false, constant_diffusion: false, time: Default::default(), unsafe_sets: vec![], goals: vec![], analyses: vec![],
//! #     };
//! #     let constants = Constants::given(&ModelInfo::from_parts(parts.clone()), vec![1.0], -1.0, 0.5, 0.0);
//! #     let spec = AnalysisSpec { name: "contraction".into(), horizon: 2.0, ..AnalysisSpec::default() };
//! #     ModelInfo::from_parts(ModelParts { analyses: vec![Analysis { spec, constants: Ok(constants) }], ..parts })
//! # }
//! # impl Model for Decay {
//! #     fn info(&self) -> &ModelInfo {
//! #         static INFO: std::sync::OnceLock<ModelInfo> = std::sync::OnceLock::new();
//! #         INFO.get_or_init(info)
//! #     }
//! # }
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // Checks the analysis and its constants once.
//! let reach = Reach::new(&Decay, "contraction")?;
//! let mut radii = Vec::new();
//! for x0 in [0.5, 1.0, 2.0] {
//!     let prs = reach.from_box(&[Bounds::new(x0 - 0.1, x0 + 0.1)])?;
//!     // The PRS at t = 1: a P-ball around the nominal state, holding X_1 with probability
//!     // at least 1 - delta.
//!     let at_1 = prs.at(1.0).expect("t = 1 is a report time");
//!     radii.push(at_1.prs_radius);
//!     // Membership is decided soundly (a point within rounding of the boundary is outside).
//!     assert_eq!(prs.contains(at_1.nominal(), 1.0), Some(true));
//!     assert_eq!(prs.contains(&[x0 + 10.0], 1.0), Some(false));
//!     // A rigorous bounding box of the same set.
//!     let hull = prs.hull(1.0).unwrap();
//!     assert!(hull[0].lo < at_1.nominal()[0] && at_1.nominal()[0] < hull[0].hi);
//! }
//! // Boxes of the same width: about the same radius wherever they start (a linear drift), up
//! // to the bound on the validated nominal's defect, which the engine keeps near 1% of the PRS.
//! assert!(radii.windows(2).all(|w| (w[0] - w[1]).abs() < 0.02 * w[0]));
//! # Ok(())
//! # }
//! ```
//!
//! What the constants were certified for cannot be changed through [`Reach`]: an initial set
//! outside the spec's domain or an input plan outside its input box is an error, and a
//! [`ModelInfo`] edited after generation (another domain or input box) is refused.

pub use reachc_core::{
    engine, func, interval, kappa, lanes, model, probability, prs, simulate, system, table,
};
pub use reachc_core::{Bounds, InputPlan, Interval, Model, ModelInfo, Prs, Reach, System, X8};

#[cfg(feature = "app")]
pub mod app;
#[cfg(feature = "app")]
pub mod failure;
mod include;
#[cfg(feature = "app")]
pub mod merge;
#[cfg(feature = "app")]
pub mod output;
#[cfg(feature = "report")]
pub mod report;
