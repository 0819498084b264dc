//! Eight paths' random streams and normals in the lanes of AVX-512 registers: lane `l` draws
//! the same numbers, to the bit, as [`PathRng::next_u64`] and [`Ziggurat::sample`] draw for
//! its path, so the paths do not depend on which loop simulates them.
//!
//! wyrand's 64 x 64 -> 128-bit product has no vector instruction; it is built from four
//! 32 x 32 -> 64-bit products (`vpmuludq`), eight lanes at a time. The ziggurat's rectangle
//! test (98.5% of the draws) runs in the lanes with two table gathers; the lanes that fail it
//! finish in the scalar [`Ziggurat::sample_slow`] with their own streams.

use super::normal::{Ziggurat, TWO52};
use super::paths::SMALL;
use super::rng::{PathRng, INC, MIX};
use crate::lanes::X8;
use std::arch::x86_64::*;

/// Whether the processor has the extensions this module needs.
pub(crate) fn available() -> bool {
    is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512dq")
}

/// For the tests of the lanes: panics, saying why, when the processor has not the extensions.
/// Those tests are ignored where the machine that builds them has none (`core/build.rs` sets
/// `reachc_avx512`), so this fails only when they were built to run here regardless
/// (`REACHC_REQUIRE_AVX512=1`) or on another machine: never a silent pass.
#[cfg(test)]
pub(crate) fn require() {
    assert!(
        available(),
        "this processor has no AVX-512 (F and DQ): the lanes cannot run (the tests were built \
         with REACHC_REQUIRE_AVX512=1, or on another machine)"
    );
}

/// The streams of eight paths: lane `l` holds the wyrand state of path `l`.
#[derive(Clone, Copy)]
pub(crate) struct Rng8(__m512i);

impl Rng8 {
    /// The eight paths' streams.
    #[target_feature(enable = "avx512f")]
    pub(crate) fn new(paths: [PathRng; 8]) -> Rng8 {
        Rng8(to_vec(paths.map(PathRng::state)))
    }

