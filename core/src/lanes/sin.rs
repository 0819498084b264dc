//! `sin` of eight lanes, bit for bit what the platform's `f64::sin` gives.
//!
//! glibc's `sin` (sysdeps/ieee754/dbl-64/s_sin.c, in its `__sin_fma` build, which x86-64
//! processors with FMA run, as every processor with AVX-512 does) returns `x` itself for
//! `|x| < 2^-26` and evaluates `|x| < 0.126` with a short polynomial (`TAYLOR_SIN` with
//! `dx = 0`). The lanes in that range are evaluated here in vector registers with the same
//! fused and plain operations in the same order as that build's machine code, so each gives
//! the library's bits; the other lanes call the library. Small angles are the common case of
//! the models we simulate (the pendulum near upright, attitude errors).
//!
//! Whether the library is that code is checked once per process ([`agrees`]) on arguments
//! spread over the polynomial's range, where any other implementation (another libm, another
//! glibc variant or version) differs from it on a large fraction of them; if one differs,
//! every lane calls the library.

use super::X8;
use std::sync::OnceLock;

/// The polynomial's coefficients, `s1` to `s5` of s_sin.c.
const S1: f64 = -0.166_666_666_666_666_66;
const S2: f64 = 0.008_333_333_333_332_329;
const S3: f64 = -0.000_198_412_698_344_146_42;
const S4: f64 = 2.755_729_806_860_771e-6;
const S5: f64 = -2.502_201_484_831_839_8e-8;

/// Below this `|x|` (high word `0x3e500000`, that is `2^-26`) the library returns `x`.
const TINY_HIGH_WORD: u32 = 0x3e50_0000;
/// Below this `|x|` the library evaluates the polynomial.
const TAYLOR_BELOW: f64 = 0.126;

/// The library's `sin` of `x` for `|x| < 0.126` (`None` above, or for NaN).
#[inline(always)]
fn small(x: f64) -> Option<f64> {
    let ax = x.abs();
    // False for NaN too.
    let in_range = ax < TAYLOR_BELOW;
    if !in_range {
        return None;
    }
    if ((ax.to_bits() >> 32) as u32) < TINY_HIGH_WORD {
        return Some(x);
    }
    Some(taylor(x))
}

/// `TAYLOR_SIN(x * x, x, 0)` as `__sin_fma` computes it: the polynomial in `xx` by fused
/// multiply-adds, then `x + xx (x p)` (the machine code's `x p - 0` and `xx t + 0` are fused
/// operations with a zero addend, which round like the plain products).
#[inline(always)]
fn taylor(x: f64) -> f64 {
    let xx = x * x;
    let p = S5.mul_add(xx, S4);
    let p = xx.mul_add(p, S3);
    let p = xx.mul_add(p, S2);
    let p = xx.mul_add(p, S1);
    let t = x * p;
    x + xx * t
}

impl X8 {
    /// `f64::sin` of every lane, to the bit: the small arguments by the library's own
    /// polynomial in vector registers where the library is the one this module follows (see
    /// the module's notes), the others by the library.
    #[inline(always)]
    pub fn sin(self) -> X8 {
        if !agrees() {
            return self.map(f64::sin);
        }
        // Every lane through the polynomial (branch-free, so it vectorises); then the lanes
        // outside its range, if any, by the library.
        let mut out = [0.0; 8];
        let mut rest = 0u8;
        for (l, (o, &x)) in out.iter_mut().zip(&self.0).enumerate() {
            let ax = x.abs();
            let tiny = ((ax.to_bits() >> 32) as u32) < TINY_HIGH_WORD;
            *o = if tiny { x } else { taylor(x) };
            // False for NaN too.
            let in_range = ax < TAYLOR_BELOW;
            rest |= u8::from(!in_range) << l;
        }
        while rest != 0 {
            let l = rest.trailing_zeros() as usize;
            out[l] = self.0[l].sin();
            rest &= rest - 1;
        }
        X8(out)
    }
}

/// Whether the library's `sin` is the code [`small`] follows, on arguments spread over its
/// range (checked once per process).
pub(crate) fn agrees() -> bool {
    static AGREES: OnceLock<bool> = OnceLock::new();
    *AGREES.get_or_init(|| agrees_with(f64::sin))
}

