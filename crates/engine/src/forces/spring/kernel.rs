//! The spring loop in blocks: gather a block of springs' end-to-end vectors
//! and relative velocities into separate arrays, compute every spring's
//! force with the widest vectors this CPU has, then add the forces to their
//! ends one spring after another, in the springs' order.
//!
//! Reproducibility: a spring's force depends only on that spring, computed
//! with the same operations in the same order on every path (nothing fused,
//! no FMA; square root and division are correctly rounded on every
//! instruction set), and the forces reach the particles in spring order, as
//! the plain loop adds them. AVX-512, AVX2 and SSE2 therefore give the same
//! bits as the plain loop, and so do many threads (`threads.rs`), where each
//! particle still sums its springs in spring order.

use super::Slice;
use glam::DVec3;

/// Springs per block: the block's arrays (9 × 64 f64, 4.5 KiB) stay in L1.
pub const BLOCK: usize = 64;

/// One block's springs, as separate arrays the force computation vectorises over.
#[derive(Clone)]
pub struct Block {
    d: [[f64; BLOCK]; 3],
    w: [[f64; BLOCK]; 3],
    /// The force on each spring's first end (minus that on its second), N.
    f: [[f64; BLOCK]; 3],
}

impl Default for Block {
    fn default() -> Self {
        Block {
            d: [[0.0; BLOCK]; 3],
            w: [[0.0; BLOCK]; 3],
            f: [[0.0; BLOCK]; 3],
        }
    }
}

impl Block {
    /// Loads up to [`BLOCK`] springs' end-to-end vectors and relative
    /// velocities.
    #[inline(always)]
    fn load(&mut self, springs: Slice, pos: &[DVec3], vel: &[DVec3]) {
        for (i, &[a, b]) in springs.ends.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let d = pos[b] - pos[a];
            let w = vel[b] - vel[a];
            self.d[0][i] = d.x;
            self.d[1][i] = d.y;
            self.d[2][i] = d.z;
            self.w[0][i] = w.x;
            self.w[1][i] = w.y;
            self.w[2][i] = w.z;
        }
    }

    /// `f = n (k (len − r) + c (w·n))` with `n = d / len` (zero for a spring
    /// squashed to a point, which has no direction), for the springs just
    /// loaded; the same expression, in the same order, as [`plain`].
    #[inline(always)]
    fn compute(&mut self, springs: Slice) {
        let n = springs.len().min(BLOCK);
        let r = &springs.rest_length[..n];
        match springs.shared {
            Some((k, c)) => self.compute_with(r, |_| k, |_| c),
            None => {
                let (k, c) = (&springs.stiffness[..n], &springs.damping[..n]);
                self.compute_with(r, |i| k[i], |i| c[i])
            }
        }
    }

    /// [`Self::compute`] for the springs of rest lengths `r`, spring `i`
    /// of stiffness `k(i)` and damping `c(i)`.
    #[inline(always)]
    fn compute_with(&mut self, r: &[f64], k: impl Fn(usize) -> f64, c: impl Fn(usize) -> f64) {
        let n = r.len().min(BLOCK);
        let [dx, dy, dz] = &self.d;
        let [wx, wy, wz] = &self.w;
        let [fx, fy, fz] = &mut self.f;
        for i in 0..n {
            [fx[i], fy[i], fz[i]] = force(
                [dx[i], dy[i], dz[i]],
                [wx[i], wy[i], wz[i]],
                k(i),
                c(i),
                r[i],
            );
        }
    }

    /// The force of spring `i` of the block.
    #[inline(always)]
    pub fn force(&self, i: usize) -> DVec3 {
        DVec3::new(self.f[0][i], self.f[1][i], self.f[2][i])
    }
}

