//! Stepping a world: the trial step, its events (checked whole, piece by
//! piece on many threads, or settled by the threads that wrote each
//! piece), backtracking in shorter pieces when an event was missed, and the
//! clock. How a world's events meet its threads is one [`Pieces`] mode; how
//! the last trial was checked, one [`Checked`].

use super::{StepReport, World};
use crate::error::SimError;
use crate::event::{DiscreteEvent, EventContext, EventState, TrialPiece};
use crate::integrators::{flat, integrate_then, Dynamics, IntegratorKind, Settled, Written, SMALL};
use crate::particle::{ParticleId, Properties, State};
use crate::simd::{chosen, Use};
use glam::DVec3;

/// How many times a step may be halved when an event is missed: pieces are
/// never shorter than `dt / 2^10`.
pub const MAX_BACKTRACK_DEPTH: u32 = 10;

/// A large world on many threads checks its events piece by piece when it
/// has at most this many (each event's answers take three bits of a `u128`).
const PIECE_EVENTS: usize = 42;
/// Those bits: some piece occurring, some piece missed, no answer by pieces.
const OCCURRING: u128 = 1;
const MISSED: u128 = 2;
const UNANSWERED: u128 = 4;

/// How a world's events meet its threads, learned as it runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Pieces {
    /// Every event settles pieces ([`crate::ByPieces::settles_pieces`];
    /// so does a world without events): the threads that integrate a trial
    /// check and handle it as they write it.
    Settle,
    /// Events are checked piece by piece on many threads where they can
    /// answer so ([`crate::ByPieces::check_piece`]).
    Check,
    /// An event could not answer by pieces: this world's events are checked
    /// on one thread (until another event is added).
    OneThread,
}

/// How the last trial's events were checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Checked {
    /// On one thread, whole (or not at all).
    Whole,
    /// Piece by piece, and those occurring can be handled so.
    ByPieces,
    /// Settled piece by piece as the trial was written: its events are
    /// handled and its finiteness known.
    Settled,
}

impl StepReport {
    /// A step taken whole, with `solver_iterations`.
    pub(super) fn whole(solver_iterations: u32) -> StepReport {
        StepReport {
            backtracks: 0,
            pieces: 1,
            unresolved: 0,
            solver_iterations,
        }
    }
}

impl World {
    /// Advances the world by `dt` seconds.
    ///
    /// The integrator takes a trial step; every event then inspects it. If one
    /// was missed, the trial is thrown away and the step is retaken in halves
    /// (recursively, down to `dt / 2^MAX_BACKTRACK_DEPTH`); occurring events
    /// are handled. If any particle ends non-finite the world stays at its
    /// last good state (with its time: after a blow-up inside a backtracked
    /// step, the time of the last piece accepted) and an error names the
    /// particle.
    ///
    /// A world that splits its work over threads, stepped from outside a
    /// rayon pool, runs the whole step on the global pool: each split would
    /// otherwise send its pieces there and wait for them (16–53 µs a split
    /// on a 2-core machine, several splits a step), where a pool's own
    /// thread splits in 0–8 µs (the `outside_pool` example of
    /// `animats-bench` measures both).
    pub fn step(&mut self, dt: f64) -> Result<StepReport, SimError> {
        if self.on_threads() && rayon::current_thread_index().is_none() {
            return self.step_in_pool(dt);
        }
        self.step_here(dt)
    }

    /// Whether [`World::step`], called from this thread, sends the step to
    /// the global rayon pool (a world that splits its work, stepped from
    /// outside a pool): then a loop of many steps is faster run whole by
    /// [`on_pool`], which enters the pool once instead of at every step.
    pub fn steps_on_pool(&self) -> bool {
        self.on_threads() && rayon::current_thread_index().is_none()
    }

    /// [`World::step`] on a thread of the global pool.
    #[cold]
    #[inline(never)]
    fn step_in_pool(&mut self, dt: f64) -> Result<StepReport, SimError> {
        rayon::scope(|_| self.step_here(dt))
    }

