//! One large world on many threads: its per-particle loops (the integrators'
//! updates, gravity, the floor's contact force) split into one contiguous piece
//! of particles per thread of the current rayon pool. Each particle's
//! arithmetic is the same wherever it runs, so the results are the same
//! bits on any number of threads. The pieces line up with the ranges the
//! springs are split into (`forces/spring/threads.rs`), so a thread mostly
//! updates the particles whose forces it just summed, in its own cache.
//!
//! Small worlds stay on the calling thread: waking another costs more than
//! their whole loop.

use glam::DVec3;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Worlds with fewer particles stay on one thread.
pub const MIN_PARTICLES: usize = 4096;

/// Particles per piece for a world of `n`, or `None` to stay on this thread.
#[inline]
pub fn piece_len(n: usize) -> Option<usize> {
    if n < MIN_PARTICLES {
        return None;
    }
    let threads = rayon::current_num_threads();
    (threads > 1).then(|| n.div_ceil(threads))
}

/// Takes the first `len` elements off the front of `s` (`len <= s.len()`).
#[inline]
pub fn take_front<'a, T>(s: &mut &'a mut [T], len: usize) -> &'a mut [T] {
    let (head, rest) = std::mem::take(s).split_at_mut(len);
    *s = rest;
    head
}

/// Calls `body(first, pieces)` for contiguous pieces `first..first + len` of
/// the `slices` (all as long as each other): once with everything for small
/// worlds or without `split`, once per thread for large ones.
#[inline]
pub fn by_pieces<const K: usize>(
    split: bool,
    slices: [&mut [DVec3]; K],
    body: impl Fn(usize, [&mut [DVec3]; K]) + Sync,
) {
    all_by_pieces(split, slices, |first, piece| {
        body(first, piece);
        true
    });
}

/// [`by_pieces`] with a question answered of each piece: true if every
/// piece's answer was true.
#[inline]
pub fn all_by_pieces<const K: usize>(
    split: bool,
    slices: [&mut [DVec3]; K],
    body: impl Fn(usize, [&mut [DVec3]; K]) -> bool + Sync,
) -> bool {
    fold_by_pieces(split, slices, body, |a, b| a & b)
}

/// [`by_pieces`] with an answer from each piece, combined in piece order by
/// `combine`, which must be associative.
#[inline]
pub fn fold_by_pieces<const K: usize, R: Send>(
    split: bool,
    slices: [&mut [DVec3]; K],
    body: impl Fn(usize, [&mut [DVec3]; K]) -> R + Sync,
    combine: impl Fn(R, R) -> R + Sync + Send,
) -> R {
    let n = slices.first().map_or(0, |s| s.len());
    let Some(len) = piece_len(n).filter(|_| split) else {
        return body(0, slices);
    };
    let mut rest = slices;
    let mut pieces = Vec::with_capacity(n.div_ceil(len));
    let mut first = 0;
    while first < n {
        let take = len.min(n - first);
        let head: [&mut [DVec3]; K] = rest.each_mut().map(|r| take_front(r, take));
        pieces.push((first, head));
        first += take;
    }
    fork_tasks(pieces, |(first, piece)| body(first, piece), combine)
        .unwrap_or_else(|| body(0, std::array::from_fn(|_| &mut [][..])))
}

/// `body` of each piece `first..first + len` of a world of `n` particles
/// (the pieces of [`by_pieces`], so each is usually read by the thread that
/// has just written it), combined in piece order by `combine`, which must
/// be associative.
#[inline]
pub fn map_pieces<R: Send>(
    n: usize,
    body: impl Fn(Range<usize>) -> R + Sync,
    combine: impl Fn(R, R) -> R + Sync + Send,
) -> R {
    let Some(len) = piece_len(n) else {
        return body(0..n);
    };
    let pieces = 0..n.div_ceil(len);
    fork_tasks(pieces, |k| body(k * len..n.min((k + 1) * len)), combine)
        .unwrap_or_else(|| body(0..0))
}

/// [`fork`] of `tasks`, at most one per thread of the current pool, each
/// run by `body` (`None` without tasks); their answers combined in task
/// order by `combine`, which must be associative.
///
/// A task that is done waits, yielding, while another of the fork's tasks
/// is still running (for at most [`LINGER`]), instead of returning to
/// rayon's wait for the stolen half: there a thread sleeps after a few
/// dozen idle rounds, and the futex calls that put it to sleep and wake
/// it took about 9 % of cloth-128's samples on two threads. (With more
/// tasks than threads the waiting would keep a thread from the tasks still
/// queued; none of the callers makes more.)
pub fn fork_tasks<T: Send, R: Send>(
    tasks: impl IntoParallelIterator<Item = T>,
    body: impl Fn(T) -> R + Sync + Send,
    combine: impl Fn(R, R) -> R + Sync + Send,
) -> Option<R> {
    let running = AtomicUsize::new(0);
    let together = |task: T| {
        running.fetch_add(1, Ordering::AcqRel);
        let r = body(task);
        running.fetch_sub(1, Ordering::AcqRel);
        let t = Instant::now();
        while running.load(Ordering::Acquire) > 0 && t.elapsed() < LINGER {
            std::thread::yield_now();
        }
        r
    };
    fork(|| tasks.into_par_iter().map(together).reduce_with(combine))
}

/// Counts the forks of every world's work: the threads [`fork`] leaves
/// spinning watch it to know when to go back to the pool.
static FORKS: AtomicU64 = AtomicU64::new(0);

/// How long a thread spins for the next fork before it lets the pool put
/// it to sleep.
const LINGER: Duration = Duration::from_micros(300);

/// Runs `work`, a fork-join of one world's work over the current pool's
/// threads, then leaves the pool's other threads (as many as the machine
/// has other cores) spinning until the next fork, or for [`LINGER`],
/// instead of asleep.
///
/// Why: a rayon thread that finds nothing to do yields 33 times (a few
/// microseconds here) and then sleeps, and waking it for the next fork
/// costs 100–300 µs on a virtual machine, longer than the gap between a
/// world's forks and often longer than the fork's whole work: the other
/// thread then arrives too late to take its half (allpairs-1000 on two
/// threads ran little faster than on one). Each fork bumps [`FORKS`];
/// after the join one job per other thread waits for the count to move,
/// yielding the core to anything else runnable. A job still queued when
/// the next fork comes sees the count moved and returns at once, so no
/// fork waits for one. Results are untouched.
pub fn fork<R>(work: impl FnOnce() -> R) -> R {
    FORKS.fetch_add(1, Ordering::Relaxed);
    let r = work();
    let others = rayon::current_num_threads().min(cores()) - 1;
    if others > 0 && rayon::current_thread_index().is_some() {
        let at = FORKS.load(Ordering::Relaxed);
        for _ in 0..others {
            rayon::spawn(move || {
                let t = Instant::now();
                while FORKS.load(Ordering::Relaxed) == at && t.elapsed() < LINGER {
                    std::thread::yield_now();
                }
            });
        }
    }
    r
}

/// The cores this process may run on (at least 1), asked once.
fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}
