//! Goal sets (method.md 8.13): reach-avoid and reach-and-stay verdicts and their certified
//! probabilities, against closed forms (a noise-free flow's containment margins, the exact
//! Gaussian law of an Ornstein-Uhlenbeck process at the reach time) and sample paths.

use reachc_e2e::{inline, normal_tail};
use reachc_runtime::probability::GoalLimit;
use reachc_runtime::prs::{GoalMiss, GoalOutcome, Prs};
use reachc_runtime::Reach;
use reachc_test_support::flow::euler_maruyama;
use reachc_test_support::rng::Rng;

fn run(src: &str, analysis: &str) -> Prs {
    let (sys, info) = inline(src);
    Reach::paired(&sys, &info, analysis).unwrap().run().unwrap()
}

/// `x' = -x` from `[0.9, 1.1]` (noise 1e-6): the PRS's box tops out at `1.1 e^-t`, so the goal
/// `|x| <= 0.5`'s margin is at most `0.5 - 1.1 e^-t` (and within 1e-3 of it), and the goal is
/// first shown reached at the first report time after `ln 2.2 = 0.7885`.
#[test]
fn margins_and_the_first_time_follow_the_flow() {
    let prs = run(
        "model decay\nstate x in [0.9, 1.1]\nnoise w\ndrift { x' = -x }\n\
         diffusion { x: 1e-6 * w }\ngoal home box { x in [-0.5, 0.5] }\n\
         analysis a { method = contraction  delta = 1e-3  horizon = 2  step = 0.01 }",
        "a",
    );
    let g = &prs.goals()[0];
    assert_eq!((g.window.lo, g.window.hi, g.stay), (0.0, 2.0, false));
    for (st, &m) in prs.steps().iter().zip(&g.margins) {
        let exact = 0.5 - 1.1 * (-st.t).exp();
        assert!(
            m <= exact && m >= exact - 1e-3,
            "t = {}: {m} vs {exact}",
            st.t
        );
    }
    let GoalOutcome::Reached { t, margin } = g.outcome else {
        panic!("{:?}", g.outcome);
    };
    assert!((0.79..=0.8 + 1e-9).contains(&t), "reached at {t}");
    assert!(margin > 0.0 && margin < 0.5 - 1.1 * (-t).exp() + 1e-12);
}

/// The OU process `x' = 1 - x` from 0 with noise 0.2 has `X_t ~ N(1 - e^-t, 0.02 (1 - e^-2t))`.
/// The certified probability of reaching `x >= 0.3` within `[0.5, 2]` is a probability that
/// `X_t*` is in the goal at the reach time `t*`, so it is at most the exact `P(X_t* >= 0.3)`;
/// so is the reach-and-stay bound of `[0.3, 1.7]` on `[1, 2]` at most `P(X_2 in [0.3, 1.7])`;
/// and sample paths (Euler-Maruyama, `dt = 1e-3`) meet both events at least that often.
#[test]
fn certified_probabilities_are_below_the_exact_law_and_the_paths() {
    let src = "model ou\nstate x = 0\nnoise w\ndrift { x' = 1 - x }\ndiffusion { x: 0.2 * w }\n\
               unsafe low halfspace { x <= -0.6 }\n\
               goal up halfspace { x >= 0.3 } within [0.5, 2]\n\
               goal hold box { x in [0.3, 1.7] } within [1, 2] stay\n\
               analysis a { method = contraction  delta = 0.05  horizon = 2  step = 0.01 }";
    let (sys, info) = inline(src);
    let reach = Reach::paired(&sys, &info, "a").unwrap();
    let mean = |t: f64| 1.0 - (-t).exp();
    let sd = |t: f64| (0.02 * (1.0 - (-2.0 * t).exp())).sqrt();
    let up = reach.goal_probability(0).unwrap();
    let hold = reach.goal_probability(1).unwrap();
    let (p_up, t_up) = (up.lower_bound().unwrap(), up.t.unwrap());
    let p_hold = hold.lower_bound().unwrap_or_else(|| panic!("{hold:?}"));
    assert!(matches!(up.limit, GoalLimit::Resolution), "{:?}", up.limit);
    let exact_up = 1.0 - normal_tail((mean(t_up) - 0.3) / sd(t_up));
    let exact_hold = 1.0 - normal_tail((mean(2.0) - 0.3) / sd(2.0));
    assert!(
        p_up > 0.9 && p_up <= exact_up,
        "{p_up} vs {exact_up} at {t_up}"
    );
    assert!(
        p_hold > 0.9 && p_hold <= exact_hold,
        "{p_hold} vs {exact_hold}"
    );
    // Sample paths: the events of the two goals, each path checked every dt.
    let (paths, dt) = (4000, 1e-3);
    let mut rng = Rng(7);
    let (mut ok_up, mut ok_hold) = (0u32, 0u32);
    for _ in 0..paths {
        let (mut x, mut t) = (vec![0.0], 0.0);
        let (mut hit, mut reached, mut inside_since) = (false, false, None::<f64>);
        while t < 2.0 - 1e-12 {
            let until = t + dt;
            euler_maruyama(&sys, &mut x, &mut t, until, dt, &mut rng);
            hit |= x[0] <= -0.6;
            if !hit && !reached && t >= 0.5 && x[0] >= 0.3 {
                reached = true;
            }
            let inside = (0.3..=1.7).contains(&x[0]);
            inside_since = match (inside, inside_since) {
                (true, None) if t >= 1.0 => Some(t),
                (true, s) => s,
                (false, _) => None,
            };
        }
        ok_up += u32::from(reached);
        ok_hold += u32::from(inside_since.is_some() && !hit);
    }
    let (f_up, f_hold) = (
        f64::from(ok_up) / f64::from(paths),
        f64::from(ok_hold) / f64::from(paths),
    );
    // (Three binomial standard deviations of slack at these fractions.)
    assert!(
        f_up >= p_up - 3.0 * (p_up * (1.0 - p_up) / 4000.0).sqrt(),
        "{f_up} < {p_up}"
    );
    assert!(f_hold >= p_hold - 3.0 * (p_hold * (1.0 - p_hold) / 4000.0).sqrt());
    println!(
        "up: P >= {p_up} (t* = {t_up}, exact pointwise {exact_up}, paths {f_up}); \
         hold: P >= {p_hold} (exact at t = 2 {exact_hold}, paths {f_hold}); runs {} + {}",
        up.runs, hold.runs
    );
}

