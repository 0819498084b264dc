//! Coordinate transforms `y = T x` of the interval method (method.md, section 6).
//!
//! The transformed system is built symbolically: every state `x_i` is replaced by
//! `(T^-1 y)_i`, and the drift and diffusion become `f_y(y, u, t) = T f(T^-1 y, u, t)` and
//! `G_y(y, t) = T G(T^-1 y, t)`, rebuilt through the pool's simplifying constructors. The
//! simplification is the point: linear terms of `T f(T^-1 y)` merge (for the paper's pendulum,
//! `y1' = -15 y1 + 11 y2 + 2 sin(y2)`), so each `y_i` occurs once where the unsimplified
//! composition repeats it, and the natural inclusion stays tight instead of diverging.
//!
//! Nothing is rounded: `T^-1` is the exact inverse of the floating-point `T` (rational
//! elimination), each entry a constant or an enclosure of it, and the pool folds the combined
//! coefficients without silent rounding (`ir/fold.rs`). So the interval forms of the frame
//! enclose `T f(T^-1 y)` exactly as the model's enclose `f` (method.md section 6).

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{ToPrimitive, Zero};
use reachc_core::interval::Interval;

use super::Derivatives;
use crate::ir::{ExprId, Pool, Var};
use crate::model::{Model, Transform};

/// A transformed system `y = T x`: its drift, diffusion and Jacobians, as expressions of the
/// model's pool in which `Var::State(j)` stands for `y_j`.
#[derive(Clone, Debug)]
pub struct Frame {
    /// `T` and `T^-1`.
    pub transform: Transform,
    /// `f_y`, one per coordinate `y_i`.
    pub drift: Vec<ExprId>,
    /// `G_y[i][k]`.
    pub diffusion: Vec<Vec<ExprId>>,
    /// `D_y f_y`, `D_u f_y` and `D_y G_y`.
    pub derivatives: Derivatives,
}

impl Frame {
    /// Builds the transformed system of `model` (adding its expressions to the model's pool).
    /// `None` if `T` is singular or an entry of its exact inverse is beyond the floating-point
    /// range (the checker refuses such a `T` first).
    pub fn of(model: &mut Model, transform: &Transform) -> Option<Frame> {
        let (n, p) = (model.states.len(), model.inputs.len());
        let pool = &mut model.pool;
        let ys: Vec<ExprId> = (0..n as u32).map(|j| pool.var(Var::State(j))).collect();
        // x_i = sum_j (T^-1)_ij y_j, with the exact entries of T^-1.
        let inverse: Vec<ExprId> = exact_inverse(&transform.matrix, n)?
            .iter()
            .map(|q| {
                let (approx, exact) = enclose(q)?;
                Some(pool.enclosure(approx, exact))
            })
            .collect::<Option<_>>()?;
        let xs: Vec<ExprId> = inverse
            .chunks(n)
            .map(|row| combine(pool, row, &ys))
            .collect();
        let substituted = |pool: &mut crate::ir::Pool, e: ExprId| {
            pool.substitute(e, &mut |v| match v {
                Var::State(i) => Some(xs[i as usize]),
                _ => None,
            })
        };
        let f: Vec<ExprId> = model.drift.iter().map(|&e| substituted(pool, e)).collect();
        let g: Vec<Vec<ExprId>> = model
            .diffusion
            .iter()
            .map(|row| row.iter().map(|&e| substituted(pool, e)).collect())
            .collect();
        let m = model.noises.len();
        let t: Vec<ExprId> = transform.matrix.iter().map(|&c| pool.num(c)).collect();
        let drift: Vec<ExprId> = t.chunks(n).map(|row| combine(pool, row, &f)).collect();
        let diffusion: Vec<Vec<ExprId>> = t
            .chunks(n)
            .map(|row| {
                (0..m)
                    .map(|k| {
                        let column: Vec<ExprId> = g.iter().map(|g_row| g_row[k]).collect();
                        combine(pool, row, &column)
                    })
                    .collect()
            })
            .collect();
        let derivatives = Derivatives::of_exprs(pool, n, p, &drift, &diffusion);
        Some(Frame {
            transform: transform.clone(),
            drift,
            diffusion,
            derivatives,
        })
    }
}

/// `sum_j coef_j e_j` for constant coefficients (exact or enclosed), simplified (zero
/// coefficients dropped).
fn combine(pool: &mut Pool, coefs: &[ExprId], es: &[ExprId]) -> ExprId {
    let mut terms: Vec<ExprId> = Vec::with_capacity(es.len());
    for (&c, &e) in coefs.iter().zip(es) {
        if pool.as_const(c) != Some(0.0) {
            terms.push(pool.mul(c, e));
        }
    }
    pool.sum(&terms)
}

