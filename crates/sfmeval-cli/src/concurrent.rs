//! Two pieces of work at the same time: reading two input files, writing two outputs.

/// Runs `a` on a scoped thread while `b` runs on this one and returns both results; a panic in
/// `a` is resumed here.
pub(crate) fn side_by_side<A: Send, B>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B,
) -> (A, B) {
    std::thread::scope(|s| {
        let a = s.spawn(a);
        let b = b();
        let a = a
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (a, b)
    })
}