    /// Whether a step splits some of its work over the current rayon
    /// pool's threads (the per-particle loops of a large world, many
    /// springs, a large n-body group).
    fn on_threads(&self) -> bool {
        (crate::parallel::piece_len(self.len()).is_some() && !self.one_piece())
            || self.forces.on_threads(self.len())
    }

    /// Whether a large world keeps its per-particle loops (the updates,
    /// gravity) in one piece: when one of its events cannot answer by
    /// pieces (sphere contact), it checks and handles every particle on
    /// one thread every step, much more work than those loops, while the
    /// pool's other threads fall asleep, and waking them for the loops
    /// cost more than the loops save (a pile of 10,000 spheres 3 % slower
    /// on two threads than on one). Springs split over threads keep the
    /// loops split with them, in the same pieces. The results are the same
    /// bits either way.
    fn one_piece(&self) -> bool {
        self.pieces == Pieces::OneThread && !self.forces.springs.on_threads()
    }

    /// [`World::step`] on the calling thread.
    #[inline(always)]
    fn step_here(&mut self, dt: f64) -> Result<StepReport, SimError> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(SimError::BadStep(dt));
        }
        let n = self.len();
        self.next.resize(n);
        self.scratch.resize(n);
        let t0 = self.time;
        if n < SMALL && self.events.is_empty() {
            let finite = self.trial_alone(t0, dt);
            self.accept(EventState::None, finite, t0 + dt)?;
            return Ok(self.end_step(dt, StepReport::whole(self.scratch.implicit.iterations)));
        }
        for e in &mut self.events {
            e.begin_step();
        }
        // The whole step first; pieces only after a missed event.
        let (events, finite) = self.trial(t0, dt, dt, false);
        let report = if events == EventState::Missed {
            self.end_settled(false);
            let first = self.scratch.implicit.iterations;
            let mut r = self.backtrack(t0, dt)?;
            r.solver_iterations += first;
            r
        } else {
            self.accept(events, finite, t0 + dt)?;
            StepReport::whole(self.scratch.implicit.iterations)
        };
        Ok(self.end_step(dt, report))
    }

    /// Advances the clock past a step that ended with `report`, and counts it.
    #[inline(always)]
    fn end_step(&mut self, dt: f64, report: StepReport) -> StepReport {
        self.advance_clock(dt);
        self.stats.steps += 1;
        self.stats.backtracks += report.backtracks as u64;
        self.stats.unresolved += report.unresolved as u64;
        self.last = report;
        report
    }

    /// [`World::trial`] for a small world without events: nothing to
    /// check, handle or backtrack, so the trial is integrated with none of
    /// the closures and passes that serve events and pieces (they cost a
    /// third of a five-body step whose force does nothing: the `step_floor`
    /// example of `animats-bench`), then kept or refused by `accept`. The
    /// same bits as the general path. Returns whether the integrator knows
    /// the trial to be finite.
    #[inline(always)]
    fn trial_alone(&mut self, t0: f64, dt: f64) -> bool {
        self.scratch.implicit.iterations = 0;
        self.forces.one_piece = self.one_piece();
        self.checked = Checked::Whole;
        let mut dynamics = Dynamics {
            forces: &mut self.forces,
            particles: &self.particles,
            scratch: &mut self.scratch,
            solver: self.solver,
        };
        let (from, to) = (&self.state, &mut self.next);
        match self.integrator {
            // The commonest, inlined whole.
            IntegratorKind::Symplectic => {
                crate::integrators::symplectic::step_small(&mut dynamics, t0, dt, from, to)
            }
            kind => integrate_then(kind, &mut dynamics, t0, dt, from, to, None).finite(),
        }
    }

    /// Integrates from the current state over `[t, t + h]` (part of a step
    /// of `step`) into the trial buffer and asks every event about the
    /// result; returns the worst state, and whether the integrator knows
    /// the trial to be finite. `finest`: the trial cannot be split further.
    ///
    /// When every event settles pieces (and there is one, or the world is
    /// not tiny), each piece of the trial is checked, handled and scanned
    /// for finiteness by the thread that has just written it, inside the
    /// integrator's last loop (those of symplectic Euler and RK4): no pass
    /// of its own, and on many threads no fork and join of its own.
    #[inline(always)]
    fn trial(&mut self, t: f64, h: f64, step: f64, finest: bool) -> (EventState, bool) {
        self.scratch.implicit.iterations = 0;
        self.forces.one_piece = self.one_piece();
        self.checked = Checked::Whole;
        let gravity = self.forces.gravity.as_ref().map_or(DVec3::ZERO, |g| g.g);
        let mut dynamics = Dynamics {
            forces: &mut self.forces,
            particles: &self.particles,
            scratch: &mut self.scratch,
            solver: self.solver,
        };
        let settle = self.pieces == Pieces::Settle
            && (!self.events.is_empty() || self.state.pos.len() >= SMALL);
        let (events, particles, from) = (&self.events, &self.particles, &self.state);
        let flight_shift = self.integrator.free_flight_shift();
        let finish = |first: usize, pos: &mut [DVec3], vel: &mut [DVec3]| {
            let r = first..first + pos.len();
            let mut piece = TrialPiece {
                t: t + h,
                h,
                step,
                flight_shift,
                finest,
                first,
                pos,
                vel,
                start_pos: &from.pos[r.clone()],
                start_vel: &from.vel[r],
                particles,
                gravity,
            };
            let mut worst = EventState::None;
            for e in events {
                if let Some(b) = e.by_pieces() {
                    worst = worst.max(b.settle_piece(&mut piece));
                }
            }
            Settled {
                finite: all_finite(piece.pos, piece.vel),
                worst,
            }
        };
        let written = integrate_then(
            self.integrator,
            &mut dynamics,
            t,
            h,
            from,
            &mut self.next,
            settle.then_some(&finish),
        );
        let mut finite = match written {
            Written::Settled(s) => {
                self.checked = Checked::Settled;
                return (s.worst, s.finite);
            }
            Written::Known(finite) => finite,
        };
        let large = crate::parallel::piece_len(self.len()).is_some()
            && self.events.len() <= PIECE_EVENTS
            && self.pieces != Pieces::OneThread;
        if self.events.is_empty() && !large {
            return (EventState::None, finite);
        }
        let ctx = EventContext {
            t: t + h,
            h,
            step,
            flight_shift: self.integrator.free_flight_shift(),
            pos: &self.next.pos,
            vel: &self.next.vel,
            start_pos: &self.state.pos,
            start_vel: &self.state.vel,
            particles: &self.particles,
            gravity: self.forces.gravity.as_ref().map_or(DVec3::ZERO, |g| g.g),
        };
        if large {
            let answer;
            (finite, answer) = check_by_pieces(&self.events, &mut self.event_states, &ctx, finite);
            match answer {
                Answer::Checked(worst) => {
                    self.checked = Checked::ByPieces;
                    return (worst, finite);
                }
                Answer::Check => {}
                // (Sphere contact, say: asking again would only cost a
                // fork-join every step.)
                Answer::Unanswered => self.pieces = Pieces::OneThread,
            }
        }
        let mut worst = EventState::None;
        for (e, s) in self.events.iter_mut().zip(&mut self.event_states) {
            *s = e.check(&ctx);
            worst = worst.max(*s);
        }
        (worst, finite)
    }

    /// Handles the events of the trial ending at `t`, checks it is finite and
    /// makes it the current state. `finite`: the integrator knows it wrote
    /// only finite numbers (then the state is read again only if an event
    /// changed it).
    #[inline]
    fn accept(&mut self, worst: EventState, finite: bool, t: f64) -> Result<(), SimError> {
        let mut known = finite;
        if self.checked == Checked::Settled {
            // Handled, and scanned after handling, piece by piece.
        } else if worst != EventState::None && self.checked == Checked::ByPieces {
            known = handle_by_pieces(
                &self.events,
                &self.event_states,
                t,
                &mut self.next,
                &self.particles,
            );
        } else if worst != EventState::None {
            for (e, s) in self.events.iter_mut().zip(&self.event_states) {
                if *s != EventState::None {
                    e.handle(t, &mut self.next.pos, &mut self.next.vel, &self.particles);
                }
            }
            known = false;
        }
        let bad = if known {
            None
        } else {
            first_non_finite(&self.next, &self.particles.fixed)
        };
        self.end_settled(bad.is_none());
        if let Some(i) = bad {
            // The world stays at its last finite state.
            return Err(SimError::NonFinite {
                particle: ParticleId(i as u32),
                time: t,
            });
        }
        swap_states(&mut self.state, &mut self.next);
        Ok(())
    }

    /// Tells the events whether the world keeps the trial they have just
    /// settled by pieces (see [`crate::ByPieces::settled`]); nothing for a
    /// trial checked otherwise.
    #[inline]
    fn end_settled(&mut self, kept: bool) {
        if self.checked == Checked::Settled {
            for e in &mut self.events {
                if let Some(b) = e.by_pieces_mut() {
                    b.settled(kept);
                }
            }
        }
    }

    /// Takes the step `[t0, t0 + dt]` in pieces: halve a piece whenever an
    /// event is missed in it, and grow the pieces back once they line up.
    #[cold]
    fn backtrack(&mut self, t0: f64, dt: f64) -> Result<StepReport, SimError> {
        let total = 1u32 << MAX_BACKTRACK_DEPTH;
        let (mut done, mut piece) = (0u32, total / 2);
        let mut report = StepReport {
            backtracks: 1,
            ..StepReport::default()
        };
        while done < total {
            let t = t0 + dt * (done as f64 / total as f64);
            let h = dt * (piece as f64 / total as f64);
            let (mut worst, finite) = self.trial(t, h, dt, piece == 1);
            report.solver_iterations += self.scratch.implicit.iterations;
            if worst == EventState::Missed {
                if piece > 1 {
                    self.end_settled(false);
                    piece /= 2;
                    report.backtracks += 1;
                    continue;
                }
                // Cannot split further: handle it as if occurring.
                report.unresolved += 1;
                worst = EventState::Occurring;
            }
            if let Err(e) = self.accept(worst, finite, t + h) {
                // The pieces already accepted moved the state: move the
                // clock with them, so time and state still agree.
                self.advance_clock(dt * (done as f64 / total as f64));
                self.last = report;
                return Err(e);
            }
            done += piece;
            report.pieces += 1;
            if piece < total && done % (2 * piece) == 0 {
                piece *= 2;
            }
        }
        Ok(report)
    }

    /// Kahan-compensated `time += dt`, so a million steps of 1 ms end at 1000 s.
    fn advance_clock(&mut self, dt: f64) {
        let y = dt - self.time_carry;
        let t = self.time + y;
        self.time_carry = (t - self.time) - y;
        self.time = t;
    }

    /// Sets the simulated time (and forgets the clock's rounding carry).
    pub fn set_time(&mut self, t: f64) {
        self.time = t;
        self.time_carry = 0.0;
    }
}

