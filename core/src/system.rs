//! The interface between a model and the engines: what generated code (and the compiler's IR
//! interpreter) implements. The data describing a spec's sets and analyses is in
//! [`model`](crate::model).
//!
//! Matrices are flat row-major slices: entry `(i, j)` of an `r x c` matrix is `[i * c + j]`.

use crate::interval::Interval;
use crate::lanes::X8;
use crate::model::ModelInfo;

#[cfg(feature = "test-util")]
mod paired;
#[cfg(feature = "test-util")]
#[doc(hidden)]
pub use paired::Paired;

/// `f(x, u, out)` lane by lane, for lane `l` of every entry of `x`, `u` and `out` (the
/// trait's default lanes forms).
fn lane_by_lane(x: &[X8], u: &[X8], out: &mut [X8], mut f: impl FnMut(&[f64], &[f64], &mut [f64])) {
    let (n, p, k) = (x.len(), u.len(), out.len());
    let (mut small, mut heap) = ([0.0; 32], Vec::new());
    let buf = if n + p + k <= small.len() {
        &mut small[..n + p + k]
    } else {
        heap.resize(n + p + k, 0.0);
        &mut heap[..]
    };
    let (xs, rest) = buf.split_at_mut(n);
    let (us, os) = rest.split_at_mut(p);
    for l in 0..8 {
        for (a, v) in xs.iter_mut().zip(x) {
            *a = v.0[l];
        }
        for (a, v) in us.iter_mut().zip(u) {
            *a = v.0[l];
        }
        f(xs, us, os);
        for (o, v) in out.iter_mut().zip(&*os) {
            o.0[l] = *v;
        }
    }
}

/// A stochastic system `dX = f(X, u, t) dt + G(X, t) dW` with its derivatives.
///
/// Implementations must be pure functions of their arguments. The interval versions must be
/// inclusion functions: for every point in the argument boxes, the point result lies in the
/// interval result (outward rounding). They are shared between threads (`Sync`): the pieces of
/// a split initial set run in parallel.
pub trait System: Sync {
    /// Number of states `n`.
    fn n(&self) -> usize;
    /// Number of inputs `p`.
    fn p(&self) -> usize;
    /// Number of noise channels `m`.
    fn m(&self) -> usize;
    /// `out[i] = f_i(x, u, t)`; `out.len() == n`.
    fn drift(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]);
    /// The drift of eight states and inputs at once: lane `l` of `out[i]` is `f_i` at the
    /// state in lane `l` of `x` and the input in lane `l` of `u`, bit for bit what
    /// [`System::drift`] gives (the Monte Carlo simulator relies on it). The default calls
    /// `drift` once per lane; generated code evaluates the same expressions over [`X8`].
    fn drift_x8(&self, x: &[X8], u: &[X8], t: f64, out: &mut [X8]) {
        lane_by_lane(x, u, out, |x, u, o| self.drift(x, u, t, o));
    }
    /// Natural inclusion function of the drift.
    fn drift_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]);
    /// `D_x f`, n x n row-major.
    fn jac_x(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]);
    /// Interval enclosure of `D_x f` over the boxes.
    fn jac_x_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]);
    /// The entries `(i, j)` of `D_x f` such that `f_i` depends on `x_j`, in row-major order:
    /// the layout of [`System::jac_x_sparse_interval`]. Engines rely on `f_i` (and row `i` of
    /// `D_x f`) not depending on the states missing from row `i`. The default lists all `n * n`
    /// entries; generated code lists the actual dependencies, so engines can work in time
    /// proportional to the expressions rather than to `n^2`.
    fn jac_x_pattern(&self) -> Vec<(usize, usize)> {
        let n = self.n();
        (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).collect()
    }
    /// Interval enclosures of the entries of `D_x f` listed by [`System::jac_x_pattern`], in
    /// that order. The default is [`System::jac_x_interval`] (the dense pattern).
    fn jac_x_sparse_interval(
        &self,
        x: &[Interval],
        u: &[Interval],
        t: Interval,
        out: &mut [Interval],
    ) {
        self.jac_x_interval(x, u, t, out);
    }
    /// `D_u f`, n x p row-major.
    fn jac_u(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]);
    /// Interval enclosure of `D_u f`.
    fn jac_u_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]);
    /// `G(x, t)`, n x m row-major.
    fn diffusion(&self, x: &[f64], t: f64, out: &mut [f64]);
    /// The diffusion of eight states at once: lane `l` of `out[i * m + k]` is `G[i, k]` at the
    /// state in lane `l` of `x`, bit for bit what [`System::diffusion`] gives (the Monte Carlo
    /// simulator relies on it). The default calls `diffusion` once per lane; generated code
    /// evaluates the same expressions over [`X8`].
    fn diffusion_x8(&self, x: &[X8], t: f64, out: &mut [X8]) {
        lane_by_lane(x, &[], out, |x, _, o| self.diffusion(x, t, o));
    }
    /// Interval enclosure of `G`.
    fn diffusion_interval(&self, x: &[Interval], t: Interval, out: &mut [Interval]);
    /// The transformed system of frame `k` (see [`Transform::frame`](crate::model::Transform::frame)): the same interface in
    /// the coordinates `y = T x`, i.e. drift `T f(T^-1 y, u, t)` and diffusion `T G(T^-1 y, t)`.
    /// `None` if the model has no such frame (the default).
    fn frame(&self, k: usize) -> Option<&dyn System> {
        let _ = k;
        None
    }
    /// Enclosures over the times `t` of the numbers of the model's moving unsafe and goal sets
    /// (method.md 8.15), one per [`Moving::number`](crate::model::Moving::number), into `out`
    /// (`ModelInfo::set_numbers` entries). The default writes nothing: no set moves.
    fn set_numbers(&self, t: Interval, out: &mut [Interval]) {
        let _ = (t, out);
    }
}

/// A [`System`] together with the model data generated with it from one spec: its sets, its
/// analyses and the constants the compiler certified for them. Generated model types implement
/// it (as does the compiler's interpreter), and the engines take a `Model`
/// ([`Reach::new`](crate::Reach::new), [`engine::run`](crate::engine::run),
/// [`simulate`](crate::simulate::simulate)), so one model's constants cannot be used with
/// another model's system:
///
/// ```compile_fail,E0061
/// # use reachc_core::{ModelInfo, Reach, System};
/// fn mixed(sys: &dyn System, other: &ModelInfo) {
///     let _ = Reach::new(sys, other, "contraction");
/// }
/// ```
pub trait Model: System {
    /// The model's data, generated with this system.
    fn info(&self) -> &ModelInfo;
}
