//! Where independent work runs (the Monte Carlo chunks, the pieces of a split initial set): on a
//! rayon pool with the `parallel` feature, otherwise in order on the calling thread. Items are
//! independent and their results come back in order, so the results are the same either way.

use crate::engine::ThreadsError;

/// The workers of one simulation or one split run.
pub(crate) struct Workers {
    /// A pool of the requested size (`None`: the current rayon pool).
    #[cfg(feature = "parallel")]
    pool: Option<rayon::ThreadPool>,
}

impl Workers {
    /// `threads` workers, or the current rayon pool when `None` (one thread without the
    /// `parallel` feature, whatever is asked).
    pub(crate) fn new(threads: Option<usize>) -> Result<Workers, ThreadsError> {
        #[cfg(feature = "parallel")]
        {
            let pool = match threads {
                Some(t) => Some(
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(t)
                        .build()
                        .map_err(|e| ThreadsError {
                            threads: t,
                            cause: e.to_string(),
                        })?,
                ),
                None => None,
            };
            Ok(Workers { pool })
        }
        #[cfg(not(feature = "parallel"))]
        {
            let _ = threads;
            Ok(Workers {})
        }
    }

    /// `f` of each item, in the items' order.
    pub(crate) fn map<T: Send, R: Send>(&self, items: Vec<T>, f: impl Fn(T) -> R + Sync) -> Vec<R> {
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            let run = || items.into_par_iter().map(&f).collect();
            match &self.pool {
                Some(p) => p.install(run),
                None => run(),
            }
        }
        #[cfg(not(feature = "parallel"))]
        {
            items.into_iter().map(f).collect()
        }
    }
}

/// The number of worker threads a simulation with `threads` uses.
pub fn thread_count(threads: Option<usize>) -> usize {
    #[cfg(feature = "parallel")]
    {
        threads.unwrap_or_else(rayon::current_num_threads)
    }
    #[cfg(not(feature = "parallel"))]
    {
        let _ = threads;
        1
    }
}
