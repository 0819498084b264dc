//! Results the tests of the checks share: a small linear system's results of both methods,
//! turned into parallelotopes and zonotopes.

use crate::engine;
use crate::interval::Interval;
use crate::model::*;
use crate::prs::{DetSet, Prs, TransformUsed};
use crate::sets::zonotope;
use crate::system::System;
use crate::test_support::models::model;
use crate::test_support::sets::zonotope_in_box;

/// `dx = A x dt + 0.2 dW` with a non-symmetric stable `A`.
struct Sys;

const A: [f64; 4] = [-1.0, 0.5, -0.3, -0.8];

impl System for Sys {
    fn n(&self) -> usize {
        2
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        2
    }
    fn drift(&self, x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = A[0] * x[0] + A[1] * x[1];
        out[1] = A[2] * x[0] + A[3] * x[1];
    }
    fn drift_interval(&self, x: &[Interval], _u: &[Interval], _t: Interval, o: &mut [Interval]) {
        let p = Interval::point;
        o[0] = p(A[0]) * x[0] + p(A[1]) * x[1];
        o[1] = p(A[2]) * x[0] + p(A[3]) * x[1];
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&A);
    }
    fn jac_x_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, o: &mut [Interval]) {
        for (o, a) in o.iter_mut().zip(A) {
            *o = Interval::point(a);
        }
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(&self, _x: &[Interval], _u: &[Interval], _t: Interval, _o: &mut [Interval]) {}
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.2, 0.0, 0.0, 0.2]);
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, o: &mut [Interval]) {
        for (o, g) in o.iter_mut().zip([0.2, 0.0, 0.0, 0.2]) {
            *o = Interval::point(g);
        }
    }
}

/// The result of `method` with `metric`; `members`: with the members of its intersection
/// (a contraction run's interval box, method.md 8.7), else its own set alone.
pub(super) fn result(method: Method, metric: Vec<f64>, members: bool) -> Prs {
    let info = model("m", &["x", "y"], &["w1", "w2"], &[(0.9, 1.1), (-0.1, 0.2)]);
    let analysis = Analysis {
        spec: AnalysisSpec {
            name: "a".into(),
            method,
            delta: 0.01,
            horizon: 1.0,
            step: 0.1,
            ..AnalysisSpec::default()
        },
        // Valid for P = I and for the skewed P below (generous c, sigma).
        constants: Ok(Constants::given(&info, metric, -0.2, 0.5, 0.0)),
    };
    let mut r = engine::run_paired(&Sys, &info, &analysis).unwrap();
    if members {
        assert!(!r.also.is_empty(), "{method:?}: an intersection");
    } else {
        r.also.clear();
    }
    r
}

/// The interval method's box result turned into a parallelotope `{x : lo <= T x <= hi}`
/// inside each box (the pendulum's `T`), so that the box's enclosing P-ball still holds it.
pub(super) fn parallelotope(metric: Vec<f64>) -> Prs {
    let mut r = result(Method::Interval, metric, false);
    let t = [[1.0, 0.2], [1.0, 0.0]];
    r.transform = Some(TransformUsed {
        matrix: t.concat(),
        inverse: vec![0.0, 1.0, 5.0, -5.0],
        inverse_error: 1e-15,
        source: TransformSource::Given,
    });
    for st in &mut r.steps {
        let DetSet::Box {
            lo,
            hi,
            center,
            radius,
        } = st.det.clone()
        else {
            panic!("a box")
        };
        // T^-1 = [[0, 1], [5, -5]] maps a y-box of half-width e into x within 10 e.
        let e = (0..2).map(|i| hi[i] - lo[i]).fold(f64::INFINITY, f64::min) / 40.0;
        let y: Vec<f64> = t
            .iter()
            .map(|row| row[0] * center[0] + row[1] * center[1])
            .collect();
        st.det = DetSet::Parallelotope {
            lo: y.iter().map(|v| v - e).collect(),
            hi: y.iter().map(|v| v + e).collect(),
            hull_lo: lo,
            hull_hi: hi,
            center,
            radius,
        };
    }
    r
}

/// Generators of [`zonotope`] in units of the box's half-widths: two (a basis), three (a
/// basis among them) and one (a flat zonotope: no basis).
pub(in crate::simulate) const SQUARE: &[[f64; 2]] = &[[0.6, 0.3], [-0.3, 0.6]];
const THREE: &[[f64; 2]] = &[[0.5, 0.2], [-0.2, 0.5], [0.2, -0.25]];
const FLAT: &[[f64; 2]] = &[[0.7, 0.5]];

/// The interval method's box result with each box replaced by a zonotope around its centre
/// (generators `gens` in units of the box's half-widths, so inside the box) plus a
/// remainder of `remainder r_t`, with the radii that hold it.
fn zonotope(metric: Vec<f64>, gens: &[[f64; 2]], remainder: f64) -> Prs {
    boxes_to_zonotopes(result(Method::Interval, metric, false), gens, remainder)
}

/// [`zonotope`] of any box result `r` in two states.
pub(in crate::simulate) fn boxes_to_zonotopes(
    mut r: Prs,
    gens: &[[f64; 2]],
    remainder: f64,
) -> Prs {
    let p = r.constants.metric.clone();
    for st in &mut r.steps {
        let (lo, hi) = st.det.box_hull().expect("a box");
        let (center, generators) = zonotope_in_box(lo, hi, gens);
        let (hull_lo, hull_hi) = zonotope::hull(&center, &generators);
        let remainder = remainder * st.r_t;
        let up = |a: f64, b: f64| (Interval::point(a) + Interval::point(b)).hi();
        let radius = up(zonotope::p_radius(&p, 2, &generators), remainder);
        st.prs_radius = up(radius, st.r_t);
        st.det = DetSet::Zonotope {
            center,
            generators,
            remainder,
            hull_lo,
            hull_hi,
            radius,
        };
    }
    r
}

/// Zonotope results for `metric`: [`zonotope`] with each set of generators (the three
/// generators' also with the initial box at `t = 0`), and the contraction method's ball cut
/// by a zonotope member (an intersection).
pub(super) fn zonotopes(metric: &[f64]) -> Vec<(&'static str, Prs)> {
    let mut cut = result(Method::Contraction, metric.to_vec(), false);
    cut.also.push(zonotope(metric.to_vec(), SQUARE, 0.3));
    let mut boxed = zonotope(metric.to_vec(), THREE, 0.5);
    boxed.steps[0] = result(Method::Interval, metric.to_vec(), false).steps[0].clone();
    vec![
        ("square", zonotope(metric.to_vec(), SQUARE, 0.5)),
        ("box at t = 0", boxed),
        ("three", zonotope(metric.to_vec(), THREE, 0.2)),
        ("flat", zonotope(metric.to_vec(), FLAT, 1.0)),
        ("member", cut),
    ]
}

/// Both methods, each with the identity and a skewed metric; the contraction method's
/// set alone and as the intersection with its interval box (`true`).
pub(super) fn methods_and_metrics() -> [(Method, Vec<f64>, bool); 6] {
    let (identity, skewed) = (vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]);
    [
        (Method::Contraction, identity.clone(), false),
        (Method::Contraction, skewed.clone(), false),
        (Method::Contraction, identity.clone(), true),
        (Method::Contraction, skewed.clone(), true),
        (Method::Interval, identity, false),
        (Method::Interval, skewed, false),
    ]
}
