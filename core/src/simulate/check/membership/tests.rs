use super::*;
use crate::interval::Interval;
use crate::model::Method;
use crate::sets::zonotope;
use crate::simulate::check::fixtures::{methods_and_metrics, parallelotope, result, zonotopes};
use crate::simulate::check::quad_small;
use crate::simulate::rng::PathRng;
use crate::test_support::rng::box_muller;

/// The lanes' shortcut (`inside_by_shortcut_x8`) against the scalar one, state by state:
/// eight states at a time from `xs`, distances around `c`.
fn lanes_agree(mem: &Membership<'_>, m: &Metric, k: usize, c: &[f64], xs: &[[f64; 2]]) {
    for chunk in xs.chunks_exact(8) {
        let x8: Vec<X8> = (0..2)
            .map(|i| X8(std::array::from_fn(|l| chunk[l][i])))
            .collect();
        let (q, a) = quad_small(&m.upper(), &x8, c);
        let mask = mem.inside_by_shortcut_x8(m, k, &x8, q, a);
        for (l, x) in chunk.iter().enumerate() {
            let (q, a) = m.quad(x, c);
            let one = mem.inside_by_shortcut(m, k, x, q, a);
            assert_eq!(mask >> l & 1 == 1, one, "k = {k}, lane {l}, x = {x:?}");
        }
    }
}

/// States in and around the P-ball of radius `1.5 r_t` about the centre of each step, for
/// boxes and parallelotopes: the ball of radius `r_t` decides many of those outside the
/// deterministic set (`near_centre`), and every shortcut, in lanes or alone, agrees with
/// `Prs::contains_at`.
#[test]
fn the_ball_around_the_centre_decides_states_outside_the_set() {
    let mut rng = PathRng::new(8, 0);
    let mut by_ball = 0;
    for metric in [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]] {
        for r in [
            parallelotope(metric.clone()),
            result(Method::Interval, metric.clone(), false),
        ] {
            let m = Metric::new(&r.constants.metric, 2);
            let mem = Membership::new(&r, &m);
            for (k, st) in r.steps.iter().enumerate() {
                let c = st.nominal();
                let mut xs = Vec::new();
                for _ in 0..400 {
                    let dir = [rng.uniform() - 0.5, rng.uniform() - 0.5];
                    let (q1, _) = m.quad(&[c[0] + dir[0], c[1] + dir[1]], c);
                    let scale = 1.5 * rng.uniform() * st.r_t / q1.sqrt();
                    let x = [c[0] + scale * dir[0], c[1] + scale * dir[1]];
                    let (q, a) = m.quad(&x, c);
                    let exact = r.contains_at(k, &x);
                    assert_eq!(mem.inside(&m, k, &x, c, q, a), exact, "k = {k}");
                    if mem.inside_by_shortcut(&m, k, &x, q, a) {
                        assert!(exact, "k = {k}: shortcut");
                        let (lo, hi) = st.det.corners().expect("corners");
                        let y = match &r.transform {
                            Some(_) => [x[0] + 0.2 * x[1], x[0]],
                            None => x,
                        };
                        if (0..2).any(|i| y[i] < lo[i] || y[i] > hi[i]) {
                            by_ball += 1;
                        }
                    }
                    xs.push(x);
                }
                lanes_agree(&mem, &m, k, c, &xs);
            }
        }
    }
    // Not vacuous.
    assert!(by_ball > 1000, "{by_ball}");
}

