//! Random initial states: uniform in the initial set (its boxes, and its balls, which are
//! ellipsoids `{x_S : (x_S - c)' M (x_S - c) <= r^2}`).

use super::error::InitialFault;
use super::normal::Ziggurat;
use super::report::InitialSampling;
use super::rng::PathRng;
use crate::model::InitialSet;

/// One ball of the initial set, ready for sampling: `x_S = c + r L^-T z` with `M = L L'` and
/// `z` uniform in the unit ball, so that `(x_S - c)' M (x_S - c) = r^2 |z|^2 <= r^2`.
#[derive(Clone, Debug)]
struct Ball {
    states: Vec<usize>,
    center: Vec<f64>,
    radius: f64,
    /// Cholesky factor `L` of `M` (k x k, row-major, lower); `None` for the identity.
    chol: Option<Vec<f64>>,
}

/// Samples initial states uniformly in the initial set.
#[derive(Clone, Debug)]
pub(crate) struct InitialSampler {
    /// `(state, lo, hi - lo)` of every non-degenerate box.
    boxes: Vec<(usize, f64, f64)>,
    /// The state with degenerate boxes filled in (the others are overwritten per sample).
    base: Vec<f64>,
    balls: Vec<Ball>,
    /// Largest ball dimension (scratch size).
    max_ball: usize,
}

impl InitialSampler {
    /// Checks the initial set (bounded, every state covered once) and prepares the sampler.
    pub(crate) fn new(set: &InitialSet, n: usize) -> Result<Self, InitialFault> {
        if set.boxes.len() != n {
            return Err(InitialFault::Entries {
                entries: set.boxes.len(),
                n,
            });
        }
        let mut covered = vec![false; n];
        let mut base = vec![0.0; n];
        let mut boxes = Vec::new();
        for (i, b) in set.boxes.iter().enumerate() {
            if let Some(crate::model::Bounds { lo, hi }) = *b {
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                    return Err(InitialFault::UnboundedBox {
                        state: i,
                        range: crate::model::Bounds { lo, hi },
                    });
                }
                covered[i] = true;
                base[i] = lo;
                if hi > lo {
                    boxes.push((i, lo, hi - lo));
                }
            }
        }
        let mut balls = Vec::new();
        for ball in &set.balls {
            let k = ball.states.len();
            if ball.center.len() != k || !(ball.radius.is_finite() && ball.radius >= 0.0) {
                return Err(InitialFault::Ball);
            }
            for &i in &ball.states {
                if i >= n || covered[i] {
                    return Err(InitialFault::Repeated { state: i });
                }
                covered[i] = true;
            }
            let chol = match &ball.metric {
                None => None,
                Some(m) => Some(cholesky(m, k).ok_or(InitialFault::BallMetric)?),
            };
            balls.push(Ball {
                states: ball.states.clone(),
                center: ball.center.clone(),
                radius: ball.radius,
                chol,
            });
        }
        if let Some(i) = covered.iter().position(|c| !c) {
            return Err(InitialFault::Missing { state: i });
        }
        let max_ball = balls.iter().map(|b| b.states.len()).max().unwrap_or(0);
        Ok(InitialSampler {
            boxes,
            base,
            balls,
            max_ball,
        })
    }

    /// What is sampled, for the report.
    pub(crate) fn describe(&self) -> InitialSampling {
        match (self.boxes.is_empty(), self.balls.is_empty()) {
            (true, true) => InitialSampling::Point,
            (false, true) => InitialSampling::Box,
            (true, false) => InitialSampling::Balls,
            (false, false) => InitialSampling::BoxAndBalls,
        }
    }

    /// Scratch length [`sample`](Self::sample) needs.
    pub(crate) fn scratch_len(&self) -> usize {
        2 * self.max_ball
    }

    /// Writes a random initial state into `x` (`scratch.len() >= scratch_len()`).
    pub(crate) fn sample(
        &self,
        rng: &mut PathRng,
        zig: &Ziggurat,
        x: &mut [f64],
        scratch: &mut [f64],
    ) {
        x.copy_from_slice(&self.base);
        for &(i, lo, width) in &self.boxes {
            x[i] = lo + width * rng.uniform();
        }
        for ball in &self.balls {
            let k = ball.states.len();
            let (z, y) = scratch[..2 * k].split_at_mut(k);
            // Uniform in the unit ball: a uniform direction times U^(1/k).
            let mut norm2 = 0.0;
            while norm2 == 0.0 {
                for zi in z.iter_mut() {
                    *zi = zig.sample(rng);
                }
                norm2 = z.iter().map(|v| v * v).sum::<f64>();
            }
            let scale = ball.radius * rng.uniform().powf(1.0 / k as f64) / norm2.sqrt();
            match &ball.chol {
                None => y.copy_from_slice(z),
                // y = L^-T z by back substitution.
                Some(l) => {
                    for i in (0..k).rev() {
                        let mut s = z[i];
                        for j in i + 1..k {
                            s -= l[j * k + i] * y[j];
                        }
                        y[i] = s / l[i * k + i];
                    }
                }
            }
            for (a, &i) in ball.states.iter().enumerate() {
                x[i] = ball.center[a] + scale * y[a];
            }
        }
    }
}

