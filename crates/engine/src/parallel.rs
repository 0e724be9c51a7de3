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
        let head: [&mut [DVec3]; K] = std::array::from_fn(|k| {
            let (head, tail) = std::mem::take(&mut rest[k]).split_at_mut(take);
            rest[k] = tail;
            head
        });
        pieces.push((first, head));
        first += take;
    }
    pieces
        .into_par_iter()
        .map(|(first, piece)| body(first, piece))
        .reduce_with(combine)
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
    (0..n.div_ceil(len))
        .into_par_iter()
        .map(|k| body(k * len..n.min((k + 1) * len)))
        .reduce_with(combine)
        .unwrap_or_else(|| body(0..0))
}