/// A large world on many threads checks its trial piece by piece, each
/// thread the piece it has just written, still in its cache: one thread
/// reading every particle (as `check` and the serial finiteness scan do)
/// would pull half the world across cores, and the other thread would then
/// have to take those lines back to write the next step. Returns whether
/// the trial is finite (`finite`: already known to be) and what the events
/// said.
#[inline(never)]
fn check_by_pieces(
    events: &[Box<dyn DiscreteEvent>],
    states: &mut [EventState],
    ctx: &EventContext,
    finite: bool,
) -> (bool, Answer) {
    let (finite, flags) = crate::parallel::map_pieces(
        ctx.pos.len(),
        |r| {
            let mut flags = 0u128;
            for (k, e) in events.iter().enumerate() {
                let code = match e.by_pieces().and_then(|b| b.check_piece(ctx, r.clone())) {
                    Some(EventState::None) => 0,
                    Some(EventState::Occurring) => OCCURRING,
                    Some(EventState::Missed) => MISSED,
                    None => UNANSWERED,
                };
                flags |= code << (3 * k);
            }
            (
                finite || all_finite(&ctx.pos[r.clone()], &ctx.vel[r]),
                flags,
            )
        },
        |a, b| (a.0 & b.0, a.1 | b.1),
    );
    if (0..events.len()).any(|k| flags >> (3 * k) & UNANSWERED != 0) {
        return (finite, Answer::Unanswered);
    }
    let (mut worst, mut by_pieces) = (EventState::None, true);
    for (k, (e, s)) in events.iter().zip(states.iter_mut()).enumerate() {
        let f = flags >> (3 * k);
        *s = if f & MISSED != 0 {
            EventState::Missed
        } else if f & OCCURRING != 0 {
            EventState::Occurring
        } else {
            EventState::None
        };
        worst = worst.max(*s);
        by_pieces &= *s == EventState::None || e.by_pieces().is_some_and(|b| b.handles_pieces());
    }
    // An event handled on one thread needs the records of its `check`.
    if worst == EventState::None || by_pieces {
        (finite, Answer::Checked(worst))
    } else {
        (finite, Answer::Check)
    }
}

