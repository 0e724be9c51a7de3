//! Springs on many threads. The springs are cut into as many consecutive
//! ranges as there are threads, and the particles into as many consecutive
//! pieces (those of `parallel.rs`, so that a thread then integrates the
//! particles it summed). Thread `t` computes spring range `t` in blocks
//! (`kernel.rs`) and adds the forces straight to the particles of piece `t`
//! whose springs all lie in range `t`, in spring order, as one thread would.
//! The few particles whose springs span ranges (a mesh's rows where the
//! ranges meet) are left to the end: their springs' forces are kept, and
//! each such particle then sums them in spring order. Either way every
//! particle adds the same forces in the same order as the one-thread loop
//! (`+f` as a spring's first end, `−f` as its second): the same bits on any
//! number of threads.
//!
//! Staged (`Parallel::apply_then`, symplectic Euler), each thread also
//! starts and hands on its own particles as its springs reach them and
//! finish with them (`kernel::Staged`), and the shared particles are
//! handed on after the join.

use super::kernel::{run, Adds, Block, Scatter, Sink, Staged, Stages, BLOCK};
use super::Slice;
use crate::forces::gravity::start_with_weights;
use crate::parallel::take_front;
use glam::DVec3;
use std::ops::Range;

/// Below this many springs a world's springs stay on one thread: the
/// fork-join would cost more than it saves.
pub const MIN_SPRINGS: usize = 8192;

/// How the springs and particles are cut for one number of threads; kept
/// between steps.
#[derive(Default)]
pub(super) struct Parallel {
    /// Springs, particles and threads the tables were made for.
    built: (usize, usize, usize),
    /// Springs per range and particles per piece (the last may have fewer).
    per_range: usize,
    per_piece: usize,
    /// For each spring, whether its first end (bit 0) and its second end
    /// (bit 1) are particles of its task's piece whose springs all lie in
    /// its range, which its task adds to directly.
    code: Vec<u8>,
    /// For each block of each range (`per_range.div_ceil(BLOCK)` a range),
    /// whether every end of its springs is its task's own (code 3): such a
    /// block goes straight to the one-thread scatter.
    whole: Vec<bool>,
    /// Each spring's ends counted from the first particle of its task's
    /// piece (meaningful where they are its task's own): the whole blocks'
    /// scatter then indexes the piece without a subtraction per end.
    local: Vec<[u32; 2]>,
    /// The other particles with springs and, for the `k`-th, its springs
    /// in order in `ends[start[k]..start[k + 1]]`, each `index << 1 | 1`
    /// where the particle is the spring's second end.
    shared: Vec<u32>,
    start: Vec<u32>,
    ends: Vec<u32>,
    /// The force of every spring with a shared end.
    f: Vec<DVec3>,
    /// For each task, the stages of its own particles (counted from its
    /// piece's first) as its springs add to them, for [`Self::apply_then`].
    stages: Vec<Stages>,
    /// For each task, the runs of consecutive shared particles in its
    /// piece (counted from its first), which it does not hand on.
    holes: Vec<Vec<Range<usize>>>,
    /// The runs of consecutive shared particles, handed on after the join.
    runs: Vec<Range<usize>>,
}

/// The particles that springs of other tasks add to (`touched` and not
/// `owned` by one task), and their springs grouped by particle in spring
/// order: particle `shared[k]`'s are `ends[start[k]..start[k + 1]]`, each
/// `spring << 1 | which end`.
fn shared_springs(
    springs: Slice,
    touched: &[bool],
    owned: &[bool],
) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let particles = touched.len();
    let mut slot = vec![u32::MAX; particles];
    let shared: Vec<u32> = (0..particles)
        .filter(|&p| touched[p] && !owned[p])
        .map(|p| p as u32)
        .collect();
    for (k, &p) in shared.iter().enumerate() {
        slot[p as usize] = k as u32;
    }
    let mut start = vec![0u32; shared.len() + 1];
    for &[a, b] in springs.ends {
        for end in [a, b] {
            let k = slot[end as usize];
            if k != u32::MAX {
                start[k as usize + 1] += 1;
            }
        }
    }
    for k in 0..shared.len() {
        start[k + 1] += start[k];
    }
    let mut next = start.clone();
    let mut ends = vec![0u32; start[shared.len()] as usize];
    for (i, &[a, b]) in springs.ends.iter().enumerate() {
        for (end, second) in [(a, 0), (b, 1)] {
            let k = slot[end as usize];
            if k != u32::MAX {
                ends[next[k as usize] as usize] = (i as u32) << 1 | second;
                next[k as usize] += 1;
            }
        }
    }
    (shared, start, ends)
}

