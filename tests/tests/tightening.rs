//! Constraint tightening for a nominal plan (method.md 8.14): the amounts against the exact
//! Gaussian of a linear system, the uniform guarantee against Monte Carlo on a nonlinear system
//! driven by an input signal, a union against its pieces, the refusals, and `--tighten`'s CSV
//! against the API.

use reachc_e2e::{inline, upper_quantile};
use reachc_runtime::app::run_cli;
use reachc_runtime::engine::{Constraint, TightenError, Tightening};
use reachc_runtime::model::{Bounds, Guarantee, UnsafeShape};
use reachc_runtime::prs::Role;
use reachc_runtime::{Reach, System};
use reachc_test_support::rng::Rng;

/// `x' = -2 x + u`, `u` in `[-1, 1]`, noise `0.3 dW`, from 0.5; one unsafe half-space and one
/// unsafe box; a pointwise and a uniform analysis at `delta = 0.05`.
const OU: &str = "model ou_input\nstate x = 0.5\ninput u in [-1, 1]\nnoise w\n\
    drift { x' = -2 * x + u }\ndiffusion { x: 0.3 * w }\n\
    unsafe high halfspace { x >= 1.5 }\nunsafe band box { x in [-3, -2.5] }\n\
    analysis pw { method = contraction  delta = 0.05  horizon = 2  step = 0.05  \
    guarantee = pointwise }\n\
    analysis uni { method = contraction  delta = 0.05  horizon = 2  step = 0.05 }\n";

/// How far a half-space constraint `normal . x <= bound` moved at each step.
fn half_space_amounts(t: &Tightening, j: usize, bound: f64) -> Vec<f64> {
    t.steps
        .iter()
        .map(|st| match &st.constraints[j] {
            Constraint::HalfSpace { bound: b, .. } => bound - b,
            other => panic!("{other:?}"),
        })
        .collect()
}

/// The linear system's deviation from its nominal under the same input is the Ornstein-Uhlenbeck
/// process from 0, `N(0, s_t^2)` with `s_t^2 = 0.09 (1 - exp(-4 t)) / 4`: the pointwise amount
/// at each report time is the two-sided `z_(0.975) s_t` (the Gaussian set of the affine model,
/// method.md 8.14), never below it and within 1e-6 of it (it holds over the report interval,
/// where `s` is largest at its end). A box `x in [lo, hi]` moves both faces by the same amount,
/// and the unsafe sets grow by it.
#[test]
fn pointwise_amounts_equal_the_exact_gaussian_quantile() {
    let (sys, info) = inline(OU);
    let reach = Reach::paired(&sys, &info, "pw").unwrap();
    let prs = reach.run().unwrap();
    let constraints = [
        Constraint::HalfSpace {
            normal: vec![1.0],
            bound: 1.0,
        },
        Constraint::Box(vec![(0, Bounds { lo: -1.0, hi: 1.0 })]),
    ];
    let t = reach.tighten(&prs, &constraints).unwrap();
    assert_eq!(t.guarantee, Guarantee::Pointwise);
    assert_eq!((t.analysis.as_str(), t.delta), ("pw", 0.05));
    assert_eq!(t.steps.len(), 41);
    let z = upper_quantile(0.025);
    assert!((z - 1.959_963_984_540_054).abs() < 1e-12);
    let amounts = half_space_amounts(&t, 0, 1.0);
    assert_eq!(amounts[0], 0.0, "the start is a point");
    for (st, s) in t.steps.iter().zip(&amounts).skip(1) {
        let exact = z * (0.09 * (1.0 - (-4.0 * st.t).exp()) / 4.0).sqrt();
        assert!(*s >= exact, "t = {}: {s} < {exact}", st.t);
        assert!(*s <= exact * (1.0 + 1e-6), "t = {}: {s} vs {exact}", st.t);
        // (Each face moves by at least the exact amount, rounded outwards: within an ulp or
        // two of the half-space's.)
        let near = |moved: f64| moved >= exact && (moved - s).abs() < 1e-15;
        let Constraint::Box(b) = &st.constraints[1] else {
            panic!()
        };
        assert!(near(b[0].1.lo + 1.0) && near(1.0 - b[0].1.hi), "{b:?}");
        let UnsafeShape::HalfSpace { offset, .. } = &st.unsafe_sets[0].shape else {
            panic!()
        };
        assert!(near(1.5 - offset), "{offset}");
        let UnsafeShape::Box(b) = &st.unsafe_sets[1].shape else {
            panic!()
        };
        assert!(near(-3.0 - b[0].1.lo) && near(b[0].1.hi + 2.5), "{b:?}");
    }
    // Against the exact one-sided quantile a half-space needs alone (z_(0.95) s_T).
    let exact_one_sided = upper_quantile(0.05) * (0.09 * (1.0 - (-8.0f64).exp()) / 4.0).sqrt();
    eprintln!(
        "t = 2: amount {:.6}, exact one-sided {exact_one_sided:.6} (ratio {:.3})",
        amounts[40],
        amounts[40] / exact_one_sided
    );
    // The uniform amount holds over all of [0, 2] at once: larger.
    let uni = Reach::paired(&sys, &info, "uni").unwrap();
    let tu = uni.tighten(&uni.run().unwrap(), &constraints).unwrap();
    assert_eq!(tu.guarantee, Guarantee::Uniform);
    let uniform = half_space_amounts(&tu, 0, 1.0);
    assert!(uniform[40] > amounts[40]);
    eprintln!("uniform amount at t = 2: {:.6}", uniform[40]);
}

