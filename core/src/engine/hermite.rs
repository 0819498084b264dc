//! The cubic Hermite interpolant of an integrator step, in interval arithmetic: the curve whose
//! defect validated steps bound (`defect.rs` for the nominal, `embedding.rs` for boxes).
//!
//! The cubic is kept in powers of `tau = (s - t0) / h`, `p = c0 + c1 tau + c2 tau^2 + c3 tau^3`:
//! for a smooth solution `c2` and `c3` are small (about `h^2 x''/2` and `h^3 x'''/6`), so
//! interval evaluation over a piece of the step stays tight; the Hermite basis itself would not
//! (its terms cancel). The coefficients of its derivatives in `s`, `p' = (c1 + 2 c2 tau + 3 c3
//! tau^2) / h` and `p'' = (2 c2 + 6 c3 tau) / h^2`, are enclosed once per step, so evaluating a
//! piece costs six products per coordinate and no division.

use crate::interval::Interval;

/// Pieces per step on which defects are bounded.
pub(crate) const PIECES: usize = 8;

/// The cubic through `(t0, x0)` and `(t1, x1)` with slopes `f0` and `f1`, per coordinate.
pub(crate) struct Cubic {
    /// `[c0, c1, c2, c3]` of `p` in powers of `tau`.
    coeffs: Vec<[Interval; 4]>,
    /// `[c1, 2 c2, 3 c3] / h`: `p'` in powers of `tau`.
    slope: Vec<[Interval; 3]>,
    /// `[2 c2, 6 c3] / h^2`: `p''` in powers of `tau`.
    curvature: Vec<[Interval; 2]>,
    /// `t1 - t0`, enclosed.
    h: Interval,
    t0: f64,
}

/// The cubic and its first two derivatives (in `s`) at some `tau`, per coordinate.
pub(crate) struct Jet {
    pub(crate) p: Vec<Interval>,
    pub(crate) dp: Vec<Interval>,
    /// `p''`; only over a piece (see [`Piece::mid`]).
    pub(crate) d2p: Vec<Interval>,
}

impl Jet {
    fn new(n: usize) -> Jet {
        Jet {
            p: vec![Interval::ZERO; n],
            dp: vec![Interval::ZERO; n],
            d2p: vec![Interval::ZERO; n],
        }
    }
}

/// One of the [`PIECES`] pieces of a step: a buffer that [`Cubic::piece`] fills, so the steps
/// of a run share one.
pub(crate) struct Piece {
    /// The times of the piece.
    pub(crate) times: Interval,
    /// The cubic over the piece.
    pub(crate) over: Jet,
    /// The cubic at the piece's midpoint (`p` and `p'`; its `d2p` is not filled).
    pub(crate) mid: Jet,
    /// `s - m` over the piece (`m` the midpoint).
    pub(crate) offset: Interval,
}

impl Piece {
    /// A buffer for the pieces of cubics of `n` coordinates.
    pub(crate) fn new(n: usize) -> Piece {
        Piece {
            times: Interval::ZERO,
            over: Jet::new(n),
            mid: Jet::new(n),
            offset: Interval::ZERO,
        }
    }
}

impl Cubic {
    /// The cubic of a step from `t0` to `t1`.
    pub(crate) fn new(t0: f64, t1: f64, x0: &[f64], x1: &[f64], f0: &[f64], f1: &[f64]) -> Cubic {
        let h = Interval::point(t1) - Interval::point(t0);
        let h2 = h.sqr();
        let (two, three, six) = (
            Interval::point(2.0),
            Interval::point(3.0),
            Interval::point(6.0),
        );
        let n = x0.len();
        let mut cubic = Cubic {
            coeffs: Vec::with_capacity(n),
            slope: Vec::with_capacity(n),
            curvature: Vec::with_capacity(n),
            h,
            t0,
        };
        for i in 0..n {
            let (a, b) = (Interval::point(x0[i]), Interval::point(x1[i]));
            let (g0, g1) = (h * Interval::point(f0[i]), h * Interval::point(f1[i]));
            let d = b - a;
            let c = [a, g0, three * d - two * g0 - g1, g0 + g1 - two * d];
            cubic.coeffs.push(c);
            cubic
                .slope
                .push([c[1] / h, two * c[2] / h, three * c[3] / h]);
            cubic.curvature.push([two * c[2] / h2, six * c[3] / h2]);
        }
        cubic
    }