impl Parallel {
    /// Makes the tables (again only when springs were added, the world grew
    /// or the number of threads changed: a spring's ends never change).
    fn index(&mut self, springs: Slice, particles: usize, threads: usize) {
        if self.built == (springs.len(), particles, threads) {
            return;
        }
        let per_range = springs.len().div_ceil(threads).max(1);
        let per_piece = particles.div_ceil(threads).max(1);
        let mut touched = vec![false; particles];
        let mut owned = vec![true; particles];
        for (i, &[a, b]) in springs.ends.iter().enumerate() {
            for end in [a as usize, b as usize] {
                touched[end] = true;
                owned[end] &= end / per_piece == i / per_range;
            }
        }
        let (shared, start, ends) = shared_springs(springs, &touched, &owned);
        let code: Vec<u8> = springs
            .ends
            .iter()
            .map(|&[a, b]| u8::from(owned[a as usize]) | u8::from(owned[b as usize]) << 1)
            .collect();
        let local: Vec<[u32; 2]> = springs
            .ends
            .iter()
            .enumerate()
            .map(|(i, &[a, b])| {
                let lo = (i / per_range * per_piece) as u32;
                [a.wrapping_sub(lo), b.wrapping_sub(lo)]
            })
            .collect();
        let per_block = per_range.div_ceil(BLOCK);
        let mut whole = vec![false; threads * per_block];
        for (t, range) in code.chunks(per_range).enumerate() {
            for (k, block) in range.chunks(BLOCK).enumerate() {
                whole[t * per_block + k] = block.iter().all(|&c| c == 3);
            }
        }
        let stages = (0..threads)
            .map(|t| {
                let r = (t * per_range).min(code.len())..((t + 1) * per_range).min(code.len());
                let blocks = local[r.clone()].chunks(BLOCK).zip(code[r].chunks(BLOCK));
                // Only the ends its task adds to directly.
                let own = blocks.map(|(ends, code)| {
                    ends.iter().zip(code).flat_map(|(&[a, b], &c)| {
                        let a = (c & 1 != 0).then_some(a);
                        a.into_iter().chain((c & 2 != 0).then_some(b))
                    })
                });
                let piece = per_piece.min(particles.saturating_sub(t * per_piece));
                Stages::of_blocks(own, piece)
            })
            .collect();
        let runs = runs_of(shared.iter().map(|&p| p as usize));
        let holes = (0..threads)
            .map(|t| {
                let lo = t * per_piece;
                let mine = shared.iter().map(|&p| p as usize);
                runs_of(mine.filter(|p| p / per_piece == t).map(|p| p - lo))
            })
            .collect();
        *self = Parallel {
            stages,
            holes,
            runs,
            built: (springs.len(), particles, threads),
            per_range,
            per_piece,
            code,
            whole,
            local,
            shared,
            start,
            ends,
            f: vec![DVec3::ZERO; springs.len()],
        };
    }

    /// Adds every spring's force to its ends, on the current rayon pool.
    /// With `start = Some((g, mass))`, each thread first sets its particles'
    /// forces to `m g` (uniform gravity on all, in the same fork), which
    /// `forces` need not hold yet.
    pub fn apply(
        &mut self,
        springs: Slice,
        pos: &[DVec3],
        vel: &[DVec3],
        forces: &mut [DVec3],
        start: Option<(DVec3, &[f64])>,
    ) {
        let per_piece = self.per_piece_for(springs, forces.len());
        let tasks = self.tasks(springs, forces, []);
        crate::parallel::fork_tasks(
            tasks,
            |mut task| {
                if let Some((g, mass)) = start {
                    let piece = &mut *task.sink.scatter.forces;
                    start_with_weights(g, &mass[task.t * per_piece..], piece);
                }
                run(
                    task.springs,
                    &mut Block::default(),
                    pos,
                    vel,
                    &mut task.sink,
                );
            },
            |(), ()| (),
        );
        self.sum_shared(forces);
    }
}

