//! Independent pieces of work at once: on several threads natively, one
//! after the other in wasm32, whose build is single-threaded (issue 15:
//! parallel natively where it pays, the page's core unchanged). Results
//! always come back in the order a single thread would produce them, so
//! the output (G-code, reports) does not depend on the thread count.
//!
//! `PCPP_THREADS` caps the threads (1: everything on the calling thread),
//! like rayon's `RAYON_NUM_THREADS`; the default is every core.

use std::ops::Range;

/// Runs `a` and `b` and returns both results; natively (unless
/// `PCPP_THREADS` is 1) `b` runs on a scoped thread while `a` runs on this
/// one. A panic in either is resumed here, as if both had run on this
/// thread.
pub fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    #[cfg(not(target_arch = "wasm32"))]
    if threads() > 1 {
        return std::thread::scope(|s| {
            let other = s.spawn(b);
            let ra = a();
            match other.join() {
                Ok(rb) => (ra, rb),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        });
    }
    let ra = a();
    (ra, b())
}

/// The threads [`map_chunks`] uses: `PCPP_THREADS` if set to a positive
/// number, else the cores available; 1 in wasm32. Found once (the core
/// count comes from the cgroup files on Linux, not worth reading per call).
fn threads() -> usize {
    #[cfg(not(target_arch = "wasm32"))]
    {
        static THREADS: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
        *THREADS.get_or_init(|| {
            std::env::var("PCPP_THREADS")
                .ok()
                .and_then(|v| v.trim().parse::<usize>().ok())
                .filter(|&n| n > 0)
                .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        })
    }
    #[cfg(target_arch = "wasm32")]
    {
        1
    }
}

/// Chunks per thread: enough that a thread left with a slow chunk does not
/// hold the others up for long.
const CHUNKS_PER_THREAD: usize = 8;

/// Calls `f` on consecutive chunks of `0..n` (each at least `min_chunk`
/// long, but the last) and returns its results in the chunks' order. With
/// one thread, or `n` at most `min_chunk`, `f(0..n)` runs once on this
/// thread; otherwise the threads take the chunks as they come free. A panic
/// in `f` is resumed here.
///
/// For work whose items are independent, so that cutting it into chunks
/// changes nothing but the order it is done in.
pub fn map_chunks<T: Send>(
    n: usize,
    min_chunk: usize,
    f: impl Fn(Range<usize>) -> T + Sync,
) -> Vec<T> {
    if n <= min_chunk.max(1) {
        return vec![f(0..n)];
    }
    let threads = threads();
    if threads <= 1 {
        return vec![f(0..n)];
    }
    let size = n
        .div_ceil(threads * CHUNKS_PER_THREAD)
        .max(min_chunk.max(1));
    let chunks = n.div_ceil(size);
    run_chunks(threads.min(chunks), chunks, |c| {
        f(c * size..((c + 1) * size).min(n))
    })
}

/// Runs `f(0..chunks)` on `threads` threads (this one among them) and
/// returns the results in chunk order.
#[cfg(not(target_arch = "wasm32"))]
fn run_chunks<T: Send>(threads: usize, chunks: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let work = || {
        let mut done = Vec::new();
        loop {
            let c = next.fetch_add(1, Ordering::Relaxed);
            if c >= chunks {
                return done;
            }
            done.push((c, f(c)));
        }
    };
    let mut slots: Vec<Option<T>> = (0..chunks).map(|_| None).collect();
    std::thread::scope(|s| {
        let others: Vec<_> = (1..threads).map(|_| s.spawn(work)).collect();
        let mut place = |done: Vec<(usize, T)>| {
            for (c, r) in done {
                slots[c] = Some(r);
            }
        };
        place(work());
        for other in others {
            match other.join() {
                Ok(done) => place(done),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        }
    });
    slots
        .into_iter()
        .map(|r| r.expect("every chunk is taken by one thread"))
        .collect()
}

#[cfg(target_arch = "wasm32")]
fn run_chunks<T: Send>(_threads: usize, chunks: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    (0..chunks).map(f).collect()
}

/// `f` over `0..n`, in order (see [`map_chunks`]).
pub fn map<T: Send>(n: usize, min_chunk: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let chunks = map_chunks(n, min_chunk, |r| r.map(&f).collect::<Vec<T>>());
    let mut out = Vec::with_capacity(n);
    for c in chunks {
        out.extend(c);
    }
    out
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

    #[test]
    fn chunks_cover_the_range_in_order() {
        for n in [0usize, 1, 5, 64, 1000, 4097] {
            for min in [1usize, 7, 100] {
                let chunks = super::map_chunks(n, min, |r| r);
                let mut next = 0;
                for (k, r) in chunks.iter().enumerate() {
                    assert_eq!(r.start, next, "n {n} min {min}");
                    assert!(
                        r.len() >= min.min(n) || k + 1 == chunks.len(),
                        "n {n} min {min}"
                    );
                    next = r.end;
                }
                assert_eq!(next, n);
            }
        }
    }

    #[test]
    fn map_keeps_the_order_of_one_thread() {
        let f = |i: usize| (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 7;
        let seq: Vec<u64> = (0..10_007).map(f).collect();
        assert_eq!(super::map(10_007, 16, f), seq);
    }

    #[test]
    #[should_panic(expected = "item 900")]
    fn a_panic_in_a_chunk_reaches_the_caller() {
        super::map(1000, 10, |i| {
            assert!(i != 900, "item {i}");
            i
        });
    }
}
