use super::*;

/// `dx = drift dt + 0.5 dW`, one state; the moving numbers of its sets are the lines
/// `a + b t` of `lines` (number `k`: `lines[k]`).
struct Brownian {
    drift: f64,
    lines: Vec<(f64, f64)>,
}

/// [`Brownian`]'s noise intensity.
const SIGMA: f64 = 0.5;

impl System for Brownian {
    fn n(&self) -> usize {
        1
    }
    fn p(&self) -> usize {
        0
    }
    fn m(&self) -> usize {
        1
    }
    fn drift(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = self.drift;
    }
    fn drift_interval(&self, _: &[Interval], _: &[Interval], _: Interval, o: &mut [Interval]) {
        o[0] = Interval::point(self.drift);
    }
    fn jac_x(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = 0.0;
    }
    fn jac_x_interval(&self, _: &[Interval], _: &[Interval], _: Interval, o: &mut [Interval]) {
        o[0] = Interval::ZERO;
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, _out: &mut [f64]) {}
    fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, _: &mut [Interval]) {}
    fn diffusion(&self, _x: &[f64], _t: f64, out: &mut [f64]) {
        out[0] = SIGMA;
    }
    fn diffusion_interval(&self, _x: &[Interval], _t: Interval, o: &mut [Interval]) {
        o[0] = Interval::point(SIGMA);
    }
    fn set_numbers(&self, t: Interval, out: &mut [Interval]) {
        for (o, &(a, b)) in out.iter_mut().zip(&self.lines) {
            *o = Interval::point(a) + Interval::point(b) * t;
        }
    }
}

/// The model of a [`Brownian`] from `x = 0` with these sets, analysed over `[0, 1]` in
/// report steps of 0.05.
fn brownian(unsafe_sets: Vec<UnsafeSet>, goals: Vec<GoalSet>) -> ModelInfo {
    let mut info = ModelInfo {
        goals,
        affine: true,
        constant_diffusion: true,
        time: Default::default(),
        unsafe_sets,
        ..model("brownian", &["x"], &["w"], &[(0.0, 0.0)])
    };
    let constants = Constants::given(&info, vec![1.0], 0.0, SIGMA, 0.0);
    info.analyses.push(Analysis {
        spec: AnalysisSpec {
            name: "a".into(),
            delta: 0.05,
            horizon: 1.0,
            step: 0.05,
            ..AnalysisSpec::default()
        },
        constants: Ok(constants),
    });
    info
}

/// `info` with every set held where it is at `t = 0`.
fn held(info: &ModelInfo) -> ModelInfo {
    let mut info = info.clone();
    for u in &mut info.unsafe_sets {
        u.moving.clear();
    }
    for g in &mut info.goals {
        g.moving.clear();
    }
    info
}

/// The report of `opts.paths` paths of `sys` checked against `info`'s sets.
fn simulate_sets(sys: &Brownian, info: &ModelInfo, opts: &Options) -> SimReport {
    let r = engine::run_paired(sys, info, &info.analyses[0]).unwrap();
    simulate(&Paired::new(sys, info), &r, opts, &mut |_, _| {}).unwrap()
}

/// The unsafe half-space `x >= offset` (at `t = 0`), its offset moving number `number`.
fn above(offset: f64, number: usize) -> UnsafeSet {
    UnsafeSet {
        name: "above".into(),
        shape: UnsafeShape::HalfSpace {
            normal: vec![1.0],
            offset,
        },
        moving: vec![Moving {
            part: 0,
            slot: Slot::Offset,
            number,
        }],
    }
}

/// `P(0.5 W_s >= a + b s` for some `s <= t)` for `a > 0`: Brownian motion crossing a line
/// (Bachelier-Levy).
fn crossing(a: f64, b: f64, t: f64) -> f64 {
    use super::normal::tests::phi;
    let s = SIGMA * t.sqrt();
    let mirror = (-2.0 * a * b / (SIGMA * SIGMA)).exp();
    1.0 - phi((a + b * t) / s) + mirror * phi((b * t - a) / s)
}