impl Parallel {
    /// [`Self::apply`] staged (see `Springs::apply_then`): each thread
    /// starts its own particles' forces with `start` as its springs reach
    /// them and hands them on to `then(first, forces, [x, v])` with the same
    /// run of `outs` as soon as they are complete; the shared particles,
    /// summed after the join, are handed on last, run by run. The answers
    /// are combined by `combine` (associative and commutative).
    #[allow(clippy::too_many_arguments)]
    pub fn apply_then<R: Send>(
        &mut self,
        springs: Slice,
        pos: &[DVec3],
        vel: &[DVec3],
        forces: &mut [DVec3],
        start: impl Fn(Range<usize>, &mut [DVec3]) + Sync,
        outs: [&mut [DVec3]; 2],
        then: impl Fn(usize, &[DVec3], [&mut [DVec3]; 2]) -> R + Sync,
        combine: impl Fn(R, R) -> R + Sync + Send,
    ) -> Option<R> {
        let per_piece = self.per_piece_for(springs, forces.len());
        let [x, v] = outs;
        let tasks = self.tasks(springs, forces, [&mut *x, &mut *v]);
        let (then, combine) = (&then, &combine);
        let either = |a: Option<R>, b: Option<R>| match (a, b) {
            (Some(a), Some(b)) => Some(combine(a, b)),
            (a, b) => a.or(b),
        };
        let answer = crate::parallel::fork_tasks(
            tasks,
            |task| {
                let Task {
                    t,
                    springs,
                    sink,
                    stages,
                    holes,
                    outs: [x, v],
                } = task;
                let lo = t * per_piece;
                let (mut answer, mut hole) = (None, 0);
                let mut sink = Staged::new(
                    sink,
                    stages,
                    |r: Range<usize>, f: &mut [DVec3]| start(lo + r.start..lo + r.end, f),
                    |r: Range<usize>, f: &[DVec3]| {
                        outside(r.clone(), holes, &mut hole, |s| {
                            let f = &f[s.start - r.start..s.end - r.start];
                            let out = [&mut x[s.clone()], &mut v[s.clone()]];
                            let a = then(lo + s.start, f, out);
                            answer = either(answer.take(), Some(a));
                        })
                    },
                );
                run(springs, &mut Block::default(), pos, vel, &mut sink);
                answer
            },
            either,
        );
        let mut answer = answer.flatten();
        self.sum_shared(forces);
        for r in &self.runs {
            let out = [&mut x[r.clone()], &mut v[r.clone()]];
            answer = either(answer, Some(then(r.start, &forces[r.clone()], out)));
        }
        answer
    }

    /// Cuts the springs and particles for the current pool: the particles
    /// per piece.
    fn per_piece_for(&mut self, springs: Slice, particles: usize) -> usize {
        self.index(springs, particles, rayon::current_num_threads());
        self.per_piece
    }

    /// One task per thread (as [`Self::per_piece_for`] cut them): its
    /// springs, its sink adding to its piece of `forces` and keeping its
    /// springs' forces for the shared particles, its stages and holes, its
    /// piece of each of `outs`.
    fn tasks<'a, const K: usize>(
        &'a mut self,
        springs: Slice<'a>,
        forces: &'a mut [DVec3],
        outs: [&'a mut [DVec3]; K],
    ) -> Vec<Task<'a, K>> {
        let (per_range, per_piece) = (self.per_range, self.per_piece);
        let per_block = per_range.div_ceil(BLOCK);
        let threads = self.stages.len();
        let (mut kept, mut piece, mut outs) = (&mut self.f[..], forces, outs);
        (0..threads)
            .map(|t| {
                // (With more threads than springs the last tasks have none.)
                let first = (t * per_range).min(springs.len());
                let last = (first + per_range).min(springs.len());
                let np = per_piece.min(piece.len());
                Task {
                    t,
                    springs: springs.range(first..last),
                    sink: Owned {
                        scatter: Scatter::new(take_front(&mut piece, np)),
                        lo: t * per_piece,
                        code: &self.code[first..last],
                        whole: &self.whole[t * per_block..(t + 1) * per_block],
                        local: &self.local[first..last],
                        kept: take_front(&mut kept, last - first),
                    },
                    stages: &self.stages[t],
                    holes: &self.holes[t],
                    outs: outs.each_mut().map(|o| take_front(o, np)),
                }
            })
            .collect()
    }

    /// Adds the kept forces of their springs to the shared particles, each
    /// in spring order.
    fn sum_shared(&self, forces: &mut [DVec3]) {
        for (k, &p) in self.shared.iter().enumerate() {
            let (from, to) = (self.start[k] as usize, self.start[k + 1] as usize);
            let mut acc = forces[p as usize];
            for &e in &self.ends[from..to] {
                // x + (−1 · f) is x − f to the bit: the one-thread loop's
                // subtraction.
                let sign = if e & 1 == 0 { 1.0 } else { -1.0 };
                acc += self.f[(e >> 1) as usize] * sign;
            }
            forces[p as usize] = acc;
        }
    }
}

/// The runs of consecutive numbers of the increasing `items`.
fn runs_of(items: impl Iterator<Item = usize>) -> Vec<Range<usize>> {
    let mut runs: Vec<Range<usize>> = Vec::new();
    for p in items {
        match runs.last_mut() {
            Some(r) if r.end == p => r.end += 1,
            _ => runs.push(p..p + 1),
        }
    }
    runs
}

