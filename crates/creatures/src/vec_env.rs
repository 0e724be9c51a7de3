//! Many copies of an environment stepped in one call, for training on
//! thousands of them: actions and observations as one flat row-major array
//! (copy by copy), the copies stepped in parallel on the current rayon pool
//! when there are enough of them to pay for waking a thread.
//!
//! A copy whose episode ended is reset on the next call to [`VecEnv::step`]
//! (its action ignored, reward 0, neither terminated nor truncated), as
//! Gymnasium's vector environments do by default ("next step" autoreset).
//! Copy `k` is reset with seed `seed + k` at first, then with the next seed
//! of its own stream, so a run is the same bits whatever the thread count.

use crate::env::{Env, Transition};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// What a step or reset stopped by its flag returns.
pub const INTERRUPTED: &str = "interrupted";

/// Copies stepped per rayon task: below this, threads cost more than they
/// save (a roobot step is about a microsecond, waking a thread 100 µs).
const CHUNK: usize = 64;

struct Copy<E> {
    /// Boxed: an environment may be kilobytes (a scene's is 5.7 kB), and
    /// a million of them moved through a parallel collect, or a slot of
    /// that size written for each copy not made after a Ctrl-C, took
    /// seconds.
    env: Box<E>,
    done: bool,
    seed: u64,
}

/// `N` copies of an environment.
pub struct VecEnv<E: Env> {
    copies: Vec<Copy<E>>,
    obs: usize,
    act: usize,
}

impl<E: Env> VecEnv<E> {
    /// Copies made by `make` (called `n` times, with the copy's index, in
    /// parallel on the current rayon pool from `2 × CHUNK` copies), each
    /// reset with seed `seed + k`. The first error `make` returns, in copy
    /// order, is returned.
    pub fn new(
        n: usize,
        seed: u64,
        make: impl Fn(usize) -> Result<E, String> + Sync,
    ) -> Result<VecEnv<E>, String> {
        if n == 0 {
            return Err("a vector environment needs at least one copy".into());
        }
        let one = |k| {
            make(k).map(|env| Copy {
                env: Box::new(env),
                done: false,
                seed: 0,
            })
        };
        let copies: Vec<Copy<E>> = if n >= 2 * CHUNK {
            // (Every copy made, then the first error in copy order: the
            // same error whatever the thread count.)
            let made: Vec<Result<Copy<E>, String>> = (0..n)
                .into_par_iter()
                .with_min_len(CHUNK)
                .map(one)
                .collect();
            made.into_iter().collect::<Result<_, _>>()?
        } else {
            (0..n).map(one).collect::<Result<_, _>>()?
        };
        let obs = copies[0].env.observation_size();
        let act = copies[0].env.action_size();
        if act == 0 {
            return Err("the environment has no actions".into());
        }
        let mut v = VecEnv { copies, obs, act };
        v.reset(seed)?;
        Ok(v)
    }

    /// Copies.
    pub fn len(&self) -> usize {
        self.copies.len()
    }

    /// Never true: a vector environment has at least one copy.
    pub fn is_empty(&self) -> bool {
        self.copies.is_empty()
    }

    /// Observations per copy.
    pub fn observation_size(&self) -> usize {
        self.obs
    }

    /// Actions per copy.
    pub fn action_size(&self) -> usize {
        self.act
    }

    /// The first copy (names, step, time limit).
    pub fn first(&self) -> &E {
        &self.copies[0].env
    }

    /// Copy `k`, if there is one.
    pub fn get(&self, k: usize) -> Option<&E> {
        self.copies.get(k).map(|c| &*c.env)
    }

    /// Resets every copy, copy `k` with seed `seed + k` (in parallel as
    /// [`VecEnv::step`]).
    pub fn reset(&mut self, seed: u64) -> Result<(), String> {
        self.reset_unless(seed, &AtomicBool::new(false))
    }

    /// [`VecEnv::reset`], which copies not yet reset when `stop` is set
    /// refuse with [`INTERRUPTED`]: the copies are then part reset.
    pub fn reset_unless(&mut self, seed: u64, stop: &AtomicBool) -> Result<(), String> {
        let one = |(k, c): (usize, &mut Copy<E>)| {
            if stop.load(Ordering::Relaxed) {
                return Err(INTERRUPTED.to_string());
            }
            c.seed = seed.wrapping_add(k as u64);
            c.env.reset(c.seed)?;
            c.done = false;
            Ok::<(), String>(())
        };
        if self.copies.len() >= 2 * CHUNK {
            self.copies
                .par_iter_mut()
                .enumerate()
                .with_min_len(CHUNK)
                .try_for_each(one)
        } else {
            self.copies.iter_mut().enumerate().try_for_each(one)
        }
    }

    /// Every copy's observation, copy by copy, into `out` (`len ×
    /// observation_size`).
    pub fn observe(&self, out: &mut [f64]) {
        for (c, o) in self.copies.iter().zip(out.chunks_mut(self.obs.max(1))) {
            c.env.observe(o);
        }
    }

    /// Steps every copy with its row of `actions` (`len × action_size`,
    /// row-major) and writes the transitions into `out` (`len` long). A copy
    /// whose episode ended at the previous call is reset instead.
    pub fn step(&mut self, actions: &[f64], out: &mut [Transition]) -> Result<(), String> {
        self.step_unless(actions, out, &AtomicBool::new(false))
    }

    /// [`VecEnv::step`], which copies not yet stepped when `stop` is set
    /// refuse with [`INTERRUPTED`]: the copies are then part stepped.
    pub fn step_unless(
        &mut self,
        actions: &[f64],
        out: &mut [Transition],
        stop: &AtomicBool,
    ) -> Result<(), String> {
        let n = self.copies.len();
        if actions.len() != n * self.act {
            return Err(format!(
                "{} actions given for {n} copies of {} each",
                actions.len(),
                self.act
            ));
        }
        if out.len() != n {
            return Err(format!("{} transitions for {n} copies", out.len()));
        }
        if let Some(i) = actions.iter().position(|a| !a.is_finite()) {
            return Err(format!(
                "the action of copy {} is not finite: {}",
                i / self.act,
                actions[i]
            ));
        }
        let act = self.act;
        let one = |(c, (a, t)): (&mut Copy<E>, (&[f64], &mut Transition))| {
            if stop.load(Ordering::Relaxed) {
                return Err(INTERRUPTED.to_string());
            }
            if c.done {
                // Each copy's own stream of seeds: the same whatever the threads.
                c.seed = c.seed.wrapping_add(n as u64);
                c.env.reset(c.seed)?;
                c.done = false;
                *t = Transition {
                    reward: 0.0,
                    terminated: false,
                    truncated: false,
                };
            } else {
                *t = c.env.step(a)?;
                c.done = t.ends();
            }
            Ok::<(), String>(())
        };
        if n >= 2 * CHUNK {
            self.copies
                .par_iter_mut()
                .zip(actions.par_chunks(act).zip(out.par_iter_mut()))
                .with_min_len(CHUNK)
                .try_for_each(one)
        } else {
            self.copies
                .iter_mut()
                .zip(actions.chunks(act).zip(out.iter_mut()))
                .try_for_each(one)
        }
    }
}
