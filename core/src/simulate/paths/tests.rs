use super::super::plan::make_plan;
use super::super::{InputMode, Options};
use super::*;
use crate::engine;
use crate::interval::Interval;
#[cfg(target_arch = "x86_64")]
use crate::lanes::X8;
use crate::model::*;
use crate::test_support::models::{pendulum_model, PENDULUM_METRIC};
use crate::test_support::systems::Pendulum;

/// The pendulum of specs/pendulum.sde: one noise channel on the second state (constant
/// `G` that is not diagonal), a drift with `sin`.
const PENDULUM: Pendulum = Pendulum::PAPER;

/// The pendulum's model; its analysis `method` with the paper's (full) metric.
fn pendulum(method: Method) -> ModelInfo {
    let mut info = pendulum_model();
    let constants = Constants::given(&info, PENDULUM_METRIC.to_vec(), -0.5, 0.12, 0.0);
    info.analyses.push(Analysis {
        spec: AnalysisSpec {
            name: "a".into(),
            method,
            delta: 1e-3,
            horizon: 1.0,
            step: 0.02,
            ..AnalysisSpec::default()
        },
        constants: Ok(constants),
    });
    info
}

/// The portable part of `lanes_x8`, on any processor: eight paths stepped with the lane
/// kernels (`InputSchedule::update_x8`, `System::drift_x8`, `Noise::apply_x8`,
/// `SetRegions::check_x8`), each lane drawing its normals from its own stream as the
/// AVX-512 lanes do (that they draw the same numbers is `avx512`'s test), against the same
/// paths stepped one by one as `step_lanes` does: the same states to the bit after every
/// step, and the same unsafe-set hits, first hit times and domain exits. The pendulum
/// (constant `G` that is not diagonal), with state-dependent noise, and forced by an input
/// in each input mode, with unsafe sets and a domain the paths enter and leave. What only
/// runs on AVX-512 (the registers' streams and loads) is
/// [`lanes_do_not_change_the_paths`].
#[cfg(target_arch = "x86_64")]
#[test]
fn lane_kernels_step_as_the_scalar_loop() {
    use crate::test_support::rng::Rng;
    let info = pendulum(Method::Interval);
    let r = engine::run_paired(&PENDULUM, &info, &info.analyses[0]).unwrap();
    let regions = with_regions(&info, true);
    let forced = with_input(&regions);
    let modes = [InputMode::Random, InputMode::Corners, InputMode::Centre];
    let systems = [
        (&PENDULUM as &dyn System, &regions, InputMode::Random),
        (&MULTIPLICATIVE, &regions, InputMode::Random),
    ]
    .into_iter()
    .chain(modes.map(|mode| (&FORCED as &dyn System, &forced, mode)));
    let mut start = Rng(0x1a4e5);
    let (mut hits, mut exits) = (0, 0);
    for (sys, info, mode) in systems {
        let opts = Options {
            inputs: mode,
            hold: Some(0.05),
            ..Options::default()
        };
        let plan = make_plan(sys, info, &r, &opts).unwrap();
        let (n, m, p, sets) = (sys.n(), sys.m(), sys.p(), plan.sets.unsafe_sets.len());
        let case = format!("{p} inputs ({mode:?}), G(x): {}", plan.noise.needs_matrix());
        // Four corners of the initial box (two heading out of the domain) and four inside.
        let a = std::f64::consts::PI / 10.0;
        let x: Vec<[f64; 2]> = [[a, 0.2], [-a, -0.2], [a, -0.2], [-a, 0.2]]
            .into_iter()
            .chain((0..4).map(|_| [start.range(-a, a), start.range(-0.2, 0.2)]))
            .collect();
        // The lanes' and the scalar loop's states, inputs, normals, drift, G, paths, hits.
        let mut xl: [X8; SMALL] =
            std::array::from_fn(|i| X8(std::array::from_fn(|l| if i < n { x[l][i] } else { 0.0 })));
        let (mut ul, mut zl) = ([X8::splat(0.0); SMALL], [X8::splat(0.0); SMALL]);
        let (mut fl, mut gl) = ([X8::splat(0.0); SMALL], [X8::splat(0.0); SMALL * SMALL]);
        let mut hold = None;
        let path = |l: usize| Path {
            rng: PathRng::new(17, l as u64),
            hold: None,
            alive: true,
            outside_any: false,
            left_tube: false,
            left_domain: false,
        };
        let mut lanes: Vec<Path> = (0..8).map(path).collect();
        let mut scalar = lanes.clone();
        let (mut hit_l, mut hit_s) = (vec![false; 8 * sets], vec![false; 8 * sets]);
        let stats = || ChunkStats::new(plan.times.len(), sets, 0, n);
        let (mut st_l, mut st_s) = (stats(), stats());
        let mut xs = x.clone();
        // Each path holds its own inputs between draws.
        let mut us = [[0.0; SMALL]; 8];
        let (mut z, mut f, mut g) = ([0.0; SMALL], [0.0; 2], [0.0; 2]);
        for span in &plan.spans {
            for i in 0..span.steps {
                let (t, t_end) = span.step_times(i);
                if p > 0 {
                    let next = || std::array::from_fn(|l| lanes[l].rng.next_u64());
                    plan.inputs.update_x8(t, &mut hold, next, &mut ul[..p]);
                }
                for zj in &mut zl[..m] {
                    *zj = X8(std::array::from_fn(|l| plan.zig.sample(&mut lanes[l].rng)));
                }
                sys.drift_x8(&xl[..n], &ul[..p], t, &mut fl[..n]);
                let (h, sqrt_h) = (span.h, span.sqrt_h);
                let (xn, fnn) = (&mut xl[..n], &fl[..n]);
                plan.noise
                    .apply_x8(sys, xn, fnn, t, h, sqrt_h, &mut zl[..m], &mut gl[..n * m]);
                plan.sets
                    .check_x8(t_end, &xl[..n], 0xff, &mut hit_l, &mut lanes, &mut st_l);
                for (l, (x, path)) in xs.iter_mut().zip(&mut scalar).enumerate() {
                    let u = &mut us[l];
                    if p > 0 {
                        plan.inputs
                            .update(t, &mut path.hold, &mut path.rng, &mut u[..p]);
                    }
                    for zj in &mut z[..m] {
                        *zj = plan.zig.sample(&mut path.rng);
                    }
                    sys.drift(x, &u[..p], t, &mut f);
                    plan.noise
                        .apply(sys, x, &f, t, h, sqrt_h, &mut z[..m], &mut g);
                    let hit = &mut hit_s[l * sets..][..sets];
                    plan.sets
                        .check(t_end, x, hit, &mut [], &mut path.left_domain, &mut st_s);
                    for (j, xj) in x.iter().enumerate() {
                        let lane = xl[j].0[l];
                        assert_eq!(lane.to_bits(), xj.to_bits(), "{case}, t = {t}, lane {l}");
                    }
                }
            }
        }
        assert_eq!(hit_l, hit_s, "{case}");
        assert_eq!(st_l, st_s, "{case}");
        let flags = |paths: &[Path]| paths.iter().map(|p| p.left_domain).collect::<Vec<_>>();
        assert_eq!(flags(&lanes), flags(&scalar), "{case}");
        for (a, b) in lanes.iter().zip(&scalar) {
            assert_eq!(
                a.rng.state(),
                b.rng.state(),
                "{case}: the streams moved alike"
            );
        }
        hits += hit_s.iter().filter(|&&h| h).count();
        exits += flags(&scalar).iter().filter(|&&e| e).count();
    }
    // Not vacuous: the paths enter unsafe sets and leave the domain.
    assert!(hits > 10, "{hits}");
    assert!(exits > 0, "{exits}");
}

