//! The interface between a model and the engines: what generated code (and the compiler's IR
//! interpreter) implements, and the plain data describing the spec's sets and analyses.
//!
//! Matrices are flat row-major slices: entry `(i, j)` of an `r x c` matrix is `[i * c + j]`.

use crate::interval::Interval;
use crate::lanes::X8;

/// A stochastic system `dX = f(X, u, t) dt + G(X, t) dW` with its derivatives.
///
/// Implementations must be pure functions of their arguments. The interval versions must be
/// inclusion functions: for every point in the argument boxes, the point result lies in the
/// interval result (outward rounding).
pub trait System {
    /// Number of states `n`.
    fn n(&self) -> usize;
    /// Number of inputs `p`.
    fn p(&self) -> usize;
    /// Number of noise channels `m`.
    fn m(&self) -> usize;
    /// `out[i] = f_i(x, u, t)`; `out.len() == n`.
    fn drift(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]);
    /// The drift of eight states at once, for models without inputs (`p == 0`): lane `l` of
    /// `out[i]` is `f_i` at the state in lane `l` of `x`, bit for bit what
    /// [`System::drift`] gives (the Monte Carlo simulator relies on it). The default calls
    /// `drift` once per lane; generated code evaluates the same expressions over [`X8`].
    fn drift_x8(&self, x: &[X8], t: f64, out: &mut [X8]) {
        let n = x.len();
        let (mut small, mut heap) = ([0.0; 16], Vec::new());
        let buf = if 2 * n <= small.len() {
            &mut small[..2 * n]
        } else {
            heap.resize(2 * n, 0.0);
            &mut heap[..]
        };
        let (xs, fs) = buf.split_at_mut(n);
        for l in 0..8 {
            for (xi, x) in xs.iter_mut().zip(x) {
                *xi = x.0[l];
            }
            self.drift(xs, &[], t, fs);
            for (o, f) in out.iter_mut().zip(&*fs) {
                o.0[l] = *f;
            }
        }
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
    /// Interval enclosure of `G`.
    fn diffusion_interval(&self, x: &[Interval], t: Interval, out: &mut [Interval]);
    /// The transformed system of frame `k` (see [`Transform::frame`]): the same interface in
    /// the coordinates `y = T x`, i.e. drift `T f(T^-1 y, u, t)` and diffusion `T G(T^-1 y, t)`.
    /// `None` if the model has no such frame (the default).
    fn frame(&self, k: usize) -> Option<&dyn System> {
        let _ = k;
        None
    }
}

/// A closed interval of reals given by its ends (`-inf`/`inf` allowed), as plain data.
pub type Range = (f64, f64);

/// Everything about a model that is not code: names, sets and analyses.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelInfo {
    /// `model NAME`.
    pub name: String,
    /// State names (family elements as `x[3]`).
    pub states: Vec<String>,
    /// Input names.
    pub inputs: Vec<String>,
    /// Noise channel names.
    pub noises: Vec<String>,
    /// The input box, one range per input.
    pub input_box: Vec<Range>,
    /// The initial set.
    pub initial: InitialSet,
    /// Per state, the box where the constants were derived (`(-inf, inf)` when unbounded).
    pub domain: Vec<Range>,
    /// Whether the spec gave a domain (results then hold while the state stays in it).
    pub has_domain: bool,
    /// Unsafe sets.
    pub unsafe_sets: Vec<UnsafeSet>,
    /// The analyses, with their derived constants.
    pub analyses: Vec<Analysis>,
}

/// The initial set: per-state boxes (points are degenerate boxes) times balls over groups.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialSet {
    /// Per state: its box, or `None` if the state belongs to a ball.
    pub boxes: Vec<Option<Range>>,
    /// Balls `{x_S : (x_S - c)' M (x_S - c) <= r^2}`.
    pub balls: Vec<InitialBall>,
}

/// One ball of the initial set.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialBall {
    /// State indices.
    pub states: Vec<usize>,
    /// Centre, one entry per state in `states`.
    pub center: Vec<f64>,
    /// Radius.
    pub radius: f64,
    /// Metric `M`, k x k row-major (`k = states.len()`); identity when `None`.
    pub metric: Option<Vec<f64>>,
}

/// A named unsafe set.
#[derive(Clone, Debug, PartialEq)]
pub struct UnsafeSet {
    /// Its name.
    pub name: String,
    /// Its shape.
    pub shape: UnsafeShape,
}

/// Shapes of unsafe sets.
#[derive(Clone, Debug, PartialEq)]
pub enum UnsafeShape {
    /// A box over some states (others unconstrained).
    Box(Vec<(usize, Range)>),
    /// A Euclidean ball over some states.
    Ball {
        /// State indices.
        states: Vec<usize>,
        /// Centre.
        center: Vec<f64>,
        /// Radius.
        radius: f64,
    },
    /// `{x : normal . x >= offset}`.
    HalfSpace {
        /// One entry per state.
        normal: Vec<f64>,
        /// Offset.
        offset: f64,
    },
}

