//! Sleeping (opt-in, `sleep_speed` > 0): which spheres sleep, when they
//! fall asleep and what wakes them (see the module above), and the sleep as
//! a snapshot holds it.

use super::SphereContact;
use crate::error::ModelError;
use crate::event::EventContext;
use crate::particle::{ParticleId, Properties};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The spheres' sleep as a [`Snapshot`](crate::Snapshot) holds it: what
/// sphere contact remembers from step to step to put spheres to sleep and
/// wake them, so that a restored world goes on as the original did. Read
/// it only through the snapshot; a value that is not yet a number (before
/// a sphere's first trial) is `None`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SleepState {
    last: Vec<[f64; 3]>,
    t_last: Option<f64>,
    origin: Vec<[f64; 3]>,
    still: Vec<f64>,
    moving: Vec<bool>,
    accel: Vec<Option<[f64; 3]>>,
    driven: Vec<bool>,
    asleep: Vec<bool>,
    anchor: Vec<[f64; 3]>,
}

/// `x` as an array, `None` if not a number.
fn known(x: DVec3) -> Option<[f64; 3]> {
    (!x.is_nan()).then(|| x.to_array())
}

impl SleepState {
    /// Checks it against a world of `n` particles; an error names `sleep`
    /// and the list that does not fit.
    pub(crate) fn check(&self, n: usize) -> Result<(), ModelError> {
        let lengths = [
            ("last", self.last.len()),
            ("origin", self.origin.len()),
            ("still", self.still.len()),
            ("moving", self.moving.len()),
            ("accel", self.accel.len()),
            ("driven", self.driven.len()),
            ("asleep", self.asleep.len()),
            ("anchor", self.anchor.len()),
        ];
        for (field, len) in lengths {
            if len != n {
                return Err(ModelError::new(
                    "sleep",
                    format!("{field} has {len} spheres, this world {n}: the snapshot is of another world"),
                ));
            }
        }
        let vectors = [&self.last, &self.origin, &self.anchor];
        let finite = vectors
            .iter()
            .all(|v| v.as_flattened().iter().all(|x| x.is_finite()))
            && self.still.iter().all(|x| x.is_finite() && *x >= 0.0)
            && self.t_last.is_none_or(f64::is_finite)
            && self.accel.iter().flatten().flatten().all(|x| x.is_finite());
        if !finite {
            return Err(ModelError::new("sleep", "holds a value that is not finite"));
        }
        Ok(())
    }
}

/// The spheres' sleep: see [`SphereContact`].
#[derive(Clone, Debug, Default)]
pub(super) struct Sleep {
    /// Each sphere's position at the start of the last step.
    last: Vec<DVec3>,
    /// When the last step started, s (NaN before the first).
    t_last: f64,
    /// Where each sphere's stillness began.
    origin: Vec<DVec3>,
    /// How long it has stayed within `sleep_speed · sleep_time` of there, s.
    still: Vec<f64>,
    /// Whether it is moving: faster than `sleep_speed` in the last step,
    /// and not for long within one place (a sphere that merely trembles
    /// there is not).
    moving: Vec<bool>,
    /// The acceleration its forces gave it: awake, in the last step's
    /// trial; asleep, in its first trial from rest (NaN until there is
    /// one). A different one means the forces on it changed.
    accel: Vec<DVec3>,
    /// Whether that changed since the step before: something drives it
    /// (a muscle, a hand on a force), and it wakes the sleepers it
    /// touches, however slowly it moves.
    driven: Vec<bool>,
    /// Whether it sleeps.
    pub(super) asleep: Vec<bool>,
    /// Where it fell asleep, and where it stays while asleep.
    pub(super) anchor: Vec<DVec3>,
    /// Whether it is in a contact (scratch, for each check).
    touched: Vec<bool>,
    /// Whether something disturbs it (scratch, for each check).
    wake: Vec<bool>,
    /// How many sleep.
    pub(super) count: usize,
    /// The next check is a step's first.
    pub(super) fresh: bool,
}

impl Sleep {
    /// Every one of `n` spheres awake, starting from `at`.
    fn awake(at: &[DVec3]) -> Sleep {
        let n = at.len();
        Sleep {
            last: at.to_vec(),
            t_last: f64::NAN,
            origin: at.to_vec(),
            still: vec![0.0; n],
            moving: vec![false; n],
            accel: vec![DVec3::NAN; n],
            driven: vec![false; n],
            asleep: vec![false; n],
            anchor: vec![DVec3::ZERO; n],
            touched: vec![false; n],
            wake: vec![false; n],
            count: 0,
            fresh: true,
        }
    }

