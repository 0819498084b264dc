//! The code `build.rs` generated from `specs/pendulum.sde` evaluates the spec's model.

use pendulum_buildrs::{analysis, Pendulum};
use reachc_runtime::Model;
use reachc_runtime::{Interval, System};

#[test]
fn drift_at_a_point_matches_the_closed_form() {
    let (theta, omega) = (0.1_f64, 0.2_f64);
    let mut f = [0.0; 2];
    Pendulum.drift(&[theta, omega], &[], 0.0, &mut f);
    let expected = [omega, 10.0 * theta.sin() - 20.0 * theta - 20.0 * omega];
    for (got, want) in f.iter().zip(expected) {
        assert!(
            (got - want).abs() <= 1e-14 * want.abs().max(1.0),
            "{f:?} vs {expected:?}"
        );
    }

    let x = [Interval::point(theta), Interval::point(omega)];
    let mut fi = [Interval::ZERO; 2];
    Pendulum.drift_interval(&x, &[], Interval::ZERO, &mut fi);
    for (i, v) in fi.iter().zip(f) {
        assert!(i.contains(v), "{i:?} does not enclose {v}");
        assert!(i.width() < 1e-12, "{i:?} is too wide");
    }
}

#[test]
fn sizes_and_diffusion_follow_the_spec() {
    assert_eq!((Pendulum.n(), Pendulum.p(), Pendulum.m()), (2, 0, 1));
    let mut g = [f64::NAN; 2];
    Pendulum.diffusion(&[0.3, -0.1], 0.0, &mut g);
    assert_eq!(g, [0.0, 0.1]);
}

#[test]
fn info_lists_the_analyses() {
    let info = Pendulum.info();
    assert_eq!(info.name(), "pendulum");
    assert_eq!(info.states(), ["theta", "omega"]);
    let names: Vec<&str> = info
        .analyses()
        .iter()
        .map(|a| a.spec.name.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "contraction",
            "interval",
            "paper_contraction",
            "paper_interval",
            "per_state",
            "per_state_uniform"
        ]
    );
    // The generated constants name them.
    assert_eq!(
        [
            analysis::CONTRACTION,
            analysis::PAPER_INTERVAL,
            analysis::PER_STATE_UNIFORM
        ],
        ["contraction", "paper_interval", "per_state_uniform"]
    );
}
