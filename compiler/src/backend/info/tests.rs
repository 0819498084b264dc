//! The constants of discrete-time analyses: nothing certified, the metric given or the Stein
//! solution for the map's Jacobian at the initial set's centre.

use std::path::Path;

use nalgebra::DMatrix;
use reachc_core::model::{Bounds, Constants, MetricRegion, Provenance};

use super::prepare;
use crate::driver::check_source;

/// The map `x1 = 0.8 x1 + 0.3 x2 + 0.1 sin(x1)`, `x2 = -0.1 x1 + 0.7 x2 + u`: its Jacobian at
/// the initial set's centre `(0, 1)` is `[[0.9, 0.3], [-0.1, 0.7]]` (spectral radius 0.8).
const MAP: &str = "model map
discrete { period = 0.5 }
state x1 in [-1, 1]
state x2 in [0, 2]
input u in [-0.1, 0.1]
noise w
update {
    x1 = 0.8 * x1 + 0.3 * x2 + 0.1 * sin(x1)
    x2 = -0.1 * x1 + 0.7 * x2 + u
}
diffusion { x2: 0.1 * w }
";

/// The constants of each analysis of `MAP` followed by `analyses`.
fn constants(analyses: &str) -> Vec<Constants> {
    let (model, diags) = check_source(&format!("{MAP}{analyses}"), Path::new("."));
    assert!(diags.is_empty(), "{diags:#?}");
    let prepared = prepare(&mut model.expect("checks"));
    assert!(prepared.warnings.is_empty(), "{:#?}", prepared.warnings);
    assert!(!prepared.info.affine());
    prepared
        .info
        .analyses()
        .iter()
        .map(|a| a.constants.clone().expect("constants"))
        .collect()
}

#[test]
fn nothing_is_certified_for_a_map() {
    let all = constants(
        "analysis a { horizon = 2 }\nanalysis b { horizon = 1  metric = [[1, 0], [0, 4]] }",
    );
    for (c, horizon) in all.iter().zip([2.0, 1.0]) {
        assert_eq!(*c.provenance(), Provenance::Map);
        assert_eq!(c.metric_region(), MetricRegion::Given);
        assert!(c.c().is_infinite() && c.sigma().is_infinite() && c.rho().is_infinite());
        assert_eq!(c.region().time, Bounds::new(0.0, horizon));
        assert_eq!(c.region().input_box, [Bounds::new(-0.1, 0.1)]);
        assert!(c.also().is_empty() && c.alternatives().is_empty());
    }
    assert_eq!(all[0].metric(), [1.0, 0.0, 0.0, 1.0]);
    // Scaled by a power of two to a largest entry in [1, 2), as every given metric.
    assert_eq!(all[1].metric(), [0.25, 0.0, 0.0, 1.0]);
}

/// `metric = auto`: `A' P A - P = -s I` to 1e-9 relative, for `A` the Jacobian at the centre
/// and `s > 0` the power of two that scaled `P` to a largest entry in `[1, 2)`.
#[test]
fn auto_metric_solves_the_stein_equation() {
    let [c] = constants("analysis a { horizon = 2  metric = auto }")
        .try_into()
        .unwrap();
    assert_eq!(c.metric_region(), MetricRegion::Map);
    let p = DMatrix::from_row_slice(2, 2, c.metric());
    let largest = p.amax();
    assert!((1.0..2.0).contains(&largest), "{p}");
    assert_eq!(p[(0, 1)], p[(1, 0)]);
    let a = DMatrix::from_row_slice(2, 2, &[0.9, 0.3, -0.1, 0.7]);
    let lhs = a.transpose() * &p * &a - &p;
    let s = -lhs[(0, 0)];
    assert!(s > 0.0 && (s.log2() - s.log2().round()).abs() < 1e-9, "{s}");
    let residual = (lhs + DMatrix::identity(2, 2) * s).amax();
    assert!(residual <= 1e-9 * largest, "{residual} {p}");
}

/// A map that does not contract at the centre: the identity, given.
#[test]
fn auto_metric_of_an_expanding_map_is_the_identity() {
    let src = "model grow\ndiscrete { period = 1 }\nstate x in [0, 1]\nupdate { x = 1.5 * x }\n\
               analysis a { horizon = 3  metric = auto }";
    let (model, diags) = check_source(src, Path::new("."));
    assert!(diags.is_empty(), "{diags:#?}");
    let prepared = prepare(&mut model.unwrap());
    assert!(prepared.info.affine());
    let c = prepared.info.analyses()[0].constants.clone().unwrap();
    assert_eq!(c.metric(), [1.0]);
    assert_eq!(c.metric_region(), MetricRegion::Given);
    assert_eq!(*c.provenance(), Provenance::Map);
}

/// An affine map with additive noise: `metric = auto` is `s Sigma_K^-1`, the inverse of the
/// deviation's covariance after the horizon's `K = 3` steps (`s` the power of two scaling it),
/// so the exact Gaussian set at the horizon is the chi-square ellipsoid itself.
#[test]
fn auto_metric_of_an_affine_map_is_its_covariance_at_the_horizon() {
    let src = "model ar\ndiscrete { period = 0.5 }\nstate x1 in [-1, 1]\nstate x2 = 0\n\
               noise w[1..2]\nupdate {\n    x1 = 0.9 * x1 + 0.2 * x2\n    x2 = 0.5 * x2\n}\n\
               diffusion {\n    x1: 0.1 * w[1]\n    x2: 0.3 * w[2]\n}\n\
               analysis a { horizon = 1.5  metric = auto }";
    let (model, diags) = check_source(src, Path::new("."));
    assert!(diags.is_empty(), "{diags:#?}");
    let prepared = prepare(&mut model.unwrap());
    assert!(prepared.info.affine());
    let c = prepared.info.analyses()[0].constants.clone().unwrap();
    assert_eq!(c.metric_region(), MetricRegion::Map);
    let a = DMatrix::from_row_slice(2, 2, &[0.9, 0.2, 0.0, 0.5]);
    let w = DMatrix::from_row_slice(2, 2, &[0.01, 0.0, 0.0, 0.09]);
    let mut sigma = DMatrix::<f64>::zeros(2, 2);
    for _ in 0..3 {
        sigma = &a * &sigma * a.transpose() + &w;
    }
    let product = DMatrix::from_row_slice(2, 2, c.metric()) * sigma;
    let s = product[(0, 0)];
    assert!(s > 0.0 && (s.log2() - s.log2().round()).abs() < 1e-9, "{s}");
    let residual = (product - DMatrix::identity(2, 2) * s).amax();
    assert!(residual <= 1e-9 * s, "{residual}");
}
