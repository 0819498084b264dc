//! The controller on the stochastic cart: one plan's guarantee against Monte Carlo (and the
//! untightened plan's failure, so the check can fail), and the closed loop.

use mpc::{closed_loop, violation, Cart, Planner, Plant, SPEED};
use reachc_runtime::engine::Constraint;
use reachc_runtime::Bounds;

/// From a state near the wall, the chosen plan held open-loop for the plan's whole second:
/// the fraction of 2,000 noisy runs that touch the wall or break the speed limit is at most
/// `delta = 0.05` (plus three standard deviations). The strongest force, whose nominal meets
/// the untightened constraints only, fails far more often.
#[test]
fn a_plan_meets_its_constraints_with_probability_one_minus_delta() {
    let sys = Cart;
    let planner = Planner::new(&sys, 21);
    let x = [0.6, 0.3];
    let plan = planner.plan(&sys, x).unwrap();
    assert!(plan.feasible);
    let rate = |force: f64| {
        let broke = (0..2000u64)
            .filter(|&seed| Plant::new(x, seed, 1e-3).run(&sys, force, 1.0))
            .count();
        broke as f64 / 2000.0
    };
    let chosen = rate(plan.force);
    let sd = (0.05 * 0.95 / 2000.0f64).sqrt();
    eprintln!(
        "force {}: {chosen} of the runs broke a constraint",
        plan.force
    );
    assert!(chosen <= 0.05 + 3.0 * sd, "{chosen}");
    // Against the plain constraints (no tightening), the strongest force whose nominal meets
    // them: the runs touch the wall often.
    let steps = planner.tightened(x).unwrap();
    let plain: Vec<_> = steps
        .iter()
        .map(|st| {
            let mut st = st.clone();
            st.constraints = vec![Constraint::Box(vec![(1, Bounds::new(-SPEED, SPEED))])];
            st.unsafe_sets = steps[0].unsafe_sets.clone();
            st
        })
        .collect();
    let strongest = (0..=20)
        .map(|i| -1.0 + 0.1 * f64::from(i))
        .rfind(|&f| violation(&sys, x, f, &plain).0 <= 0.0)
        .unwrap();
    assert!(strongest > plan.force);
    assert!(violation(&sys, x, strongest, &steps).0 > 0.0);
    let untightened = rate(strongest);
    eprintln!("force {strongest}: {untightened} of the runs broke a constraint");
    assert!(untightened > 0.2, "{untightened}");
}

/// 30 periods from rest: a feasible plan every period, no violation, and the cart settles
/// between the tightened wall's distance and the wall.
#[test]
fn the_closed_loop_approaches_the_tightened_wall() {
    let s = closed_loop(&Cart, 30, 7).unwrap();
    assert_eq!((s.periods, s.infeasible, s.violations), (30, 0, 0));
    let wall = s.walls[29];
    assert!(wall > 0.5 && wall < 0.8, "{wall}");
    let end = s.positions[29];
    assert!(end > 0.4 && end < 0.8, "{end}");
}
