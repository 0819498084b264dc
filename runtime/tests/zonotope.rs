//! Results with first-order zonotopes (`DetSet::Zonotope`), as the main sets and as a member
//! of an intersection: the JSON shape and its fields, the CSV and summary, the bounding boxes
//! and membership.

mod common;

use reachc_runtime::model::*;
use reachc_runtime::prs::{DetSet, Role};
use reachc_runtime::{report, Prs, Reach};
use reachc_test_support::models;
use reachc_test_support::rng::Lcg64;
use reachc_test_support::sets::zonotope_in_box;
use reachc_test_support::systems::Linear;

/// `dx = -x dt + 0.2 dW` in two states.
const DECAY: Linear = Linear {
    n: 2,
    a: -1.0,
    b: 0.0,
    s: 0.2,
};

/// The metric `P` and its inverse.
const P: [f64; 4] = [2.0, 0.5, 0.5, 1.0];
const P_INV: [f64; 4] = [1.0 / 1.75, -0.5 / 1.75, -0.5 / 1.75, 2.0 / 1.75];

/// Generators in units of the box's half-widths.
const GENS: [[f64; 2]; 2] = [[0.6, 0.3], [-0.3, 0.6]];

/// `|v|_P` and `sqrt(a' P^-1 a)`.
fn p_norm(v: &[f64]) -> f64 {
    (P[0] * v[0] * v[0] + 2.0 * P[1] * v[0] * v[1] + P[3] * v[1] * v[1]).sqrt()
}
fn dual_norm(a: &[f64]) -> f64 {
    (P_INV[0] * a[0] * a[0] + 2.0 * P_INV[1] * a[0] * a[1] + P_INV[3] * a[1] * a[1]).sqrt()
}

fn model() -> ModelInfo {
    let mut info = models::model(
        "decay",
        &["x", "y"],
        &["w1", "w2"],
        &[(0.9, 1.1), (-0.2, 0.2)],
    );
    for (name, method) in [("ball", Method::Contraction), ("boxes", Method::Interval)] {
        let constants = Constants::given(&info, P.to_vec(), -1.0, 0.3, 0.0);
        info.analyses_mut()
            .push(common::decay_analysis(name, method, Ok(constants)));
    }
    info
}

/// The interval run with each box replaced by the zonotope of [`GENS`] around its centre plus
/// a remainder of `0.5 r_t`.
fn zonotopes() -> Prs {
    let mut r = Reach::paired(&DECAY, &model(), "boxes")
        .unwrap()
        .run()
        .unwrap();
    for st in r.steps_mut() {
        let (lo, hi) = st.det.box_hull().unwrap();
        let (center, generators) = zonotope_in_box(lo, hi, &GENS);
        let reach: Vec<f64> = (0..2)
            .map(|i| (generators[i].abs() + generators[2 + i].abs()) * 1.000_000_1)
            .collect();
        let remainder = 0.5 * st.r_t;
        let radius = (p_norm(&generators[..2]) + p_norm(&generators[2..]) + remainder) * 1.000_001;
        st.prs_radius = (radius + st.r_t) * 1.000_001;
        st.det = DetSet::Zonotope {
            hull_lo: (0..2).map(|i| center[i] - reach[i]).collect(),
            hull_hi: (0..2).map(|i| center[i] + reach[i]).collect(),
            center,
            generators,
            remainder,
            radius,
        };
    }
    // Its own first-order member (the run's real one) would cut the synthetic sets.
    r.also_mut().clear();
    r.set_role(Role::FirstOrder);
    r
}

/// The contraction run's ball alone (without the interval box it may be cut by).
fn ball() -> Prs {
    let mut r = Reach::paired(&DECAY, &model(), "ball")
        .unwrap()
        .run()
        .unwrap();
    r.also_mut().clear();
    r
}

/// [`ball`] cut by [`zonotopes`] as the member of its intersection.
fn ball_cut_by_zonotopes() -> Prs {
    let mut r = ball();
    *r.also_mut() = vec![zonotopes()];
    r
}

fn csv(prs: &Prs) -> String {
    let mut out = Vec::new();
    report::write_csv(prs, &mut out).unwrap();
    String::from_utf8(out).unwrap()
}