/// The force on the first end of a spring from it to its second end `d`
/// away, whose second end moves at `w` relative to the first: stiffness
/// `k`, damping `c`, rest length `r`. Every vectorised spring loop computes
/// it so, in this order, nothing fused (the plain loop writes the same
/// with glam's vectors).
#[inline(always)]
pub(super) fn force(d: [f64; 3], w: [f64; 3], k: f64, c: f64, r: f64) -> [f64; 3] {
    let len = ((d[0] * d[0] + d[1] * d[1]) + d[2] * d[2]).sqrt();
    let inv = if len > 0.0 { 1.0 / len } else { 0.0 };
    let n = [d[0] * inv, d[1] * inv, d[2] * inv];
    let s = k * (len - r) + c * ((w[0] * n[0] + w[1] * n[1]) + w[2] * n[2]);
    [n[0] * s, n[1] * s, n[2] * s]
}

/// Below this many springs the plain loop is faster than blocks (a
/// creature's few springs: nothing to vectorise over).
pub const MIN_BLOCKED: usize = 16;

/// The plain loop, one spring at a time: the same operations in the same
/// order as a block's, so the same bits.
#[inline]
pub(super) fn plain(springs: Slice, pos: &[DVec3], vel: &[DVec3], forces: &mut [DVec3]) {
    for (i, &[a, b]) in springs.ends.iter().enumerate() {
        let (a, b) = (a as usize, b as usize);
        let d = pos[b] - pos[a];
        let len = d.length();
        let n = d * if len > 0.0 { 1.0 / len } else { 0.0 };
        let f = n
            * (springs.stiffness[i] * (len - springs.rest_length[i])
                + springs.damping[i] * (vel[b] - vel[a]).dot(n));
        forces[a] += f;
        forces[b] -= f;
    }
}

/// What becomes of each spring's force once a block is computed.
///
/// It takes a whole block at a time, so that what it keeps from one spring
/// to the next can live in registers (in locals of its own loop).
pub(super) trait Sink {
    /// Springs `first..first + ends.len()` of the slice, with ends `ends`,
    /// computed in `block`: spring `i` pulls its first end with
    /// `block.force(i)` and its second with minus that. Called in order.
    fn take(&mut self, first: usize, ends: &[[u32; 2]], block: &Block);
    /// After the last block.
    fn finish(&mut self) {}
}

