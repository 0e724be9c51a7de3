//! Springs listed as a mesh lists them, summed as a stencil.
//!
//! A cloth or a chain built particle by particle lists, for each particle
//! `p` in turn, its springs to `p + o` for a few fixed offsets `o` in a
//! fixed order (the workloads' cloth: right `1`, down `n`, and the
//! diagonals `n + 1` and `n − 1`; a chain: `1`), some missing at the
//! edges. Such a list is a few *families* of springs, one per offset, each
//! from consecutive particles to consecutive particles. Here the positions
//! and velocities of a window of particles are copied into separate x, y,
//! z arrays, each family's forces are computed from two runs of
//! consecutive particles (whole vectors, no gathering by index), and each
//! particle then sums its springs' forces from the families' arrays (no
//! scattering by index).
//!
//! The same bits as the springs in list order ([`super::kernel`]): each
//! spring's force is computed by the same code ([`super::kernel::force`]),
//! and each particle adds its springs in list order. A particle `p`'s
//! springs come in the list first as the second end of the springs of
//! earlier particles `p − o`, earliest first (the largest offset first),
//! then as the first end of its own, in family order; it subtracts and
//! adds them in that order. A spring the mesh lacks adds nothing (not a
//! zero, which could change the sign of a zero sum).

use super::kernel::{force, BLOCK};
use super::Slice;
use crate::parallel::take_front;
use crate::simd::{chosen, Use};
use glam::DVec3;
use std::ops::Range;

/// At most this many families (offsets); more is no mesh of this kind.
const MAX_FAMILIES: usize = 8;

/// Fewer springs than this are not worth the families' arrays: chain-64's
/// 63 springs took 0.563–0.586 ms a run as families against 0.491–0.494
/// ms in blocks (`animats bench chain-64`); cloth-32's 3,906 gain.
pub(super) const MIN_SPRINGS: usize = 256;

/// Particles taken at a time: their springs' forces computed, summed and
/// handed on while they are in the cache.
const CHUNK: usize = 16 * BLOCK;

/// No spring: the mesh lacks it.
const NONE: u32 = u32::MAX;

/// A spring list that is a mesh's, and what summing it as one needs.
pub(super) struct Grid {
    /// Each family's offset, in the order a particle lists its springs.
    offsets: Vec<usize>,
    /// The families by decreasing offset: the order in which a particle's
    /// springs from earlier particles come in the list.
    down: Vec<usize>,
    /// `index[d][p]`: the spring from `p` to `p + offsets[d]`, or [`NONE`].
    index: Vec<Vec<u32>>,
    /// Each spring's family and first end: where its parameters are copied.
    place: Vec<(u32, u32)>,
    /// The springs' rest lengths, stiffness and damping by family and
    /// first end, copied from the table (kept up to date by
    /// [`Self::set`]); zero where the mesh lacks a spring. Stiffness and
    /// damping are left empty when every spring has the same.
    rest: Vec<Vec<f64>>,
    stiffness: Vec<Vec<f64>>,
    damping: Vec<Vec<f64>>,
    /// The particles that lack one of their families' springs either way
    /// (a mesh's edges), in order: summed again one at a time.
    lacking: Vec<u32>,
    /// The largest offset.
    reach: usize,
    /// Working arrays, one per thread.
    works: Vec<Work>,
}

