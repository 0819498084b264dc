//! The cubic Hermite interpolant of an integrator step, in interval arithmetic: the curve whose
//! defect validated steps bound (`defect.rs` for the nominal, `embedding.rs` for boxes).
//!
//! The cubic is kept in powers of `tau = (s - t0) / h`, `p = c0 + c1 tau + c2 tau^2 + c3 tau^3`:
//! for a smooth solution `c2` and `c3` are small (about `h^2 x''/2` and `h^3 x'''/6`), so
//! interval evaluation over a piece of the step stays tight; the Hermite basis itself would not
//! (its terms cancel).

use crate::interval::Interval;

/// Pieces per step on which defects are bounded.
pub(crate) const PIECES: usize = 8;

/// The cubic through `(t0, x0)` and `(t1, x1)` with slopes `f0` and `f1`, per coordinate.
pub(crate) struct Cubic {
    coeffs: Vec<[Interval; 4]>,
    /// `t1 - t0`, enclosed.
    h: Interval,
    t0: f64,
}

/// The cubic and its first two derivatives (in `s`) at some `tau`, per coordinate.
pub(crate) struct Jet {
    pub(crate) p: Vec<Interval>,
    pub(crate) dp: Vec<Interval>,
    pub(crate) d2p: Vec<Interval>,
}

/// One of the [`PIECES`] pieces of a step.
pub(crate) struct Piece {
    /// The times of the piece.
    pub(crate) times: Interval,
    /// The cubic over the piece.
    pub(crate) over: Jet,
    /// The cubic at the piece's midpoint.
    pub(crate) mid: Jet,
    /// `s - m` over the piece (`m` the midpoint).
    pub(crate) offset: Interval,
}

impl Cubic {
    /// The cubic of a step from `t0` to `t1`.
    pub(crate) fn new(t0: f64, t1: f64, x0: &[f64], x1: &[f64], f0: &[f64], f1: &[f64]) -> Cubic {
        let h = Interval::point(t1) - Interval::point(t0);
        let coeffs = (0..x0.len())
            .map(|i| {
                let (a, b) = (Interval::point(x0[i]), Interval::point(x1[i]));
                let (g0, g1) = (h * Interval::point(f0[i]), h * Interval::point(f1[i]));
                let d = b - a;
                [
                    a,
                    g0,
                    Interval::point(3.0) * d - Interval::point(2.0) * g0 - g1,
                    g0 + g1 - Interval::point(2.0) * d,
                ]
            })
            .collect();
        Cubic { coeffs, h, t0 }
    }

    /// The cubic and its derivatives for `tau` in an interval.
    pub(crate) fn jet(&self, tau: Interval) -> Jet {
        let (two, three, six) = (
            Interval::point(2.0),
            Interval::point(3.0),
            Interval::point(6.0),
        );
        let n = self.coeffs.len();
        let mut jet = Jet {
            p: Vec::with_capacity(n),
            dp: Vec::with_capacity(n),
            d2p: Vec::with_capacity(n),
        };
        for c in &self.coeffs {
            jet.p.push(c[0] + tau * (c[1] + tau * (c[2] + tau * c[3])));
            jet.dp
                .push((c[1] + tau * (two * c[2] + three * c[3] * tau)) / self.h);
            jet.d2p.push((two * c[2] + six * c[3] * tau) / self.h.sqr());
        }
        jet
    }

    /// The step's pieces, in order.
    pub(crate) fn pieces(&self) -> impl Iterator<Item = Piece> + '_ {
        (0..PIECES).map(move |k| {
            let (a, b) = (k as f64 / PIECES as f64, (k + 1) as f64 / PIECES as f64);
            let tau = Interval::new(a, b);
            let mid = Interval::point(0.5 * (a + b));
            Piece {
                times: Interval::point(self.t0) + tau * self.h,
                over: self.jet(tau),
                mid: self.jet(mid),
                offset: (tau - mid) * self.h,
            }
        })
    }

    /// The cubic at the end of the step (`tau = 1`), enclosed.
    pub(crate) fn end(&self) -> Vec<Interval> {
        self.coeffs
            .iter()
            .map(|c| c[0] + c[1] + c[2] + c[3])
            .collect()
    }
}
