//! Per-path random streams: one wyrand sequence cut into disjoint segments, one per path.
//!
//! wyrand's state is a Weyl sequence `s_i = s_0 + i * INC (mod 2^64)` with an odd `INC`, so
//! `i -> s_i` is a bijection: path `p` starts at draw `p * 2^32` and the segments of paths
//! `0 .. 2^32` never overlap (a path draws far fewer than `2^32` numbers; the simulator checks).
//! A path's numbers therefore depend only on `(seed, p)`, never on which thread ran it or on
//! how paths were grouped, which is what makes the results independent of the thread count.

/// wyrand's Weyl increment (odd).
pub(super) const INC: u64 = 0xa076_1d64_78bd_642f;
/// wyrand's mixing constant.
pub(super) const MIX: u64 = 0xe703_7ed1_a0b4_28db;

/// Number of draws reserved for each path (the segment length).
pub(crate) const DRAWS_PER_PATH: u64 = 1 << 32;

/// Largest number of paths with disjoint segments.
pub(crate) const MAX_PATHS: u64 = 1 << 32;

/// SplitMix64's finaliser: spreads a user seed (often 0, 1, 2...) over the whole state space.
fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Uniform on `[0, 1)` from the top 53 of 64 random `bits`.
#[inline(always)]
pub(crate) fn uniform(bits: u64) -> f64 {
    // Through i64: 53 bits fit, and the signed conversion is one instruction.
    ((bits >> 11) as i64) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The random stream of one path (wyrand).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathRng {
    state: u64,
}

impl PathRng {
    /// The stream of path `path` for `seed`.
    pub(crate) fn new(seed: u64, path: u64) -> Self {
        let start = path.wrapping_mul(DRAWS_PER_PATH).wrapping_mul(INC);
        PathRng {
            state: splitmix64(seed).wrapping_add(start),
        }
    }

    /// The stream at wyrand state `state` (see [`state`](Self::state)).
    pub(super) fn at(state: u64) -> Self {
        PathRng { state }
    }

    /// Its wyrand state: the stream continues from [`at`](Self::at) of it.
    pub(super) fn state(self) -> u64 {
        self.state
    }

    /// The next 64 random bits.
    #[inline(always)]
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(INC);
        let t = u128::from(self.state) * u128::from(self.state ^ MIX);
        ((t >> 64) as u64) ^ (t as u64)
    }

    /// Uniform on `[0, 1)` with 53 random bits.
    #[inline(always)]
    pub(crate) fn uniform(&mut self) -> f64 {
        uniform(self.next_u64())
    }

    /// Uniform on `(0, 1]` (never 0: safe under `ln`).
    #[inline]
    pub(crate) fn uniform_open0(&mut self) -> f64 {
        (((self.next_u64() >> 11) + 1) as i64) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_continues_where_the_previous_segment_would_end() {
        // Path 1 starts exactly DRAWS_PER_PATH draws after path 0 (disjoint segments).
        let mut p0 = PathRng::new(7, 0);
        p0.state = p0.state.wrapping_add(DRAWS_PER_PATH.wrapping_mul(INC));
        let mut p1 = PathRng::new(7, 1);
        for _ in 0..10 {
            assert_eq!(p0.next_u64(), p1.next_u64());
        }
    }

    #[test]
    fn uniforms_have_the_right_mean_and_range() {
        let mut r = PathRng::new(1, 3);
        let n = 200_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
            let v = r.uniform_open0();
            assert!(v > 0.0 && v <= 1.0);
            sum += u;
        }
        // Standard error of the mean: sqrt(1/12 / n) ~ 6.5e-4.
        assert!((sum / n as f64 - 0.5).abs() < 4e-3);
    }

    #[test]
    fn different_seeds_and_paths_give_different_streams() {
        let first = |seed, path| PathRng::new(seed, path).next_u64();
        assert_ne!(first(0, 0), first(1, 0));
        assert_ne!(first(0, 0), first(0, 1));
        assert_eq!(first(5, 9), first(5, 9));
    }
}
