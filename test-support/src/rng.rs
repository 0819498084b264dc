//! Deterministic random numbers for tests (no `rand` dependency), so that failures reproduce:
//! [`Rng`] (xorshift64*) for new tests, and the two generators older tests draw their fixed
//! sequences from, [`XorShift64`] and [`Lcg64`]. A generator is its state: `Rng(seed)`, any
//! seed but 0 for the xorshifts (0 stays 0).
//!
//! This file is also compiled into reachc-core's own unit tests (`core/src/test_support.rs`),
//! so it names nothing outside `std`.

use std::f64::consts::TAU;

/// `2^-53`: a 53-bit integer times this is uniform in `[0, 1)`.
const UNIT: f64 = 1.0 / (1u64 << 53) as f64;

/// xorshift64* (Vigna): the tests' generator.
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `[0, 1)` (the top 53 bits).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * UNIT
    }

    /// Uniform in `(0, 1)` (the top 53 bits and a half), for logarithms.
    pub fn open(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) * UNIT
    }

    /// Uniform in `[lo, hi)`: `lo + (hi - lo) u`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// A standard normal: [`box_muller`] of `1 - u` (in `(0, 1]`) and a second uniform.
    pub fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        box_muller(u, self.uniform())
    }

    /// Two independent standard normals: both of Box-Muller's, from two [`open`](Self::open)
    /// uniforms.
    pub fn normal_pair(&mut self) -> (f64, f64) {
        let (u, v) = (self.open(), self.open());
        let r = (-2.0 * u.ln()).sqrt();
        let th = TAU * v;
        (r * th.cos(), r * th.sin())
    }
}

/// Box-Muller: the standard normal `sqrt(-2 ln u) cos(2 pi v)` of `u` in `(0, 1]` and `v` in
/// `[0, 1)`.
pub fn box_muller(u: f64, v: f64) -> f64 {
    (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
}

/// Marsaglia's xorshift64 (shifts 13, 7, 17), without the multiplication of [`Rng`].
#[derive(Clone, Debug)]
pub struct XorShift64(pub u64);

impl XorShift64 {
    /// The next 64 bits (the state itself).
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in `[0, 1)` (the top 53 bits).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * UNIT
    }

    /// Uniform in `[lo, hi)`: `lo + (hi - lo) u`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Below `n` (the next 64 bits modulo `n`).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
}

/// Knuth's MMIX linear congruential generator.
#[derive(Clone, Debug)]
pub struct Lcg64(pub u64);

impl Lcg64 {
    /// The next 64 bits (the state itself).
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0
    }

    /// Uniform in `[lo, hi)`: `lo + (hi - lo) u`, `u` the top 53 bits in `[0, 1)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 * UNIT)
    }
}
