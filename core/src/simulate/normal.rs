//! Standard normal variates by the ziggurat method (Marsaglia and Tsang 2000, in Doornik's 2005
//! formulation "An improved ziggurat method to generate normal random samples"), 256 layers.
//!
//! One 64-bit draw gives the layer (low 8 bits) and a uniform in `[-1, 1)` (high 53 bits);
//! about 99% of the samples are accepted in the rectangle test, the rest go through the wedge
//! test (one `exp`) or, in the bottom layer, Marsaglia's exact tail sampler. The result has the
//! exact normal distribution up to the 52-bit resolution of the uniform.

use super::rng::PathRng;
use std::sync::OnceLock;

/// Number of layers.
const LAYERS: usize = 256;
/// Start of the tail (Marsaglia and Tsang's `r` for 256 layers).
const R: f64 = 3.654_152_885_361_009;
/// Area of every layer under `exp(-x^2 / 2)` (Marsaglia and Tsang's `v` for 256 layers).
const V: f64 = 4.928_673_233_99e-3;
/// `2^52`: the uniforms' resolution is `2^-52`.
pub(super) const TWO52: f64 = (1u64 << 52) as f64;

/// The layer tables.
#[derive(Debug)]
pub(crate) struct Ziggurat {
    /// Layer boundaries, decreasing: `x[0] = V / f(R)` (the bottom layer's width), `x[1] = R`,
    /// ..., `x[LAYERS] = 0`.
    x: [f64; LAYERS + 1],
    /// `x[i + 1] / x[i]`: a uniform below this (in absolute value) is in layer `i`'s rectangle.
    ratio: [f64; LAYERS],
    /// `f(x[i])`, the density at the layer boundaries (for the wedge test).
    fx: [f64; LAYERS + 1],
    /// `ratio` and `x` scaled by `2^52` and `2^-52` (exactly: powers of two), for the
    /// rectangle test on the uniform's integer numerator (see [`sample`](Self::sample)).
    pub(super) ratio52: [f64; LAYERS],
    pub(super) x52: [f64; LAYERS],
}

/// `exp(-x^2 / 2)`, the unnormalised density.
fn density(x: f64) -> f64 {
    (-0.5 * x * x).exp()
}

impl Ziggurat {
    /// The tables (computed once per process).
    pub(crate) fn get() -> &'static Ziggurat {
        static TABLES: OnceLock<Ziggurat> = OnceLock::new();
        TABLES.get_or_init(Ziggurat::build)
    }

    fn build() -> Ziggurat {
        let mut x = [0.0; LAYERS + 1];
        let mut f = density(R);
        x[0] = V / f;
        x[1] = R;
        for i in 2..LAYERS {
            // Layer i - 1 spans heights f(x[i-1]) .. f(x[i]) with area V.
            x[i] = (-2.0 * (V / x[i - 1] + f).ln()).sqrt();
            f = density(x[i]);
        }
        x[LAYERS] = 0.0;
        let (mut ratio, mut fx) = ([0.0; LAYERS], [0.0; LAYERS + 1]);
        let (mut ratio52, mut x52) = ([0.0; LAYERS], [0.0; LAYERS]);
        for i in 0..LAYERS {
            ratio[i] = x[i + 1] / x[i];
            ratio52[i] = ratio[i] * TWO52;
            x52[i] = x[i] / TWO52;
        }
        for i in 0..=LAYERS {
            fx[i] = density(x[i]);
        }
        Ziggurat {
            x,
            ratio,
            fx,
            ratio52,
            x52,
        }
    }

    /// One standard normal variate from `rng`.
    #[inline(always)]
    pub(crate) fn sample(&self, rng: &mut PathRng) -> f64 {
        let bits = rng.next_u64();
        let i = (bits & 0xff) as usize;
        // The uniform is u = v / 2^52 with v an integer in [-2^52, 2^52): working with v (exact
        // in f64; through i64, whose conversion is one instruction) and the scaled tables
        // saves a multiplication and gives the same comparisons and the same products, to the
        // bit, as u with the plain tables (scaling by a power of two is exact).
        let v = ((bits >> 11) as i64 - (1 << 52)) as f64;
        if v.abs() < self.ratio52[i] {
            return v * self.x52[i];
        }
        // The stream goes by value: a pointer to it would keep the caller's copy out of
        // registers on the fast path too.
        let (z, next) = self.sample_slow(i, v / TWO52, *rng);
        *rng = next;
        z
    }

    /// The rare cases: the bottom layer's tail, or a wedge (then, on rejection, start over).
    /// Returns the sample and the stream after it.
    #[cold]
    #[inline(never)]
    pub(super) fn sample_slow(&self, mut i: usize, mut u: f64, mut rng: PathRng) -> (f64, PathRng) {
        loop {
            if i == 0 {
                return (tail(u < 0.0, &mut rng), rng);
            }
            let x = u * self.x[i];
            // A uniform height in the layer, between f(x[i]) and f(x[i + 1]), under f(x).
            let (f0, f1) = (self.fx[i], self.fx[i + 1]);
            if f1 + rng.uniform() * (f0 - f1) < density(x) {
                return (x, rng);
            }
            let bits = rng.next_u64();
            i = (bits & 0xff) as usize;
            u = ((bits >> 11) as i64) as f64 * (1.0 / (1u64 << 52) as f64) - 1.0;
            if u.abs() < self.ratio[i] {
                return (u * self.x[i], rng);
            }
        }
    }
}