/// Points near the faces of the parallelotopes, just inside and just outside: the
/// shortcut's "inside" always agrees with `Prs::contains_at`.
#[test]
fn the_parallelotope_shortcut_agrees_with_contains() {
    let mut rng = PathRng::new(6, 0);
    let mut shortcut = 0;
    for metric in [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]] {
        let r = parallelotope(metric);
        let m = Metric::new(&r.constants.metric, 2);
        let mem = Membership::new(&r, &m);
        assert!(mem.has_shortcuts());
        for (k, st) in r.steps.iter().enumerate() {
            let DetSet::Parallelotope { lo, hi, .. } = &st.det else {
                panic!("a parallelotope")
            };
            let mut xs = Vec::new();
            for i in 0..400 {
                // y uniform in the box, then one coordinate moved to a face, off by a few
                // ulps to a relative 1e-6 either way.
                let mut y: Vec<f64> = (0..2)
                    .map(|j| lo[j] + (hi[j] - lo[j]) * rng.uniform())
                    .collect();
                let j = i % 2;
                let face = if rng.uniform() < 0.5 { lo[j] } else { hi[j] };
                let off = (rng.uniform() - 0.5) * [1e-15, 1e-12, 1e-6, 0.0][i / 2 % 4];
                y[j] = face * (1.0 + off);
                let x = [y[1], 5.0 * (y[0] - y[1])];
                xs.push(x);
                let (q, a) = m.quad(&x, st.nominal());
                let exact = r.contains_at(k, &x);
                assert_eq!(mem.inside(&m, k, &x, st.nominal(), q, a), exact, "k = {k}");
                if mem.inside_by_shortcut(&m, k, &x, q, a) {
                    assert!(exact, "k = {k}: shortcut");
                    shortcut += 1;
                }
            }
            lanes_agree(&mem, &m, k, st.nominal(), &xs);
        }
    }
    // Not vacuous: points off the faces by 1e-6 are decided by the shortcut.
    assert!(shortcut > 500, "{shortcut}");
}

/// Points at relative P-distances from far inside to far outside, many within rounding of
/// the boundary: the shortcuts never disagree with `Prs::contains_at`, for every shape
/// (the zonotopes of [`zonotopes`] too).
#[test]
fn shortcuts_agree_with_contains() {
    let mut rng = PathRng::new(5, 0);
    let zonotopes = [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]]
        .iter()
        .flat_map(|metric| zonotopes(metric))
        .map(|(name, r)| (format!("zonotope {name}"), r))
        .collect::<Vec<_>>();
    let cases = methods_and_metrics()
        .into_iter()
        .map(|(method, metric, members)| (format!("{method:?}"), result(method, metric, members)))
        .chain(zonotopes);
    for (case, r) in cases {
        let m = Metric::new(&r.constants.metric, 2);
        let mem = Membership::new(&r, &m);
        for (k, st) in r.steps.iter().enumerate() {
            let c = st.nominal();
            let mut xs = Vec::new();
            for i in 0..400 {
                // A random direction, scaled to a P-distance s * prs_radius.
                let dir = [rng.uniform() - 0.5, rng.uniform() - 0.5];
                let (q1, _) = m.quad(&[c[0] + dir[0], c[1] + dir[1]], c);
                let s = match i % 4 {
                    0 => 1.0 + (rng.uniform() - 0.5) * 1e-12,
                    1 => 1.0 + (rng.uniform() - 0.5) * 1e-6,
                    2 => rng.uniform() * 2.0,
                    _ => 0.9 + rng.uniform() * 0.2,
                };
                let scale = s * st.prs_radius / q1.sqrt();
                let x = [c[0] + scale * dir[0], c[1] + scale * dir[1]];
                xs.push(x);
                let (q, a) = m.quad(&x, c);
                assert_eq!((q, a), quad_small(&m.upper(), &x, c));
                let fast = mem.inside(&m, k, &x, c, q, a);
                let exact = r.contains_at(k, &x);
                assert_eq!(fast, exact, "{case} k = {k} s = {s}");
                if mem.inside_by_shortcut(&m, k, &x, q, a)
                    || mem.inside_below(k).is_some_and(|b| q < b)
                {
                    assert!(exact, "{case} k = {k} s = {s}: shortcut");
                }
            }
            lanes_agree(&mem, &m, k, c, &xs);
        }
    }
}