    /// The cubic and its slope for `tau` in an interval, and its second derivative if
    /// `second`, into `jet`.
    fn jet(&self, tau: Interval, jet: &mut Jet, second: bool) {
        for (i, c) in self.coeffs.iter().enumerate() {
            jet.p[i] = c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]));
            let d = &self.slope[i];
            jet.dp[i] = d[0] + tau * (d[1] + tau * d[2]);
        }
        if second {
            for (out, d) in jet.d2p.iter_mut().zip(&self.curvature) {
                *out = d[0] + tau * d[1];
            }
        }
    }

    /// Piece `k` (of [`PIECES`], in order) into `piece`.
    pub(crate) fn piece(&self, k: usize, piece: &mut Piece) {
        let (a, b) = (k as f64 / PIECES as f64, (k + 1) as f64 / PIECES as f64);
        let tau = Interval::new(a, b);
        let mid = Interval::point(0.5 * (a + b));
        piece.times = Interval::point(self.t0) + tau * self.h;
        self.jet(tau, &mut piece.over, true);
        self.jet(mid, &mut piece.mid, false);
        piece.offset = (tau - mid) * self.h;
    }

    /// The cubic at the end of the step (`tau = 1`), enclosed.
    pub(crate) fn end(&self) -> Vec<Interval> {
        self.coeffs
            .iter()
            .map(|c| c[0] + c[1] + c[2] + c[3])
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The enclosures of `p`, `p'` and `p''` over each piece hold the exact cubic (from its
    /// Hermite data, in exact rational steps of `tau`) and its derivatives at sampled times.
    #[test]
    fn pieces_enclose_the_cubic_and_its_derivatives() {
        let (t0, t1) = (0.3, 0.3 + 0.0625);
        let (x0, x1, f0, f1) = ([1.0, -2.0], [1.1, -1.7], [0.5, 3.0], [2.5, -1.0]);
        let cubic = Cubic::new(t0, t1, &x0, &x1, &f0, &f1);
        let h = t1 - t0;
        let mut piece = Piece::new(2);
        for k in 0..PIECES {
            cubic.piece(k, &mut piece);
            for j in 0..=16 {
                let tau = (k as f64 + j as f64 / 16.0) / PIECES as f64;
                for i in 0..2 {
                    // The Hermite basis on [0, 1], in f64 (the enclosures are far wider than
                    // its rounding: tested with a margin).
                    let (h00, h10) = (
                        2.0 * tau.powi(3) - 3.0 * tau.powi(2) + 1.0,
                        tau.powi(3) - 2.0 * tau.powi(2) + tau,
                    );
                    let (h01, h11) = (
                        -2.0 * tau.powi(3) + 3.0 * tau.powi(2),
                        tau.powi(3) - tau.powi(2),
                    );
                    let p = h00 * x0[i] + h10 * h * f0[i] + h01 * x1[i] + h11 * h * f1[i];
                    let dp = ((6.0 * tau * tau - 6.0 * tau) * x0[i]
                        + (3.0 * tau * tau - 4.0 * tau + 1.0) * h * f0[i]
                        + (-6.0 * tau * tau + 6.0 * tau) * x1[i]
                        + (3.0 * tau * tau - 2.0 * tau) * h * f1[i])
                        / h;
                    let d2p = ((12.0 * tau - 6.0) * x0[i]
                        + (6.0 * tau - 4.0) * h * f0[i]
                        + (-12.0 * tau + 6.0) * x1[i]
                        + (6.0 * tau - 2.0) * h * f1[i])
                        / (h * h);
                    let near = |v: Interval, x: f64| {
                        v.lo() - 1e-9 * (1.0 + x.abs()) <= x && x <= v.hi() + 1e-9 * (1.0 + x.abs())
                    };
                    assert!(near(piece.over.p[i], p), "p at tau {tau}");
                    assert!(near(piece.over.dp[i], dp), "p' at tau {tau}");
                    assert!(near(piece.over.d2p[i], d2p), "p'' at tau {tau}");
                }
                let s = t0 + tau * h;
                assert!(piece.times.lo() - 1e-15 <= s && s <= piece.times.hi() + 1e-15);
            }
            // At the midpoint, the cubic's value and slope.
            let tau = (k as f64 + 0.5) / PIECES as f64;
            let mut jet = Jet::new(2);
            cubic.jet(Interval::point(tau), &mut jet, false);
            assert_eq!(jet.p, piece.mid.p);
            assert_eq!(jet.dp, piece.mid.dp);
        }
        // The ends: the Hermite data.
        let end = cubic.end();
        for i in 0..2 {
            assert!(end[i].contains(x1[i]));
        }
    }
}