    /// Wakes sphere `i` if it sleeps.
    pub(super) fn wake(&mut self, i: usize) {
        if self.asleep[i] {
            self.asleep[i] = false;
            self.still[i] = 0.0;
            self.origin[i] = self.anchor[i];
            self.count -= 1;
        }
    }
}

/// Whether acceleration `a` differs from `b`: steady forces give the same
/// acceleration to the bit, step after step; the margin only forgives
/// rounding.
fn changed(a: DVec3, b: DVec3) -> bool {
    (a - b).length() > 1e-9 * b.length()
}

fn movable(p: &Properties, i: usize) -> bool {
    p.inv_mass[i] != 0.0 && p.radius[i] > 0.0
}

impl SphereContact {
    /// How many spheres sleep.
    pub fn sleeping(&self) -> usize {
        self.sleep.count
    }

    /// Whether sphere `i` sleeps.
    pub fn is_asleep(&self, i: ParticleId) -> bool {
        self.sleep
            .asleep
            .get(i.0 as usize)
            .copied()
            .unwrap_or(false)
    }

    /// The sleep, for a snapshot: `None` when spheres do not sleep or
    /// before the first step.
    pub(crate) fn sleep_state(&self) -> Option<SleepState> {
        let s = &self.sleep;
        if self.def.sleep_speed <= 0.0 || s.last.is_empty() {
            return None;
        }
        let arrays = |v: &[DVec3]| v.iter().map(|x| x.to_array()).collect();
        Some(SleepState {
            last: arrays(&s.last),
            t_last: (!s.t_last.is_nan()).then_some(s.t_last),
            origin: arrays(&s.origin),
            still: s.still.clone(),
            moving: s.moving.clone(),
            accel: s.accel.iter().map(|&a| known(a)).collect(),
            driven: s.driven.clone(),
            asleep: s.asleep.clone(),
            anchor: arrays(&s.anchor),
        })
    }

    /// Takes the sleep of a snapshot ([`SleepState::check`]ed); `None`:
    /// every sphere awake, as before the first step.
    pub(crate) fn restore_sleep(&mut self, state: Option<&SleepState>) {
        let Some(st) = state else {
            self.sleep = Sleep::default();
            return;
        };
        let vectors = |v: &[[f64; 3]]| v.iter().map(|&x| DVec3::from_array(x)).collect();
        let n = st.asleep.len();
        self.sleep = Sleep {
            last: vectors(&st.last),
            t_last: st.t_last.unwrap_or(f64::NAN),
            origin: vectors(&st.origin),
            still: st.still.clone(),
            moving: st.moving.clone(),
            accel: st
                .accel
                .iter()
                .map(|a| a.map_or(DVec3::NAN, DVec3::from_array))
                .collect(),
            driven: st.driven.clone(),
            asleep: st.asleep.clone(),
            anchor: vectors(&st.anchor),
            touched: vec![false; n],
            wake: vec![false; n],
            count: st.asleep.iter().filter(|&&a| a).count(),
            fresh: false,
        };
    }

    /// Sleeping and waking, sphere by sphere: at a step's first check,
    /// times each sphere's stillness over the step before and puts to
    /// sleep each sphere in contact that has been still for `sleep_time`;
    /// at every check, wakes each sleeper that something disturbs: a
    /// moving neighbour, a change of the forces on it, a hand (its position
    /// or velocity set from outside), or the loss of every contact.
    pub(super) fn sleep_or_wake(&mut self, ctx: &EventContext) {
        let x0 = ctx.start_pos;
        let n = x0.len().min(ctx.pos.len());
        let s = &mut self.sleep;
        // New spheres, or the clock set back by hand (`World::set_time`;
        // a restored snapshot brings its own sleep): every sphere starts
        // awake.
        if s.last.len() != n || (s.fresh && ctx.t - ctx.h < s.t_last) {
            *s = Sleep::awake(&x0[..n]);
        }
        s.touched.iter_mut().for_each(|t| *t = false);
        for q in &self.pairs {
            s.touched[q.a as usize] = true;
            s.touched[q.b as usize] = true;
        }
        // `wake`: the sleepers disturbed.
        s.wake.iter_mut().for_each(|w| *w = false);
        if std::mem::take(&mut s.fresh) {
            self.time_stillness(ctx, n);
        }
        if self.sleep.count > 0 {
            self.wake_the_disturbed(ctx, n);
        }
    }