    /// The next 64 random bits of every lane ([`PathRng::next_u64`]).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn next(&mut self) -> __m512i {
        let low = _mm512_set1_epi64(0xffff_ffff);
        let s = _mm512_add_epi64(self.0, _mm512_set1_epi64(INC as i64));
        self.0 = s;
        let b = _mm512_xor_si512(s, _mm512_set1_epi64(MIX as i64));
        let (s_hi, b_hi) = (_mm512_srli_epi64::<32>(s), _mm512_srli_epi64::<32>(b));
        // The four partial products of (s_hi 2^32 + s_lo)(b_hi 2^32 + b_lo).
        let ll = _mm512_mul_epu32(s, b);
        let lh = _mm512_mul_epu32(s, b_hi);
        let hl = _mm512_mul_epu32(s_hi, b);
        let hh = _mm512_mul_epu32(s_hi, b_hi);
        // Bits 32..96 of the product: below 3 * 2^32, no overflow.
        let mid = _mm512_add_epi64(
            _mm512_srli_epi64::<32>(ll),
            _mm512_add_epi64(_mm512_and_si512(lh, low), _mm512_and_si512(hl, low)),
        );
        let lo = _mm512_or_si512(_mm512_slli_epi64::<32>(mid), _mm512_and_si512(ll, low));
        let hi = _mm512_add_epi64(
            _mm512_add_epi64(hh, _mm512_srli_epi64::<32>(mid)),
            _mm512_add_epi64(_mm512_srli_epi64::<32>(lh), _mm512_srli_epi64::<32>(hl)),
        );
        _mm512_xor_si512(hi, lo)
    }

    /// One standard normal per lane ([`Ziggurat::sample`]); the lanes outside `live` may get
    /// any value (their paths have ended).
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(crate) fn normal(&mut self, zig: &Ziggurat, live: u8) -> X8 {
        let bits = self.next();
        let layer = _mm512_and_si512(bits, _mm512_set1_epi64(0xff));
        let v = _mm512_cvtepi64_pd(_mm512_sub_epi64(
            _mm512_srli_epi64::<11>(bits),
            _mm512_set1_epi64(1 << 52),
        ));
        // SAFETY: every index is below 256, the tables' length.
        let (ratio, x) = unsafe {
            (
                _mm512_i64gather_pd::<8>(layer, zig.ratio52.as_ptr()),
                _mm512_i64gather_pd::<8>(layer, zig.x52.as_ptr()),
            )
        };
        let inside = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(_mm512_abs_pd(v), ratio);
        let z = _mm512_mul_pd(v, x);
        let slow = live & !inside;
        if slow == 0 {
            return to_x8(z);
        }
        to_x8(self.finish(zig, slow, z, v, layer))
    }

    /// The lanes in `slow` that failed the rectangle test: [`Ziggurat::sample_slow`] from
    /// where [`Ziggurat::sample`] calls it, with their streams. Lanes move between vectors
    /// and scalars in registers: through memory, a 64-byte store read back as 8-byte loads
    /// (or the reverse) stalls store forwarding, which cost more than the rest here.
    #[cold]
    #[inline(never)]
    #[target_feature(enable = "avx512f")]
    fn finish(
        &mut self,
        zig: &Ziggurat,
        slow: u8,
        z: __m512d,
        v: __m512d,
        layer: __m512i,
    ) -> __m512d {
        let mut z = z;
        let mut rest = slow;
        while rest != 0 {
            let l = rest.trailing_zeros();
            rest &= rest - 1;
            let pick = _mm512_set1_epi64(i64::from(l));
            let lane_i = |w: __m512i| {
                _mm_cvtsi128_si64(_mm512_castsi512_si128(_mm512_permutexvar_epi64(pick, w))) as u64
            };
            let lane_d = |w: __m512d| _mm512_cvtsd_f64(_mm512_permutexvar_pd(pick, w));
            let rng = PathRng::at(lane_i(self.0));
            let (zl, rng) = zig.sample_slow(lane_i(layer) as usize, lane_d(v) / TWO52, rng);
            z = _mm512_mask_broadcastsd_pd(z, 1 << l, _mm_set_sd(zl));
            self.0 = _mm512_mask_set1_epi64(self.0, 1 << l, rng.state() as i64);
        }
        z
    }
}

/// Eight paths of a model with at most [`SMALL`] states: state `i` of path `l` in lane `l` of
/// vector `i`, and their streams.
pub(crate) struct Group8 {
    x: [__m512d; SMALL],
    rng: Rng8,
}

impl Group8 {
    /// The paths with states `x` (`n` per path, one path after the other; eight paths
    /// read) and streams `paths`.
    #[target_feature(enable = "avx512f")]
    pub(crate) fn new(n: usize, x: &[f64], paths: [PathRng; 8]) -> Group8 {
        Group8 {
            x: std::array::from_fn(|i| {
                let lanes: [f64; 8] =
                    std::array::from_fn(|l| if i < n { x[l * n + i] } else { 0.0 });
                to_pd(X8(lanes))
            }),
            rng: Rng8::new(paths),
        }
    }

    /// The states, for [`System::drift_x8`](crate::System::drift_x8).
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn states(&self) -> [X8; SMALL] {
        // SAFETY: as in `to_x8`, per vector.
        unsafe { std::mem::transmute(self.x) }
    }

    /// Replaces the states (after [`Noise::apply_x8`](super::noise::Noise::apply_x8)).
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn set_states(&mut self, x: &[X8; SMALL]) {
        // SAFETY: as in `to_pd`, per vector.
        self.x = unsafe { std::mem::transmute::<[X8; SMALL], [__m512d; SMALL]>(*x) };
    }

    /// One standard normal per lane from the lanes' streams ([`Rng8::normal`]).
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(crate) fn normal(&mut self, zig: &Ziggurat, live: u8) -> X8 {
        self.rng.normal(zig, live)
    }

