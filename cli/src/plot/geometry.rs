//! The sets of a result in a 2-D projection, exactly: the projection of a Minkowski sum is the
//! sum of the projections, and every set involved projects to something with a closed-form
//! support function.
//!
//! - A box or a parallelotope `{x = T^-1 y : lo <= y <= hi}` projects to a zonogon
//!   `c + sum_j s_j g_j`, `|s_j| <= 1`, with one generator per column of `T^-1` (the box: per
//!   state): `h(d) = c . d + sum_j |g_j . d|`. So does a zonotope, with its generators
//!   projected.
//! - A P-ball `{x : (x - c)' P (x - c) <= R^2}` projects to the ellipse with the same `R` and
//!   shape `S`, the 2 x 2 block of `P^-1` on the plotted states: `h(d) = c . d + R sqrt(d' S d)`.
//!   A first-order set, a zonotope plus `B_P(remainder)`, is the sum of its zonogon and that
//!   ellipse.
//!
//! The PRS is the deterministic set plus `B_P(r_t)`, so its support function is the sum. Its
//! boundary is drawn as the polygon cut out by the support lines in many directions, always
//! including the edge normals of the zonogon: a polygon that contains the set, with the
//! zonogon's vertices exact and the curved parts tight to within the angular spacing.

use std::f64::consts::{PI, TAU};

use nalgebra::{DMatrix, DVector};

/// A point or direction in the plane.
pub type Point = [f64; 2];

/// Number of evenly spaced directions of a boundary polygon (plus the zonogon's edge normals).
const DIRECTIONS: usize = 720;
/// Edge normals closer than this (radians) are one.
const MERGE: f64 = 1e-9;
/// Evenly spaced directions closer than this to an edge normal are left out.
const GAP: f64 = 1e-6;

/// A convex set in the plane: a zonogon plus an ellipse (either may be absent).
#[derive(Clone, Debug, PartialEq)]
pub struct Projected {
    /// The centre.
    pub center: Point,
    /// Zonogon generators `g_j` (the set contains `center + sum_j s_j g_j`, `|s_j| <= 1`).
    pub generators: Vec<Point>,
    /// The ellipse part: its shape `S` (symmetric positive semidefinite) and radius `R`, the
    /// set `{S^(1/2) z : |z| <= R}`.
    pub ellipse: Option<([[f64; 2]; 2], f64)>,
}

impl Projected {
    /// The support function `h(d) = max {d . z : z in the set}`.
    pub fn support(&self, d: Point) -> f64 {
        let zonogon: f64 = self.generators.iter().map(|g| dot(*g, d).abs()).sum();
        let ellipse = self.ellipse.map_or(0.0, |(s, r)| r * quad(s, d).sqrt());
        dot(self.center, d) + zonogon + ellipse
    }

    /// The same set plus the ellipse `{S^(1/2) z : |z| <= r}` (`S` must be this set's ellipse
    /// shape when it has one: the sum of two ellipses is an ellipse only for a common shape).
    pub fn plus_ellipse(&self, shape: [[f64; 2]; 2], r: f64) -> Projected {
        let radius = self.ellipse.map_or(0.0, |(_, r0)| r0) + r;
        Projected {
            ellipse: Some((shape, radius)),
            ..self.clone()
        }
    }