/// The exact inverse of the `n x n` row-major matrix of floats `t` (every float is a rational),
/// by Gauss-Jordan elimination in rationals; `None` if `t` is singular.
fn exact_inverse(t: &[f64], n: usize) -> Option<Vec<BigRational>> {
    let mut a: Vec<Vec<BigRational>> = (0..n)
        .map(|i| {
            let mut row: Vec<BigRational> = t[i * n..(i + 1) * n]
                .iter()
                .map(|&v| BigRational::from_float(v))
                .collect::<Option<_>>()?;
            row.extend((0..n).map(|j| BigRational::from_integer(BigInt::from(u8::from(i == j)))));
            Some(row)
        })
        .collect::<Option<_>>()?;
    for col in 0..n {
        let pivot = (col..n).find(|&r| !a[r][col].is_zero())?;
        a.swap(col, pivot);
        let inv = a[col][col].recip();
        for v in a[col].iter_mut() {
            *v *= &inv;
        }
        for r in 0..n {
            if r != col && !a[r][col].is_zero() {
                let factor = a[r][col].clone();
                let pivot_row = a[col].clone();
                for (v, p) in a[r].iter_mut().zip(&pivot_row) {
                    *v -= &factor * p;
                }
            }
        }
    }
    Some(
        a.into_iter()
            .flat_map(|row| row.into_iter().skip(n))
            .collect(),
    )
}