/// The paths of `dx = 0.5 dW` from 0 that enter the moving unsafe half-space
/// `x >= 0.5 + 0.25 t` on `[0, 1]`: Brownian motion crossing a line, whose probability is
/// Bachelier-Levy's closed form, 0.1803. Euler-Maruyama sees the state at its steps only
/// and misses the crossings in between: what it counts is, to `o(sqrt h)`, the closed form
/// for the line moved up by `beta sigma sqrt(h)`, `beta = -zeta(1/2) / sqrt(2 pi) = 0.5826`
/// (Broadie, Glasserman and Kou, 1997): with `h = 2e-4` a shift of 0.0041, and 0.1773
/// instead of 0.1803, about one standard deviation (0.0027) of 20 000 paths. The simulated
/// fraction matches the shifted closed form within 4 standard deviations and is far (over
/// 15 of them) from the set held at its start (0.3173) or at its end (0.1336). The same
/// paths of `dx = -0.25 dt + 0.5 dW` (the set's frame) enter the set held at its start at
/// the same steps.
#[test]
fn a_moving_half_space_is_entered_as_brownian_motion_crosses_a_line() {
    let (a, b) = (0.5, 0.25);
    let info = brownian(vec![above(a, 0)], vec![]);
    let opts = Options {
        paths: 20_000,
        seed: 7,
        dt: Some(2e-4),
        ..Options::default()
    };
    let moving = Brownian {
        drift: 0.0,
        lines: vec![(a, b)],
    };
    let rep = simulate_sets(&moving, &info, &opts);
    let hits = &rep.unsafe_sets[0];
    let n = opts.paths as f64;
    let beta = 0.5826;
    let seen = crossing(a + beta * SIGMA * opts.dt.unwrap().sqrt(), b, 1.0);
    let sd = (seen * (1.0 - seen) / n).sqrt();
    let exact = crossing(a, b, 1.0);
    let (start, end) = (crossing(a, 0.0, 1.0), crossing(a + b, 0.0, 1.0));
    eprintln!(
        "simulated {} ({} paths), closed form {exact:.4}, seen by the steps {seen:.4} \
         (sd {sd:.4}), held at the start {start:.4}, at the end {end:.4}",
        hits.fraction, hits.hits
    );
    assert!((hits.fraction - seen).abs() < 4.0 * sd, "{hits:?} {seen}");
    assert!(exact - seen < 1.5 * sd);
    assert!(start - hits.fraction > 15.0 * sd && hits.fraction - end > 15.0 * sd);
    let frame = Brownian {
        drift: -b,
        lines: vec![],
    };
    let fixed = simulate_sets(&frame, &held(&info), &opts);
    assert_eq!(fixed.unsafe_sets, rep.unsafe_sets);
    assert_eq!(fixed.safety, rep.safety);
}

/// Goals moving with the unsafe half-space (`x >= 0.6 + 0.5 t`): a box `[0.05, 0.35] +
/// 0.5 t` (both sides moving) to reach in the window `[0.25, 1]`, and a ball (an interval)
/// about `0.2 + 0.5 t` of radius 0.4 (its centre moving) to reach and stay in from `t <=
/// 0.9`. The same paths of `dx = -0.5 dt + 0.5 dW` (the sets' frame) enter the unsafe set
/// and reach the goals held at their start in the same numbers; the paths of `dx = 0.5 dW`
/// with the sets held there do not (hundreds of paths apart). Three shards (blocks of paths
/// cut elsewhere), through their part files, merge into the same report.
#[test]
fn moving_goals_are_reached_as_in_their_frame() {
    let v = 0.5;
    let moving = |part, slot, number| Moving { part, slot, number };
    let goal = |name: &str, part, moving, window: (f64, f64), stay| GoalSet {
        name: name.into(),
        parts: vec![part],
        moving,
        window: Some(Bounds::new(window.0, window.1)),
        stay,
    };
    let info = brownian(
        vec![above(0.6, 0)],
        vec![
            goal(
                "box",
                UnsafeShape::Box(vec![(0, Bounds::new(0.05, 0.35))]),
                vec![moving(0, Slot::Lo(0), 1), moving(0, Slot::Hi(0), 2)],
                (0.25, 1.0),
                false,
            ),
            goal(
                "ball",
                UnsafeShape::Ball {
                    states: vec![0],
                    center: vec![0.2],
                    radius: 0.4,
                },
                vec![moving(0, Slot::Center(0), 3)],
                (0.0, 0.9),
                true,
            ),
        ],
    );
    let sys = |drift, lines| Brownian { drift, lines };
    let lines = vec![(0.6, v), (0.05, v), (0.35, v), (0.2, v)];
    let opts = Options {
        paths: 4_000,
        seed: 3,
        dt: Some(1e-3),
        ..Options::default()
    };
    let moving = sys(0.0, lines);
    let rep = simulate_sets(&moving, &info, &opts);
    let r = engine::run_paired(&moving, &info, &info.analyses[0]).unwrap();
    let parts = (0..3).map(|i| {
        let shard = Shard::new(i, 3).unwrap();
        let part = run_part(
            &Paired::new(&moving, &info),
            &r,
            &opts,
            shard,
            &mut |_, _| {},
        )
        .unwrap();
        (i.to_string(), Part::from_bytes(&part.to_bytes()).unwrap())
    });
    assert_eq!(merge(parts).unwrap(), rep);
    let fixed = simulate_sets(&sys(-v, vec![]), &held(&info), &opts);
    assert_eq!(fixed.unsafe_sets, rep.unsafe_sets);
    assert_eq!(fixed.goals, rep.goals);
    let still = simulate_sets(&sys(0.0, vec![]), &held(&info), &opts);
    let reached = |r: &SimReport| r.goals.iter().map(|g| g.reached).collect::<Vec<_>>();
    eprintln!(
        "moving: unsafe {}, goals {:?}; held still: unsafe {}, goals {:?}",
        rep.unsafe_sets[0].hits,
        reached(&rep),
        still.unsafe_sets[0].hits,
        reached(&still)
    );
    // Not vacuous: many paths enter the unsafe set, reach a goal and miss it.
    assert!((100..3_900).contains(&rep.unsafe_sets[0].hits));
    for (moved, held) in reached(&rep).into_iter().zip(reached(&still)) {
        assert!((100..3_900).contains(&moved), "{moved}");
        assert!(moved.abs_diff(held) > 300, "{moved} {held}");
    }
}