/// Eight paths in lanes (`lanes_x8`; of 203 paths, the last three in the scalar loops)
/// against the scalar loops, path by path: a constant `G` that is not diagonal, a full
/// metric, the contraction method's intersection with its interval box (time-uniform: the
/// tube at every step; and pointwise) and the interval method's box, with and without
/// quantile candidates, and with sets narrowed so that paths leave them (then also with
/// unsafe sets and a domain, checked after every step); the pendulum, the pendulum with
/// state-dependent noise, and a forced pendulum in each input mode. The records, counts,
/// tube exits, unsafe-set hits with their first times, and domain exits are the same.
///
/// The lanes need AVX-512 (F and DQ). Where the processor that built the tests has none,
/// the test is ignored (`cargo test` lists it as such: a skip that shows, not a pass), and
/// [`lane_kernels_step_as_the_scalar_loop`] still checks the portable kernels; the build
/// script decides (`reachc_avx512`). `REACHC_REQUIRE_AVX512=1` at build time runs it
/// regardless, so that a machine meant to test the lanes fails without them.
#[cfg(target_arch = "x86_64")]
#[cfg_attr(
    not(reachc_avx512),
    ignore = "no AVX-512 (F and DQ) on the machine that built the tests: the lanes cannot run"
)]
#[test]
fn lanes_do_not_change_the_paths() {
    super::super::avx512::require();
    // The lanes record a group's steps in turn, the scalar loops a step's paths.
    let sorted = ChunkStats::sorted;
    let (mut outside, mut hits, mut late) = (0, 0, 0.0_f64);
    for method in [Method::Contraction, Method::Interval] {
        for guarantee in [Guarantee::Uniform, Guarantee::Pointwise] {
            let info = pendulum(method);
            let mut r = engine::run_paired(&PENDULUM, &info, &info.analyses[0]).unwrap();
            r.guarantee = guarantee;
            if method == Method::Contraction {
                assert!(!r.also.is_empty(), "an intersection");
            }
            for narrow in [false, true] {
                if narrow {
                    // Radii and spans at a third: some paths leave the sets.
                    for st in &mut r.steps {
                        st.prs_radius /= 3.0;
                        st.span.radius /= 3.0;
                    }
                }
                // With unsafe sets and a domain (checked after every step), and without;
                // the pendulum, with state-dependent noise, and forced by an input in each
                // of the input modes.
                let regions = with_regions(&info, narrow);
                let forced = with_input(&regions);
                let modes = [InputMode::Random, InputMode::Corners, InputMode::Centre];
                let systems = [
                    (&PENDULUM as &dyn System, &regions, InputMode::Random, true),
                    (&MULTIPLICATIVE, &regions, InputMode::Random, false),
                ]
                .into_iter()
                .chain(modes.map(|mode| (&FORCED as &dyn System, &forced, mode, true)));
                for ((sys, info, mode, constant), threshold) in
                    systems.flat_map(|s| [(s, f64::NEG_INFINITY), (s, 0.5)])
                {
                    let opts = Options {
                        inputs: mode,
                        hold: Some(0.05),
                        ..Options::default()
                    };
                    let mut plan = make_plan(sys, info, &r, &opts).unwrap();
                    assert!(plan.lanes_take(2) && plan.noise.diagonal().is_none());
                    assert_eq!(plan.noise.needs_matrix(), !constant);
                    let thresholds = Thresholds::uniform(plan.times.len(), plan.sys.n(), threshold);
                    plan.avx512 = true;
                    let lanes = sorted(plan.run_chunk(0..203, &thresholds));
                    plan.avx512 = false;
                    let scalar = sorted(plan.run_chunk(0..203, &thresholds));
                    let case = format!(
                        "{method:?} {guarantee:?} narrow {narrow} {threshold} inputs {} \
                         {mode:?}",
                        sys.p()
                    );
                    assert_eq!(lanes, scalar, "{case}");
                    outside += scalar.outside_any + scalar.outside_tube;
                    hits += scalar.unsafe_hits.iter().sum::<u64>() + scalar.left_domain;
                    if let Some(&t) = scalar.first_hit.get(1).filter(|t| t.is_finite()) {
                        late = late.max(t);
                    }
                }
            }
        }
    }
    // Not vacuous: the narrowed sets are left, the unsafe sets hit, the domain left.
    assert!(outside > 100, "{outside}");
    assert!(hits > 100, "{hits}");
    assert!(late > 0.0, "the ball is first entered after the start");
}

