//! Moving unsafe and goal sets (method.md 8.15): the margins against those of the same set held
//! fixed, the certified probability of safety against the closed form of a Brownian motion
//! crossing a moving line, tables against the same motion written with `t`, and the tightened
//! sets of a moving obstacle.

use reachc_e2e::{inline, shipped, upper_quantile};
use reachc_runtime::model::{Slot, UnsafeShape};
use reachc_runtime::probability::SafetyLimit;
use reachc_runtime::prs::GoalOutcome;
use reachc_runtime::Reach;

/// `x' = 0` with noise `0.5 dW` from 0 (a Brownian motion), the unsafe set `SET`, horizon 1,
/// step 0.1; with the goal `GOAL` if given.
fn brownian(set: &str, goal: &str) -> String {
    format!(
        "model bm\nstate x = 0\nnoise w\ndrift {{ x' = 0 }}\ndiffusion {{ x: 0.5 * w }}\n\
         unsafe wall halfspace {{ {set} }}\n{goal}\n\
         analysis a {{ method = contraction  delta = 0.1  horizon = 1  step = 0.1 }}\n"
    )
}

/// `P(Phi)`: the standard normal distribution function, from the upper tail.
fn phi(x: f64) -> f64 {
    // `Q(z)` for `z >= 1` by its continued fraction (reachc_e2e), else by symmetry and a
    // series: only the values used below are needed to 1e-9.
    let series = |z: f64| {
        // 0.5 + phi(z) (z - z^3/6 + z^5/40 - ...) for |z| < 1 (the Taylor series of the
        // integral of the density).
        let mut term = z;
        let mut sum = z;
        for k in 1..60 {
            term *= -z * z / (2.0 * k as f64);
            sum += term / (2 * k + 1) as f64;
        }
        0.5 + sum / (2.0 * std::f64::consts::PI).sqrt()
    };
    if x.abs() < 1.0 {
        series(x)
    } else if x > 0.0 {
        1.0 - reachc_e2e::normal_tail(x)
    } else {
        reachc_e2e::normal_tail(-x)
    }
}

/// The wall `x >= 1 + 0.5 t` moves away: at each report interval `[t_(k-1), t_k]` the result
/// checks it where it is nearest, `x >= 1 + 0.5 t_(k-1)` (rounded down), so each margin is the
/// fixed wall's `x >= 1` plus `0.5 t_(k-1)` (the deterministic set and radius are the same).
#[test]
fn a_moving_wall_is_checked_where_it_is_nearest_over_each_interval() {
    let (sys, info) = inline(&brownian("x >= 1 + 0.5 * t", ""));
    assert_eq!(info.unsafe_sets()[0].moving[0].slot, Slot::Offset);
    let moving = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let (fixed_sys, fixed_info) = inline(&brownian("x >= 1", ""));
    let fixed = Reach::paired(&fixed_sys, &fixed_info, "a")
        .unwrap()
        .run()
        .unwrap();
    let swept = &moving.unsafe_sets()[0].swept;
    assert_eq!(swept.len(), moving.steps().len());
    assert!(fixed.unsafe_sets()[0].swept.is_empty());
    for (k, (m, f)) in moving.steps().iter().zip(fixed.steps()).enumerate() {
        let nearest = if k == 0 { 0.0 } else { moving.steps()[k - 1].t };
        let UnsafeShape::HalfSpace { offset, .. } = swept[k] else {
            panic!("{:?}", swept[k])
        };
        let exact = 1.0 + 0.5 * nearest;
        assert!(
            offset <= exact && offset >= exact - 1e-15,
            "step {k}: {offset}"
        );
        let gained = m.margins[0] - f.margins[0];
        assert!(
            (gained - 0.5 * nearest).abs() < 1e-12,
            "step {k}: {gained} vs {}",
            0.5 * nearest
        );
    }
}

/// The certified probability of safety against the exact one: `P(exists s <= 1: 0.5 W_s >= 1 +
/// 0.5 s) = 1 - Phi(3) + exp(-4) Phi(-1)` (Bachelier-Levy). The bound is never below it.
#[test]
fn the_probability_of_safety_holds_against_the_moving_line_crossing() {
    let (sys, info) = inline(&brownian("x >= 1 + 0.5 * t", ""));
    let p = Reach::paired(&sys, &info, "a")
        .unwrap()
        .safety_probability()
        .unwrap();
    let delta = p.delta.expect("a bound");
    let exact = 1.0 - phi(3.0) + (-4.0f64).exp() * phi(-1.0);
    assert!((exact - 4.25577e-3).abs() < 1e-8, "{exact}");
    eprintln!(
        "certified {delta:.4e}, exact {exact:.4e} (ratio {:.1}, {} runs)",
        delta / exact,
        p.runs
    );
    assert!(delta >= exact, "{delta} < {exact}");
    assert_eq!(p.limit, SafetyLimit::Resolution);
    // A wall that stays at 1 is crossed more often: a smaller certified probability of safety
    // (a larger delta), or none.
    let (fixed_sys, fixed_info) = inline(&brownian("x >= 1", ""));
    let fixed = Reach::paired(&fixed_sys, &fixed_info, "a")
        .unwrap()
        .safety_probability()
        .unwrap();
    assert!(fixed.delta.is_none_or(|d| d > delta), "{fixed:?}");
    // (The sanity of `phi`: the two-sided 95% point.)
    assert!((phi(upper_quantile(0.025)) - 0.975).abs() < 1e-9);
}