/// Points `c + G xi + w` around every zonotope of [`zonotopes`]: `xi` in the cube with one
/// coordinate at a face, off by a few ulps to a relative 1e-6 either way or well beyond,
/// and `w` of P-norm from 0 to 1.5 times `remainder + r_t`. Every decision (alone, in
/// lanes, by the shortcut) agrees with `Prs::contains_at`; the shortcut decides most of the
/// states inside, and `contains_at` finds the states built inside (by a relative 1e-9 of
/// the radius) inside (at `t = 0`, where the radius is 0, those of the basis'
/// parallelotope; the flat zonotope has no basis, and its shortcut is the ball around the
/// centre alone).
#[test]
fn the_zonotope_shortcut_agrees_with_contains() {
    let mut rng = PathRng::new(9, 0);
    for metric in [vec![1.0, 0.0, 0.0, 1.0], vec![2.0, 0.7, 0.7, 1.0]] {
        for (name, r) in zonotopes(&metric) {
            let m = Metric::new(&r.constants.metric, 2);
            let mem = Membership::new(&r, &m);
            assert!(mem.has_shortcuts(), "{name}");
            let z = r.also.first().unwrap_or(&r);
            let zm = Metric::new(&z.constants.metric, 2);
            let (mut built_in, mut found_in, mut by_shortcut, mut inside) = (0, 0, 0, 0);
            for (k, st) in z.steps.iter().enumerate() {
                let DetSet::Zonotope {
                    center,
                    generators,
                    remainder,
                    ..
                } = &st.det
                else {
                    // The initial box (shortcuts_agree_with_contains checks it).
                    continue;
                };
                let radius = remainder + st.r_t;
                let gens: Vec<&[f64]> = generators.chunks(2).collect();
                let c = r.steps[k].nominal();
                let mut xs = Vec::new();
                for i in 0..400 {
                    let mut xi: Vec<f64> = gens.iter().map(|_| 2.0 * rng.uniform() - 1.0).collect();
                    let j = i % gens.len();
                    let face = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                    let off = [1e-15, 1e-12, 1e-6, 0.3, 0.0][i / 2 % 5];
                    xi[j] = face * (1.0 + (rng.uniform() - 0.5) * off);
                    if i % 7 == 0 {
                        // Inside: away from the faces.
                        xi[j] = (rng.uniform() - 0.5) * 1.8;
                    }
                    let dir = [rng.uniform() - 0.5, rng.uniform() - 0.5];
                    let (q1, _) = zm.quad(&dir, &[0.0, 0.0]);
                    let s = 1.5 * rng.uniform();
                    let w = s * radius / q1.sqrt();
                    let x: Vec<f64> = (0..2)
                        .map(|d| {
                            center[d]
                                + gens.iter().zip(&xi).map(|(g, v)| g[d] * v).sum::<f64>()
                                + w * dir[d]
                        })
                        .collect();
                    let x = [x[0], x[1]];
                    xs.push(x);
                    let (q, a) = m.quad(&x, c);
                    let exact = r.contains_at(k, &x);
                    assert_eq!(mem.inside(&m, k, &x, c, q, a), exact, "{name} k = {k}");
                    if mem.inside_by_shortcut(&m, k, &x, q, a) {
                        assert!(exact, "{name} k = {k}: shortcut");
                        by_shortcut += 1;
                    }
                    inside += u64::from(exact);
                    let cube = xi.iter().all(|v| v.abs() <= 1.0 - 1e-9);
                    // With radius 0 (t = 0) only the basis' parallelotope is certain: a
                    // point of the zonotope outside it has no certified neighbour.
                    let certain = radius > 0.0 || gens.len() == 2;
                    if cube && s < 1.0 - 1e-9 && r.also.is_empty() && certain {
                        built_in += 1;
                        found_in += u64::from(exact);
                    }
                }
                lanes_agree(&mem, &m, k, c, &xs);
            }
            eprintln!(
                "{name}: {by_shortcut} by the shortcut, {inside} inside; {found_in} of \
                 {built_in} built inside found"
            );
            assert!(
                by_shortcut > inside / 2,
                "{name}: {by_shortcut} of {inside}"
            );
            if name != "member" {
                assert_eq!(found_in, built_in, "{name}");
                assert!(built_in > 500, "{name}: {built_in}");
            }
        }
    }
}
/// A hand-made result in `n` states with a zonotope of `n` random generators (entries up
/// to 0.15) at each of `steps` report times, a random metric `A' A + I / 2`, `r_t = 0.05`
/// and a remainder of 0.01; and `count` states `c + G xi + w` at random report steps, `xi`
/// uniform in the cube and `w` Gaussian scaled to a P-norm of about 0.8 of
/// `remainder + r_t` (inside the PRS, most in the shell around the zonotope that its
/// shortcut does not decide).
fn high_dimensional(n: usize, steps: usize, count: usize) -> (Prs, Vec<(usize, Vec<f64>)>) {
    let mut rng = PathRng::new(n as u64, 0);
    let normal = |rng: &mut PathRng| {
        let u = rng.uniform_open0();
        box_muller(u, rng.uniform())
    };
    let mut r = result(Method::Interval, vec![1.0, 0.0, 0.0, 1.0], false);
    let a: Vec<f64> = (0..n * n).map(|_| rng.uniform() - 0.5).collect();
    let p: Vec<f64> = (0..n * n)
        .map(|v| {
            let (i, j) = (v / n, v % n);
            let aa: f64 = (0..n).map(|l| a[l * n + i] * a[l * n + j]).sum();
            aa + if i == j { 0.5 } else { 0.0 }
        })
        .collect();
    r.states = (0..n).map(|i| format!("x{i}")).collect();
    r.constants.metric = p.clone();
    let template = r.steps[1].clone();
    r.steps = (0..steps)
        .map(|k| {
            let center: Vec<f64> = (0..n).map(|_| rng.uniform()).collect();
            let generators: Vec<f64> = (0..n * n).map(|_| 0.3 * (rng.uniform() - 0.5)).collect();
            let (hull_lo, hull_hi) = zonotope::hull(&center, &generators);
            let (r_t, remainder) = (0.05, 0.01);
            let up = |a: f64, b: f64| (Interval::point(a) + Interval::point(b)).hi();
            let radius = up(zonotope::p_radius(&p, n, &generators), remainder);
            let mut st = template.clone();
            st.t = k as f64;
            st.r_t = r_t;
            st.prs_radius = up(radius, r_t);
            st.span.lo.clone_from(&hull_lo);
            st.span.hi.clone_from(&hull_hi);
            st.det = DetSet::Zonotope {
                center,
                generators,
                remainder,
                hull_lo,
                hull_hi,
                radius,
            };
            st
        })
        .collect();
    let m = Metric::new(&p, n);
    let states = (0..count)
        .map(|i| {
            let k = i % steps;
            let st = &r.steps[k];
            let gens: Vec<&[f64]> = st.det.generators();
            let xi: Vec<f64> = (0..n).map(|_| 2.0 * rng.uniform() - 1.0).collect();
            let w: Vec<f64> = (0..n).map(|_| normal(&mut rng)).collect();
            let (qw, _) = m.quad(&w, &vec![0.0; n]);
            let s = 0.8 * (st.det.ball_added() + st.r_t) / qw.sqrt();
            let x = (0..n)
                .map(|d| {
                    let gx: f64 = gens.iter().zip(&xi).map(|(g, v)| g[d] * v).sum();
                    st.det.center()[d] + gx + s * w[d]
                })
                .collect();
            (k, x)
        })
        .collect();
    (r, states)
}