/// What [`check_by_pieces`] found.
enum Answer {
    /// Every event answered, and those occurring can be handled by pieces:
    /// the worst state (each event's is set).
    Checked(EventState),
    /// Every event answered, but one occurring must be checked and handled
    /// on one thread.
    Check,
    /// Some event cannot answer by pieces.
    Unanswered,
}

/// Handles the events of a trial that [`check_by_pieces`] found occurring,
/// each thread the piece it checked, and looks at it again: true if it is
/// then finite.
#[inline(never)]
fn handle_by_pieces(
    events: &[Box<dyn DiscreteEvent>],
    states: &[EventState],
    t: f64,
    next: &mut State,
    particles: &Properties,
) -> bool {
    crate::parallel::all_by_pieces(true, [&mut next.pos, &mut next.vel], |first, [pos, vel]| {
        for (e, s) in events.iter().zip(states) {
            if let (true, Some(b)) = (*s != EventState::None, e.by_pieces()) {
                b.handle_piece(t, first, pos, vel, particles);
            }
        }
        all_finite(pos, vel)
    })
}

/// The index of the first particle with a non-finite position or velocity,
/// preferring a moving one: a nail next to an overflowing spring goes NaN
/// only because 0 × ∞ is NaN, and is not the one to blame.
fn first_non_finite(s: &State, fixed: &[bool]) -> Option<usize> {
    let n = s.pos.len().min(s.vel.len());
    let (pos, vel) = (&s.pos[..n], &s.vel[..n]);
    if all_finite(pos, vel) {
        return None;
    }
    let bad = |i: &usize| !(pos[*i].is_finite() && vel[*i].is_finite());
    (0..n)
        .filter(|&i| !fixed[i])
        .find(bad)
        .or_else(|| (0..n).find(bad))
}