    /// At a step's first check: how long each sphere has been still, which
    /// are moving or driven, and which fall asleep; a sleeper moved by hand
    /// is marked to wake.
    fn time_stillness(&mut self, ctx: &EventContext, n: usize) {
        let (speed, time, p) = (self.def.sleep_speed, self.def.sleep_time, ctx.particles);
        let envelope = self.def.envelope;
        let (x0, v0) = (ctx.start_pos, ctx.start_vel);
        let s = &mut self.sleep;
        let dt = if s.t_last.is_nan() {
            0.0
        } else {
            ctx.t - ctx.h - s.t_last
        };
        s.t_last = ctx.t - ctx.h;
        // Stillness is judged over `sleep_time`, not step by step: a
        // resting sphere trembles by about a step's sag under gravity
        // (g h², as far as `sleep_speed` goes in a step at the defaults),
        // but goes nowhere.
        let reach = speed * time;
        self.def.targets.for_each(n, |i| {
            if !movable(p, i) {
                return;
            }
            if s.asleep[i] {
                // Moved by hand?
                s.wake[i] = x0[i] != s.anchor[i] || v0[i] != DVec3::ZERO;
            } else {
                let a = (ctx.vel[i] - v0[i]) / ctx.h;
                let before = std::mem::replace(&mut s.accel[i], a);
                s.driven[i] = !before.is_nan() && changed(a, before);
                if s.driven[i] {
                    s.still[i] = 0.0;
                    s.origin[i] = x0[i];
                } else if (x0[i] - s.origin[i]).length() <= reach {
                    s.still[i] += dt;
                } else {
                    s.still[i] = 0.0;
                    s.origin[i] = x0[i];
                }
                s.moving[i] = (x0[i] - s.last[i]).length() > speed * dt && s.still[i] < 0.5 * time;
                // Still for a step at least (so not at once when
                // `sleep_time` is 0), and not so fast in the trial that
                // holding it back where it was could leave an overlap
                // deeper than the envelope (a backtrack at every step).
                let calm = (ctx.pos[i] - x0[i]).length() <= 0.25 * envelope;
                if s.still[i] >= time && s.still[i] > 0.0 && calm && s.touched[i] {
                    s.asleep[i] = true;
                    s.anchor[i] = x0[i];
                    s.accel[i] = DVec3::NAN;
                    s.count += 1;
                }
            }
            s.last[i] = x0[i];
        });
    }

    /// Wakes each sleeper that a moving or driven neighbour touches, whose
    /// forces changed, or that lost every contact (one that strikes it
    /// wakes it in the handling).
    fn wake_the_disturbed(&mut self, ctx: &EventContext, n: usize) {
        let (p, v0) = (ctx.particles, ctx.start_vel);
        let s = &mut self.sleep;
        for q in &self.pairs {
            let (a, b) = (q.a as usize, q.b as usize);
            if s.asleep[a] != s.asleep[b] {
                let (sleeper, other) = if s.asleep[a] { (a, b) } else { (b, a) };
                s.wake[sleeper] |= (s.moving[other] || s.driven[other]) && movable(p, other);
            }
        }
        let sleepers = (s.asleep.iter().zip(&s.touched))
            .zip(s.accel.iter_mut().zip(s.wake.iter_mut()))
            .zip(ctx.vel.iter().zip(v0));
        for (((&asleep, &touched), (first, wake)), (v1, v0)) in sleepers {
            if !asleep {
                continue;
            }
            // Its forces over a trial from rest: the same while nothing
            // around it changes. (The first is taken from rest, not from
            // the step it fell asleep in.)
            let a = (*v1 - *v0) / ctx.h;
            if !touched {
                *wake = true;
            } else if first.is_nan() {
                if *v0 == DVec3::ZERO {
                    *first = a;
                }
            } else if changed(a, *first) {
                *wake = true;
            }
        }
        for i in 0..n {
            if s.wake[i] {
                s.wake(i);
            }
        }
    }
}