/// Marsaglia's exact sampler of the normal tail beyond `R`, with the given sign.
fn tail(negative: bool, rng: &mut PathRng) -> f64 {
    loop {
        let x = rng.uniform_open0().ln() / R;
        let y = rng.uniform_open0().ln();
        if -2.0 * y >= x * x {
            return if negative { x - R } else { R - x };
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// Standard normal CDF via erfc (Numerical Recipes' Chebyshev fit, |error| < 1.2e-7).
    pub(in crate::simulate) fn phi(x: f64) -> f64 {
        let z = x.abs() / std::f64::consts::SQRT_2;
        let t = 1.0 / (1.0 + 0.5 * z);
        let erfc = t
            * (-z * z - 1.265_512_23
                + t * (1.000_023_68
                    + t * (0.374_091_96
                        + t * (0.096_784_18
                            + t * (-0.186_288_06
                                + t * (0.278_868_07
                                    + t * (-1.135_203_98
                                        + t * (1.488_515_87
                                            + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
                .exp();
        if x >= 0.0 {
            1.0 - 0.5 * erfc
        } else {
            0.5 * erfc
        }
    }

    /// The rectangle test on the uniform's numerator with the scaled tables accepts exactly
    /// what the plain test on the uniform accepts, with the same sample to the bit.
    #[test]
    fn the_scaled_rectangle_test_is_the_plain_one() {
        let z = Ziggurat::get();
        let mut rng = PathRng::new(2, 0);
        // Random draws, and the numerators next to every layer's boundary `+-ratio * 2^52`.
        let edges = (0..LAYERS as u64).flat_map(|i| {
            let r = z.ratio52[i as usize] as i64;
            [-r - 1, -r, -r + 1, r - 1, r, r + 1].map(|v| (((v + (1 << 52)) as u64) << 11) | i)
        });
        let random = (0..1_000_000).map(|_| rng.next_u64());
        for bits in edges.collect::<Vec<_>>().into_iter().chain(random) {
            let i = (bits & 0xff) as usize;
            let u = ((bits >> 11) as i64) as f64 * (1.0 / TWO52) - 1.0;
            let v = ((bits >> 11) as i64 - (1 << 52)) as f64;
            assert_eq!(u.abs() < z.ratio[i], v.abs() < z.ratio52[i], "{bits:#x}");
            assert_eq!(u, v / TWO52);
            if u.abs() < z.ratio[i] {
                assert_eq!(u * z.x[i], v * z.x52[i], "{bits:#x}");
            }
        }
    }

    #[test]
    fn the_layers_close_at_the_top() {
        let z = Ziggurat::get();
        // The top layer (x[255] .. 0, height 1 - f(x[255])) must also have area V.
        let top = z.x[LAYERS - 1] * (1.0 - density(z.x[LAYERS - 1]));
        assert!((top - V).abs() < 1e-9 * V, "top layer area {top} vs {V}");
        assert!(z.x.windows(2).all(|w| w[0] > w[1]));
    }

    #[test]
    fn samples_follow_the_normal_distribution() {
        let z = Ziggurat::get();
        let mut rng = PathRng::new(11, 0);
        let n = 1_000_000;
        let mut xs: Vec<f64> = (0..n).map(|_| z.sample(&mut rng)).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64;
        let kurt = xs.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / n as f64 / (var * var);
        // Standard errors: mean 1e-3, variance 1.4e-3, kurtosis ~5e-3.
        assert!(mean.abs() < 5e-3, "mean {mean}");
        assert!((var - 1.0).abs() < 7e-3, "variance {var}");
        assert!((kurt - 3.0).abs() < 0.03, "kurtosis {kurt}");
        // Kolmogorov-Smirnov: the 0.1% critical value is 1.95 / sqrt(n).
        xs.sort_by(f64::total_cmp);
        let ks = xs
            .iter()
            .enumerate()
            .map(|(k, &x)| {
                let f = phi(x);
                (f - k as f64 / n as f64)
                    .abs()
                    .max(((k + 1) as f64 / n as f64 - f).abs())
            })
            .fold(0.0, f64::max);
        assert!(ks < 1.95 / (n as f64).sqrt(), "KS statistic {ks}");
        // The tail beyond R (bottom layer, Marsaglia's sampler): P(|Z| > R) = 2.58e-4.
        let beyond = xs.iter().filter(|x| x.abs() > R).count() as f64;
        let expected = 2.0 * (1.0 - phi(R)) * n as f64;
        assert!(
            (beyond - expected).abs() < 4.0 * expected.sqrt(),
            "{beyond} beyond R, expected {expected}"
        );
        // And a deeper tail: P(Z > 4) = 3.17e-5.
        let beyond4 = xs.iter().filter(|&&x| x > 4.0).count() as f64;
        assert!(
            (beyond4 - 31.7).abs() < 4.0 * 31.7f64.sqrt(),
            "{beyond4} beyond 4"
        );
    }
}
