//! The embedding's boxes, computed once per [`Reach`](crate::Reach) for the runs that repeat
//! them.
//!
//! The boxes of the embedding system (`interval.rs`) depend on the model, the analysis' grid,
//! integrator and transform, the initial set, the inputs, the inclusion and the step budget,
//! and not on delta or the metric. One `Reach` runs them several times over: its plain and
//! delta-split runs (method.md 8.10), one run per metric (section 8.6), the candidates of a
//! probability's bisection (8.13), and a contraction run's box (8.7) for each of these. The
//! memo keeps each result (an error too) under everything it depends on, so a repeat returns
//! the same boxes bit for bit.
//!
//! Architecture Invariant: the key holds every input of the computation except the model,
//! which is the `Reach`'s own; results are the same as recomputing them.

use super::embedding::Budget;
use super::RunError;
use crate::interval::Interval;
use crate::model::{AnalysisSpec, Inclusion, InitialSet};
use std::sync::{Arc, Mutex};

/// The numbers (states of steps) the memo may hold before it forgets its oldest entries: about
/// 128 MiB.
const CAPACITY: usize = 1 << 24;

/// What the boxes depend on besides the model.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Key {
    /// The analysis with its delta set aside (the boxes do not depend on it).
    spec: AnalysisSpec,
    initial: InitialSet,
    /// The input box of each report step.
    inputs: Vec<Vec<Interval>>,
    inclusion: Inclusion,
    budget: Budget,
}

impl Key {
    /// The key of the boxes of `spec` (any delta) from `initial` with `inputs`.
    pub(super) fn new(
        spec: &AnalysisSpec,
        initial: &InitialSet,
        inputs: &[Vec<Interval>],
        inclusion: Inclusion,
        budget: Budget,
    ) -> Key {
        Key {
            spec: AnalysisSpec {
                delta: 0.5,
                ..spec.clone()
            },
            initial: initial.clone(),
            inputs: inputs.to_vec(),
            inclusion,
            budget,
        }
    }
}

/// A result as held: shared by every run that asks for it.
type Held<T> = Arc<Result<T, RunError>>;

/// Results kept under their keys, with their sizes (numbers held).
pub(crate) struct Memo<T> {
    entries: Mutex<Vec<(Key, Held<T>, usize)>>,
}

impl<T> Default for Memo<T> {
    fn default() -> Self {
        Memo {
            entries: Mutex::new(Vec::new()),
        }
    }
}

impl<T> Memo<T> {
    /// The result under `key`, computed by `compute` (with its size) if not held.
    pub(super) fn get_or(
        &self,
        key: Key,
        compute: impl FnOnce() -> (Result<T, RunError>, usize),
    ) -> Held<T> {
        if let Some(hit) = self.find(&key) {
            return hit;
        }
        // Computed outside the lock: runs of other pieces go on meanwhile (two threads asking
        // for the same key both compute it, with the same result).
        let (value, size) = compute();
        let value = Arc::new(value);
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        entries.push((key, value.clone(), size));
        let mut held: usize = entries.iter().map(|e| e.2).sum();
        while held > CAPACITY && entries.len() > 1 {
            held -= entries.remove(0).2;
        }
        value
    }

    fn find(&self, key: &Key) -> Option<Held<T>> {
        let entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        entries
            .iter()
            .find(|(k, _, _)| k == key)
            .map(|(_, v, _)| v.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Detail;
    use crate::model::Bounds;
    use std::cell::Cell;

    fn key(delta: f64, lo: f64, inclusion: Inclusion) -> Key {
        let spec = AnalysisSpec {
            delta,
            ..AnalysisSpec::default()
        };
        let initial = InitialSet {
            boxes: vec![Some(Bounds { lo, hi: 1.0 })],
            ..InitialSet::default()
        };
        let inputs = vec![vec![Interval::new(-1.0, 1.0)]; 3];
        Key::new(&spec, &initial, &inputs, inclusion, Budget::FULL)
    }

    #[test]
    fn computes_once_per_key_whatever_the_delta() {
        let memo = Memo::<u32>::default();
        let calls = Cell::new(0);
        let get = |k: Key| {
            *memo
                .get_or(k, || {
                    calls.set(calls.get() + 1);
                    (Ok(calls.get()), 1)
                })
                .as_ref()
                .as_ref()
                .unwrap()
        };
        assert_eq!(get(key(1e-3, 0.0, Inclusion::Jacobian)), 1);
        // Another delta: the same boxes.
        assert_eq!(get(key(5e-4, 0.0, Inclusion::Jacobian)), 1);
        // Another initial set or inclusion: computed anew.
        assert_eq!(get(key(1e-3, -0.5, Inclusion::Jacobian)), 2);
        assert_eq!(get(key(1e-3, 0.0, Inclusion::Natural)), 3);
        assert_eq!(get(key(1e-3, 0.0, Inclusion::Jacobian)), 1);
        assert_eq!(calls.get(), 3);
    }

    #[test]
    fn forgets_the_oldest_beyond_its_capacity_and_keeps_errors() {
        let memo = Memo::<u32>::default();
        let failed = RunError::Invalid(Detail::from(crate::engine::Problem::NoStates));
        let first = memo.get_or(key(1e-3, 0.0, Inclusion::Jacobian), || {
            (Err(failed.clone()), CAPACITY / 2)
        });
        assert_eq!(*first, Err(failed.clone()));
        // Held: the error comes back without a computation.
        let again = memo.get_or(key(1e-3, 0.0, Inclusion::Jacobian), || unreachable!());
        assert_eq!(*again, Err(failed));
        memo.get_or(key(1e-3, 0.1, Inclusion::Jacobian), || (Ok(2), CAPACITY));
        // Over capacity: the first entry is gone.
        let redone = memo.get_or(key(1e-3, 0.0, Inclusion::Jacobian), || (Ok(7), 1));
        assert_eq!(*redone, Ok(7));
    }
}