/// Calls `each` with the runs of `r` outside the `holes` (increasing and
/// apart), in order; `next` is the first hole not yet passed, kept between
/// calls with increasing ranges.
fn outside(
    r: Range<usize>,
    holes: &[Range<usize>],
    next: &mut usize,
    mut each: impl FnMut(Range<usize>),
) {
    let mut at = r.start;
    while at < r.end {
        while holes.get(*next).is_some_and(|h| h.end <= at) {
            *next += 1;
        }
        match holes.get(*next) {
            Some(h) if h.start <= at => at = h.end.min(r.end),
            h => {
                let end = h.map_or(r.end, |h| h.start.min(r.end));
                each(at..end);
                at = end;
            }
        }
    }
}

/// One thread's part of the springs (see [`Parallel::tasks`]).
struct Task<'a, const K: usize> {
    t: usize,
    springs: Slice<'a>,
    sink: Owned<'a>,
    stages: &'a Stages,
    holes: &'a [Range<usize>],
    outs: [&'a mut [DVec3]; K],
}

/// One task's sink: forces on its own particles go straight to them, the
/// forces of springs with another end are kept for later.
struct Owned<'a> {
    /// Adds to the piece's particles (all of a block's springs' ends are
    /// owned, the usual case).
    scatter: Scatter<'a>,
    /// The first particle of the piece.
    lo: usize,
    /// This range's springs' ends counted from `lo` (see [`Parallel::local`]).
    local: &'a [[u32; 2]],
    /// This range's springs' codes (see [`Parallel::code`]).
    code: &'a [u8],
    /// This range's blocks' flags (see [`Parallel::whole`]).
    whole: &'a [bool],
    /// This range's springs' kept forces.
    kept: &'a mut [DVec3],
}

impl Sink for Owned<'_> {
    #[inline(always)]
    fn take(&mut self, first: usize, ends: &[[u32; 2]], block: &Block) {
        if self.whole[first / BLOCK] {
            let local = &self.local[first..first + ends.len()];
            return self.scatter.take(first, local, block);
        }
        let code = &self.code[first..first + ends.len()];
        self.scatter.finish();
        let lo = self.lo;
        let piece = &mut *self.scatter.forces;
        let kept = &mut self.kept[first..first + ends.len()];
        // As the one-thread sink: a run of springs with the same first end
        // adds in a register (here `run` is an index into the piece).
        let (mut run, mut acc) = (None, DVec3::ZERO);
        for (i, (&[a, b], &c)) in ends.iter().zip(code).enumerate() {
            let f = block.force(i);
            let (ia, ib) = ((a as usize).wrapping_sub(lo), (b as usize).wrapping_sub(lo));
            let (own_a, own_b) = (c & 1 != 0, c & 2 != 0);
            if own_a {
                if run != Some(ia) {
                    if let Some(p) = run {
                        piece[p] = acc;
                    }
                    run = Some(ia);
                    acc = piece[ia];
                }
                acc += f;
            } else if let Some(p) = run.take() {
                // This spring's second end may be the run's particle.
                piece[p] = acc;
            }
            if own_b {
                // Never the run's particle: this spring starts at it, or the
                // run was just stored.
                piece[ib] -= f;
            }
            if c != 3 {
                kept[i] = f;
            }
        }
        if let Some(p) = run {
            piece[p] = acc;
        }
    }

    #[inline(always)]
    fn finish(&mut self) {
        self.scatter.finish();
    }
}

impl Adds for Owned<'_> {
    #[inline(always)]
    fn forces(&mut self) -> &mut [DVec3] {
        self.scatter.forces()
    }

    #[inline(always)]
    fn store_run(&mut self) {
        self.scatter.store_run();
    }
}

#[cfg(test)]
mod tests {
    use super::{outside, runs_of};
    use std::ops::Range;

    /// The runs a thread hands on leave out exactly its shared particles,
    /// whatever ranges the stages cut (a hole across two of them, at the
    /// start, at the end, a range all hole).
    #[test]
    fn the_runs_handed_on_are_every_particle_but_the_shared() {
        let n = 40;
        let shared = [0, 1, 7, 8, 9, 10, 15, 30, 31, 39];
        let holes = runs_of(shared.iter().copied());
        assert_eq!(holes, vec![0..2, 7..11, 15..16, 30..32, 39..40]);
        for cuts in [
            vec![0, 40],
            vec![0, 8, 9, 12, 31, 40],
            vec![0, 1, 2, 3, 16, 39, 40],
        ] {
            let mut next = 0;
            let mut got: Vec<Range<usize>> = Vec::new();
            for w in cuts.windows(2) {
                outside(w[0]..w[1], &holes, &mut next, |r| {
                    assert!(!r.is_empty() && r.start >= w[0] && r.end <= w[1]);
                    got.push(r);
                });
            }
            let covered: Vec<usize> = got.iter().flat_map(|r| r.clone()).collect();
            let want: Vec<usize> = (0..n).filter(|p| !shared.contains(p)).collect();
            assert_eq!(covered, want, "cut at {cuts:?}");
        }
    }
}