    /// The next 64 random bits of every lane's stream ([`PathRng::next_u64`]; lane `l` in
    /// entry `l`), for the draws of inputs.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn bits(&mut self) -> [u64; 8] {
        // SAFETY: eight 64-bit lanes, any bit pattern a valid `u64`.
        unsafe { std::mem::transmute::<__m512i, [u64; 8]>(self.rng.next()) }
    }

    /// Path `l`'s state (by permutes: indexing into memory would keep the states out of
    /// registers in the whole loop).
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn lane(&self, l: usize) -> [f64; SMALL] {
        let pick = _mm512_set1_epi64(l as i64);
        let mut out = [0.0; SMALL];
        for (o, &x) in out.iter_mut().zip(&self.x) {
            *o = _mm512_cvtsd_f64(_mm512_permutexvar_pd(pick, x));
        }
        out
    }

    /// One Euler-Maruyama step of the first `n` states with drift `f`: `x_i + (f_i h + ds_i
    /// z_i)`, the `z_i` drawn in state order ([`Plan::additive_lanes`]'s operations).
    ///
    /// [`Plan::additive_lanes`]: super::paths
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(crate) fn step(
        &mut self,
        n: usize,
        f: &[X8; SMALL],
        h: f64,
        ds: &[f64; SMALL],
        zig: &Ziggurat,
        live: u8,
    ) {
        let hv = _mm512_set1_pd(h);
        for i in 0..n {
            let z = to_pd(self.rng.normal(zig, live));
            let noise = _mm512_mul_pd(_mm512_set1_pd(ds[i]), z);
            let inc = _mm512_add_pd(_mm512_mul_pd(to_pd(f[i]), hv), noise);
            self.x[i] = _mm512_add_pd(self.x[i], inc);
        }
    }

    /// `q = sum_i w_i (x_i - c_i)^2` per lane (as `diag_quad` sums it) and the mask of the
    /// lanes where `q < bound` is false (NaN included).
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn quad(&self, n: usize, w: &[f64], c: &[f64], bound: f64) -> (X8, u8) {
        let mut q = _mm512_setzero_pd();
        for i in 0..n {
            let d = _mm512_sub_pd(self.x[i], _mm512_set1_pd(c[i]));
            let t = _mm512_mul_pd(_mm512_mul_pd(_mm512_set1_pd(w[i]), d), d);
            q = if i == 0 { t } else { _mm512_add_pd(q, t) };
        }
        let loud = _mm512_cmp_pd_mask::<_CMP_NLT_UQ>(q, _mm512_set1_pd(bound));
        (to_x8(q), loud)
    }

    /// The mask of the lanes where `q < bound` is false (NaN included), `q = sum_i w_i (x_i -
    /// y_i)^2` with `y_i` the state clamped into `[lo_i, hi_i]`: per lane, what
    /// [`diag_quad_to_box`](super::check::diag_quad_to_box) computes, to the bit.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn outside_box(
        &self,
        n: usize,
        w: &[f64],
        lo: &[f64],
        hi: &[f64],
        bound: f64,
    ) -> u8 {
        let mut q = _mm512_setzero_pd();
        for i in 0..n {
            let x = self.x[i];
            let (l, u) = (_mm512_set1_pd(lo[i]), _mm512_set1_pd(hi[i]));
            // `clamp`: above `hi` takes `hi`, then below `lo` takes `lo` (so `lo` wins, as in
            // the scalar `if`s); NaN compares false and stays.
            let above = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(x, u);
            let below = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(x, l);
            let y = _mm512_mask_blend_pd(below, _mm512_mask_blend_pd(above, x, u), l);
            let d = _mm512_sub_pd(x, y);
            let t = _mm512_mul_pd(_mm512_mul_pd(_mm512_set1_pd(w[i]), d), d);
            q = if i == 0 { t } else { _mm512_add_pd(q, t) };
        }
        _mm512_cmp_pd_mask::<_CMP_NLT_UQ>(q, _mm512_set1_pd(bound))
    }
}

#[inline]
#[target_feature(enable = "avx512f")]
fn to_vec(a: [u64; 8]) -> __m512i {
    // SAFETY: eight u64 are the vector's 64 bytes, any bits valid.
    unsafe { std::mem::transmute(a) }
}

#[inline]
#[target_feature(enable = "avx512f")]
fn to_x8(v: __m512d) -> X8 {
    // SAFETY: `X8` is eight f64 (`repr(C)`), the vector's 64 bytes.
    unsafe { std::mem::transmute(v) }
}