/// States `x` of [`high_dimensional`] against their step's PRS: `(inside, by the
/// shortcut)` counts, each decision asserted equal to `Prs::contains_at`'s.
fn decide(r: &Prs, states: &[(usize, Vec<f64>)]) -> (usize, usize) {
    let m = Metric::new(&r.constants.metric, r.n());
    let mem = Membership::new(r, &m);
    let (mut inside, mut by_shortcut) = (0, 0);
    for (k, x) in states {
        let c = r.steps[*k].nominal();
        let (q, a) = m.quad(x, c);
        let shortcut = mem.inside_by_shortcut(&m, *k, x, q, a);
        let decided = shortcut || mem.inside(&m, *k, x, c, q, a);
        assert_eq!(decided, r.contains_at(*k, x), "k = {k}, x = {x:?}");
        inside += usize::from(decided);
        by_shortcut += usize::from(shortcut);
    }
    (inside, by_shortcut)
}

/// Zonotopes of 2, 6 and 12 states: every state built inside the PRS (by a fifth of the
/// ball's radius) is found inside, by the same decisions as `Prs::contains_at`'s.
#[test]
fn high_dimensional_zonotopes_hold_their_states() {
    for n in [2, 6, 12] {
        let (r, states) = high_dimensional(n, 20, 1000);
        let (inside, by_shortcut) = decide(&r, &states);
        assert_eq!(inside, states.len(), "n = {n}");
        assert!(by_shortcut > states.len() / 4, "n = {n}: {by_shortcut}");
    }
}
