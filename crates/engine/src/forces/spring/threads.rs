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

use super::kernel::{run, Block, Scatter, Sink, BLOCK};
use super::Slice;
use crate::parallel::take_front;
use glam::DVec3;
use rayon::prelude::*;

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
        // The shared particles' springs, grouped by particle in spring order.
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
        let code: Vec<u8> = springs
            .ends
            .iter()
            .map(|&[a, b]| u8::from(owned[a as usize]) | u8::from(owned[b as usize]) << 1)
            .collect();
        let local = springs
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
        *self = Parallel {
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
        let threads = rayon::current_num_threads();
        self.index(springs, forces.len(), threads);
        let (per_range, per_piece) = (self.per_range, self.per_piece);
        // One task per thread: its springs' kept forces, its particles.
        let mut tasks = Vec::with_capacity(threads);
        let (mut kept, mut piece) = (&mut self.f[..], &mut *forces);
        let mut code = &self.code[..];
        for t in 0..threads {
            let (c, rest) = code.split_at(per_range.min(code.len()));
            code = rest;
            let (nk, np) = (per_range.min(kept.len()), per_piece.min(piece.len()));
            tasks.push((t, c, take_front(&mut kept, nk), take_front(&mut piece, np)));
        }
        let (whole, per_block, local) =
            (&self.whole[..], per_range.div_ceil(BLOCK), &self.local[..]);
        crate::parallel::fork(|| {
            tasks.into_par_iter().for_each(|(t, code, kept, piece)| {
                // (With more threads than springs the last tasks have none.)
                if let Some((g, mass)) = start {
                    for (f, &m) in piece.iter_mut().zip(&mass[t * per_piece..]) {
                        *f = m * g;
                    }
                }
                let first = (t * per_range).min(springs.len());
                let range = springs.range(first..first + kept.len());
                let mut sink = Owned {
                    scatter: Scatter::new(piece),
                    lo: t * per_piece,
                    code,
                    whole: &whole[t * per_block..(t + 1) * per_block],
                    local: &local[first..first + kept.len()],
                    kept,
                };
                run(range, &mut Block::default(), pos, vel, &mut sink);
            });
        });
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