#[inline]
#[target_feature(enable = "avx512f")]
fn to_pd(v: X8) -> __m512d {
    // SAFETY: as in `to_x8`.
    unsafe { std::mem::transmute(v) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lane draws its path's numbers and normals, including the slow cases (wedges,
    /// the tail: about 1.5% of the draws, so thousands here). Ignored where the machine that
    /// built the tests has no AVX-512 (see [`require`]).
    #[cfg_attr(
        not(reachc_avx512),
        ignore = "no AVX-512 (F and DQ) on the machine that built the tests: the lanes cannot run"
    )]
    #[test]
    fn lanes_draw_what_each_path_draws() {
        require();
        let zig = Ziggurat::get();
        let paths: [PathRng; 8] = std::array::from_fn(|l| PathRng::new(3, 100 + l as u64));
        let mut scalar = paths;
        // SAFETY: `require()`: the processor has the extensions.
        let mut lanes = unsafe { Rng8::new(paths) };
        for draw in 0..100_000 {
            // Every third draw, lane 5 is left out: its stream must not move.
            let live = if draw % 3 == 0 { !(1 << 5) } else { 0xff };
            // SAFETY: `require()`: the processor has the extensions.
            let z = unsafe { lanes.normal(zig, live) };
            for (l, rng) in scalar.iter_mut().enumerate() {
                if live & (1 << l) != 0 {
                    assert_eq!(z.0[l].to_bits(), zig.sample(rng).to_bits(), "draw {draw}");
                } else {
                    rng.next_u64();
                }
            }
        }
        // SAFETY: eight u64 are the vector's 64 bytes.
        let states: [u64; 8] = unsafe { std::mem::transmute(lanes.0) };
        assert_eq!(states, scalar.map(PathRng::state));
    }

    /// The lanes' distance to a box is the scalar `diag_quad_to_box`, and so is the decision
    /// against the bound: random states inside, outside and on the faces of a box, with
    /// states far away, infinite and NaN, and the bound at the lanes' own values. Ignored where
    /// the machine that built the tests has no AVX-512 (see [`require`]).
    #[cfg_attr(
        not(reachc_avx512),
        ignore = "no AVX-512 (F and DQ) on the machine that built the tests: the lanes cannot run"
    )]
    #[test]
    fn lanes_measure_the_distance_to_a_box_as_the_scalar_loop() {
        use super::super::check::diag_quad_to_box;
        require();
        let mut rng = PathRng::new(4, 0);
        let (w, lo, hi) = ([2.0, 0.5, 1.0], [-1.0, 0.0, 0.25], [1.0, 0.0, 0.75]);
        let special = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0, 0.0, 1e300];
        let mut loud = 0;
        for round in 0..2000 {
            let n = 1 + round % 3;
            let x: Vec<f64> = (0..8 * n)
                .map(|v| match (round + v) % 11 {
                    0 => special[(round / 11 + v) % special.len()],
                    1 => [lo[v % n], hi[v % n]][round % 2],
                    _ => 4.0 * rng.uniform() - 2.0,
                })
                .collect();
            let paths = [PathRng::new(0, 0); 8];
            // SAFETY: `require()`: the processor has the extensions.
            let group = unsafe { Group8::new(n, &x, paths) };
            let q: Vec<f64> = (0..8)
                .map(|l| diag_quad_to_box(&w[..n], &x[l * n..][..n], &lo, &hi))
                .collect();
            for bound in [q[round % 8], 0.5, f64::INFINITY] {
                // SAFETY: `require()`: the processor has the extensions.
                let mask = unsafe { group.outside_box(n, &w, &lo, &hi, bound) };
                for (l, q) in q.iter().enumerate() {
                    let scalar = q.partial_cmp(&bound) != Some(std::cmp::Ordering::Less);
                    assert_eq!(
                        mask >> l & 1 == 1,
                        scalar,
                        "round {round}, lane {l}, q = {q}"
                    );
                    loud += u32::from(scalar);
                }
            }
        }
        assert!(loud > 1000, "{loud}");
    }
}