    /// The boundary polygon (counter-clockwise): the intersection of the support half-planes in
    /// 720 evenly spaced directions and the zonogon's edge normals, so it contains
    /// the set and has the zonogon's vertices exactly.
    pub fn polygon(&self) -> Vec<Point> {
        // The edge normals first: with them the zonogon's vertices are exact.
        let mut normals: Vec<f64> = Vec::new();
        for g in self
            .generators
            .iter()
            .filter(|g| g[0] != 0.0 || g[1] != 0.0)
        {
            let a = g[0].atan2(-g[1]).rem_euclid(TAU);
            normals.extend([a, (a + PI).rem_euclid(TAU)]);
        }
        normals.sort_by(f64::total_cmp);
        // Parallel generators share their edges.
        normals.dedup_by(|b, a| *b - *a < MERGE);
        if normals.len() > 1 && normals[0] + TAU - normals[normals.len() - 1] < MERGE {
            normals.pop();
        }
        // Evenly spaced directions, except next to an edge normal: two almost parallel support
        // lines intersect ill-conditioned (and add no vertex there).
        let near = |a: f64| {
            normals.iter().any(|&n| {
                let d = (a - n).rem_euclid(TAU);
                d.min(TAU - d) < GAP
            })
        };
        let mut angles: Vec<f64> = (0..DIRECTIONS)
            .map(|k| TAU * k as f64 / DIRECTIONS as f64)
            .filter(|&a| !near(a))
            .chain(normals.iter().copied())
            .collect();
        angles.sort_by(f64::total_cmp);
        let lines: Vec<(Point, f64)> = angles
            .iter()
            .map(|&a| {
                let d = [a.cos(), a.sin()];
                (d, self.support(d))
            })
            .collect();
        // A polytope gives the same vertex for all directions in its normal cone: such
        // repeats (equal up to rounding, relative to the set's size) are dropped.
        let size = self.support([1.0, 0.0])
            + self.support([-1.0, 0.0])
            + self.support([0.0, 1.0])
            + self.support([0.0, -1.0]);
        let tol = 1e-9 * (size + self.center[0].abs() + self.center[1].abs());
        let same = |p: Point, q: Point| (p[0] - q[0]).abs().max((p[1] - q[1]).abs()) <= tol;
        let mut poly: Vec<Point> = Vec::with_capacity(lines.len());
        for k in 0..lines.len() {
            let (d1, h1) = lines[k];
            let (d2, h2) = lines[(k + 1) % lines.len()];
            let det = d1[0] * d2[1] - d1[1] * d2[0];
            let v = [
                (h1 * d2[1] - h2 * d1[1]) / det,
                (d1[0] * h2 - d2[0] * h1) / det,
            ];
            if poly.last().is_none_or(|&p| !same(p, v)) {
                poly.push(v);
            }
        }
        while poly.len() > 1 && same(poly[0], poly[poly.len() - 1]) {
            poly.pop();
        }
        poly
    }
}

/// The plane of two states `(a, b)` and the 2 x 2 block of `P^-1` there.
#[derive(Clone, Debug)]
pub struct Plane {
    /// The plotted states (horizontal, vertical).
    pub states: [usize; 2],
    /// The block of `P^-1` on the plotted states: the shape of every projected P-ball.
    pub shape: [[f64; 2]; 2],
}

impl Plane {
    /// The plane of states `states` for the metric `p` (`n x n`, by rows, positive definite);
    /// `None` if `p` is not positive definite.
    pub fn new(states: [usize; 2], p: &[Vec<f64>]) -> Option<Plane> {
        let n = p.len();
        let m = DMatrix::from_fn(n, n, |i, j| p[i][j]);
        let chol = nalgebra::Cholesky::new(m)?;
        // Columns a and b of P^-1 (two solves, not the whole inverse: n can be large).
        let col = |i: usize| {
            let mut e = DVector::zeros(n);
            e[i] = 1.0;
            chol.solve(&e)
        };
        let (ca, cb) = (col(states[0]), col(states[1]));
        let (a, b) = (states[0], states[1]);
        // Symmetrised: the two solves agree only up to rounding.
        let off = 0.5 * (ca[b] + cb[a]);
        Some(Plane {
            states,
            shape: [[ca[a], off], [off, cb[b]]],
        })
    }

    /// The plane of two states for drawing points only (when there is no metric): its shape
    /// is that of the identity metric.
    pub fn of_states(states: [usize; 2]) -> Plane {
        Plane {
            states,
            shape: [[1.0, 0.0], [0.0, 1.0]],
        }
    }

    /// The projection of a point.
    pub fn point(&self, x: &[f64]) -> Point {
        [x[self.states[0]], x[self.states[1]]]
    }

    /// The P-ball `{x : (x - c)' P (x - c) <= r^2}`.
    pub fn p_ball(&self, center: &[f64], r: f64) -> Projected {
        Projected {
            center: self.point(center),
            generators: Vec::new(),
            ellipse: Some((self.shape, r)),
        }
    }