impl Grid {
    /// The families of `ends` among `particles` particles, if the list is a
    /// mesh's: particles in increasing order, each listing its springs (to
    /// later particles) in one order of at most [`MAX_FAMILIES`] offsets,
    /// skipping some, with at least half the families' places filled.
    pub fn find(springs: Slice, particles: usize) -> Option<Grid> {
        let ends = springs.ends;
        if ends.len() < MIN_SPRINGS {
            return None;
        }
        // Each particle's springs, as runs of the list.
        let mut groups = Vec::new();
        let mut i = 0;
        while i < ends.len() {
            let a = ends[i][0];
            let mut j = i;
            while j < ends.len() && ends[j][0] == a {
                if ends[j][1] <= a {
                    return None;
                }
                j += 1;
            }
            if groups
                .last()
                .is_some_and(|&(_, prev): &(usize, u32)| prev >= a)
            {
                return None;
            }
            groups.push((i, a));
            i = j;
        }
        groups.push((ends.len(), u32::MAX));
        // The longest group's offsets are the families' order; every group
        // must list a part of them in that order.
        let offsets_of = |g: usize| {
            let (from, a) = groups[g];
            let to = groups[g + 1].0;
            ends[from..to].iter().map(move |e| (e[1] - a) as usize)
        };
        let longest = (0..groups.len() - 1)
            .max_by_key(|&g| (groups[g + 1].0 - groups[g].0, usize::MAX - g))?;
        let offsets: Vec<usize> = offsets_of(longest).collect();
        if offsets.len() > MAX_FAMILIES
            || ends.len() * 2 < offsets.len() * particles
            || offsets
                .iter()
                .enumerate()
                .any(|(k, o)| offsets[..k].contains(o))
        {
            return None;
        }
        let mut index = vec![vec![NONE; particles]; offsets.len()];
        let mut place = vec![(0, 0); ends.len()];
        for (g, &(from, a)) in groups[..groups.len() - 1].iter().enumerate() {
            let mut d = 0;
            for (k, o) in offsets_of(g).enumerate() {
                while d < offsets.len() && offsets[d] != o {
                    d += 1;
                }
                if d == offsets.len() {
                    return None; // not in the families' order
                }
                index[d][a as usize] = (from + k) as u32;
                place[from + k] = (d as u32, a);
                d += 1;
            }
        }
        let mut down: Vec<usize> = (0..offsets.len()).collect();
        down.sort_by_key(|&d| std::cmp::Reverse(offsets[d]));
        let full = |p: usize| {
            offsets
                .iter()
                .enumerate()
                .all(|(d, &o)| index[d][p] != NONE && p >= o && index[d][p - o] != NONE)
        };
        let lacking = (0..particles as u32)
            .filter(|&p| !full(p as usize))
            .collect();
        let each = |v: &[f64]| by_family(&place, v, offsets.len(), particles);
        let rest = each(springs.rest_length);
        let (stiffness, damping) = match springs.shared {
            Some(_) => (Vec::new(), Vec::new()),
            None => (each(springs.stiffness), each(springs.damping)),
        };
        Some(Grid {
            reach: offsets.iter().copied().max().unwrap_or(0),
            works: Vec::new(),
            offsets,
            down,
            index,
            place,
            rest,
            stiffness,
            damping,
            lacking,
        })
    }

    /// Copies spring `i`'s parameters (after a change) from `springs`.
    pub fn set(&mut self, springs: Slice, i: usize) {
        let (d, a) = self.place[i];
        let (d, a) = (d as usize, a as usize);
        self.rest[d][a] = springs.rest_length[i];
        if springs.shared.is_none() {
            if self.stiffness.is_empty() {
                // The springs no longer share theirs: copy them all.
                let (n, families) = (self.index[0].len(), self.offsets.len());
                self.stiffness = by_family(&self.place, springs.stiffness, families, n);
                self.damping = by_family(&self.place, springs.damping, families, n);
            } else {
                self.stiffness[d][a] = springs.stiffness[i];
                self.damping[d][a] = springs.damping[i];
            }
        }
    }

    /// [`Self::run`] with nothing handed on: `start(range, forces)` before
    /// any spring adds to a chunk.
    pub fn add(
        &mut self,
        springs: Slice,
        pos: &[DVec3],
        vel: &[DVec3],
        forces: &mut [DVec3],
        threads: usize,
        start: impl Fn(Range<usize>, &mut [DVec3]) + Sync,
    ) {
        let none = [&mut [][..], &mut []];
        self.run(
            springs,
            pos,
            vel,
            forces,
            threads,
            start,
            none,
            |_, _, _| (),
            |_, _| (),
        );
    }

