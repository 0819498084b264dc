//! The typed API on generated code: sweeps give the radius the box width fixes, trajectories
//! of the deterministic system under the forcing stay in the PRS, and what the constants do not
//! cover is refused.

use reach_api::{analysis, forced, forcing, start, sweep, Duffing};
use reachc_runtime::engine::{Problem, RunError};
use reachc_runtime::{InputPlan, Reach, System};

/// RK4 on `x' = f(x, u(t))` with `u` from the forcing plan, `steps` steps of `h`.
fn rk4(x: &mut [f64; 2], t0: f64, h: f64, steps: usize) {
    let plan = forcing();
    let f = |x: &[f64], t: f64| {
        let mut out = [0.0; 2];
        Duffing.drift(x, plan.at(t), t, &mut out);
        out
    };
    for k in 0..steps {
        let t = t0 + k as f64 * h;
        let k1 = f(x, t);
        let k2 = f(
            &[x[0] + 0.5 * h * k1[0], x[1] + 0.5 * h * k1[1]],
            t + 0.5 * h,
        );
        let k3 = f(
            &[x[0] + 0.5 * h * k2[0], x[1] + 0.5 * h * k2[1]],
            t + 0.5 * h,
        );
        let k4 = f(&[x[0] + h * k3[0], x[1] + h * k3[1]], t + h);
        for i in 0..2 {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
}

#[test]
fn a_sweep_of_equal_boxes_has_equal_initial_radii() {
    let reach = Reach::new(&Duffing, analysis::CONTRACTION).unwrap();
    let prs = sweep(&reach, &[-1.0, 0.0, 1.0]).unwrap();
    // r1 is the P-radius of the box about its centre: the same for boxes of the same widths
    // (up to the rounding of the widths x0 +- 0.1).
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs();
    assert!(prs.windows(2).all(|w| close(w[0].r1(), w[1].r1())));
    assert!(prs[0].r1() > 0.0);
    // Nominals differ; so do the stochastic radii: local rates are certified around each
    // tube, where the cubic spring's stiffness differs. Each is finite.
    let at5: Vec<_> = prs.iter().map(|p| p.at(5.0).unwrap()).collect();
    assert!(at5.iter().all(|s| s.r_t > 0.0 && s.prs_radius.is_finite()));
    assert!(at5[0].nominal()[0] < 0.0 && at5[2].nominal()[0] > 0.0);
}

#[test]
fn forced_trajectories_stay_in_the_prs() {
    let reach = Reach::new(&Duffing, analysis::CONTRACTION).unwrap();
    let prs = forced(&reach, 1.0).unwrap();
    let free = reach.from_box(&start(1.0)).unwrap();
    assert_eq!(prs.r2(), 0.0);
    let corners = [[0.9, -0.1], [0.9, 0.1], [1.1, -0.1], [1.1, 0.1], [1.0, 0.0]];
    for mut x in corners {
        let mut t = 0.0;
        for (k, st) in prs.steps().iter().enumerate().skip(1) {
            // 20 RK4 steps per report step: far below the PRS radius.
            rk4(&mut x, t, (st.t - t) / 20.0, 20);
            t = st.t;
            assert!(prs.contains_at(k, &x), "t = {t}: {x:?}");
            // Without the input uncertainty the deterministic set is smaller.
            assert!(st.det.radius() <= free.steps()[k].det.radius());
        }
    }
}

#[test]
fn what_the_constants_do_not_cover_is_refused() {
    let reach = Reach::new(&Duffing, analysis::CONTRACTION).unwrap();
    // The domain is x in [-2, 2]: local rates need no domain, so a box reaching 2.05 is not
    // refused; from there, without the domain's constants to lean on, the cubic spring's tube
    // outgrows its regions and the run says when (the global rate refuses the box outright).
    assert!(matches!(
        reach.from_box(&start(1.95)),
        Err(RunError::NonFinite(m))
            if matches!(*m.problem, Problem::LocalRates { t, .. } if (4.5..4.6).contains(&t))
    ));
    // The input box is [-0.05, 0.05].
    let strong = InputPlan::constant(&[0.1]);
    assert!(reach.from_box_with(&start(1.0), &strong).is_err());
    // The model data cannot be edited after generation (`ModelInfo` is sealed), nor paired
    // with another system: `Reach::new` takes the model, whose data it carries.
}