/// Whether `sin` gives [`small`]'s bits on every argument of the probe.
fn agrees_with(sin: impl Fn(f64) -> f64) -> bool {
    let args: Vec<f64> = probe().collect();
    #[cfg(target_arch = "x86_64")]
    if is_x86_feature_detected!("fma") {
        // SAFETY: the processor has the extension.
        return unsafe { agrees_on_with_fma(&args, sin) };
    }
    agrees_on(&args, sin)
}

/// Whether `sin` gives [`small`]'s bits on every argument of `args`.
#[inline(always)]
fn agrees_on(args: &[f64], sin: impl Fn(f64) -> f64) -> bool {
    // A loop (not iterator adapters) so that it is compiled with the caller's extensions.
    for &x in args {
        if small(x).map(f64::to_bits) != Some(sin(x).to_bits()) {
            return false;
        }
    }
    true
}

/// [`agrees_on`] with fused multiply-adds in instructions rather than library calls (the
/// same results, tens of milliseconds less per process).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn agrees_on_with_fma(args: &[f64], sin: impl Fn(f64) -> f64) -> bool {
    agrees_on(args, sin)
}

/// `2^15` arguments below `0.126`: both signs, every binade from `2^-28` up (each split
/// evenly), the range's ends, and its upper part sampled densely (where the polynomial's
/// terms matter most to the rounding).
fn probe() -> impl Iterator<Item = f64> {
    // A fixed sequence (splitmix64), so every process checks the same arguments.
    let mut s = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let unit = move |bits: u64| (bits >> 11) as f64 / (1u64 << 53) as f64;
    let ends = [
        f64::from_bits(u64::from(TINY_HIGH_WORD) << 32),
        f64::from_bits((u64::from(TINY_HIGH_WORD) << 32) - 1),
        TAYLOR_BELOW.next_down(),
        0.0,
    ];
    (0..1 << 14)
        .map(move |i| {
            let r = next();
            let x = if i % 2 == 0 {
                // Binades 2^-28 .. 2^-3 (0.126 lies in the last).
                let e = (r % 26) as i32 - 28;
                2f64.powi(e) * (1.0 + unit(next()))
            } else {
                0.03 + (TAYLOR_BELOW - 0.03) * unit(r)
            };
            x.min(TAYLOR_BELOW.next_down())
        })
        .chain(ends)
        .flat_map(|x| [x, -x])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng::XorShift64;

    /// Lanes against `f64::sin` over and around the polynomial's range, and the special values.
    #[test]
    fn sin_lanes_are_the_librarys() {
        assert!(
            agrees(),
            "this platform's sin is not glibc's __sin_fma: the lanes call the library (correct, \
             but the vector path this test is for is not exercised)"
        );
        let mut rng = XorShift64(12345);
        let mut next = move || rng.next_u64();
        let specials = [
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            5e-324,
            1e-300,
            2f64.powi(-26),
            2f64.powi(-26).next_down(),
            0.126,
            0.126f64.next_down(),
            0.126f64.next_up(),
            0.5,
            1.0,
            3.0,
            1e6,
            f64::INFINITY,
            f64::NAN,
        ];
        let mut xs: Vec<f64> = specials.iter().flat_map(|&x| [x, -x]).collect();
        for _ in 0..1 << 20 {
            let r = next();
            let x = match r % 4 {
                // Uniform over [-0.2, 0.2]: both sides of 0.126.
                0 | 1 => ((r >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.4,
                // Random bits with exponents up to 2^0 (down to subnormals).
                2 => f64::from_bits(next() & 0xbfff_ffff_ffff_ffff) % 1.0,
                _ => f64::from_bits(next()),
            };
            xs.push(x);
        }
        for chunk in xs.chunks_exact(8) {
            let lanes = X8(std::array::from_fn(|l| chunk[l])).sin();
            for (l, &x) in chunk.iter().enumerate() {
                assert_eq!(
                    lanes.0[l].to_bits(),
                    x.sin().to_bits(),
                    "sin({x:e}) in lane {l}"
                );
            }
        }
    }

    /// A library that differs from the polynomial on one argument in a thousand (one ulp)
    /// is caught by the probe, whichever thousandth.
    #[test]
    fn the_probe_catches_a_library_that_differs() {
        for salt in 0..20u64 {
            let other = |x: f64| {
                let s = x.sin();
                let h = (x.to_bits() ^ salt).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 54;
                if h == 0 {
                    s.next_up()
                } else {
                    s
                }
            };
            assert!(!agrees_with(other), "salt {salt}");
        }
        assert!(agrees_with(|x| small(x).unwrap_or(0.0)));
    }
}