/// Why a goal is not shown reached: an unsafe set on the way, a window without a report time,
/// a tube that leaves a goal it must stay in, a pointwise guarantee.
#[test]
fn misses_say_why() {
    let model = "model push\nstate x = 0\nnoise w\ndrift { x' = 1 }\ndiffusion { x: 0.01 * w }\n\
                 unsafe wall halfspace { x >= 1 }\n\
                 goal beyond box { x in [2, 3] }\n\
                 goal gap box { x in [-1, 5] } within [0.501, 0.509]\n";
    let uniform = format!("{model}analysis a {{ horizon = 2.5  step = 0.01  delta = 1e-3 }}");
    let prs = run(&uniform, "a");
    let outcome = |i: usize| prs.goals()[i].outcome.clone();
    let GoalOutcome::NotShown(GoalMiss::Unsafe { t, set: 0 }) = outcome(0) else {
        panic!("{:?}", outcome(0));
    };
    assert!(
        (0.9..1.0).contains(&t),
        "the tube meets x >= 1 before t = 1: {t}"
    );
    assert_eq!(outcome(1), GoalOutcome::NotShown(GoalMiss::NoReportTime));
    // Without the wall: the tube enters [0.2, 0.8] and leaves it about t = 0.8.
    let free = "model push\nstate x = 0\nnoise w\ndrift { x' = 1 }\ndiffusion { x: 0.01 * w }\n\
                goal pass box { x in [0.2, 0.8] } within [0, 0.9] stay\n\
                analysis a { horizon = 2.5  step = 0.01  delta = 1e-3 }";
    let left = run(free, "a").goals()[0].outcome.clone();
    let GoalOutcome::NotShown(GoalMiss::Leaves { t }) = left else {
        panic!("{left:?}");
    };
    assert!(
        (0.75..=0.9).contains(&t),
        "the tube leaves x <= 0.8 about t = 0.8: {t}"
    );
    let pointwise = format!(
        "{model}analysis p {{ horizon = 2.5  step = 0.01  delta = 1e-3  guarantee = pointwise }}"
    );
    let prs = run(&pointwise, "p");
    assert!(prs
        .goals()
        .iter()
        .all(|g| g.outcome == GoalOutcome::NeedsUniform));
}