/// How the deterministic reachable set is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Proposition 3: a P-ball around the nominal trajectory.
    Contraction,
    /// Proposition 4: an embedding system on boxes.
    Interval,
}

/// The stochastic radius rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RadiusRule {
    /// The averaged-MGF bound (default).
    Amgf,
    /// Theorem 1 with a given eps in (0, 1).
    Paper(f64),
    /// Theorem 1 with eps minimising the radius.
    PaperOptimal,
}

/// The inclusion function of the drift used by the interval method's embedding system.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Inclusion {
    /// Natural inclusion: `System::drift_interval` on the (pinned) box and the input box.
    Natural,
    /// Jacobian-based (mean-value) inclusion around the centre `(xc, uc)` of the pinned box and
    /// the input box: `f(xc, uc) + J_x([x], U) ([x] - xc) + J_u([x], U) (U - uc)`.
    #[default]
    Jacobian,
    /// Mixed Jacobian (one column at a time, as immrax's `mjacif`).
    Mixed,
}

impl Inclusion {
    /// Its name in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Inclusion::Natural => "natural",
            Inclusion::Jacobian => "jacobian",
            Inclusion::Mixed => "mixed",
        }
    }
}

/// Time integrator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Classical Runge-Kutta of order 4.
    Rk4,
    /// Forward Euler.
    Euler,
}

/// A coordinate transform `y = T x` of an interval analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct Transform {
    /// `T`, n x n row-major.
    pub matrix: Vec<f64>,
    /// `T^-1` as computed by the compiler in floating point, n x n row-major (the engine
    /// encloses the exact inverse around it).
    pub inverse: Vec<f64>,
    /// Which [`System::frame`] holds the transformed system (analyses with the same `T` share
    /// one).
    pub frame: usize,
}

/// Where the contraction rate `c_t` of a contraction analysis comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Rate {
    /// One rate for the whole run, certified by the compiler over the domain ([`Constants::c`]).
    #[default]
    Certified,
    /// Estimated per report step from sample paths (the paper's approach for the unicycle):
    /// the largest one-sided Lipschitz quotient between a sampled state and the nominal. Not a
    /// guarantee, and labelled so.
    Empirical {
        /// Number of sample paths of the estimate.
        paths: u64,
    },
}

impl Rate {
    /// Its name in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Rate::Certified => "certified",
            Rate::Empirical { .. } => "empirical",
        }
    }
}

/// Constants of Assumption 1 for one metric, derived by the compiler.
#[derive(Clone, Debug, PartialEq)]
pub struct Constants {
    /// The metric `P`, n x n row-major, symmetric positive definite.
    pub metric: Vec<f64>,
    /// Contraction rate: `mu_P(D_x f) <= c` on the domain, for all inputs and times (`inf` for a
    /// [`Rate::Empirical`] analysis: the compiler does not bound it then).
    pub c: f64,
    /// Noise level: `P^(1/2) G G' P^(1/2) <= sigma^2 I`.
    pub sigma: f64,
    /// Input gain: `|D_u f v|_P <= rho |v|_U`, where `|v|_U = max_j |v_j| / h_j` for the input
    /// box half-widths `h_j` (so the input box is the U-ball of radius 1 around its centre).
    pub rho: f64,
    /// How they were obtained (for the report), e.g. "max over 2 atom vertices, certified".
    pub how: String,
}

/// One analysis of the spec, with everything the engine needs.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    /// Its name.
    pub name: String,
    /// Contraction or interval.
    pub method: Method,
    /// Probability level: the PRS holds the state with probability >= 1 - delta.
    pub delta: f64,
    /// Final time.
    pub horizon: f64,
    /// Time step of the nominal trajectory and of the report.
    pub step: f64,
    /// Radius rule.
    pub radius: RadiusRule,
    /// Where the contraction rate comes from (contraction method).
    pub rate: Rate,
    /// Integrator.
    pub integrator: Integrator,
    /// Inclusion function of the interval method.
    pub inclusion: Inclusion,
    /// States to report (indices).
    pub outputs: Vec<usize>,
    /// The coordinate transform `y = T x` of the interval method, if given. An engine that
    /// cannot honour it must refuse the analysis rather than ignore it.
    pub transform: Option<Transform>,
    /// Derived constants (`None` if they could not be bounded; the engine refuses to run then).
    pub constants: Option<Constants>,
    /// Why `constants` is `None` (e.g. "`d f[omega] / d theta` is unbounded over the domain"),
    /// shown when the analysis is asked to run.
    pub constants_error: Option<String>,
}