/// A goal that moves right, `x in [-2 + t, 2 + t]`: held inside all its positions at each
/// report time, its margins are the fixed goal's `[-2, 2]` less `t` (the PRS is symmetric about
/// 0), and it is reached in its window.
#[test]
fn a_moving_goal_is_reached_where_it_is() {
    let goal = |g: &str| {
        brownian(
            "x >= 3",
            &format!("goal home box {{ x in {g} }} within [0.5, 1]"),
        )
    };
    let (sys, info) = inline(&goal("[-2 + t, 2 + t]"));
    let moving = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let (fixed_sys, fixed_info) = inline(&goal("[-2, 2]"));
    let fixed = Reach::paired(&fixed_sys, &fixed_info, "a")
        .unwrap()
        .run()
        .unwrap();
    let (gm, gf) = (&moving.goals()[0], &fixed.goals()[0]);
    assert_eq!(gm.swept.len(), moving.steps().len());
    for (k, st) in moving.steps().iter().enumerate() {
        let UnsafeShape::Box(sides) = &gm.swept[k][0] else {
            panic!()
        };
        let b = sides[0].1;
        assert!(
            b.lo >= -2.0 + st.t && b.lo <= -2.0 + st.t + 1e-15,
            "{k}: {b:?}"
        );
        assert!(
            b.hi <= 2.0 + st.t && b.hi >= 2.0 + st.t - 1e-15,
            "{k}: {b:?}"
        );
        let lost = gf.margins[k] - gm.margins[k];
        assert!((lost - st.t).abs() < 1e-12, "step {k}: {lost} vs {}", st.t);
    }
    assert!(
        matches!(gm.outcome, GoalOutcome::Reached { .. }),
        "{:?}",
        gm.outcome
    );
}

/// A table column that samples a line gives the same sets as the line written with `t`
/// (interpolation is exact on a line, up to rounding).
#[test]
fn a_table_moves_a_set_as_the_same_expression_of_t_does() {
    let dir = std::env::temp_dir().join(format!("reachc-moving-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("wall.csv"), "t,at\n0,1\n0.5,1.25\n1,1.5\n").unwrap();
    let spec = brownian("x >= path.at", "").replace(
        "noise w\n",
        &format!(
            "noise w\ntable path = csv(\"{}\")\n",
            dir.join("wall.csv").display()
        ),
    );
    let (sys, info) = inline(&spec);
    let table = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let (line_sys, line_info) = inline(&brownian("x >= 1 + 0.5 * t", ""));
    let line = Reach::paired(&line_sys, &line_info, "a")
        .unwrap()
        .run()
        .unwrap();
    for (k, (a, b)) in table.steps().iter().zip(line.steps()).enumerate() {
        assert!((a.margins[0] - b.margins[0]).abs() < 1e-12, "step {k}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The shipped overtaking spec: the lead vehicle's box moves with its recorded path, the
/// certified probability of safety is a real number, and the tightening inflates the box where
/// the result held it at each report interval.
#[test]
fn the_overtaking_spec_avoids_the_moving_lead_vehicle() {
    let (sys, info) = shipped("overtake.sde");
    assert!(info.has_moving_sets());
    let reach = Reach::paired(&sys, &info, "contraction").unwrap();
    let prs = reach.run().unwrap();
    assert!(
        prs.unsafe_sets().iter().all(|u| u.safe),
        "{:?}",
        prs.verdict()
    );
    assert!(matches!(
        prs.goals()[0].outcome,
        GoalOutcome::Reached { .. }
    ));
    // The box follows the lead: its lower end in `s` grows by about 15 m/s.
    let lo = |k: usize| match &prs.unsafe_sets()[0].swept[k] {
        UnsafeShape::Box(sides) => sides[0].1.lo,
        other => panic!("{other:?}"),
    };
    let (first, last) = (lo(1), lo(prs.steps().len() - 1));
    assert!(
        ((last - first) / (7.0 - 0.05) - 15.0).abs() < 0.5,
        "{first} .. {last}"
    );
    let t = reach.tighten(&prs, &[]).unwrap();
    for (k, st) in t.steps.iter().enumerate() {
        let UnsafeShape::Box(sides) = &st.unsafe_sets[0].shape else {
            panic!()
        };
        assert!(sides[0].1.lo <= lo(k), "step {k}");
    }
}