/// Computes every spring of `springs` in blocks and hands each force to
/// `sink`, in order, with the vectors chosen for arithmetic on this CPU
/// (`crate::simd`).
pub(super) fn run<S: Sink>(
    springs: Slice,
    block: &mut Block,
    pos: &[DVec3],
    vel: &[DVec3],
    sink: &mut S,
) {
    #[cfg(target_arch = "x86_64")]
    {
        use crate::simd::{width, Use, Width};
        let width = width(Use::Arithmetic);
        if width == Width::Avx512 {
            // SAFETY: the CPU has AVX-512F (`width` chooses only what it has).
            return unsafe { run_avx512(springs, block, pos, vel, sink) };
        }
        if width == Width::Avx2 {
            // SAFETY: the CPU has AVX2 (`width` chooses only what it has).
            return unsafe { run_avx2(springs, block, pos, vel, sink) };
        }
    }
    run_any(springs, block, pos, vel, sink)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn run_avx512<S: Sink>(
    springs: Slice,
    block: &mut Block,
    pos: &[DVec3],
    vel: &[DVec3],
    sink: &mut S,
) {
    run_any(springs, block, pos, vel, sink)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2<S: Sink>(
    springs: Slice,
    block: &mut Block,
    pos: &[DVec3],
    vel: &[DVec3],
    sink: &mut S,
) {
    run_any(springs, block, pos, vel, sink)
}

/// The loop itself; inlined into each instruction set's copy, where the
/// compiler vectorises [`Block::compute`] as wide as it may.
#[inline(always)]
fn run_any<S: Sink>(springs: Slice, block: &mut Block, pos: &[DVec3], vel: &[DVec3], sink: &mut S) {
    for (k, chunk) in springs.chunks(BLOCK).enumerate() {
        block.load(chunk, pos, vel);
        block.compute(chunk);
        sink.take(k * BLOCK, chunk.ends, block);
    }
    sink.finish();
}

/// The one-thread sink: `+f` on `a`, `−f` on `b`, straight into `forces`,
/// indexed by the ends it is given (the world's particle indices, or a
/// thread's piece's: `threads.rs` gives its blocks ends counted from the
/// piece's first particle, so that no end needs a subtraction here).
///
/// Two particles' sums are held in registers instead of memory: that of
/// the open run of consecutive springs sharing their first end (a mesh
/// lists a particle's springs together), and that of the last spring's
/// second end, until a spring with another second end comes (a chain's
/// next spring starts from it). The same additions in the same order,
/// without waiting for each store to reach the next load. The two are
/// never the same particle: a run that opens on the held second end
/// takes its sum over, and no spring of a run has its first end as its
/// second (a spring's ends differ).
pub(super) struct Scatter<'a> {
    pub forces: &'a mut [DVec3],
    run: Option<usize>,
    acc: DVec3,
    second: Option<usize>,
    held: DVec3,
}

impl<'a> Scatter<'a> {
    /// A sink adding to `forces`.
    pub fn new(forces: &'a mut [DVec3]) -> Self {
        Scatter {
            forces,
            run: None,
            acc: DVec3::ZERO,
            second: None,
            held: DVec3::ZERO,
        }
    }
}

impl Sink for Scatter<'_> {
    #[inline(always)]
    fn take(&mut self, _: usize, ends: &[[u32; 2]], block: &Block) {
        let (mut run, mut acc) = (self.run, self.acc);
        let (mut second, mut held) = (self.second, self.held);
        let forces = &mut *self.forces;
        for (i, &[a, b]) in ends.iter().enumerate() {
            let f = block.force(i);
            let (a, b) = (a as usize, b as usize);
            if run != Some(a) {
                if let Some(p) = run {
                    forces[p] = acc;
                }
                run = Some(a);
                acc = if second == Some(a) {
                    second = None;
                    held
                } else {
                    forces[a]
                };
            }
            acc += f;
            if second != Some(b) {
                if let Some(q) = second {
                    forces[q] = held;
                }
                second = Some(b);
                held = forces[b];
            }
            held -= f;
        }
        (self.run, self.acc) = (run, acc);
        (self.second, self.held) = (second, held);
    }

    #[inline(always)]
    fn finish(&mut self) {
        self.store_run();
        self.run = None;
        self.second = None;
    }
}

/// Particles handed on at a time by [`Staged`] (fewer wait for the next
/// block): a few pages of each array, still in the cache the springs
/// warmed.
const STAGE: usize = 256;

/// Where a world's particles stand as its springs are added in blocks, for
/// [`Staged`].
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Stages {
    /// Before block `b`, every particle before `first_touch[b]` must have
    /// its force started (no spring up to block `b` touches a later one).
    first_touch: Vec<u32>,
    /// After block `b`, every particle before `complete[b]` has its force
    /// (no later spring touches it).
    complete: Vec<u32>,
}

impl Stages {
    /// The stages of the springs with `ends` among `particles` particles.
    pub fn new(ends: &[[u32; 2]], particles: usize) -> Self {
        Self::of_blocks(
            ends.chunks(BLOCK)
                .map(|b| b.iter().flat_map(|&[a, b]| [a, b])),
            particles,
        )
    }

    /// The stages of `particles` particles of which each block of springs
    /// adds to the particles it yields (a thread's springs add to its own
    /// particles only: `threads.rs`).
    pub fn of_blocks<B: IntoIterator<Item = u32>>(
        blocks: impl Iterator<Item = B>,
        particles: usize,
    ) -> Self {
        // The block of each particle's last spring, plus one (0: none).
        let mut last = vec![0usize; particles];
        let mut reach = 0;
        let mut first_touch = Vec::with_capacity(blocks.size_hint().0);
        for (k, block) in blocks.enumerate() {
            for p in block {
                last[p as usize] = k + 1;
                reach = reach.max(p + 1);
            }
            first_touch.push(reach);
        }
        let mut p = 0;
        let complete = (0..first_touch.len())
            .map(|k| {
                while p < particles && last[p] <= k + 1 {
                    p += 1;
                }
                p as u32
            })
            .collect();
        Stages {
            first_touch,
            complete,
        }
    }
}