    /// The box `{x : lo <= x <= hi}`.
    pub fn boxed(&self, lo: &[f64], hi: &[f64]) -> Projected {
        let [a, b] = self.states;
        Projected {
            center: [0.5 * (lo[a] + hi[a]), 0.5 * (lo[b] + hi[b])],
            generators: vec![[0.5 * (hi[a] - lo[a]), 0.0], [0.0, 0.5 * (hi[b] - lo[b])]],
            ellipse: None,
        }
    }

    /// The parallelotope `{x : lo <= T x <= hi}` given `T^-1` by rows.
    pub fn parallelotope(&self, lo: &[f64], hi: &[f64], t_inv: &[Vec<f64>]) -> Projected {
        let rows = [&t_inv[self.states[0]], &t_inv[self.states[1]]];
        let mid: Vec<f64> = lo.iter().zip(hi).map(|(l, h)| 0.5 * (l + h)).collect();
        let center = [dot_n(rows[0], &mid), dot_n(rows[1], &mid)];
        zonogon(
            center,
            (0..lo.len()).map(|j| {
                let half = 0.5 * (hi[j] - lo[j]);
                [half * rows[0][j], half * rows[1][j]]
            }),
        )
    }

    /// The zonotope `{c + sum_j xi_j g_j : |xi_j| <= 1}` plus the P-ball `B_P(remainder)`.
    pub fn zonotope(&self, center: &[f64], generators: &[Vec<f64>], remainder: f64) -> Projected {
        let z = zonogon(self.point(center), generators.iter().map(|g| self.point(g)));
        z.plus_ellipse(self.shape, remainder)
    }
}

/// The zonogon `center + sum_j s_j g_j`, `|s_j| <= 1` (generators of length 0 dropped).
fn zonogon(center: Point, generators: impl Iterator<Item = Point>) -> Projected {
    Projected {
        center,
        generators: generators.filter(|g| g[0] != 0.0 || g[1] != 0.0).collect(),
        ellipse: None,
    }
}

fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn dot_n(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `d' S d`, clamped at 0 (rounding).
fn quad(s: [[f64; 2]; 2], d: Point) -> f64 {
    (s[0][0] * d[0] * d[0] + 2.0 * s[0][1] * d[0] * d[1] + s[1][1] * d[1] * d[1]).max(0.0)
}

/// The half-planes `(n, c)` (`n . z <= c`) of a convex polygon with counter-clockwise vertices,
/// one per edge, for [`clip`]: the outward normal of edge `(p, q)` is `q - p` turned right.
pub fn half_planes(poly: &[Point]) -> Vec<(Point, f64)> {
    (0..poly.len())
        .map(|i| {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let n = [q[1] - p[1], p[0] - q[0]];
            (n, n[0] * p[0] + n[1] * p[1])
        })
        .collect()
}

/// Clips a polygon to the convex region `{z : n . z <= c}` of each `(n, c)` (Sutherland and
/// Hodgman); the result may be empty.
pub fn clip(poly: &[Point], planes: &[(Point, f64)]) -> Vec<Point> {
    let mut out = poly.to_vec();
    for &(n, c) in planes {
        let input = std::mem::take(&mut out);
        for (k, &p) in input.iter().enumerate() {
            let q = input[(k + 1) % input.len()];
            let (fp, fq) = (dot(n, p) - c, dot(n, q) - c);
            if fp <= 0.0 {
                out.push(p);
            }
            if (fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0) {
                let s = fp / (fp - fq);
                out.push([p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])]);
            }
        }
    }
    out
}

