//! A result's sets at one report time: the deterministic set ([`DetSet`]), the radii, and the
//! span over the report interval ending there.

/// The sets at one report time.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// Time.
    pub t: f64,
    /// The deterministic reachable set `Rbar_t`.
    pub det: DetSet,
    /// Stochastic radius `r_t` (in `|.|_P`) of the analysis' guarantee: the time-uniform
    /// tube's radius at `t` (uniform), or the radius for time `t` alone (pointwise).
    pub r_t: f64,
    /// The pointwise radius at `t` (what `r_t` would be for this time alone: the price of
    /// uniformity is `r_t / r_pointwise`).
    pub r_pointwise: f64,
    /// The stochastic radius of the report interval ending here (method.md 8.14): the largest
    /// over the interval for a uniform guarantee, `r_t` for a pointwise one (0 at `t = 0`, and
    /// in a split's union, whose pieces hold theirs).
    pub r_span: f64,
    /// `Psi_t` (upper bound).
    pub psi: f64,
    /// Contraction rate on the step ending here.
    pub c: f64,
    /// Noise level on the step ending here.
    pub sigma: f64,
    /// Radius of a P-ball around [`DetSet::center`] containing the PRS: the PRS itself for
    /// [`DetSet::Ball`] (`R_t + r_t`), coarser than the PRS for boxes.
    pub prs_radius: f64,
    /// The PRS over the whole report interval ending at `t` (after the previous report time;
    /// at `t = 0`, the PRS at 0): the sets of every time in between lie in it.
    pub span: Span,
    /// Safety margin per unsafe set over [`Step::span`] (the order of [`Prs::unsafe_sets`](super::Prs::unsafe_sets);
    /// `> 0` means shown safe at every time of the interval).
    pub margins: Vec<f64>,
}

/// The set `{x : lo <= x <= hi} (+) B_P(radius)` holding the PRS of every time of an interval.
#[derive(Clone, Debug, PartialEq)]
pub struct Span {
    /// Lower corner of the box.
    pub lo: Vec<f64>,
    /// Upper corner of the box.
    pub hi: Vec<f64>,
    /// The radius of the P-ball added to it.
    pub radius: f64,
}

/// A deterministic reachable set.
#[derive(Clone, Debug, PartialEq)]
pub enum DetSet {
    /// `{x : |x - center|_P <= radius}` (contraction method; `radius` is `R_t`).
    Ball {
        /// The nominal state.
        center: Vec<f64>,
        /// `R_t` (upper bound).
        radius: f64,
    },
    /// `{x : lo <= x <= hi}` (interval method), inside the P-ball `(center, radius)`.
    Box {
        /// Lower corner.
        lo: Vec<f64>,
        /// Upper corner.
        hi: Vec<f64>,
        /// Centre of the box.
        center: Vec<f64>,
        /// Upper bound of the box's P-radius around `center`.
        radius: f64,
    },
    /// `{x : lo <= T x <= hi}` (interval method with the transform `T` of
    /// [`Prs::transform`](super::Prs::transform)), with its interval hull `[hull_lo, hull_hi]` in `x`, inside the
    /// P-ball `(center, radius)` of the hull.
    Parallelotope {
        /// Lower corner of the box in `y = T x`.
        lo: Vec<f64>,
        /// Upper corner of the box in `y`.
        hi: Vec<f64>,
        /// Lower corner of the interval hull in `x`.
        hull_lo: Vec<f64>,
        /// Upper corner of the interval hull in `x`.
        hull_hi: Vec<f64>,
        /// Centre of the hull.
        center: Vec<f64>,
        /// Upper bound of the hull's P-radius around `center`.
        radius: f64,
    },
    /// `{center + sum_j xi_j g_j : |xi_j| <= 1} (+) B_P(remainder)` (first-order sets,
    /// method.md 8.8): the image of the initial box under the flow's linearisation along the
    /// nominal (a zonotope with the generators `g_j`), plus a P-ball bounding the error of the
    /// linearisation; with the zonotope's interval hull `[hull_lo, hull_hi]` (without the
    /// ball), all inside the P-ball `(center, radius)`.
    Zonotope {
        /// The centre (the nominal state).
        center: Vec<f64>,
        /// The generators, generator-major: `g_j` is `generators[j n..(j + 1) n]`.
        generators: Vec<f64>,
        /// The P-radius of the ball added to the zonotope (upper bound).
        remainder: f64,
        /// Lower corner of the zonotope's interval hull.
        hull_lo: Vec<f64>,
        /// Upper corner of the zonotope's interval hull.
        hull_hi: Vec<f64>,
        /// Upper bound of the whole set's P-radius around `center`.
        radius: f64,
    },
}