/// A sink that adds to one array of forces, keeping the sum of a run of
/// springs with the same first end in a register: what [`Staged`] wraps.
pub(super) trait Adds: Sink {
    /// The forces it adds to.
    fn forces(&mut self) -> &mut [DVec3];
    /// Stores the sums held in registers so far (the open run's and the
    /// last second end's), leaving them held.
    fn store_run(&mut self);
}

impl Adds for Scatter<'_> {
    #[inline(always)]
    fn forces(&mut self) -> &mut [DVec3] {
        self.forces
    }

    #[inline(always)]
    fn store_run(&mut self) {
        if let Some(p) = self.run {
            self.forces[p] = self.acc;
        }
        if let Some(q) = self.second {
            self.forces[q] = self.held;
        }
    }
}

/// The sink that starts each particle's force just before the
/// first spring adds to it (`start(range, forces)`, in order, each particle
/// once), and hands it on as soon as it is complete (`then(range,
/// forces)`, in order, each particle once, the last of them after the last
/// block). A mesh lists its springs particle by particle, so its particles
/// are started and handed on while they are in the cache, and no pass over
/// all of them comes before or after the springs.
pub(super) struct Staged<'a, K, S, F> {
    inner: K,
    stages: &'a Stages,
    /// The particles started so far: `0..started`.
    started: usize,
    /// The particles handed on so far: `0..done`.
    done: usize,
    start: S,
    then: F,
}

impl<'a, K, S, F> Staged<'a, K, S, F>
where
    K: Adds,
    S: FnMut(std::ops::Range<usize>, &mut [DVec3]),
    F: FnMut(std::ops::Range<usize>, &[DVec3]),
{
    /// The sink `inner` (adding to the particles `stages` counts), staged
    /// by `stages`.
    pub fn new(inner: K, stages: &'a Stages, start: S, then: F) -> Self {
        Staged {
            inner,
            stages,
            started: 0,
            done: 0,
            start,
            then,
        }
    }

    /// Starts the particles up to `to`.
    fn start_to(&mut self, to: usize) {
        if to > self.started {
            let range = self.started..to;
            (self.start)(range.clone(), &mut self.inner.forces()[range]);
            self.started = to;
        }
    }

    /// Hands on the particles up to `to`.
    fn hand_on(&mut self, to: usize) {
        // A particle no spring touches may come before the springs reach it.
        self.start_to(to);
        let range = self.done..to;
        (self.then)(range.clone(), &self.inner.forces()[range]);
        self.done = to;
    }
}