/// The nearest float of `q` (as far as `to_f64` rounds) and the tightest float interval holding
/// it (a point when `q` is a float); `None` beyond the floating-point range.
fn enclose(q: &BigRational) -> Option<(f64, Interval)> {
    let approx = q.to_f64().filter(|v| v.is_finite())?;
    let exact = |v: f64| BigRational::from_float(v);
    let (mut lo, mut hi) = (approx, approx);
    while exact(lo)? > *q {
        lo = lo.next_down();
    }
    while exact(hi)? < *q {
        hi = hi.next_up();
    }
    (lo.is_finite() && hi.is_finite()).then(|| (approx, Interval::new(lo, hi)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::driver::check_source;
    use crate::ir::Names;
    use reachc_test_support::rng::XorShift64;

    fn pendulum() -> Model {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../specs");
        let src = std::fs::read_to_string(dir.join("pendulum.sde")).unwrap();
        check_source(&src, &dir).0.unwrap()
    }

    /// `q` lies in the interval `iv` (exact comparison).
    fn holds(iv: Interval, q: &BigRational) -> bool {
        BigRational::from_float(iv.lo()).unwrap() <= *q
            && *q <= BigRational::from_float(iv.hi()).unwrap()
    }

    /// A polynomial model in `y = T x` with a `T` whose inverse is not a float matrix: the
    /// frame's interval drift and Jacobian at points `y` hold the exact `T f(T^-1 y)` and its
    /// derivative, computed in rational arithmetic (nothing rounded).
    #[test]
    fn frame_encloses_the_exact_transformed_drift() {
        let src = "model m\nstate a in [0, 1]\nstate b in [0, 1]\n\
                   drift {\n a' = -a + 0.3 * b^2 + 0.1\n b' = 0.7 * a - 2 * b + a * b / 3\n}\n\
                   analysis box {\n method = interval\n transform = [[1, 0.2], [0.3, 1]]\n\
                   metric = auto\n delta = 0.01\n horizon = 1\n step = 0.1\n}\n";
        let (model, diags) = check_source(src, std::path::Path::new("."));
        let mut model = model.unwrap_or_else(|| panic!("{diags:?}"));
        let t = model.analyses[0].spec.transform.clone().unwrap();
        let frame = Frame::of(&mut model, &t).unwrap();
        let q = |v: f64| BigRational::from_float(v).unwrap();
        let tinv = exact_inverse(&t.matrix, 2).unwrap();
        // The coefficients are enclosures, not floats (the test would be vacuous otherwise).
        assert!(model
            .pool
            .reachable(&frame.drift)
            .iter()
            .any(|&id| matches!(model.pool.node(id), crate::ir::Node::Enclosure { .. })));
        let mut roots = frame.drift.clone();
        roots.extend(frame.derivatives.jac_x.iter().flatten());
        let mut rng = XorShift64(0x2545_f491_4f6c_dd1d);
        let mut next = || rng.range(-2.0, 2.0);
        for _ in 0..200 {
            let y = [next(), next()];
            let ys = [Interval::point(y[0]), Interval::point(y[1])];
            let vars = crate::ir::VarValues {
                states: &ys[..],
                inputs: &[],
                noises: &[],
                time: Interval::ZERO,
            };
            let got = model.pool.eval(&roots, &vars, &model.tables);
            // x = T^-1 y and f(x), exactly.
            let x: Vec<BigRational> = (0..2)
                .map(|i| &tinv[2 * i] * q(y[0]) + &tinv[2 * i + 1] * q(y[1]))
                .collect();
            let three = BigRational::from_integer(3.into());
            let f = [
                -&x[0] + q(0.3) * &x[1] * &x[1] + q(0.1),
                q(0.7) * &x[0] - q(2.0) * &x[1] + &x[0] * &x[1] / &three,
            ];
            // D_x f, then T f and T (D_x f) T^-1.
            let jf = [
                [
                    -BigRational::from_integer(1.into()),
                    q(0.3) * q(2.0) * &x[1],
                ],
                [q(0.7) + &x[1] / &three, -q(2.0) + &x[0] / &three],
            ];
            for i in 0..2 {
                let fy = q(t.matrix[2 * i]) * &f[0] + q(t.matrix[2 * i + 1]) * &f[1];
                assert!(holds(got[i], &fy), "y = {y:?}: {} misses {fy}", got[i]);
                for j in 0..2 {
                    let mut d = BigRational::zero();
                    for (k, row) in jf.iter().enumerate() {
                        for (l, entry) in row.iter().enumerate() {
                            d += q(t.matrix[2 * i + k]) * entry * &tinv[2 * l + j];
                        }
                    }
                    let g = got[2 + 2 * i + j];
                    assert!(holds(g, &d), "y = {y:?}: J[{i}][{j}] {g} misses {d}");
                    assert!(g.width() <= 1e-13 * (1.0 + g.mag()), "{g} too wide");
                }
                assert!(got[i].width() <= 1e-13 * (1.0 + got[i].mag()));
            }
        }
    }

    /// The paper's pendulum in `y = T x` simplifies to one occurrence of each `y_i` per term:
    /// `y1' = -15 y1 + 11 y2 + 2 sin(y2)` (up to rounding of the folded coefficients).
    #[test]
    fn pendulum_frame_is_simplified() {
        let mut model = pendulum();
        let t = model.analyses[1].spec.transform.clone().unwrap();
        let frame = Frame::of(&mut model, &t).unwrap();
        let names = ["y1".to_string(), "y2".to_string()];
        let noises = ["w".to_string()];
        let sde = Names {
            states: &names,
            inputs: &[],
            noises: &noises,
            tables: &model.tables,
        };
        let printed: Vec<String> = frame
            .drift
            .iter()
            .map(|&e| model.pool.to_sde(e, &sde))
            .collect();
        // Each y_j occurs once per equation (the composition repeats y2 in theta and omega).
        // (The coefficients are enclosures: `T^-1` has the entries 1/fl(0.2) = 4.999..., so
        // `-15` is an enclosure of 1/fl(0.2) - 20, printed as its float.)
        assert_eq!(printed, ["2*sin(y2) + 11*y2 - 15*y1", "5*y1 - 5*y2"]);
    }

    /// `f_y(y) = T f(T^-1 y)` and `G_y = T G(T^-1 y)` by value at random points, and the frame's
    /// Jacobian against central differences.
    #[test]
    fn frame_matches_composition_and_differences() {
        let mut model = pendulum();
        let t = model.analyses[1].spec.transform.clone().unwrap();
        let frame = Frame::of(&mut model, &t).unwrap();
        let eval = |model: &Model, roots: &[ExprId], x: &[f64]| -> Vec<f64> {
            let vars = crate::ir::VarValues {
                states: x,
                inputs: &[],
                noises: &[],
                time: 0.0,
            };
            let order = model.pool.reachable(roots);
            model.pool.eval_ordered(&order, roots, &vars, &model.tables)
        };
        let mut rng = XorShift64(0x9e37_79b9_7f4a_7c15);
        let mut next = || rng.range(-2.0, 2.0);
        for _ in 0..50 {
            let y = [next(), next()];
            let x: Vec<f64> = t
                .inverse
                .chunks(2)
                .map(|r| r[0] * y[0] + r[1] * y[1])
                .collect();
            let f = eval(&model, &model.drift, &x);
            let fy = eval(&model, &frame.drift, &y);
            for i in 0..2 {
                let want = t.matrix[2 * i] * f[0] + t.matrix[2 * i + 1] * f[1];
                assert!((fy[i] - want).abs() <= 1e-12 * (1.0 + want.abs()), "{fy:?}");
            }
            let g = eval(&model, &[model.diffusion[1][0]], &x)[0];
            let gy: Vec<ExprId> = frame.diffusion.iter().map(|r| r[0]).collect();
            let gy = eval(&model, &gy, &y);
            for (gyi, row) in gy.iter().zip(t.matrix.chunks(2)) {
                assert!((gyi - row[1] * g).abs() <= 1e-15);
            }
            let h = 1e-6;
            for j in 0..2 {
                let (mut yp, mut ym) = (y, y);
                yp[j] += h;
                ym[j] -= h;
                let (fp, fm) = (
                    eval(&model, &frame.drift, &yp),
                    eval(&model, &frame.drift, &ym),
                );
                let jac: Vec<ExprId> = frame.derivatives.jac_x.iter().map(|r| r[j]).collect();
                let jac = eval(&model, &jac, &y);
                for i in 0..2 {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    assert!(
                        (jac[i] - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                        "{jac:?} {fd}"
                    );
                }
            }
        }
    }
}