/// `reachc simulate`'s goal check on `x' = 1` from 0 with noise 0.01: every path passes
/// through `[0.2, 0.8]` within `[0, 1]` (reach), none stays in it to the horizon (stay), none
/// reaches `[2, 3]` without first entering the wall `x >= 1`; a certified bound above the
/// paths' Clopper-Pearson upper bound fails, a valid one passes; and shards merge into the
/// unsharded report exactly, goal counts included.
#[test]
fn simulate_counts_goal_events_and_tests_their_bounds() {
    use reachc_runtime::simulate::{self, merge, run_part, Options, Shard};
    use reachc_runtime::system::Paired;
    let src = "model push\nstate x = 0\nnoise w\ndrift { x' = 1 }\ndiffusion { x: 0.01 * w }\n\
               unsafe wall halfspace { x >= 1 }\n\
               goal pass box { x in [0.2, 0.8] } within [0, 1]\n\
               goal keep box { x in [0.2, 0.8] } within [0, 1] stay\n\
               goal beyond box { x in [2, 3] }\n\
               goal start box { x in [-0.5, 0.5] } within [0, 0.3] stay\n\
               analysis a { horizon = 2.5  step = 0.01  delta = 1e-3 }";
    let (sys, info) = inline(src);
    let prs = Reach::paired(&sys, &info, "a").unwrap().run().unwrap();
    let opts = |bounds: Vec<Option<f64>>| Options {
        paths: 500,
        goal_bounds: bounds,
        ..Options::default()
    };
    let run = |o: &Options| {
        simulate::simulate(&Paired::new(&sys, &info), &prs, o, &mut |_, _| {}).unwrap()
    };
    let report = run(&opts(vec![Some(0.99), Some(0.5), None, Some(0.05)]));
    let counts: Vec<u64> = report.goals.iter().map(|g| g.reached).collect();
    // `start`: in [-0.5, 0.5] from t = 0, but not to the horizon: no path.
    assert_eq!(counts, [500, 0, 0, 0], "{:?}", report.goals);
    let passed: Vec<bool> = report.goals.iter().map(|g| g.passed).collect();
    assert_eq!(passed, [true, false, true, false]);
    assert!(!report.passed());
    // The same paths in three shards, merged.
    let o = opts(vec![Some(0.99), Some(0.5), None, Some(0.05)]);
    let parts: Vec<(String, _)> = (0..3)
        .map(|i| {
            let shard = Shard::new(i, 3).unwrap();
            let part =
                run_part(&Paired::new(&sys, &info), &prs, &o, shard, &mut |_, _| {}).unwrap();
            (format!("part {i}"), part)
        })
        .collect();
    assert_eq!(merge(parts).unwrap(), report);
}

/// Reaching alone in a model without unsafe sets asks about one time: the pointwise radius at
/// the reach time serves (method.md 8.13), for a uniform analysis and a pointwise one alike.
/// The OU process of the test above, goal `x >= 0.5` within `[0.5, 2]`: the time-uniform tube
/// gives no bound at any delta; the pointwise sets give one, below the exact `P(X_t* >= 0.5)`.
#[test]
fn reaching_alone_uses_the_pointwise_radius() {
    let src = "model ou\nstate x = 0\nnoise w\ndrift { x' = 1 - x }\ndiffusion { x: 0.2 * w }\n\
               goal up halfspace { x >= 0.5 } within [0.5, 2]\n\
               goal hold box { x in [0.3, 1.7] } within [1, 2] stay\n\
               analysis a { method = contraction  delta = 0.05  horizon = 2  step = 0.01 }\n\
               analysis p { method = contraction  delta = 0.05  horizon = 2  step = 0.01  \
               guarantee = pointwise }";
    let (sys, info) = inline(src);
    let mean = |t: f64| 1.0 - (-t).exp();
    let sd = |t: f64| (0.02 * (1.0 - (-2.0 * t).exp())).sqrt();
    for analysis in ["a", "p"] {
        let reach = Reach::paired(&sys, &info, analysis).unwrap();
        let prs = reach.run().unwrap();
        assert!(
            prs.goals()[0].reached(),
            "{analysis}: {:?}",
            prs.goals()[0].outcome
        );
        // Each margin is that of a box holding the pointwise set: inside the uniform one's.
        for (k, &m) in prs.goals()[0].margins.iter().enumerate() {
            let uniform = prs.hull_at(k).unwrap()[0].lo - 0.5;
            let pointwise = prs.pointwise_hull_at(k).unwrap()[0].lo - 0.5;
            assert!(
                m >= uniform - 1e-12,
                "{analysis}: step {k}: {m} < {uniform}"
            );
            assert!((m - pointwise).abs() <= 1e-12, "{analysis}: step {k}");
        }
        let up = reach.goal_probability(0).unwrap();
        let (p, t) = (up.lower_bound().unwrap(), up.t.unwrap());
        let exact = 1.0 - normal_tail((mean(t) - 0.5) / sd(t));
        assert!(
            p > 0.98 && p <= exact,
            "{analysis}: {p} vs the exact {exact} at {t}"
        );
    }
    let pointwise = run(src, "p");
    assert_eq!(pointwise.goals()[1].outcome, GoalOutcome::NeedsUniform);
}