/// The JSON `det_set` of a zonotope: its shape, hull, generators (one array each) and
/// remainder, no corners; a member's own steps are zonotopes. The CSV shows the hull and the
/// remainder; the summaries say what the sets are.
#[test]
fn zonotopes_render() {
    let z = zonotopes();
    let v: serde_json::Value = serde_json::from_str(&report::to_json(&z)).unwrap();
    let (st, det) = (&z.steps()[3], &v["steps"][3]["det_set"]);
    let DetSet::Zonotope {
        center,
        generators,
        remainder,
        hull_lo,
        hull_hi,
        radius,
    } = &st.det
    else {
        panic!("a zonotope")
    };
    assert_eq!(det["shape"], "zonotope");
    assert!(det.get("lo").is_none() && det.get("hi").is_none());
    assert_eq!(det["center"], serde_json::json!(center));
    assert_eq!(det["radius"], *radius);
    assert_eq!(det["remainder"], *remainder);
    assert!(*remainder > 0.0);
    assert_eq!(det["hull_lo"], serde_json::json!(hull_lo));
    assert_eq!(det["hull_hi"], serde_json::json!(hull_hi));
    assert_eq!(
        det["generators"],
        serde_json::json!([&generators[..2], &generators[2..]])
    );
    // The hull of the PRS: the zonotope's widened by (remainder + r_t) sqrt((P^-1)_ii).
    for i in 0..2 {
        let widen = (remainder + st.r_t) * P_INV[i * 3].sqrt();
        let lo = v["steps"][3]["prs_hull_lo"][i].as_f64().unwrap();
        let hi = v["steps"][3]["prs_hull_hi"][i].as_f64().unwrap();
        assert!(lo <= hull_lo[i] - widen && lo > hull_lo[i] - widen - 1e-12);
        assert!(hi >= hull_hi[i] + widen && hi < hull_hi[i] + widen + 1e-12);
    }
    let table = csv(&z);
    assert!(
        table.starts_with("t,x_lo,x_hi,y_lo,y_hi,remainder,r_t,psi\n"),
        "{table}"
    );
    let row3: Vec<f64> = table
        .lines()
        .nth(4)
        .unwrap()
        .split(',')
        .map(|c| c.parse().unwrap())
        .collect();
    assert_eq!(
        row3,
        [st.t, hull_lo[0], hull_hi[0], hull_lo[1], hull_hi[1], *remainder, st.r_t, st.psi]
    );
    let s = report::summary(&z);
    assert!(s.contains("first-order zonotopes"), "{s}");
    assert!(s.contains("PRS = zonotope (+) B_P(remainder + r_t)"), "{s}");
    assert!(s.contains("remainder") && s.contains("x [lo, hi]"), "{s}");
    assert!(!s.contains("boxes of the embedding system"), "{s}");

    let cut = ball_cut_by_zonotopes();
    let v: serde_json::Value = serde_json::from_str(&report::to_json(&cut)).unwrap();
    assert_eq!(v["steps"][3]["det_set"]["shape"], "p_ball");
    assert_eq!(v["also"][0]["steps"][3]["det_set"]["shape"], "zonotope");
    assert_eq!(v["also"][0]["role"], "first_order");
    assert!(v.get("role").is_none(), "the result itself has no role");
    assert_eq!(
        v["also"][0]["steps"][3]["det_set"]["generators"],
        serde_json::json!([&generators[..2], &generators[2..]])
    );
    let s = report::summary(&cut);
    assert!(s.contains("cut by the first-order zonotope"), "{s}");
    assert!(s.contains("(2 generators)"), "{s}");
    // A zonotope is not a further metric: the radius rule is at the full delta.
    assert!(!s.contains("several metrics"), "{s}");
    assert!(s.contains("kappa(n = 2, delta = 0.01)"), "{s}");
    // The CSV's bounding boxes are the intersection's.
    let table = csv(&cut);
    assert!(table.starts_with(
        "t,x,y,det_radius,r_t,psi,c,sigma,prs_radius,prs_x_lo,prs_x_hi,prs_y_lo,prs_y_hi\n"
    ));
}

/// `hull_at` is the zonotope's hull widened by `(remainder + r_t) sqrt((P^-1)_ii)` (rounded
/// outward), intersected with the ball's for the cut result; `contains_at` finds points
/// `c + G xi + w` built inside (`|xi| < 1`, `|w|_P` below `remainder + r_t`) inside, and
/// points beyond the PRS's support in some direction outside.
#[test]
fn zonotope_hulls_and_membership() {
    let (z, ball, cut) = (zonotopes(), ball(), ball_cut_by_zonotopes());
    let mut rng = Lcg64(7);
    let mut rnd = move || rng.range(-1.0, 1.0);
    let (mut inside, mut outside) = (0, 0);
    for (k, st) in z.steps().iter().enumerate() {
        let DetSet::Zonotope {
            center,
            generators,
            remainder,
            hull_lo,
            hull_hi,
            ..
        } = &st.det
        else {
            panic!("a zonotope")
        };
        let r = remainder + st.r_t;
        let hull = z.hull_at(k).unwrap();
        let ball_hull = ball.hull_at(k).unwrap();
        let both = cut.hull_at(k).unwrap();
        for i in 0..2 {
            let widen = r * P_INV[i * 3].sqrt();
            assert!(hull[i].lo <= hull_lo[i] - widen && hull[i].lo > hull_lo[i] - widen - 1e-12);
            assert!(hull[i].hi >= hull_hi[i] + widen && hull[i].hi < hull_hi[i] + widen + 1e-12);
            assert_eq!(both[i].lo, hull[i].lo.max(ball_hull[i].lo));
            assert_eq!(both[i].hi, hull[i].hi.min(ball_hull[i].hi));
        }
        let g = [&generators[..2], &generators[2..]];
        for _ in 0..200 {
            let xi = [rnd() * (1.0 - 1e-9), rnd() * (1.0 - 1e-9)];
            let dir = [rnd(), rnd()];
            let w = rnd().abs() * (1.0 - 1e-9) * r / p_norm(&dir);
            let x: Vec<f64> = (0..2)
                .map(|i| center[i] + xi[0] * g[0][i] + xi[1] * g[1][i] + w * dir[i])
                .collect();
            assert!(z.contains_at(k, &x), "k = {k}: {x:?}");
            assert_eq!(cut.contains_at(k, &x), ball.contains_at(k, &x));
            inside += 1;
            // Beyond the support in direction a by a relative 1e-6.
            let a = [rnd(), rnd()];
            let dot = |v: &[f64]| a[0] * v[0] + a[1] * v[1];
            let support = dot(center) + dot(g[0]).abs() + dot(g[1]).abs() + r * dual_norm(&a);
            let t = (support * (1.0 + 1e-6) + 1e-9 - dot(center)) / (a[0] * a[0] + a[1] * a[1]);
            let y: Vec<f64> = (0..2).map(|i| center[i] + t * a[i]).collect();
            assert!(
                !z.contains_at(k, &y) && !cut.contains_at(k, &y),
                "k = {k}: {y:?}"
            );
            outside += 1;
        }
    }
    assert_eq!(
        (inside, outside),
        (200 * z.steps().len(), 200 * z.steps().len())
    );
}