/// A contracting nonlinear system with two states, driven by the input signal
/// `u(t) = 0.5 sin 3t` (inside the input box): 2,000 Euler-Maruyama paths (`dt = 1e-3`) from a
/// corner of the initial box against the noise-free Euler solution from the same start under
/// the same signal. The fraction of paths whose deviation leaves a tightened amount at any step
/// (a half-space's `a . (X - x)` above its amount, a box coordinate beyond its own) over the
/// whole horizon is at most `delta` (plus three standard deviations).
#[test]
fn uniform_amounts_hold_against_monte_carlo_with_an_input_signal() {
    let (sys, info) = inline(
        "model nl\nstate x in [-0.1, 0.1]\nstate y in [0, 0.2]\ninput u in [-0.5, 0.5]\n\
         noise w1\nnoise w2\n\
         drift { x' = -x + 0.5 * sin(y) + u\n y' = -2 * y + 0.3 * tanh(x) }\n\
         diffusion { x: 0.2 * w1\n y: 0.1 * w1 + 0.25 * w2 }\n\
         analysis a { method = contraction  delta = 0.1  horizon = 2  step = 0.05 }\n",
    );
    let reach = Reach::paired(&sys, &info, "a").unwrap();
    let prs = reach.run().unwrap();
    let normal = [0.6, -0.8];
    let constraints = [
        Constraint::HalfSpace {
            normal: normal.to_vec(),
            bound: 0.0,
        },
        Constraint::Box(vec![
            (0, Bounds { lo: -1.0, hi: 1.0 }),
            (1, Bounds { lo: -1.0, hi: 1.0 }),
        ]),
    ];
    let t = reach.tighten(&prs, &constraints).unwrap();
    assert_eq!(t.guarantee, Guarantee::Uniform);
    assert!(t.validation.not_validated.is_empty());
    let half = half_space_amounts(&t, 0, 0.0);
    let boxes: Vec<[f64; 2]> = t
        .steps
        .iter()
        .map(|st| match &st.constraints[1] {
            Constraint::Box(b) => [1.0 - b[0].1.hi, 1.0 - b[1].1.hi],
            other => panic!("{other:?}"),
        })
        .collect();
    let report: Vec<f64> = t.steps.iter().map(|st| st.t).collect();
    let (dt, steps, paths) = (1e-3, 2000, 2000); // to the horizon 2
    let u = |t: f64| [0.5 * (3.0 * t).sin()];
    let start = [0.1, 0.2];
    let (mut f, mut g) = ([0.0; 2], [0.0; 4]);
    // The nominal, once.
    let mut nominal = vec![start];
    let mut x = start;
    for k in 0..steps {
        let t = k as f64 * dt;
        sys.drift(&x, &u(t), t, &mut f);
        x = [x[0] + f[0] * dt, x[1] + f[1] * dt];
        nominal.push(x);
    }
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let (mut out, mut worst) = (0usize, Vec::with_capacity(paths));
    for _ in 0..paths {
        let mut x = start;
        let mut most = 0.0f64;
        for k in 0..steps {
            let t = k as f64 * dt;
            sys.drift(&x, &u(t), t, &mut f);
            sys.diffusion(&x, t, &mut g);
            let (w1, w2) = (rng.normal() * dt.sqrt(), rng.normal() * dt.sqrt());
            x = [
                x[0] + f[0] * dt + g[0] * w1 + g[1] * w2,
                x[1] + f[1] * dt + g[2] * w1 + g[3] * w2,
            ];
            let now = (k + 1) as f64 * dt;
            // The report interval (t_(j-1), t_j] holding `now`.
            let j = report
                .partition_point(|&r| r < now - 1e-12)
                .min(report.len() - 1);
            let d = [x[0] - nominal[k + 1][0], x[1] - nominal[k + 1][1]];
            let ratio = ((normal[0] * d[0] + normal[1] * d[1]) / half[j])
                .max(d[0].abs() / boxes[j][0])
                .max(d[1].abs() / boxes[j][1]);
            most = most.max(ratio);
        }
        if most > 1.0 {
            out += 1;
        }
        worst.push(most);
    }
    let rate = out as f64 / paths as f64;
    let sd = (0.1 * 0.9 / paths as f64).sqrt();
    worst.sort_by(f64::total_cmp);
    let quantile = worst[(0.9 * paths as f64) as usize];
    eprintln!(
        "{out} of {paths} paths left the tightening (delta 0.1); the empirical 0.9 quantile of \
         the worst ratio is {quantile:.3}: the amounts are {:.2}x what the sample needs",
        1.0 / quantile
    );
    assert!(rate <= 0.1 + 3.0 * sd, "{rate}");
    assert!(quantile < 1.0, "{quantile}");
}