    /// Adds the springs' forces to `forces` on `threads` threads (of the
    /// current pool), each its own run of particles, in chunks of
    /// [`CHUNK`] in order: `start(range, forces)` before any spring adds
    /// to a chunk, `then(first, forces, [x, v])` once they all have, with
    /// the same chunk of `outs` (or empty slices, if `outs` are empty); the
    /// answers combined by `combine` (associative and commutative).
    ///
    /// A thread also computes the springs from the `reach` particles before
    /// its run, which the thread before it computes too: the same forces,
    /// by the same code, so the bits do not depend on the threads.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn run<R: Send>(
        &mut self,
        springs: Slice,
        pos: &[DVec3],
        vel: &[DVec3],
        forces: &mut [DVec3],
        threads: usize,
        start: impl Fn(Range<usize>, &mut [DVec3]) + Sync,
        outs: [&mut [DVec3]; 2],
        then: impl Fn(usize, &[DVec3], [&mut [DVec3]; 2]) -> R + Sync,
        combine: impl Fn(R, R) -> R + Sync + Send,
    ) -> Option<R> {
        let n = forces.len();
        let Grid {
            offsets,
            down,
            index,
            rest,
            stiffness,
            damping,
            lacking,
            reach,
            works,
            ..
        } = self;
        let mesh = Mesh {
            offsets,
            down,
            index,
            rest,
            stiffness,
            damping,
            shared: springs.shared,
            reach: *reach,
        };
        // Runs of whole chunks, no shorter than what they reach back.
        let per = n
            .div_ceil(threads.max(1))
            .div_ceil(CHUNK)
            .max(reach.div_ceil(CHUNK))
            * CHUNK;
        let tasks = n.div_ceil(per).max(1);
        works.resize_with(tasks, Default::default);
        let (mesh, lacking, reach) = (&mesh, &lacking[..], *reach);
        let (start, then) = (&start, &then);
        let job = |(range, work, forces, outs): (
            Range<usize>,
            &mut Work,
            &mut [DVec3],
            [&mut [DVec3]; 2],
        )| {
            chosen(
                Use::Arithmetic,
                #[inline(always)]
                || {
                    mesh.run(
                        work, lacking, reach, pos, vel, range, forces, start, outs, then, &combine,
                    )
                },
            )
        };
        if tasks == 1 {
            // No list of jobs: nothing allocated in a step.
            job((0..n, &mut works[0], forces, outs))
        } else {
            let has_outs = !outs[0].is_empty();
            let [mut x, mut v] = outs;
            let mut rest_forces = forces;
            let mut jobs = Vec::with_capacity(tasks);
            for (t, work) in works.iter_mut().enumerate() {
                let range = t * per..n.min((t + 1) * per);
                let len = if has_outs { range.len() } else { 0 };
                let (x, v) = (take_front(&mut x, len), take_front(&mut v, len));
                let f = take_front(&mut rest_forces, range.len());
                jobs.push((range, work, f, [x, v]));
            }
            crate::parallel::fork_tasks(jobs, job, |a, b| match (a, b) {
                (Some(a), Some(b)) => Some(combine(a, b)),
                (a, b) => a.or(b),
            })
            .flatten()
        }
    }
}

/// The mesh's tables, borrowed for a run.
struct Mesh<'a> {
    offsets: &'a [usize],
    down: &'a [usize],
    index: &'a [Vec<u32>],
    rest: &'a [Vec<f64>],
    stiffness: &'a [Vec<f64>],
    damping: &'a [Vec<f64>],
    shared: Option<(f64, f64)>,
    /// The largest offset.
    reach: usize,
}

/// Working arrays for a window of particles that slides along a thread's
/// run: their positions and velocities as separate coordinates (from the
/// chunk's first particle to the last its springs reach), the families'
/// forces (from the first particle whose springs reach the chunk to its
/// last), and a chunk's sums. Kept this short, they stay in the cache.
#[derive(Default)]
struct Work {
    /// The state window: particles `s0..s0 + s_len`.
    s0: usize,
    s_len: usize,
    /// x, y, z, then the velocity's: `state[k][p − s0]`.
    state: [Vec<f64>; 6],
    /// The force window: particles `f0..f0 + f_len`.
    f0: usize,
    f_len: usize,
    /// `force[d][k][p − f0]`: coordinate `k` of family `d`'s force at `p`.
    force: Vec<[Vec<f64>; 3]>,
    sum: [Vec<f64>; 3],
    /// A chunk's particles that lack a spring, with their starting forces.
    lacking: Vec<(usize, [f64; 3])>,
}