/// `std::mem::swap(a, b)`, out of line: inline, where the two states lie
/// side by side in the world, LLVM swapped them through overlapping
/// vector moves, storing part of one and at once loading it back wider, a
/// load that waited for the store (`perf annotate`: four fifths of
/// `accept`'s time, 4 % of a swimming body's run).
#[inline(never)]
fn swap_states(a: &mut State, b: &mut State) {
    std::mem::swap(a, b);
}

/// True if every coordinate of `pos` and `vel` (as long as each other) is
/// finite.
fn all_finite(pos: &[DVec3], vel: &[DVec3]) -> bool {
    let n = pos.len().min(vel.len());
    let (pos, vel) = (&pos[..n], &vel[..n]);
    // A sum of finite numbers is finite (unless it overflows, which the
    // confirming scan at the end tells apart) and any inf or NaN makes it
    // non-finite. In a large world sixteen independent lanes over the flat
    // coordinates, in the vectors chosen for updates (`simd.rs`), keep the
    // pass short next to the force loops.
    let (p, v) = (flat(pos), flat(vel));
    // A small world (the creatures of evolution: a few dozen coordinates)
    // in four lanes, and their sum checked once: no call through the
    // instruction-set choice, no sixteen lanes to test one by one. (A lane
    // that is not finite makes the sum not finite: ±∞ stays, ∞ − ∞ and
    // NaN are NaN; a sum that overflows is looked at below.)
    if p.len() < 64 {
        let acc = lane_sums::<4>(p, v);
        if ((acc[0] + acc[1]) + (acc[2] + acc[3])).is_finite() {
            return true;
        }
    } else if chosen(
        Use::Updates,
        #[inline(always)]
        || lane_sums::<16>(p, v).iter().all(|a| a.is_finite()),
    ) {
        return true;
    }
    // A sum may overflow with every term finite: look at each.
    pos.iter()
        .zip(vel)
        .all(|(p, v)| p.is_finite() && v.is_finite())
}