impl<K, S, F> Sink for Staged<'_, K, S, F>
where
    K: Adds,
    S: FnMut(std::ops::Range<usize>, &mut [DVec3]),
    F: FnMut(std::ops::Range<usize>, &[DVec3]),
{
    #[inline(always)]
    fn take(&mut self, first: usize, ends: &[[u32; 2]], block: &Block) {
        let k = first / BLOCK;
        self.start_to(self.stages.first_touch[k] as usize);
        self.inner.take(first, ends, block);
        let complete = self.stages.complete[k] as usize;
        if complete >= self.done + STAGE {
            // The particle of the open run may be among them: its sum so
            // far is its force if no later spring touches it, and is
            // stored again if one does.
            self.inner.store_run();
            self.hand_on(complete);
        }
    }

    fn finish(&mut self) {
        self.inner.finish();
        let n = self.inner.forces().len();
        if self.done < n {
            self.hand_on(n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::Table;
    use super::*;
    use std::ops::Range;

    /// 300 springs among 120 particles, in no particular order: runs of a
    /// shared first end, chains, repeated pairs, a spring squashed to a point,
    /// and a length (301) that is no multiple of a block.
    fn springs() -> (Table, Vec<DVec3>, Vec<DVec3>) {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut u = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let n = 120u64;
        let mut pos: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(u() as f64, u() as f64, u() as f64) / u64::MAX as f64)
            .collect();
        let vel: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(u() as f64, u() as f64, u() as f64) / u64::MAX as f64 - 0.5)
            .collect();
        pos[9] = pos[10];
        let mut t = Table::default();
        let push = |a: u64, b: u64, t: &mut Table, r: u64| {
            t.ends.push([a as u32, b as u32]);
            t.stiffness.push(1.0 + (r % 1000) as f64);
            t.damping.push((r % 7) as f64 * 0.1);
            t.rest_length.push(0.1 + (r % 13) as f64 * 0.05);
        };
        push(9, 10, &mut t, 5);
        for i in 0..300 {
            let r = u();
            let a = if i % 3 == 0 { r % n } else { (i / 3) % n };
            let b = (a + 1 + (r >> 20) % (n - 1)) % n;
            push(a, b, &mut t, r >> 8);
        }
        // Then the cases the one-thread sink holds in registers: a chain
        // (each spring starting at the last one's second end), springs
        // sharing their second end in a row, a run of one first end, and
        // springs to particles whose sums were stored before.
        let (mut a, mut b) = (0, 1);
        for i in 0..300 {
            let r = u();
            let other = |x: u64| (x + 1 + (r >> 24) % (n - 1)) % n;
            (a, b) = match r % 4 {
                0 => (b, other(b)),
                1 => (other(b), b),
                2 => (a, other(a)),
                _ => ((i * 7) % n, other((i * 7) % n)),
            };
            push(a, b, &mut t, r >> 8);
        }
        (t, pos, vel)
    }

    fn bits(forces: &[DVec3]) -> Vec<u64> {
        forces
            .iter()
            .flat_map(|f| f.to_array().map(f64::to_bits))
            .collect()
    }

    /// What a staged run gives: the forces, the ranges started, and the
    /// ranges handed on with their forces then.
    type StagedRun = (
        Vec<DVec3>,
        Vec<Range<usize>>,
        Vec<(Range<usize>, Vec<DVec3>)>,
    );

    /// Runs the staged sink over `t`, the forces started at `start`.
    fn staged(t: &Table, pos: &[DVec3], vel: &[DVec3], start: &[DVec3]) -> StagedRun {
        let stages = Stages::new(&t.ends, pos.len());
        let mut forces = vec![DVec3::NAN; pos.len()];
        let (mut started, mut handed) = (Vec::new(), Vec::new());
        let mut sink = Staged::new(
            Scatter::new(&mut forces),
            &stages,
            |r: Range<usize>, f: &mut [DVec3]| {
                f.copy_from_slice(&start[r.clone()]);
                started.push(r);
            },
            |r: Range<usize>, f: &[DVec3]| handed.push((r, f.to_vec())),
        );
        run(t.all(), &mut Block::default(), pos, vel, &mut sink);
        (forces, started, handed)
    }

    /// The ranges cover `0..n` in order, each particle once.
    fn consecutive<'a>(ranges: impl Iterator<Item = &'a Range<usize>>, n: usize) {
        let mut next = 0;
        for r in ranges {
            assert_eq!(r.start, next, "ranges in order, none left out");
            assert!(r.end > r.start, "no empty range");
            next = r.end;
        }
        assert_eq!(next, n, "every particle");
    }

    /// Staged, the springs add the same bits as the plain loop: every
    /// particle is started before a spring adds to it (else the spring's
    /// part would be lost), once, and handed on with its final force (no
    /// spring added to it afterwards), once, in order; springs in no
    /// particular order, and a few particles no spring touches.
    #[test]
    fn staged_springs_start_and_hand_on_each_particle_once_with_its_final_force() {
        let (t, mut pos, mut vel) = springs();
        // Particles 120..130 have no springs.
        pos.extend((0..10).map(|i| DVec3::splat(i as f64)));
        vel.extend((0..10).map(|i| DVec3::splat(-(i as f64))));
        let start: Vec<DVec3> = (0..pos.len()).map(|i| DVec3::splat(i as f64)).collect();
        let mut want = start.clone();
        plain(t.all(), &pos, &vel, &mut want);
        let (forces, started, handed) = staged(&t, &pos, &vel, &start);
        assert_eq!(bits(&forces), bits(&want));
        consecutive(started.iter(), pos.len());
        consecutive(handed.iter().map(|(r, _)| r), pos.len());
        for (r, f) in &handed {
            assert_eq!(bits(f), bits(&want[r.clone()]), "{r:?} handed on complete");
        }
    }

    /// Springs listed particle by particle (a chain of 2,000) come out in
    /// stages of at least `STAGE` particles while the springs are added,
    /// not all at the end.
    #[test]
    fn staged_a_chain_in_order_is_handed_on_while_its_springs_are_added() {
        // Listed forward, each spring starts where the last ended; listed
        // backward, each spring's second end is complete once the next
        // spring is added (handed on while the sink may hold its sum).
        for backward in [false, true] {
            let n = 2000;
            let mut t = Table::default();
            for i in 0..n as u32 - 1 {
                t.ends.push(if backward { [i + 1, i] } else { [i, i + 1] });
                t.stiffness.push(10.0);
                t.damping.push(0.1);
                t.rest_length.push(0.5);
            }
            let pos: Vec<DVec3> = (0..n)
                .map(|i| DVec3::new(i as f64, 0.01 * i as f64, 0.0))
                .collect();
            let vel = vec![DVec3::ZERO; n];
            let start = vec![DVec3::ZERO; n];
            let mut want = start.clone();
            plain(t.all(), &pos, &vel, &mut want);
            let (forces, started, handed) = staged(&t, &pos, &vel, &start);
            assert_eq!(bits(&forces), bits(&want), "backward {backward}");
            assert!(started.len() > n / BLOCK / 2, "{} starts", started.len());
            assert!(
                handed.len() >= n / (STAGE + BLOCK),
                "{} hand-ons",
                handed.len()
            );
            for (r, f) in &handed {
                assert_eq!(
                    bits(f),
                    bits(&want[r.clone()]),
                    "{r:?} handed on complete (backward {backward})"
                );
            }
            let (last, rest) = handed.split_last().unwrap();
            assert!(rest.iter().all(|(r, _)| r.len() >= STAGE));
            assert!(
                last.0.len() <= STAGE + BLOCK,
                "{:?} left to the end",
                last.0
            );
        }
    }

    #[test]
    fn every_instruction_set_adds_the_same_bits_as_the_plain_loop() {
        let (t, pos, vel) = springs();
        let start: Vec<DVec3> = (0..pos.len()).map(|i| DVec3::splat(i as f64)).collect();
        let mut want = start.clone();
        plain(t.all(), &pos, &vel, &mut want);
        assert!(want.iter().all(|f| f.is_finite()));
        let run = |path: &str| {
            let mut forces = start.clone();
            let mut block = Block::default();
            let s = t.all();
            let mut sink = Scatter::new(&mut forces);
            match path {
                "any" => run_any(s, &mut block, &pos, &vel, &mut sink),
                #[cfg(target_arch = "x86_64")]
                "avx2" => unsafe { run_avx2(s, &mut block, &pos, &vel, &mut sink) },
                #[cfg(target_arch = "x86_64")]
                "avx512" => unsafe { run_avx512(s, &mut block, &pos, &vel, &mut sink) },
                _ => unreachable!(),
            }
            bits(&forces)
        };
        assert_eq!(run("any"), bits(&want), "portable");
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                assert_eq!(run("avx2"), bits(&want), "avx2");
            }
            if std::arch::is_x86_feature_detected!("avx512f") {
                assert_eq!(run("avx512"), bits(&want), "avx512");
            }
        }
    }
}