/// A split initial set: the union's amounts are the largest of its pieces' at each step.
#[test]
fn a_union_takes_the_largest_amount_of_its_pieces() {
    let (sys, info) = inline(
        "model sp\nstate x in [-0.5, 0.5]\nstate y in [-0.2, 0.2]\nnoise w\n\
         drift { x' = -x + 0.4 * sin(y)\n y' = -y - 0.6 * x * x }\n\
         diffusion { x: 0.2 * w\n y: 0.1 * w * (1 + 0.2 * sin(x)) }\n\
         analysis a { method = contraction  delta = 0.1  horizon = 1  step = 0.1  split = [2, 1] }\n",
    );
    let reach = Reach::paired(&sys, &info, "a").unwrap();
    let prs = reach.run().unwrap();
    assert_eq!(prs.pieces().len(), 2);
    let c = [Constraint::HalfSpace {
        normal: vec![1.0, 1.0],
        bound: 2.0,
    }];
    let whole = half_space_amounts(&reach.tighten(&prs, &c).unwrap(), 0, 2.0);
    let pieces: Vec<Vec<f64>> = prs
        .pieces()
        .iter()
        .map(|p| half_space_amounts(&reach.tighten(p, &c).unwrap(), 0, 2.0))
        .collect();
    for (k, w) in whole.iter().enumerate() {
        assert_eq!(*w, pieces[0][k].max(pieces[1][k]), "step {k}");
    }
    assert!(whole.iter().skip(1).all(|&w| w > 0.0));
}

/// Constraints that do not fit the model and results without a deviation bound are refused.
#[test]
fn bad_constraints_and_results_without_a_ball_are_refused() {
    let (sys, info) = inline(OU);
    let reach = Reach::paired(&sys, &info, "uni").unwrap();
    let prs = reach.run().unwrap();
    let refused = |c: Constraint| reach.tighten(&prs, &[c]).unwrap_err();
    for (c, what) in [
        (
            Constraint::HalfSpace {
                normal: vec![1.0, 0.0],
                bound: 1.0,
            },
            "the normal needs one entry per state",
        ),
        (
            Constraint::HalfSpace {
                normal: vec![f64::INFINITY],
                bound: 1.0,
            },
            "the normal must be finite and the bound a number",
        ),
        (
            Constraint::Box(vec![(1, Bounds { lo: 0.0, hi: 1.0 })]),
            "a state index is out of range",
        ),
        (
            Constraint::Box(vec![(0, Bounds { lo: 1.0, hi: 0.0 })]),
            "a range must be numbers with lo <= hi",
        ),
    ] {
        assert_eq!(refused(c), TightenError::Malformed { index: 0, what });
    }
    let mut gaussian_only = prs.clone();
    gaussian_only.set_role(Role::Linearised);
    assert_eq!(
        reach.tighten(&gaussian_only, &[]).unwrap_err(),
        TightenError::NoDeviationBound
    );
}

/// `--tighten` writes `<analysis>.tightening.csv` with the API's numbers (the model's unsafe
/// sets inflated), and a summary line.
#[test]
fn the_tightening_csv_carries_the_api_values() {
    let (sys, info) = inline(OU);
    let dir = std::env::temp_dir().join(format!("reachc-tighten-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let args: Vec<String> = ["--analysis", "pw", "--tighten", "-o"]
        .iter()
        .map(|s| s.to_string())
        .chain([dir.display().to_string()])
        .collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    assert_eq!(run_cli(&sys, &args, &mut out, &mut err), 0);
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains("unsafe sets inflated, `high` by up to 0.29"),
        "{text}"
    );
    let csv = std::fs::read_to_string(dir.join("pw.tightening.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t,high.offset,band.x_lo,band.x_hi"));
    let reach = Reach::paired(&sys, &info, "pw").unwrap();
    let t = reach.tighten(&reach.run().unwrap(), &[]).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), t.steps.len());
    for (row, st) in rows.iter().zip(&t.steps) {
        let UnsafeShape::HalfSpace { offset, .. } = &st.unsafe_sets[0].shape else {
            panic!()
        };
        let UnsafeShape::Box(b) = &st.unsafe_sets[1].shape else {
            panic!()
        };
        assert_eq!(row, &vec![st.t, *offset, b[0].1.lo, b[0].1.hi]);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
