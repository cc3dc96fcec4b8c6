//! Order-preserving parallel map: rayon with the `parallel` feature, a plain loop without it.
//! Results come back in input order, so every later reduction is independent of thread count.

use crate::progress::Progress;

/// Items per progress tick and per parallel work unit.
const CHUNK: usize = 8192;

/// Maps `f` over `items`, keeping order, reporting progress per chunk.
pub fn map<T, R, F>(items: &[T], progress: &dyn Progress, f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(&T) -> R + Sync + Send,
{
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        let chunks: Vec<Vec<R>> = items
            .par_chunks(CHUNK)
            .map(|c| {
                let out: Vec<R> = c.iter().map(&f).collect();
                progress.advance(c.len() as u64);
                out
            })
            .collect();
        let mut out = Vec::with_capacity(items.len());
        for c in chunks {
            out.extend(c);
        }
        out
    }
    #[cfg(not(feature = "parallel"))]
    {
        let mut out = Vec::with_capacity(items.len());
        for c in items.chunks(CHUNK) {
            out.extend(c.iter().map(&f));
            progress.advance(c.len() as u64);
        }
        out
    }
}