impl Step {
    /// The nominal state `x*_t` (all states); for the interval method the centre of the set's
    /// hull.
    pub fn nominal(&self) -> &[f64] {
        self.det.center()
    }
}

impl DetSet {
    /// The name of the set's shape in result files: `"p_ball"`, `"box"`, `"parallelotope"` or
    /// `"zonotope"`.
    pub fn shape(&self) -> &'static str {
        match self {
            DetSet::Ball { .. } => "p_ball",
            DetSet::Box { .. } => "box",
            DetSet::Parallelotope { .. } => "parallelotope",
            DetSet::Zonotope { .. } => "zonotope",
        }
    }

    /// The centre of the set (of its hull for a parallelotope).
    pub fn center(&self) -> &[f64] {
        match self {
            DetSet::Ball { center, .. }
            | DetSet::Box { center, .. }
            | DetSet::Parallelotope { center, .. }
            | DetSet::Zonotope { center, .. } => center,
        }
    }

    /// The radius of a P-ball around [`DetSet::center`] containing the set (`R_t` for a ball).
    pub fn radius(&self) -> f64 {
        match self {
            DetSet::Ball { radius, .. }
            | DetSet::Box { radius, .. }
            | DetSet::Parallelotope { radius, .. }
            | DetSet::Zonotope { radius, .. } => *radius,
        }
    }

    /// The box of an interval method's set, `(lo, hi)`: in `x` for [`DetSet::Box`], in
    /// `y = T x` for [`DetSet::Parallelotope`]; `None` for a ball or a zonotope.
    pub fn corners(&self) -> Option<(&[f64], &[f64])> {
        match self {
            DetSet::Ball { .. } | DetSet::Zonotope { .. } => None,
            DetSet::Box { lo, hi, .. } | DetSet::Parallelotope { lo, hi, .. } => Some((lo, hi)),
        }
    }

    /// An interval hull in `x` of the set without its [`DetSet::ball_added`]: `None` for a
    /// ball (its hull needs `P^-1`, see [`Prs::hull`](super::Prs::hull)).
    pub fn box_hull(&self) -> Option<(&[f64], &[f64])> {
        match self {
            DetSet::Ball { .. } => None,
            DetSet::Box { lo, hi, .. } => Some((lo, hi)),
            DetSet::Parallelotope {
                hull_lo, hull_hi, ..
            }
            | DetSet::Zonotope {
                hull_lo, hull_hi, ..
            } => Some((hull_lo, hull_hi)),
        }
    }

    /// The P-radius of the ball added to the set's [`DetSet::box_hull`] part: a zonotope's
    /// remainder, 0 for boxes and parallelotopes (and for a ball, which has no such part).
    pub fn ball_added(&self) -> f64 {
        match self {
            DetSet::Zonotope { remainder, .. } => *remainder,
            _ => 0.0,
        }
    }

    /// The generators of a zonotope, `g_j` one per item; empty for the other shapes.
    pub fn generators(&self) -> Vec<&[f64]> {
        match self {
            DetSet::Zonotope {
                center, generators, ..
            } if !center.is_empty() => generators.chunks(center.len()).collect(),
            _ => Vec::new(),
        }
    }
}
