//! Exact empirical quantiles in bounded memory: per report step, only the `j` largest
//! (squared) distances can matter for the `(1 - delta)` quantile (the `j`-th largest, `j = floor(delta N)
//! + 1`), so each step keeps a buffer of at most `2 j` values and prunes it to its `j` largest
//! when it overflows. Memory is `O(j * steps)`, independent of the number of paths beyond `j`.
//!
//! The `j`-th largest of what has been kept so far is a threshold: later values not above it
//! cannot change the result and are dropped before they are stored (workers compare with a
//! snapshot of it). The kept multiset's `j`-th largest equals that of all values whatever the
//! order values arrive in, so the quantile does not depend on threads or batching.

/// The buffers of all steps.
#[derive(Clone, Debug)]
pub(crate) struct TopK {
    j: usize,
    bufs: Vec<Vec<f64>>,
    /// Per step, the `j`-th largest kept value once known (`-inf` before).
    thresholds: Vec<f64>,
}

/// Sorts descending (largest first); distances are never NaN here (non-finite ones are `inf`).
fn descending(a: &f64, b: &f64) -> std::cmp::Ordering {
    b.total_cmp(a)
}

impl TopK {
    /// For `steps` report steps, keeping the `j >= 1` largest.
    pub(crate) fn new(steps: usize, j: usize) -> Self {
        TopK {
            j,
            bufs: vec![Vec::new(); steps],
            thresholds: vec![f64::NEG_INFINITY; steps],
        }
    }

    /// Values not above these cannot enter the result (one per step).
    pub(crate) fn thresholds(&self) -> &[f64] {
        &self.thresholds
    }

    /// Sets the threshold of every step that has `j` values but no threshold yet (`push` sets
    /// one only when a buffer reaches `2 j`), so that the next batch's workers drop more.
    pub(crate) fn tighten(&mut self) {
        for (buf, thr) in self.bufs.iter_mut().zip(&mut self.thresholds) {
            if *thr == f64::NEG_INFINITY && buf.len() >= self.j {
                buf.select_nth_unstable_by(self.j - 1, descending);
                buf.truncate(self.j);
                *thr = buf.iter().copied().fold(f64::INFINITY, f64::min);
            }
        }
    }

    /// Adds a value of step `k`.
    pub(crate) fn push(&mut self, k: usize, v: f64) {
        if v <= self.thresholds[k] {
            return;
        }
        let buf = &mut self.bufs[k];
        buf.push(v);
        if buf.len() >= 2 * self.j {
            buf.select_nth_unstable_by(self.j - 1, descending);
            buf.truncate(self.j);
            self.thresholds[k] = buf.iter().copied().fold(f64::INFINITY, f64::min);
        }
    }

    /// Per step, the `j` largest values (all of them if fewer were pushed), largest first: what
    /// another `TopK` of the same `j` needs to give the same results after more values.
    pub(crate) fn into_largest(self) -> Vec<Vec<f64>> {
        let j = self.j;
        self.bufs
            .into_iter()
            .map(|mut buf| {
                buf.sort_unstable_by(descending);
                buf.truncate(j);
                buf
            })
            .collect()
    }

    /// `(j-th largest, largest)` of step `k`, or `None` if fewer than `j` values were pushed.
    pub(crate) fn result(&mut self, k: usize) -> Option<(f64, f64)> {
        let buf = &mut self.bufs[k];
        if buf.len() < self.j {
            return None;
        }
        let (_, &mut kth, _) = buf.select_nth_unstable_by(self.j - 1, descending);
        let max = buf.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Some((kth, max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_exact_order_statistic_in_any_order() {
        let values: Vec<f64> = (0..10_000u64)
            .map(|i| ((i * 7919) % 10_007) as f64 * 0.5)
            .collect();
        let mut sorted = values.clone();
        sorted.sort_by(descending);
        for j in [1, 3, 100, 2500] {
            let mut fwd = TopK::new(1, j);
            let mut rev = TopK::new(1, j);
            for &v in &values {
                fwd.push(0, v);
            }
            for &v in values.iter().rev() {
                rev.push(0, v);
            }
            let want = Some((sorted[j - 1], sorted[0]));
            assert_eq!(fwd.result(0), want, "j = {j}");
            // Tightening between pushes (as between batches) keeps the result.
            let mut tight = TopK::new(1, j);
            for (i, &v) in values.iter().enumerate() {
                tight.push(0, v);
                if i % 1000 == 999 {
                    tight.tighten();
                }
            }
            assert_eq!(tight.result(0), want, "j = {j}");
            assert_eq!(rev.result(0), want, "j = {j}");
            assert!(fwd.bufs[0].len() < 2 * j);
        }
        assert_eq!(TopK::new(1, 5).result(0), None);
    }

    /// The `j` largest of two halves, pushed into a third buffer, give the results of all values.
    #[test]
    fn the_largest_of_parts_merge_exactly() {
        let values: Vec<f64> = (0..5_000u64)
            .map(|i| ((i * 7919) % 5_003) as f64 * 0.25)
            .collect();
        for j in [1, 7, 2_400, 5_000] {
            let mut all = TopK::new(1, j);
            let mut merged = TopK::new(1, j);
            for half in values.chunks(2_500) {
                let mut part = TopK::new(1, j);
                for &v in half {
                    part.push(0, v);
                    all.push(0, v);
                }
                let largest = part.into_largest();
                assert_eq!(largest[0].len(), j.min(2_500));
                assert!(largest[0].windows(2).all(|w| w[0] >= w[1]));
                largest[0].iter().for_each(|&v| merged.push(0, v));
            }
            assert_eq!(merged.result(0), all.result(0), "j = {j}");
        }
    }
}
