//! Shards of a simulation: shard `I` of `K` runs the paths `[floor(I N / K), floor((I + 1) N /
//! K))` of `N`. Every path draws from its own stream, derived from `(seed, path index)`, so a
//! shard's paths are, bit for bit, those an unsharded run gives that range.

use std::fmt;
use std::ops::Range;

/// Shard `index` of `count` (0-based): always `index < count`, checked where it is made
/// ([`Shard::new`], [`Shard::parse`], or read from a part file), so no consumer checks again:
///
/// ```compile_fail,E0451
/// let shard = reachc_core::simulate::Shard { index: 9, count: 3 };
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Shard {
    /// Which shard, `0 <= index < count`.
    pub(crate) index: u64,
    /// How many shards share the paths (at least 1).
    pub(crate) count: u64,
}

/// Why `I/K` is not a shard.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ShardError {
    /// `K = 0`.
    NoShards,
    /// `I >= K`.
    IndexTooLarge {
        /// `I`.
        index: u64,
        /// `K`.
        count: u64,
    },
    /// Not `I/K` with whole numbers.
    Syntax {
        /// The text given.
        text: String,
    },
}

impl std::error::Error for ShardError {}

impl Shard {
    /// All paths in one shard (an unsharded run).
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Shard `index` of `count`, or why not (`count` is 0, or `index >= count`).
    pub fn new(index: u64, count: u64) -> Result<Shard, ShardError> {
        if count == 0 {
            return Err(ShardError::NoShards);
        }
        if index >= count {
            return Err(ShardError::IndexTooLarge { index, count });
        }
        Ok(Shard { index, count })
    }

    /// Parses `I/K`, e.g. `3/8`.
    pub fn parse(s: &str) -> Result<Shard, ShardError> {
        let syntax = || ShardError::Syntax {
            text: s.to_string(),
        };
        let number = |v: &str| v.trim().parse::<u64>().map_err(|_| syntax());
        let (i, k) = s.split_once('/').ok_or_else(syntax)?;
        Shard::new(number(i)?, number(k)?)
    }

    /// Which shard, `0 <= index < count`.
    pub fn index(self) -> u64 {
        self.index
    }

    /// How many shards share the paths (at least 1).
    pub fn count(self) -> u64 {
        self.count
    }

    /// This shard's paths among `paths` (`floor(I N / K) .. floor((I + 1) N / K)`; empty when
    /// there are more shards than paths).
    pub fn paths(self, paths: u64) -> Range<u64> {
        let at = |i: u64| (u128::from(i) * u128::from(paths) / u128::from(self.count)) as u64;
        at(self.index)..at(self.index + 1)
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_paths_in_order() {
        for (n, k) in [(10, 3), (10, 1), (7, 7), (3, 5), (1 << 32, 8), (100_003, 4)] {
            let mut next = 0;
            for i in 0..k {
                let r = Shard::new(i, k).unwrap().paths(n);
                assert_eq!(r.start, next, "{n} paths, shard {i}/{k}");
                assert!(r.end - r.start <= n.div_ceil(k));
                next = r.end;
            }
            assert_eq!(next, n);
        }
        assert_eq!(Shard::new(1, 3).unwrap().paths(10), 3..6);
    }

    #[test]
    fn shards_parse_and_print() {
        assert_eq!(Shard::parse("3/8"), Ok(Shard { index: 3, count: 8 }));
        assert_eq!(Shard::parse("3/8").unwrap().to_string(), "3/8");
        let e = Shard::parse("8/8").unwrap_err();
        assert_eq!(e, ShardError::IndexTooLarge { index: 8, count: 8 });
        assert_eq!(
            e.to_string(),
            "shard 8/8: the index must be below the number of shards (0-based)"
        );
        assert_eq!(Shard::parse("0/0"), Err(ShardError::NoShards));
        assert_eq!(
            ShardError::NoShards.to_string(),
            "the number of shards must be at least 1"
        );
        for text in ["1-4", "a/4", "1/"] {
            let e = Shard::parse(text).unwrap_err();
            assert_eq!(e, ShardError::Syntax { text: text.into() });
            assert!(e.to_string().contains("expected I/K with whole numbers"));
        }
    }
}