impl Work {
    /// Empty windows from particle `first`, for `families` families and
    /// springs reaching `reach` particles on.
    fn prepare(&mut self, families: usize, reach: usize, first: usize) {
        let len = CHUNK + reach;
        for v in &mut self.state {
            v.resize(len, 0.0);
        }
        self.force.resize_with(families, Default::default);
        for f in &mut self.force {
            for v in f {
                v.resize(len, 0.0);
            }
        }
        for v in &mut self.sum {
            v.resize(CHUNK, 0.0);
        }
        (self.s0, self.s_len, self.f0, self.f_len) = (first, 0, first, 0);
    }

    /// Slides the state window to start at `from` and fills it with the
    /// positions and velocities up to particle `to`.
    #[inline(always)]
    fn states(&mut self, pos: &[DVec3], vel: &[DVec3], from: usize, to: usize) {
        let shift = (from - self.s0).min(self.s_len);
        for v in &mut self.state {
            v.copy_within(shift..self.s_len, 0);
        }
        (self.s0, self.s_len) = (from, self.s_len - shift);
        let r = self.s0 + self.s_len..to;
        if r.is_empty() {
            return;
        }
        let a = r.start - self.s0..r.end - self.s0;
        let [x, y, z, vx, vy, vz] = &mut self.state;
        split(
            &pos[r.clone()],
            &mut x[a.clone()],
            &mut y[a.clone()],
            &mut z[a.clone()],
        );
        split(&vel[r], &mut vx[a.clone()], &mut vy[a.clone()], &mut vz[a]);
        self.s_len = to - self.s0;
    }

    /// Slides the force window to start at `from`, keeping what it holds
    /// from there on.
    #[inline(always)]
    fn forces_from(&mut self, from: usize) {
        let shift = (from - self.f0).min(self.f_len);
        for f in &mut self.force {
            for v in f {
                v.copy_within(shift..self.f_len, 0);
            }
        }
        (self.f0, self.f_len) = (from, self.f_len - shift);
    }
}

/// Each spring's value `v[i]` at its place `place[i]` (family, first end)
/// among `families` families of `particles` places; zero where the mesh
/// lacks a spring.
fn by_family(place: &[(u32, u32)], v: &[f64], families: usize, particles: usize) -> Vec<Vec<f64>> {
    let mut by = vec![vec![0.0; particles]; families];
    for (&(d, a), &v) in place.iter().zip(v) {
        by[d as usize][a as usize] = v;
    }
    by
}

/// The coordinates of `v` into `x`, `y`, `z` (parameters, so that the
/// compiler knows them apart).
#[inline(always)]
fn split(v: &[DVec3], x: &mut [f64], y: &mut [f64], z: &mut [f64]) {
    let n = v.len();
    let (x, y, z) = (&mut x[..n], &mut y[..n], &mut z[..n]);
    for (i, v) in v.iter().enumerate() {
        (x[i], y[i], z[i]) = (v.x, v.y, v.z);
    }
}

/// `x`, `y`, `z` into the coordinates of `v` (parameters, as in [`split`]).
#[inline(always)]
fn join(x: &[f64], y: &[f64], z: &[f64], v: &mut [DVec3]) {
    let n = v.len();
    let (x, y, z) = (&x[..n], &y[..n], &z[..n]);
    for (i, v) in v.iter_mut().enumerate() {
        *v = DVec3::new(x[i], y[i], z[i]);
    }
}

