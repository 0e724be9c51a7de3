//! Springs on many threads, as a gather: first every spring's force, split
//! among threads by springs (each computed as in `kernel.rs`); then every
//! particle sums the forces of its own springs, split among threads by
//! particles. A particle's springs are listed in spring order, so it adds the
//! same forces in the same order as the one-thread loop (`+f` as the first
//! end, `−f` as the second): the same bits on any number of threads.

use super::kernel::{forces_into, Block, BLOCK};
use super::Slice;
use glam::DVec3;
use rayon::prelude::*;

/// Below this many springs a world's springs stay on one thread: two
/// fork-joins a step would cost more than they save.
pub const MIN_SPRINGS: usize = 8192;

/// Springs per task in the first pass (a multiple of [`BLOCK`]).
const SPRINGS_PER_TASK: usize = 32 * BLOCK;

/// Particles per task in the second pass.
const PARTICLES_PER_TASK: usize = 1024;

/// Each particle's springs, and the per-spring forces, kept between steps.
#[derive(Default)]
pub(super) struct Gather {
    /// `ends[start[p]..start[p + 1]]` are particle `p`'s springs in order,
    /// each `index << 1 | 1` where `p` is the spring's second end.
    start: Vec<u32>,
    ends: Vec<u32>,
    /// The springs and particles the lists were made for.
    built: (usize, usize),
    f: Vec<DVec3>,
}

impl Gather {
    /// Lists each particle's springs (again only when springs were added or
    /// the world grew: a spring's ends never change).
    fn index(&mut self, springs: Slice, particles: usize) {
        if self.built == (springs.len(), particles) {
            return;
        }
        let mut count = vec![0u32; particles + 1];
        for &[a, b] in springs.ends {
            count[a as usize + 1] += 1;
            count[b as usize + 1] += 1;
        }
        for p in 0..particles {
            count[p + 1] += count[p];
        }
        let mut next = count.clone();
        self.ends = vec![0; 2 * springs.len()];
        for (i, &[a, b]) in springs.ends.iter().enumerate() {
            for (end, second) in [(a, 0), (b, 1)] {
                let slot = &mut next[end as usize];
                self.ends[*slot as usize] = (i as u32) << 1 | second;
                *slot += 1;
            }
        }
        self.start = count;
        self.f.clear();
        self.f.resize(springs.len(), DVec3::ZERO);
        self.built = (springs.len(), particles);
    }

    /// Adds every spring's force to its ends, on the current rayon pool.
    pub fn apply(&mut self, springs: Slice, pos: &[DVec3], vel: &[DVec3], forces: &mut [DVec3]) {
        self.index(springs, forces.len());
        self.f
            .par_chunks_mut(SPRINGS_PER_TASK)
            .enumerate()
            .for_each(|(c, f)| {
                let first = c * SPRINGS_PER_TASK;
                let s = springs.range(first..first + f.len());
                let mut block = Block::default();
                forces_into(s, &mut block, pos, vel, f);
            });
        let (start, ends, f) = (&self.start, &self.ends, &self.f);
        forces
            .par_chunks_mut(PARTICLES_PER_TASK)
            .enumerate()
            .for_each(|(c, chunk)| {
                let first = c * PARTICLES_PER_TASK;
                for (k, out) in chunk.iter_mut().enumerate() {
                    let p = first + k;
                    let mut acc = *out;
                    for &e in &ends[start[p] as usize..start[p + 1] as usize] {
                        // x + (−1 · f) is x − f to the bit: the serial loop's
                        // subtraction, without a branch.
                        let sign = if e & 1 == 0 { 1.0 } else { -1.0 };
                        acc += f[(e >> 1) as usize] * sign;
                    }
                    *out = acc;
                }
            });
    }
}