/// `p[i] + v[i]` summed in `L` independent lanes (lane `k` takes every
/// `L`-th coordinate from `k`).
#[inline(always)]
fn lane_sums<const L: usize>(p: &[f64], v: &[f64]) -> [f64; L] {
    let mut acc = [0.0f64; L];
    let (pc, vc) = (p.chunks_exact(L), v.chunks_exact(L));
    let (pr, vr) = (pc.remainder(), vc.remainder());
    for (p, v) in pc.zip(vc) {
        for k in 0..L {
            acc[k] += p[k] + v[k];
        }
    }
    // The rest summed apart, one by one, then into lane 0 (any order
    // tells finite from not): added into the lanes themselves, LLVM
    // vectorised the rest with masked stores to the lanes' stack copy
    // and the loads after them waited for the stores (`perf`: the scan
    // 9.9 % of a land-task run's samples, 1.3 % this way).
    let mut rest = 0.0;
    for (p, v) in pr.iter().zip(vr) {
        rest += p + v;
    }
    acc[0] += rest;
    acc
}

#[cfg(test)]
mod tests {
    use super::{all_finite, first_non_finite};
    use crate::particle::State;
    use glam::DVec3;

    /// The scan finds one bad coordinate wherever it is (inside the
    /// vectors or in the remainder; a small world's four lanes up to 21
    /// particles, the wide lanes from 22), and is not fooled by finite
    /// numbers whose sum overflows.
    #[test]
    fn the_finiteness_scan_finds_every_bad_coordinate() {
        for n in [1, 5, 16, 21, 22, 37] {
            let pos: Vec<DVec3> = (0..n).map(|i| DVec3::splat(i as f64 - 3.5)).collect();
            let vel: Vec<DVec3> = (0..n).map(|i| DVec3::splat(0.25 * i as f64)).collect();
            assert!(all_finite(&pos, &vel));
            let huge = vec![DVec3::splat(f64::MAX); n];
            assert!(
                all_finite(&huge, &huge),
                "{n}: finite, though the sums overflow"
            );
            for i in 0..n {
                for k in 0..3 {
                    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                        for in_pos in [true, false] {
                            let (mut p, mut v) = (pos.clone(), vel.clone());
                            let x = if in_pos { &mut p[i] } else { &mut v[i] };
                            x[k] = bad;
                            assert!(!all_finite(&p, &v), "{n} particles, {i}.{k} = {bad}");
                            let s = State { pos: p, vel: v };
                            assert_eq!(first_non_finite(&s, &vec![false; n]), Some(i));
                        }
                    }
                }
            }
        }
    }
}