/// `s[i] − sub[0][i] − … + add[0][i] + …` into `s`, in that order: the
/// particles of a run with every spring, `D` families.
#[inline(always)]
fn full_run<const D: usize>(s: &mut [f64], sub: [&[f64]; D], add: [&[f64]; D]) {
    let n = s.len();
    let sub = sub.map(|f| &f[..n]);
    let add = add.map(|f| &f[..n]);
    for i in 0..n {
        let mut v = s[i];
        for f in sub {
            v -= f[i];
        }
        for f in add {
            v += f[i];
        }
        s[i] = v;
    }
}

/// One family's springs: from the particles of `a` (x, y, z, then the
/// velocity's) to those of `xb` … `vzb`, rest lengths `rest` and
/// `kc(i) = (stiffness, damping)`, into `fx`, `fy`, `fz`. The slices are
/// parameters, each cut here to `rest`'s length, so that the compiler knows
/// the outputs apart from the inputs, checks no bounds in the loop and
/// vectorises it.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn family(
    a: [&[f64]; 6],
    xb: &[f64],
    yb: &[f64],
    zb: &[f64],
    vxb: &[f64],
    vyb: &[f64],
    vzb: &[f64],
    kc: impl Fn(usize) -> (f64, f64),
    rest: &[f64],
    fx: &mut [f64],
    fy: &mut [f64],
    fz: &mut [f64],
) {
    let n = rest.len();
    let [xa, ya, za, vxa, vya, vza] = a.map(|s| &s[..n]);
    let (xb, yb, zb, vxb, vyb, vzb) = (
        &xb[..n],
        &yb[..n],
        &zb[..n],
        &vxb[..n],
        &vyb[..n],
        &vzb[..n],
    );
    let (fx, fy, fz) = (&mut fx[..n], &mut fy[..n], &mut fz[..n]);
    for i in 0..n {
        let (k, c) = kc(i);
        [fx[i], fy[i], fz[i]] = force(
            [xb[i] - xa[i], yb[i] - ya[i], zb[i] - za[i]],
            [vxb[i] - vxa[i], vyb[i] - vya[i], vzb[i] - vza[i]],
            k,
            c,
            rest[i],
        );
    }
}