/// Cholesky factor of a symmetric positive definite k x k matrix (row-major, lower), in f64
/// (sampling needs no rigour); `None` if a pivot is not positive.
fn cholesky(a: &[f64], k: usize) -> Option<Vec<f64>> {
    if a.len() != k * k {
        return None;
    }
    let mut l = vec![0.0; k * k];
    for j in 0..k {
        let d = a[j * k + j] - (0..j).map(|c| l[j * k + c] * l[j * k + c]).sum::<f64>();
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        l[j * k + j] = d.sqrt();
        for i in j + 1..k {
            let s = a[i * k + j] - (0..j).map(|c| l[i * k + c] * l[j * k + c]).sum::<f64>();
            l[i * k + j] = s / l[j * k + j];
        }
    }
    Some(l)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Ball, Bounds};

    #[test]
    fn ellipsoid_samples_are_inside_and_fill_it_uniformly() {
        // {(x - c)' M (x - c) <= r^2} with M = [[4, 1], [1, 2]], r = 0.5, plus a box state.
        let set = InitialSet {
            boxes: vec![None, Some(Bounds::new(1.0, 3.0)), None],
            balls: vec![Ball {
                states: vec![0, 2],
                center: vec![1.0, -1.0],
                radius: 0.5,
                metric: Some(vec![4.0, 1.0, 1.0, 2.0]),
            }],
        };
        let s = InitialSampler::new(&set, 3).unwrap();
        let zig = Ziggurat::get();
        let mut rng = PathRng::new(3, 0);
        let (mut x, mut scratch) = (vec![0.0; 3], vec![0.0; s.scratch_len()]);
        let n = 100_000;
        let mut inner = 0;
        for _ in 0..n {
            s.sample(&mut rng, zig, &mut x, &mut scratch);
            let (a, b) = (x[0] - 1.0, x[2] + 1.0);
            let q = 4.0 * a * a + 2.0 * a * b + 2.0 * b * b;
            assert!(q <= 0.25 * (1.0 + 1e-12), "{q}");
            assert!((1.0..=3.0).contains(&x[1]));
            // Uniform in a 2-ellipsoid: the inner half-radius ellipsoid holds 1/4 of the mass.
            if q <= 0.0625 {
                inner += 1;
            }
        }
        let frac = f64::from(inner) / f64::from(n);
        assert!((frac - 0.25).abs() < 0.006, "{frac}");
    }

    #[test]
    fn unbounded_or_missing_initial_values_are_refused() {
        let set = InitialSet {
            boxes: vec![Some(Bounds::new(0.0, f64::INFINITY))],
            balls: vec![],
        };
        assert!(matches!(
            InitialSampler::new(&set, 1),
            Err(InitialFault::UnboundedBox { state: 0, .. })
        ));
        let set = InitialSet {
            boxes: vec![None],
            balls: vec![],
        };
        assert!(matches!(
            InitialSampler::new(&set, 1),
            Err(InitialFault::Missing { state: 0 })
        ));
    }
}