/// The half-planes of the rectangle `[x0, x1] x [y0, y1]`, for [`clip`].
pub fn rectangle(x: (f64, f64), y: (f64, f64)) -> [(Point, f64); 4] {
    [
        ([1.0, 0.0], x.1),
        ([-1.0, 0.0], -x.0),
        ([0.0, 1.0], y.1),
        ([0.0, -1.0], -y.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use reachc_test_support::rng::XorShift64 as Rng;

    fn mat_vec(m: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
        m.iter().map(|r| dot_n(r, v)).collect()
    }

    /// Is `z` in the convex polygon (counter-clockwise), up to `tol`?
    fn inside(poly: &[Point], z: Point, tol: f64) -> bool {
        (0..poly.len()).all(|k| {
            let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
            let cross = (q[0] - p[0]) * (z[1] - p[1]) - (q[1] - p[1]) * (z[0] - p[0]);
            cross >= -tol * ((q[0] - p[0]).hypot(q[1] - p[1]))
        })
    }

    /// `T^-1` of a 3-D parallelotope (invertible, no two columns parallel in any plane).
    fn t_inv() -> Vec<Vec<f64>> {
        vec![
            vec![1.0, 0.5, -1.0],
            vec![0.0, 1.0, 2.0],
            vec![0.3, 0.0, 1.0],
        ]
    }

    fn metric() -> Vec<Vec<f64>> {
        vec![
            vec![4.0, 1.0, 0.5],
            vec![1.0, 3.0, -0.2],
            vec![0.5, -0.2, 2.0],
        ]
    }

    #[test]
    fn parallelotope_support_is_the_max_over_its_vertices() {
        let (lo, hi) = ([-1.0, 0.5, -0.2], [2.0, 1.5, 0.3]);
        let plane = Plane::new([0, 2], &metric()).unwrap();
        let set = plane.parallelotope(&lo, &hi, &t_inv());
        let mut rng = Rng(7);
        for _ in 0..200 {
            let d = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
            // Brute force: every vertex y of the box, x = T^-1 y, projected.
            let brute = (0..8)
                .map(|mask: u32| {
                    let y: Vec<f64> = (0..3)
                        .map(|j| if mask >> j & 1 == 1 { hi[j] } else { lo[j] })
                        .collect();
                    dot(plane.point(&mat_vec(&t_inv(), &y)), d)
                })
                .fold(f64::NEG_INFINITY, f64::max);
            assert!((set.support(d) - brute).abs() < 1e-12, "{d:?}");
        }
    }

    #[test]
    fn projected_p_ball_support_matches_the_maximiser() {
        // max d . x over (x - c)' P (x - c) <= r^2 is at x = c + r P^-1 D / sqrt(D' P^-1 D),
        // D the direction lifted to R^3: check against P^-1 computed independently.
        let p = metric();
        let pm = DMatrix::from_fn(3, 3, |i, j| p[i][j]);
        let pinv = pm.clone().try_inverse().unwrap();
        let plane = Plane::new([2, 0], &p).unwrap();
        let (c, r) = ([0.3, -1.0, 2.0], 0.7);
        let ball = plane.p_ball(&c, r);
        let mut rng = Rng(3);
        for _ in 0..100 {
            let d = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
            let lift = DVector::from_vec(vec![d[1], 0.0, d[0]]);
            let w = &pinv * &lift;
            let x: Vec<f64> = (0..3)
                .map(|i| c[i] + r * w[i] / lift.dot(&w).sqrt())
                .collect();
            // The maximiser is on the ball's boundary, and attains the support value.
            let dx = DVector::from_vec((0..3).map(|i| x[i] - c[i]).collect());
            assert!((dx.dot(&(&pm * &dx)) - r * r).abs() < 1e-12);
            assert!((ball.support(d) - dot(plane.point(&x), d)).abs() < 1e-12);
        }
    }

    /// Checks `prs`, the projection onto `plane` of `conv(vertices) (+) B_P(r)` (`p` the
    /// metric, the vertices in three states, `sample` a random point of the polytope): its
    /// polygon holds sampled points of the set (the ball's by `P = L L'`, `x = L^-T z` with
    /// `|z| <= r`, half of them on its boundary); points on the set's boundary (a maximising
    /// vertex plus the maximiser over `B_P(r)` of the lifted direction) are inside and near the
    /// edges; no vertex of the polygon lies beyond the support function by more than the
    /// angular spacing allows.
    fn check_polygon(
        plane: &Plane,
        p: &[Vec<f64>],
        prs: &Projected,
        vertices: &[Vec<f64>],
        r: f64,
        sample: &mut dyn FnMut(&mut Rng) -> Vec<f64>,
    ) {
        let poly = prs.polygon();
        let pm = DMatrix::from_fn(3, 3, |i, j| p[i][j]);
        let l = nalgebra::Cholesky::new(pm.clone()).unwrap().l();
        let mut rng = Rng(11);
        for _ in 0..20_000 {
            let y = sample(&mut rng);
            let mut z = DVector::from_vec(vec![
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ]);
            let scale = if rng.uniform() < 0.5 {
                r
            } else {
                r * rng.uniform()
            };
            z *= scale / z.norm();
            let w = l.transpose().solve_upper_triangular(&z).unwrap();
            let x: Vec<f64> = y.iter().zip(w.iter()).map(|(a, b)| a + b).collect();
            let pt = plane.point(&x);
            assert!(inside(&poly, pt, 1e-9), "{pt:?} outside");
        }
        let pinv = pm.try_inverse().unwrap();
        for k in 0..500 {
            let a = std::f64::consts::TAU * (f64::from(k) + 0.5) / 500.0;
            let d = [a.cos(), a.sin()];
            let mut lift = DVector::zeros(3);
            lift[plane.states[0]] = d[0];
            lift[plane.states[1]] = d[1];
            let w = &pinv * &lift;
            let w = w.clone() * (r / lift.dot(&w).sqrt());
            let vertex = vertices
                .iter()
                .max_by(|u, v| dot(plane.point(u), d).total_cmp(&dot(plane.point(v), d)))
                .unwrap();
            let x: Vec<f64> = vertex.iter().zip(w.iter()).map(|(a, b)| a + b).collect();
            let pt = plane.point(&x);
            assert!(inside(&poly, pt, 1e-9), "{pt:?} outside");
            assert!(!inside(&poly, pt, -1e-4 * r), "{pt:?} far inside");
        }
        for k in 0..360 {
            let a = std::f64::consts::TAU * (k as f64 + 0.37) / 360.0;
            let d = [a.cos(), a.sin()];
            let h = poly
                .iter()
                .map(|&v| dot(v, d))
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(h >= prs.support(d) - 1e-9);
            assert!(
                h <= prs.support(d) + 1e-4 * r,
                "{k}: {h} vs {}",
                prs.support(d)
            );
        }
    }

    #[test]
    fn prs_polygon_contains_sampled_points_and_is_tight() {
        // PRS = parallelotope (+) B_P(r).
        let (lo, hi) = ([-1.0, 0.5, -0.2], [2.0, 1.5, 0.3]);
        let p = metric();
        let plane = Plane::new([0, 1], &p).unwrap();
        let r = 0.4;
        let prs = plane
            .parallelotope(&lo, &hi, &t_inv())
            .plus_ellipse(plane.shape, r);
        let corner = |mask: u32| -> Vec<f64> {
            (0..3)
                .map(|j| if mask >> j & 1 == 1 { hi[j] } else { lo[j] })
                .collect()
        };
        let vertices: Vec<Vec<f64>> = (0..8).map(|m| mat_vec(&t_inv(), &corner(m))).collect();
        check_polygon(&plane, &p, &prs, &vertices, r, &mut |rng| {
            let y: Vec<f64> = (0..3)
                .map(|j| lo[j] + (hi[j] - lo[j]) * rng.uniform())
                .collect();
            mat_vec(&t_inv(), &y)
        });
    }

    /// A zonotope of four generators in three states (centre `c`, generators `g`).
    fn zonotope() -> (Vec<f64>, Vec<Vec<f64>>) {
        let g = vec![
            vec![1.0, 0.2, -0.5],
            vec![0.3, -0.8, 0.4],
            vec![-0.2, 0.1, 0.9],
            vec![0.5, 0.5, 0.5],
        ];
        (vec![0.5, -1.0, 2.0], g)
    }

    /// The point `c + sum_j xi_j g_j`.
    fn zonotope_point(c: &[f64], g: &[Vec<f64>], xi: &[f64]) -> Vec<f64> {
        (0..3)
            .map(|i| c[i] + g.iter().zip(xi).map(|(g, v)| g[i] * v).sum::<f64>())
            .collect()
    }

    /// A first-order set `Z (+) B_P(remainder)` plus `B_P(r_t)`: its support is the
    /// zonotope's (the largest over its 16 vertices, projected) plus
    /// `(remainder + r_t) sqrt(d' S d)` with `S` the block of `P^-1` computed independently; its
    /// polygon holds the PRS's sampled points, is tight, and with no ball it is the zonogon
    /// with its 8 vertices exactly.
    #[test]
    fn zonotope_prs_is_the_zonogon_plus_both_balls() {
        let (c, g) = zonotope();
        let p = metric();
        let pinv = DMatrix::from_fn(3, 3, |i, j| p[i][j])
            .try_inverse()
            .unwrap();
        let (remainder, r_t) = (0.25, 0.15);
        let vertices: Vec<Vec<f64>> = (0..16)
            .map(|mask: u32| {
                let xi: Vec<f64> = (0..4)
                    .map(|j| if mask >> j & 1 == 1 { 1.0 } else { -1.0 })
                    .collect();
                zonotope_point(&c, &g, &xi)
            })
            .collect();
        for states in [[0, 2], [1, 0]] {
            let plane = Plane::new(states, &p).unwrap();
            let det = plane.zonotope(&c, &g, remainder);
            let prs = det.plus_ellipse(plane.shape, r_t);
            let mut rng = Rng(5);
            for _ in 0..200 {
                let d = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
                let zonogon = vertices
                    .iter()
                    .map(|v| dot(plane.point(v), d))
                    .fold(f64::NEG_INFINITY, f64::max);
                let (a, b) = (states[0], states[1]);
                let sds = pinv[(a, a)] * d[0] * d[0]
                    + 2.0 * pinv[(a, b)] * d[0] * d[1]
                    + pinv[(b, b)] * d[1] * d[1];
                let exact = zonogon + (remainder + r_t) * sds.sqrt();
                assert!((prs.support(d) - exact).abs() < 1e-12, "{d:?}");
                let exact = zonogon + remainder * sds.sqrt();
                assert!((det.support(d) - exact).abs() < 1e-12, "{d:?}");
            }
            check_polygon(&plane, &p, &prs, &vertices, remainder + r_t, &mut |rng| {
                let xi: Vec<f64> = (0..4).map(|_| rng.range(-1.0, 1.0)).collect();
                zonotope_point(&c, &g, &xi)
            });
            let zonogon = plane.zonotope(&c, &g, 0.0).polygon();
            assert_eq!(zonogon.len(), 8, "{zonogon:?}");
            for v in &zonogon {
                assert!(
                    vertices.iter().any(|u| {
                        let u = plane.point(u);
                        (u[0] - v[0]).abs() + (u[1] - v[1]).abs() < 1e-12
                    }),
                    "{v:?}"
                );
            }
        }
    }

    #[test]
    fn zonogon_polygon_has_the_exact_vertices() {
        // A box projects to its rectangle: exactly four vertices.
        let plane = Plane::new([0, 1], &metric()).unwrap();
        let poly = plane.boxed(&[-1.0, 2.0, 0.0], &[3.0, 2.5, 1.0]).polygon();
        assert_eq!(poly.len(), 4, "{poly:?}");
        for v in [[3.0, 2.5], [-1.0, 2.5], [-1.0, 2.0], [3.0, 2.0]] {
            assert!(poly
                .iter()
                .any(|p| (p[0] - v[0]).abs() + (p[1] - v[1]).abs() < 1e-12));
        }
        // A parallelotope in (x0, x1): a hexagon (3 generators in general position).
        let set = plane.parallelotope(&[-1.0, 0.5, -0.2], &[2.0, 1.5, 0.3], &t_inv());
        assert_eq!(set.generators.len(), 3);
        assert_eq!(set.polygon().len(), 6, "{:?}", set.polygon());
    }

    #[test]
    fn clipping_to_a_rectangle() {
        let square = [[-2.0, -2.0], [2.0, -2.0], [2.0, 2.0], [-2.0, 2.0]];
        let out = clip(&square, &rectangle((0.0, 1.0), (-1.0, 5.0)));
        let area: f64 = (0..out.len())
            .map(|k| {
                let (p, q) = (out[k], out[(k + 1) % out.len()]);
                p[0] * q[1] - q[0] * p[1]
            })
            .sum::<f64>()
            / 2.0;
        assert!((area - 3.0).abs() < 1e-12, "{out:?}");
        assert!(clip(&square, &rectangle((5.0, 6.0), (0.0, 1.0))).is_empty());
    }
}