impl Mesh<'_> {
    /// One thread's run of particles `range` (see [`Grid::run`]); `forces`
    /// and `outs` are the run's.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn run<R>(
        &self,
        work: &mut Work,
        lacking: &[u32],
        reach: usize,
        pos: &[DVec3],
        vel: &[DVec3],
        range: Range<usize>,
        forces: &mut [DVec3],
        start: &impl Fn(Range<usize>, &mut [DVec3]),
        outs: [&mut [DVec3]; 2],
        then: &impl Fn(usize, &[DVec3], [&mut [DVec3]; 2]) -> R,
        combine: &impl Fn(R, R) -> R,
    ) -> Option<R> {
        let n = pos.len();
        let lo = range.start.saturating_sub(reach);
        work.prepare(self.offsets.len(), reach, lo);
        // The springs from the particles before the run that reach into it.
        if lo < range.start {
            work.states(pos, vel, lo, n.min(range.start + reach));
            self.compute(work, lo..range.start, n);
        }
        let [mut x, mut v] = outs;
        let has_outs = !x.is_empty();
        let mut answer = None;
        for first in range.clone().step_by(CHUNK) {
            let chunk = first..range.end.min(first + CHUNK);
            work.states(pos, vel, chunk.start, n.min(chunk.end + reach));
            work.forces_from(lo.max(chunk.start.saturating_sub(reach)));
            self.compute(work, chunk.clone(), n);
            let local = chunk.start - range.start..chunk.end - range.start;
            let f = &mut forces[local.clone()];
            start(chunk.clone(), f);
            let first = lacking.partition_point(|&p| (p as usize) < chunk.start);
            let last = lacking.partition_point(|&p| (p as usize) < chunk.end);
            self.sum(work, &lacking[first..last], f, chunk.clone());
            let len = if has_outs { chunk.len() } else { 0 };
            let out = [take_front(&mut x, len), take_front(&mut v, len)];
            let a = then(chunk.start, f, out);
            answer = Some(match answer.take() {
                Some(b) => combine(b, a),
                None => a,
            });
        }
        answer
    }

    /// The forces of every family's springs from the particles `chunk`
    /// (of `n`).
    #[inline(always)]
    fn compute(&self, work: &mut Work, chunk: Range<usize>, n: usize) {
        let (s0, f0) = (work.s0, work.f0);
        work.f_len = work.f_len.max(chunk.end - f0);
        let [x, y, z, vx, vy, vz] = &work.state;
        for (d, &o) in self.offsets.iter().enumerate() {
            let r = chunk.start..chunk.end.min(n - o).max(chunk.start);
            let (a, b) = (r.start - s0..r.end - s0, r.start - s0 + o..r.end - s0 + o);
            let fa = r.start - f0..r.end - f0;
            let (xa, ya, za) = (&x[a.clone()], &y[a.clone()], &z[a.clone()]);
            let (xb, yb, zb) = (&x[b.clone()], &y[b.clone()], &z[b.clone()]);
            let (vxa, vya, vza) = (&vx[a.clone()], &vy[a.clone()], &vz[a.clone()]);
            let (vxb, vyb, vzb) = (&vx[b.clone()], &vy[b.clone()], &vz[b]);
            let rest = &self.rest[d][r.clone()];
            let [fx, fy, fz] = &mut work.force[d];
            let (fx, fy, fz) = (&mut fx[fa.clone()], &mut fy[fa.clone()], &mut fz[fa]);
            // A spring the mesh lacks is computed (from zeros) and never used.
            match self.shared {
                Some((ks, cs)) => family(
                    [xa, ya, za, vxa, vya, vza],
                    xb,
                    yb,
                    zb,
                    vxb,
                    vyb,
                    vzb,
                    |_| (ks, cs),
                    rest,
                    fx,
                    fy,
                    fz,
                ),
                None => {
                    let (k, c) = (&self.stiffness[d][r.clone()], &self.damping[d][r]);
                    family(
                        [xa, ya, za, vxa, vya, vza],
                        xb,
                        yb,
                        zb,
                        vxb,
                        vyb,
                        vzb,
                        |i| (k[i], c[i]),
                        rest,
                        fx,
                        fy,
                        fz,
                    )
                }
            }
        }
    }

    /// Adds to the forces `out` of the particles `chunk` their springs'
    /// forces, in list order; `lacks` are the chunk's particles that lack a
    /// spring.
    #[inline(always)]
    fn sum(&self, work: &mut Work, lacks: &[u32], out: &mut [DVec3], chunk: Range<usize>) {
        let len = chunk.len();
        let Work {
            f0,
            force,
            sum,
            lacking,
            ..
        } = work;
        let lo = *f0;
        {
            let [sx, sy, sz] = sum;
            split(out, sx, sy, sz);
        }
        // The particles that lack a spring, and their starting forces.
        lacking.clear();
        lacking.extend(lacks.iter().map(|&p| {
            let i = p as usize - chunk.start;
            (p as usize, [sum[0][i], sum[1][i], sum[2][i]])
        }));
        // Every particle from where all of its springs' forces are in the
        // window, as if it had every spring, in one vectorised loop a
        // coordinate; then those that lack one again, one at a time, from
        // their starting forces (what the loop read for a missing spring
        // is dropped with its sum). Before `lo + reach` every particle
        // lacks a spring.
        let first = chunk.start.max(lo + self.reach);
        if first < chunk.end {
            let at = first - chunk.start..len;
            for (s, k) in sum.iter_mut().zip(0..3) {
                let s = &mut s[at.clone()];
                let sub = |j: usize| {
                    let (d, o) = (self.down[j], self.offsets[self.down[j]]);
                    &force[d][k][first - o - lo..chunk.end - o - lo]
                };
                let add = |d: usize| &force[d][k][first - lo..chunk.end - lo];
                macro_rules! families {
                    ($($d:literal)*) => {
                        match self.offsets.len() {
                            $($d => full_run::<$d>(
                                s,
                                std::array::from_fn(sub),
                                std::array::from_fn(add),
                            ),)*
                            _ => unreachable!("at most {MAX_FAMILIES} families"),
                        }
                    };
                }
                families!(1 2 3 4 5 6 7 8);
            }
        }
        for &(p, start) in lacking.iter() {
            let i = p - chunk.start;
            for (s, (k, start)) in sum.iter_mut().zip(start.into_iter().enumerate()) {
                let mut v = start;
                for &d in self.down {
                    let o = self.offsets[d];
                    if p >= o && self.index[d][p - o] != NONE {
                        v -= force[d][k][p - o - lo];
                    }
                }
                for (d, f) in force.iter().enumerate() {
                    if self.index[d][p] != NONE {
                        v += f[k][p - lo];
                    }
                }
                s[i] = v;
            }
        }
        let [sx, sy, sz] = &*sum;
        join(sx, sy, sz, &mut out[..len]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Grid::find` of springs with these ends.
    fn find(ends: &[[u32; 2]], particles: usize) -> Option<Grid> {
        let ones = vec![1.0; ends.len()];
        Grid::find(
            Slice {
                ends,
                stiffness: &ones,
                damping: &ones,
                rest_length: &ones,
                shared: Some((1.0, 1.0)),
            },
            particles,
        )
    }

    /// A cloth of `rows` × `cols` in the workloads' order.
    fn cloth(rows: usize, cols: usize) -> Vec<[u32; 2]> {
        let mut e = Vec::new();
        for i in 0..rows {
            for j in 0..cols {
                let p = (i * cols + j) as u32;
                let c = cols as u32;
                if j + 1 < cols {
                    e.push([p, p + 1]);
                }
                if i + 1 < rows {
                    e.push([p, p + c]);
                }
                if i + 1 < rows && j + 1 < cols {
                    e.push([p, p + c + 1]);
                }
                if i + 1 < rows && j > 0 {
                    e.push([p, p + c - 1]);
                }
            }
        }
        e
    }

    /// xorshift64: a fixed stream.
    struct Stream(u64);
    impl Stream {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// Springs with `ends` among `n` particles in a jittered grid (`cols`
    /// a row), moving at random, with random parameters (or the same for
    /// all): the grid's forces on 1, 2, 3 and 7 threads against the plain
    /// loop in list order, bit for bit, from random starting forces; and
    /// each particle handed on once, with its final force.
    fn same_as_the_list(ends: &[[u32; 2]], n: usize, cols: usize, shared: bool, seed: u64) {
        let mut r = Stream(seed);
        let pos: Vec<DVec3> = (0..n)
            .map(|p| {
                let (i, j) = ((p / cols) as f64, (p % cols) as f64);
                DVec3::new(
                    0.02 * j + 0.004 * r.next(),
                    0.003 * r.next(),
                    0.02 * i + 0.004 * r.next(),
                )
            })
            .collect();
        let vel: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(r.next(), r.next(), r.next()))
            .collect();
        let start: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(r.next(), r.next(), 0.0))
            .collect();
        let m = ends.len();
        let mut stiffness: Vec<f64> = (0..m).map(|_| 100.0 * (1.0 + r.next())).collect();
        let mut damping: Vec<f64> = (0..m).map(|_| 0.1 * (1.0 + r.next())).collect();
        let mut rest_length: Vec<f64> = (0..m).map(|_| 0.02 * (1.0 + 0.5 * r.next())).collect();
        if shared {
            stiffness.fill(150.0);
            damping.fill(0.05);
        }
        let mut grid = None;
        for round in 0..2 {
            if round == 1 {
                // Change some springs: the grid's copies follow.
                for i in (0..m).step_by(7) {
                    rest_length[i] *= 1.1;
                    stiffness[i] += 1.0;
                }
            }
            let springs = Slice {
                ends,
                stiffness: &stiffness,
                damping: &damping,
                rest_length: &rest_length,
                shared: (shared && round == 0).then_some((150.0, 0.05)),
            };
            let g: &mut Grid = grid.get_or_insert_with(|| Grid::find(springs, n).expect("a mesh"));
            if round == 1 {
                for i in (0..m).step_by(7) {
                    g.set(springs, i);
                }
            }
            let mut want = start.clone();
            super::super::kernel::plain(springs, &pos, &vel, &mut want);
            for threads in [1, 2, 3, 7] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut got = vec![DVec3::ZERO; n];
                let seen = std::sync::Mutex::new(vec![0u32; n]);
                let start = |r: Range<usize>, f: &mut [DVec3]| f.copy_from_slice(&start[r]);
                let then = |first: usize, f: &[DVec3], _: [&mut [DVec3]; 2]| {
                    let mut seen = seen.lock().unwrap();
                    for (i, f) in f.iter().enumerate() {
                        seen[first + i] += 1;
                        assert_eq!(
                            f.to_array().map(f64::to_bits),
                            want[first + i].to_array().map(f64::to_bits)
                        );
                    }
                };
                pool.install(|| {
                    g.run(
                        springs,
                        &pos,
                        &vel,
                        &mut got,
                        threads,
                        start,
                        [&mut [], &mut []],
                        then,
                        |_, _| (),
                    )
                });
                assert!(
                    seen.into_inner().unwrap().iter().all(|&s| s == 1),
                    "{threads} threads"
                );
                for (p, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert_eq!(
                        g.to_array().map(f64::to_bits),
                        w.to_array().map(f64::to_bits),
                        "particle {p}, {threads} threads, round {round}: {g} against {w}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_mesh_adds_the_same_bits_as_its_springs_in_list_order() {
        // One chunk; two and three runs of whole chunks, cut mid-row on
        // two and more threads (1,320 and 2,100 particles).
        for (rows, cols) in [(12, 10), (40, 33), (3, 700)] {
            let ends = cloth(rows, cols);
            for shared in [true, false] {
                same_as_the_list(&ends, rows * cols, cols, shared, 7 + rows as u64);
            }
            // Springs missing inside the mesh too.
            let holes: Vec<[u32; 2]> = ends
                .iter()
                .enumerate()
                .filter(|(i, _)| i % 11 != 5)
                .map(|(_, e)| *e)
                .collect();
            same_as_the_list(&holes, rows * cols, cols, true, 3);
        }
        let chain: Vec<[u32; 2]> = (0..2999).map(|p| [p, p + 1]).collect();
        same_as_the_list(&chain, 3000, 3000, false, 11);
    }

    #[test]
    fn a_cloth_is_four_families_and_a_chain_one() {
        let g = find(&cloth(12, 10), 120).expect("a mesh");
        assert_eq!(g.offsets, [1, 10, 11, 9]);
        assert_eq!(g.down, [2, 1, 3, 0]);
        let chain: Vec<[u32; 2]> = (0..299).map(|p| [p, p + 1]).collect();
        let g = find(&chain, 300).expect("a mesh");
        assert_eq!(g.offsets, [1]);
        // Every particle but the ends has both springs.
        assert_eq!(g.lacking, [0, 299]);
    }

    #[test]
    fn lists_that_are_no_mesh_are_refused() {
        let mut e = cloth(12, 10);
        // A particle's springs out of the families' order.
        let mut swapped = e.clone();
        swapped.swap(20, 21);
        assert!(find(&swapped, 120).is_none());
        // A spring to an earlier particle.
        e.push([119, 3]);
        assert!(find(&e, 120).is_none());
        // Particles out of order.
        let chain: Vec<[u32; 2]> = (0..299).rev().map(|p| [p, p + 1]).collect();
        assert!(find(&chain, 300).is_none());
        // Too few springs to be worth it.
        let short: Vec<[u32; 2]> = (0..99).map(|p| [p, p + 1]).collect();
        assert!(find(&short, 100).is_none());
        // Too few springs for the families' places.
        let sparse: Vec<[u32; 2]> = (0..300).map(|p| [p * 10, p * 10 + 1]).collect();
        assert!(find(&sparse, 3001).is_none());
        // Too many offsets.
        let wide: Vec<[u32; 2]> = (0..100u32)
            .flat_map(|p| (1..=9).map(move |o| [p, p + o]))
            .collect();
        assert!(find(&wide, 109).is_none());
    }
}