/// [`Pendulum`], `forced` by an input `u` on the second state (`omega' = ... + u`), or with
/// `multiplicative` noise (`G = [0, 0.1 + 0.05 sin theta]'`).
struct Variant {
    forced: bool,
    multiplicative: bool,
}

const FORCED: Variant = Variant {
    forced: true,
    multiplicative: false,
};
const MULTIPLICATIVE: Variant = Variant {
    forced: false,
    multiplicative: true,
};

impl System for Variant {
    fn n(&self) -> usize {
        2
    }
    fn p(&self) -> usize {
        usize::from(self.forced)
    }
    fn m(&self) -> usize {
        1
    }
    fn drift(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        PENDULUM.drift(x, u, t, out);
        if self.forced {
            out[1] += u[0];
        }
    }
    fn drift_interval(&self, x: &[Interval], u: &[Interval], t: Interval, o: &mut [Interval]) {
        PENDULUM.drift_interval(x, u, t, o);
        if self.forced {
            o[1] += u[0];
        }
    }
    fn jac_x(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        PENDULUM.jac_x(x, u, t, out);
    }
    fn jac_x_interval(&self, x: &[Interval], u: &[Interval], t: Interval, o: &mut [Interval]) {
        PENDULUM.jac_x_interval(x, u, t, o);
    }
    fn jac_u(&self, _x: &[f64], _u: &[f64], _t: f64, out: &mut [f64]) {
        if self.forced {
            out.copy_from_slice(&[0.0, 1.0]);
        }
    }
    fn jac_u_interval(&self, _: &[Interval], _: &[Interval], _: Interval, o: &mut [Interval]) {
        if self.forced {
            o.copy_from_slice(&[Interval::ZERO, Interval::ONE]);
        }
    }
    fn diffusion(&self, x: &[f64], t: f64, out: &mut [f64]) {
        if self.multiplicative {
            out.copy_from_slice(&[0.0, 0.1 + 0.05 * x[0].sin()]);
        } else {
            PENDULUM.diffusion(x, t, out);
        }
    }
    fn diffusion_interval(&self, x: &[Interval], t: Interval, o: &mut [Interval]) {
        if self.multiplicative {
            let p = Interval::point;
            o.copy_from_slice(&[Interval::ZERO, p(0.1) + p(0.05) * x[0].sin()]);
        } else {
            PENDULUM.diffusion_interval(x, t, o);
        }
    }
}

