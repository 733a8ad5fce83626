//! Two independent pieces of work at once: on two threads natively, one
//! after the other in wasm32, whose build is single-threaded (issue 15:
//! parallel natively where it pays, the page's core unchanged).

/// Runs `a` and `b` and returns both results; natively `b` runs on a
/// scoped thread while `a` runs on this one. A panic in either is
/// resumed here, as if both had run on this thread.
pub fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    #[cfg(not(target_arch = "wasm32"))]
    {
        std::thread::scope(|s| {
            let other = s.spawn(b);
            let ra = a();
            match other.join() {
                Ok(rb) => (ra, rb),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        })
    }
    #[cfg(target_arch = "wasm32")]
    {
        let ra = a();
        (ra, b())
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn both_results_come_back_in_order() {
        let data: Vec<u64> = (1..=1000).collect();
        let (sum, max) = super::join(|| data.iter().sum::<u64>(), || data.iter().max().copied());
        assert_eq!((sum, max), (500_500, Some(1000)));
    }

    #[test]
    #[should_panic(expected = "from b")]
    fn a_panic_on_the_other_thread_reaches_the_caller() {
        super::join(|| 1, || -> i32 { panic!("from b") });
    }
}