/// `info` for [`FORCED`]: its input in `[-0.5, 1]`.
fn with_input(info: &ModelInfo) -> ModelInfo {
    let mut info = info.clone();
    info.inputs = vec!["u".into()];
    info.input_box = vec![Bounds::new(-0.5, 1.0)];
    info
}

/// `info` with three unsafe sets (a box, a ball and a half-space, which pendulum paths
/// enter, the ball only after the start) and a domain that some leave, if `add`.
fn with_regions(info: &ModelInfo, add: bool) -> ModelInfo {
    let mut info = info.clone();
    if add {
        let set = |name: &str, shape| UnsafeSet {
            name: name.into(),
            shape,
            moving: Vec::new(),
        };
        info.unsafe_sets = vec![
            set("box", UnsafeShape::Box(vec![(1, Bounds::new(0.12, 1.0))])),
            set(
                "ball",
                UnsafeShape::Ball {
                    states: vec![0, 1],
                    center: vec![0.15, -0.0765],
                    radius: 0.01,
                },
            ),
            set(
                "half",
                UnsafeShape::HalfSpace {
                    normal: vec![1.0, 0.5],
                    offset: 0.3,
                },
            ),
        ];
        info.domain = vec![Bounds::new(-0.315, 0.315), Bounds::ENTIRE];
        info.has_domain = true;
    }
    info
}
