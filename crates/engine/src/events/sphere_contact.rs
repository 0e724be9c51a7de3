//! Sphere–sphere contact, as a discrete event (thesis §3.1.3: "new kinds of
//! event, sphere–sphere collisions for instance, plug in without changing
//! the integrator").
//!
//! After a trial step, two spheres that overlap are `Occurring`; an overlap
//! deeper than `envelope` was `Missed` (they met somewhere inside the step,
//! and it is retaken in shorter pieces). So was a step in which a sphere
//! that moved further than its radius passed deeper than `envelope` into
//! another on the way, overlapping at neither end (the swept test: both
//! moving in straight lines over the step), so that nothing passes through
//! anything however fast it goes, down to the backtracking's shortest
//! piece. Handling takes the contacts one
//! after another, in a fixed order (by cell of the grid, then by sphere),
//! in up to [`PASSES`] passes:
//! - the overlap is removed by moving the two apart along the line of
//!   centres, in inverse proportion to their masses (the centre of mass
//!   stays put);
//! - if they approach, the normal relative velocity `u_n` is reversed and
//!   scaled by the restitution `e` (the product of the two spheres', unless
//!   the contact says otherwise; 0 below `rest_speed`, so that resting
//!   spheres settle as on the floor) by an impulse `J = −(1 + e) u_n /
//!   (1/m_a + 1/m_b)`: momentum is exchanged exactly, and the relative
//!   kinetic energy along the normal keeps the factor `e²`;
//! - Coulomb friction: a tangential impulse opposes the sliding, stopping it
//!   if that takes at most `μ_s J` (static), else `μ_k J` (kinetic), with
//!   each coefficient the geometric mean of the two spheres' (as Box2D mixes
//!   them).
//!
//! The contacts handled are the pairs that overlap or come within
//! `rest_speed · h` of each other, and every pass visits each of them,
//! whether an earlier pass has already parted it or not: a resting sphere
//! pushed down by the one above passes that on to the one below in the
//! same handling, even where the two below merely touch. Across a gap a
//! slow approach is limited to what closes the gap within the next step
//! (a speculative contact); a fast one is left to bounce once they touch.
//!
//! A chain of touching spheres (Newton's cradle) passes an impulse along in
//! one handling, since each contact is recomputed after the ones before it.
//! With a floor, a sphere resting on it that a contact pushes down is held
//! by the floor (immovable for that contact), and no contact moves it below
//! the plane.
//!
//! Broad phase: a uniform grid of cells twice the largest radius, rebuilt at
//! every check, so that each sphere is tested only against the spheres of
//! its 27 neighbouring cells (each cell against itself and 13 neighbours):
//! the cost grows with the number of spheres, not its square. When the
//! spheres fill their bounding box the grid is a dense array filled by a
//! counting sort; when they are spread far apart, a hash map of the
//! occupied cells. Pairs given as excluded (the scene excludes the pairs
//! joined by a spring or a joint) never collide.
//!
//! Sleeping (opt-in, `sleep_speed` > 0; Box2D's and Rapier's remedy for a
//! heap that an iterative solve leaves creeping): a sphere in contact that
//! has stayed within `sleep_speed · sleep_time` of one place for
//! `sleep_time` sleeps, held where it fell asleep at rest and immovable to
//! its contacts, until something disturbs it: a strike (an approach at
//! `rest_speed` or faster, which wakes it within the handling, so a blow
//! passes on as through awake spheres), a neighbour moving faster than
//! `sleep_speed` or driven (the forces on it changing from step to step,
//! so that it pushes however slowly it goes), a change of the forces on it
//! (its trial's acceleration from rest differs from its first one asleep),
//! a hand (its position or velocity set from outside), or the loss of
//! every contact. A driven sphere never falls asleep. Stillness is
//! judged over `sleep_time`, not step by step, because a resting sphere
//! trembles by a step's sag under gravity. Per sphere, not per island:
//! a heap's solve keeps a few spheres moving for seconds, which would keep
//! a whole island awake.

use crate::error::ModelError;
use crate::event::{DiscreteEvent, EventContext, EventState};
use crate::force::Targets;
use crate::particle::{non_negative, ParticleId, Properties};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// The settings of sphere–sphere contact.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereContactDef {
    /// Overlap beyond which a contact counts as missed, m.
    pub envelope: f64,
    /// Approaches slower than this do not bounce, m/s.
    pub rest_speed: f64,
    /// The restitution of every contact; `None`: the product of the two
    /// spheres' restitutions.
    pub restitution: Option<f64>,
    /// The spheres that collide with each other.
    pub targets: Targets,
    /// Pairs that never collide.
    pub excluded: Vec<(ParticleId, ParticleId)>,
    /// Sleeping, m/s: a sphere in contact that stays within `sleep_speed ·
    /// sleep_time` of one place for `sleep_time` falls asleep (see
    /// [`SphereContact`]); 0 (the default): none ever does.
    pub sleep_speed: f64,
    /// How long a sphere must stay that still to fall asleep, s (default
    /// 0.5, Box2D's).
    pub sleep_time: f64,
}

impl Default for SphereContactDef {
    fn default() -> Self {
        SphereContactDef {
            envelope: 0.01,
            rest_speed: 0.05,
            restitution: None,
            targets: Targets::All,
            excluded: Vec::new(),
            sleep_speed: 0.0,
            sleep_time: 0.5,
        }
    }
}

/// One contact found by the last check.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pair {
    a: u32,
    b: u32,
}

/// One impact (an approach at `rest_speed` or faster) handled during the
/// last step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impact {
    /// The two spheres.
    pub spheres: (ParticleId, ParticleId),
    /// When, s.
    pub t: f64,
    /// Their approach speed along the line of centres, m/s.
    pub speed: f64,
}

/// A cheap, deterministic hasher for cell keys.
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x100_0000_01b3);
        }
    }
    fn write_u64(&mut self, k: u64) {
        // MurmurHash3's finaliser: every bit of the packed coordinates
        // reaches both the low bits (the bucket) and the high bits (the
        // table's tag), so neighbouring cells do not cluster.
        let mut k = k;
        k ^= k >> 33;
        k = k.wrapping_mul(0xff51_afd7_ed55_8ccd);
        k ^= k >> 33;
        k = k.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        self.0 = k ^ (k >> 33);
    }
}

/// Passes over the contacts in one handling: each pass moves apart what the
/// one before left overlapping (a stack shares its corrections down to the
/// floor), so overlaps shrink geometrically.
pub const PASSES: usize = 8;

/// A pass that corrected no overlap deeper than this (m) ends the handling:
/// what is left is far below anything visible or any envelope.
const SETTLED: f64 = 1e-6;

/// How close to the floor a sphere counts as resting on it, m.
const FLOOR_TOLERANCE: f64 = 1e-6;

/// The event.
#[derive(Clone, Debug)]
pub struct SphereContact {
    def: SphereContactDef,
    /// The spheres the floor (y = 0) holds up, if there is one: contacts
    /// never push them into it.
    floor: Option<Vec<bool>>,
    /// Excluded pairs as sorted keys `(min << 32) | max`.
    excluded: Vec<u64>,
    pairs: Vec<Pair>,
    /// (cell key, sphere), sorted.
    cells: Vec<(u64, u32)>,
    /// The same, while counting-sorting.
    sorted: Vec<(u64, u32)>,
    /// Dense grid: where each cell's run starts in `cells` (and one more).
    starts: Vec<u32>,
    /// The next free place of each cell's run, while counting-sorting.
    next: Vec<u32>,
    /// (centre, radius, nailed) of each entry of `cells`, in its order.
    near: Vec<(DVec3, f64, bool)>,
    /// Cell key → its run in `cells`.
    runs: HashMap<u64, (u32, u32), BuildHasherDefault<CellHasher>>,
    impacts: Vec<Impact>,
    /// The spheres that moved further than their radius in the trial.
    fast: Vec<u32>,
    /// The step of the last check, s (0 before any).
    h: f64,
    /// How many of `pairs` overlapped at the last check.
    overlapping: usize,
    /// Every colliding sphere with the box of its path in the trial.
    moving: Vec<(u32, DVec3, DVec3)>,
    /// Which spheres sleep (empty unless `sleep_speed` > 0).
    sleep: Sleep,
}

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
struct Sleep {
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
    asleep: Vec<bool>,
    /// Where it fell asleep, and where it stays while asleep.
    anchor: Vec<DVec3>,
    /// Whether it is in a contact (scratch, for each check).
    touched: Vec<bool>,
    /// Whether something disturbs it (scratch, for each check).
    wake: Vec<bool>,
    /// How many sleep.
    count: usize,
    /// The next check is a step's first.
    fresh: bool,
}

impl Sleep {
    fn wake(&mut self, i: usize) {
        if self.asleep[i] {
            self.asleep[i] = false;
            self.still[i] = 0.0;
            self.origin[i] = self.anchor[i];
            self.count -= 1;
        }
    }
}

/// 21 bits per coordinate, offset so that cells from −2²⁰ to 2²⁰ pack.
fn cell_key(c: [i64; 3]) -> u64 {
    const OFF: i64 = 1 << 20;
    let f = |x: i64| ((x + OFF).clamp(0, (1 << 21) - 1)) as u64;
    (f(c[0]) << 42) | (f(c[1]) << 21) | f(c[2])
}

/// `x.floor() as i64` for `|x| ≤ 10¹²`, without a call: on the baseline
/// x86-64 instruction set (no SSE4.1 rounding) `f64::floor` is a call into
/// libm, a tenth of the contact check's time in a large pile. Truncating
/// and stepping down below a negative non-integer gives the same integer
/// (every such `x` and its truncation are exact in f64).
#[inline(always)]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t - 1
    } else {
        t
    }
}

/// `[a₀ / b₀, a₁ / b₁]`, in one instruction on x86-64: each quotient is
/// correctly rounded either way, so the bits are those of two divisions,
/// for half the divider's time (the contact handling waits on it).
#[inline(always)]
fn div2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtsd_f64, _mm_div_pd, _mm_set_pd, _mm_unpackhi_pd};
        // SAFETY: SSE2 is part of x86-64, so every x86-64 CPU has these
        // instructions; they read and write only registers.
        unsafe {
            let q = _mm_div_pd(_mm_set_pd(a[1], a[0]), _mm_set_pd(b[1], b[0]));
            [_mm_cvtsd_f64(q), _mm_cvtsd_f64(_mm_unpackhi_pd(q, q))]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [a[0] / b[0], a[1] / b[1]]
    }
}

/// `[√x₀, √x₁]`, in one instruction on x86-64 (correctly rounded either way).
#[inline(always)]
fn sqrt2(x: [f64; 2]) -> [f64; 2] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtsd_f64, _mm_set_pd, _mm_sqrt_pd, _mm_unpackhi_pd};
        // SAFETY: as in `div2`.
        unsafe {
            let r = _mm_sqrt_pd(_mm_set_pd(x[1], x[0]));
            [_mm_cvtsd_f64(r), _mm_cvtsd_f64(_mm_unpackhi_pd(r, r))]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [x[0].sqrt(), x[1].sqrt()]
    }
}

fn pair_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

impl SphereContact {
    /// Sphere–sphere contact with the given settings.
    pub fn new(def: SphereContactDef) -> Result<Self, ModelError> {
        if def.envelope.is_nan() || def.envelope < 0.0 {
            return Err(ModelError::new(
                "envelope",
                format!("must be >= 0, got {}", def.envelope),
            ));
        }
        non_negative("rest_speed", def.rest_speed)?;
        non_negative("sleep_speed", def.sleep_speed)?;
        non_negative("sleep_time", def.sleep_time)?;
        if let Some(e) = def.restitution {
            non_negative("restitution", e)?;
            if e > 1.0 {
                return Err(ModelError::new(
                    "restitution",
                    format!("must be in [0, 1], got {e}"),
                ));
            }
        }
        let mut excluded: Vec<u64> = def
            .excluded
            .iter()
            .map(|(a, b)| pair_key(a.0, b.0))
            .collect();
        excluded.sort_unstable();
        excluded.dedup();
        Ok(SphereContact {
            def,
            floor: None,
            excluded,
            pairs: Vec::new(),
            cells: Vec::new(),
            sorted: Vec::new(),
            starts: Vec::new(),
            next: Vec::new(),
            near: Vec::new(),
            runs: HashMap::default(),
            impacts: Vec::new(),
            fast: Vec::new(),
            moving: Vec::new(),
            h: 0.0,
            overlapping: 0,
            sleep: Sleep::default(),
        })
    }

    /// Makes the contacts respect the floor y = 0 for the `n` particles'
    /// `targets`: a sphere that a contact would push below it stays on it,
    /// and its velocity into it is removed (the floor holds up what rests
    /// on a sphere resting on it).
    pub fn on_floor(&mut self, n: usize, targets: &Targets) {
        let mut held = vec![false; n];
        targets.for_each(n, |i| held[i] = true);
        self.floor = Some(held);
    }

    /// How far apart (m) a pair still counts as a contact: two spheres
    /// closing more slowly than `rest_speed` cannot cross a wider gap
    /// within one step, and a faster approach is an impact, handled once
    /// they touch.
    fn margin(&self) -> f64 {
        self.def.rest_speed * self.h
    }

    /// The settings.
    pub fn def(&self) -> &SphereContactDef {
        &self.def
    }

    /// How many pairs overlapped at the last check (resting contacts too).
    pub fn touching(&self) -> usize {
        self.overlapping
    }

    /// How many spheres sleep.
    pub fn sleeping(&self) -> usize {
        self.sleep.count
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

    /// Whether sphere `i` sleeps.
    pub fn is_asleep(&self, i: ParticleId) -> bool {
        self.sleep
            .asleep
            .get(i.0 as usize)
            .copied()
            .unwrap_or(false)
    }

    /// Sleeping and waking, sphere by sphere: at a step's first check,
    /// times each sphere's stillness over the step before and puts to
    /// sleep each sphere in contact that has been still for `sleep_time`;
    /// at every check, wakes each sleeper that something disturbs: a
    /// moving neighbour, a change of the forces on it, a hand (its position
    /// or velocity set from outside), or the loss of every contact.
    fn sleep_or_wake(&mut self, ctx: &EventContext) {
        let (speed, time, p) = (self.def.sleep_speed, self.def.sleep_time, ctx.particles);
        let envelope = self.def.envelope;
        let (x0, v0) = (ctx.start_pos, ctx.start_vel);
        let n = x0.len().min(ctx.pos.len());
        let s = &mut self.sleep;
        // New spheres, or the clock set back by hand (`World::set_time`;
        // a restored snapshot brings its own sleep): every sphere starts
        // awake.
        if s.last.len() != n || (s.fresh && ctx.t - ctx.h < s.t_last) {
            *s = Sleep {
                last: x0[..n].to_vec(),
                t_last: f64::NAN,
                origin: x0[..n].to_vec(),
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
            };
        }
        let movable = |i: usize| p.inv_mass[i] != 0.0 && p.radius[i] > 0.0;
        // Steady forces give the same acceleration to the bit, step after
        // step; the margin only forgives rounding.
        let changed = |a: DVec3, b: DVec3| (a - b).length() > 1e-9 * b.length();
        s.touched.iter_mut().for_each(|t| *t = false);
        for q in &self.pairs {
            s.touched[q.a as usize] = true;
            s.touched[q.b as usize] = true;
        }
        // `wake`: the sleepers disturbed.
        s.wake.iter_mut().for_each(|w| *w = false);
        if std::mem::take(&mut s.fresh) {
            let dt = if s.t_last.is_nan() {
                0.0
            } else {
                ctx.t - ctx.h - s.t_last
            };
            s.t_last = ctx.t - ctx.h;
            // Stillness is judged over `sleep_time`, not step by step: a
            // resting sphere trembles by about a step's sag under gravity
            // (g h², as far as `sleep_speed` goes in a step at the
            // defaults), but goes nowhere.
            let reach = speed * time;
            self.def.targets.for_each(n, |i| {
                if !movable(i) {
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
                    s.moving[i] =
                        (x0[i] - s.last[i]).length() > speed * dt && s.still[i] < 0.5 * time;
                    // Still for a step at least (so not at once when
                    // `sleep_time` is 0), and not so fast in the trial
                    // that holding it back where it was could leave an
                    // overlap deeper than the envelope (a backtrack at
                    // every step).
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
        if s.count == 0 {
            return;
        }
        // A moving or driven neighbour disturbs a sleeper (one that strikes
        // it wakes it in the handling).
        for q in &self.pairs {
            let (a, b) = (q.a as usize, q.b as usize);
            if s.asleep[a] != s.asleep[b] {
                let (sleeper, other) = if s.asleep[a] { (a, b) } else { (b, a) };
                s.wake[sleeper] |= (s.moving[other] || s.driven[other]) && movable(other);
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

    /// The impacts of the last step (approaches at `rest_speed` or faster;
    /// resting contacts are not listed).
    pub fn impacts(&self) -> &[Impact] {
        &self.impacts
    }

    /// The deepest overlap among the targets at `pos`, m (0 if none): for
    /// tests and diagnostics; the same broad phase as a check.
    pub fn deepest_overlap(&mut self, pos: &[DVec3], particles: &Properties) -> f64 {
        self.find(pos, particles)
    }

    /// Fills `pairs` with the pairs at `pos` that overlap or are less than
    /// [`Self::margin`] apart; returns the deepest overlap.
    fn find(&mut self, pos: &[DVec3], p: &Properties) -> f64 {
        self.pairs.clear();
        self.cells.clear();
        self.runs.clear();
        let n = pos.len();
        let mut largest = 0.0f64;
        self.def.targets.for_each(n, |i| {
            if p.radius[i] > 0.0 {
                largest = largest.max(p.radius[i]);
            }
        });
        if largest <= 0.0 {
            return 0.0;
        }
        let size = 2.0 * largest;
        // Clamped far beyond the packed range, so that a neighbour's
        // coordinate (±1) never overflows, wherever a sphere has flown.
        let cell = |x: DVec3| {
            let c = (x / size).clamp(DVec3::splat(-1e12), DVec3::splat(1e12));
            [floor_i64(c.x), floor_i64(c.y), floor_i64(c.z)]
        };
        // Where the spheres are: the bounds of their cells.
        let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
        let mut count = 0usize;
        self.def.targets.for_each(n, |i| {
            if p.radius[i] > 0.0 && pos[i].is_finite() {
                let c = cell(pos[i]);
                for k in 0..3 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
                count += 1;
            }
        });
        if count == 0 {
            return 0.0;
        }
        let dims = [0, 1, 2].map(|k| (hi[k] - lo[k] + 1) as f64);
        let total = dims[0] * dims[1] * dims[2];
        // A dense grid (an array of cell starts, filled by counting) when
        // the spheres fill their box; a hash map of occupied cells when
        // they are spread far apart.
        let dense = total <= (4 * count + 4096) as f64;
        let [_, ny, nz] = dims.map(|d| d as i64);
        let linear =
            |c: [i64; 3]| (((c[0] - lo[0]) * ny + (c[1] - lo[1])) * nz + (c[2] - lo[2])) as u64;
        let key = |c: [i64; 3]| if dense { linear(c) } else { cell_key(c) };
        let cells = &mut self.cells;
        self.def.targets.for_each(n, |i| {
            if p.radius[i] > 0.0 && pos[i].is_finite() {
                cells.push((key(cell(pos[i])), i as u32));
            }
        });
        if dense {
            // Counting sort: by cell, and by sphere within a cell.
            let starts = &mut self.starts;
            starts.clear();
            starts.resize(total as usize + 1, 0);
            for &(k, _) in cells.iter() {
                starts[k as usize + 1] += 1;
            }
            for k in 1..starts.len() {
                starts[k] += starts[k - 1];
            }
            let next = &mut self.next;
            next.clear();
            next.extend_from_slice(starts);
            self.sorted.clear();
            self.sorted.resize(cells.len(), (0, 0));
            for &(k, i) in cells.iter() {
                let at = &mut next[k as usize];
                self.sorted[*at as usize] = (k, i);
                *at += 1;
            }
            std::mem::swap(cells, &mut self.sorted);
        } else {
            cells.sort_unstable();
            let mut start = 0;
            while start < cells.len() {
                let key = cells[start].0;
                let mut end = start + 1;
                while end < cells.len() && cells[end].0 == key {
                    end += 1;
                }
                self.runs.insert(key, (start as u32, end as u32));
                start = end;
            }
        }
        let (starts, runs) = (&self.starts, &self.runs);
        // The spheres of cell `c`, as a range of `cells`.
        let run_of = |c: [i64; 3]| -> Option<(usize, usize)> {
            if dense {
                if (0..3).any(|k| c[k] < lo[k] || c[k] > hi[k]) {
                    return None;
                }
                let k = linear(c) as usize;
                let (s, e) = (starts[k] as usize, starts[k + 1] as usize);
                (e > s).then_some((s, e))
            } else {
                runs.get(&cell_key(c))
                    .map(|&(s, e)| (s as usize, e as usize))
            }
        };
        // Each cell against itself and its 13 neighbours in the forward
        // half of the 3×3×3 block: every pair of neighbouring cells once.
        const FORWARD: [[i64; 3]; 14] = [
            [0, 0, 0],
            [0, 0, 1],
            [0, 1, -1],
            [0, 1, 0],
            [0, 1, 1],
            [1, -1, -1],
            [1, -1, 0],
            [1, -1, 1],
            [1, 0, -1],
            [1, 0, 0],
            [1, 0, 1],
            [1, 1, -1],
            [1, 1, 0],
            [1, 1, 1],
        ];
        let mut deepest = 0.0f64;
        // The spheres' centres, radii and mobility copied in cell order, so
        // that the tests below read neighbours side by side.
        self.near.clear();
        self.near.extend(self.cells.iter().map(|&(_, i)| {
            let i = i as usize;
            (pos[i], p.radius[i], p.inv_mass[i] == 0.0)
        }));
        let margin = self.margin();
        self.overlapping = 0;
        let (cells, near, pairs, excluded, overlapping) = (
            &self.cells,
            &self.near,
            &mut self.pairs,
            &self.excluded,
            &mut self.overlapping,
        );
        let mut test = |x: usize, y: usize| {
            let ((pa, ra, fa), (pb, rb, fb)) = (near[x], near[y]);
            if fa && fb {
                return;
            }
            let reach = ra + rb;
            let d2 = (pb - pa).length_squared();
            let outer = reach + margin;
            if d2 >= outer * outer {
                return;
            }
            let (a, b) = (cells[x].1, cells[y].1);
            if !excluded.is_empty() && excluded.binary_search(&pair_key(a, b)).is_ok() {
                return;
            }
            deepest = deepest.max(reach - d2.sqrt());
            if d2 < reach * reach {
                *overlapping += 1;
            }
            let (a, b) = if a < b { (a, b) } else { (b, a) };
            pairs.push(Pair { a, b });
        };
        let mut start = 0;
        while start < cells.len() {
            let c = cell(near[start].0);
            let end = run_of(c).map_or(start + 1, |r| r.1);
            for (k, off) in FORWARD.iter().enumerate() {
                if k == 0 {
                    for x in start..end {
                        for y in x + 1..end {
                            test(x, y);
                        }
                    }
                    continue;
                }
                let Some((s, e)) = run_of([c[0] + off[0], c[1] + off[1], c[2] + off[2]]) else {
                    continue;
                };
                for x in start..end {
                    for y in s..e {
                        test(x, y);
                    }
                }
            }
            start = end;
        }
        deepest
    }
}

impl SphereContact {
    /// The swept test: how deep two spheres came into each other during
    /// the step, moving in straight lines from their start to their end,
    /// for every pair with a sphere that moved further than its radius
    /// (slower pairs cannot pass through each other unseen: crossing from
    /// touching on one side to the other takes 2 (r_a + r_b), and each
    /// moved at most its radius). Each fast sphere is tested against every
    /// sphere whose path's box comes near its own: cheap for a few fast
    /// spheres, quadratic if most move further than their radius in a step
    /// (where the remedy is a smaller step).
    fn swept(&mut self, ctx: &EventContext) -> f64 {
        let (x0, x1, p) = (ctx.start_pos, ctx.pos, ctx.particles);
        let n = x0.len().min(x1.len());
        self.fast.clear();
        self.moving.clear();
        let (fast, moving) = (&mut self.fast, &mut self.moving);
        let usable = |i: usize| p.radius[i] > 0.0 && x0[i].is_finite() && x1[i].is_finite();
        self.def.targets.for_each(n, |i| {
            let r = p.radius[i];
            if usable(i) && (x1[i] - x0[i]).length_squared() > r * r {
                fast.push(i as u32);
            }
        });
        if fast.is_empty() {
            return 0.0;
        }
        // Every sphere's path, as a box grown by its radius.
        self.def.targets.for_each(n, |i| {
            if usable(i) {
                let r = p.radius[i];
                moving.push((i as u32, x0[i].min(x1[i]) - r, x0[i].max(x1[i]) + r));
            }
        });
        let mut deepest = 0.0f64;
        for &i in &self.fast {
            let i = i as usize;
            let r = p.radius[i];
            let (lo, hi) = (x0[i].min(x1[i]) - r, x0[i].max(x1[i]) + r);
            for &(j, jlo, jhi) in &self.moving {
                let j = j as usize;
                if j == i
                    || jlo.cmpgt(hi).any()
                    || jhi.cmplt(lo).any()
                    || (p.inv_mass[i] == 0.0 && p.inv_mass[j] == 0.0)
                {
                    continue;
                }
                let key = pair_key(i as u32, j as u32);
                if !self.excluded.is_empty() && self.excluded.binary_search(&key).is_ok() {
                    continue;
                }
                // Closest approach of the relative motion d(t) = d0 + t m.
                let d0 = x0[j] - x0[i];
                let m = (x1[j] - x1[i]) - d0;
                let mm = m.length_squared();
                let t = if mm > 0.0 {
                    (-d0.dot(m) / mm).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                deepest = deepest.max(r + p.radius[j] - (d0 + m * t).length());
            }
        }
        deepest
    }
}

impl DiscreteEvent for SphereContact {
    fn check(&mut self, ctx: &EventContext) -> EventState {
        self.h = ctx.step;
        let mut deepest = self.find(ctx.pos, ctx.particles);
        if self.def.sleep_speed > 0.0 {
            self.sleep_or_wake(ctx);
        }
        if deepest <= self.def.envelope {
            deepest = deepest.max(self.swept(ctx));
        }
        if deepest > self.def.envelope {
            EventState::Missed
        } else if self.pairs.is_empty() {
            EventState::None
        } else {
            EventState::Occurring
        }
    }

    fn handle(&mut self, t: f64, pos: &mut [DVec3], vel: &mut [DVec3], p: &Properties) {
        let (h, margin) = (self.h, self.margin());
        let floor = &self.floor;
        let held = |i: usize| {
            floor
                .as_ref()
                .is_some_and(|f| f.get(i).copied().unwrap_or(false))
        };
        // Sleepers stay where they fell asleep, at rest.
        let sleep = &mut self.sleep;
        if sleep.count > 0 {
            for (i, _) in sleep.asleep.iter().enumerate().filter(|(_, &z)| z) {
                pos[i] = sleep.anchor[i];
                vel[i] = DVec3::ZERO;
            }
        }
        for pass in 0..PASSES {
            let mut largest = 0.0f64;
            for q in &self.pairs {
                let (a, b) = (q.a as usize, q.b as usize);
                let d = pos[b] - pos[a];
                let dist = d.length();
                let reach = p.radius[a] + p.radius[b];
                let overlap = reach - dist;
                if overlap <= -margin || dist == 0.0 {
                    continue; // parted by an earlier contact, or no direction
                }
                let n = d / dist;
                // A sphere resting on the floor, pushed down into it, is
                // held by the floor: immovable for this contact.
                let on_floor = |i: usize| held(i) && pos[i].y <= p.radius[i] + FLOOR_TOLERANCE;
                let mut wa = if n.y > 0.0 && on_floor(a) {
                    0.0
                } else {
                    p.inv_mass[a]
                };
                let mut wb = if n.y < 0.0 && on_floor(b) {
                    0.0
                } else {
                    p.inv_mass[b]
                };
                if sleep.count > 0 && (sleep.asleep[a] || sleep.asleep[b]) {
                    // A sleeper is immovable, unless struck: then it wakes
                    // and takes its part from this contact on (so a blow
                    // passes through a sleeping heap as through an awake
                    // one, waking only what it reaches).
                    let struck = -(vel[b] - vel[a]).dot(n) >= self.def.rest_speed;
                    for (i, wi) in [(a, &mut wa), (b, &mut wb)] {
                        if sleep.asleep[i] {
                            if struck {
                                sleep.wake(i);
                            } else {
                                *wi = 0.0;
                            }
                        }
                    }
                }
                let w = wa + wb;
                if w == 0.0 {
                    continue;
                }
                let u = vel[b] - vel[a];
                let un = u.dot(n);
                // Touching or overlapping, they must not approach; across
                // a gap, not close it within the next step. Only a slow
                // approach is limited across a gap: a fast one bounces
                // once they touch.
                let allowed = overlap.min(0.0) / h;
                let resting = -un < self.def.rest_speed;
                if un < allowed && (overlap >= 0.0 || resting) {
                    let e = if resting || overlap < 0.0 {
                        0.0
                    } else {
                        self.def
                            .restitution
                            .unwrap_or(p.restitution[a] * p.restitution[b])
                    };
                    let ut = u - n * un;
                    let slide = ut.length();
                    // The normal impulse and the one that would stop the
                    // sliding, in one division.
                    let target = if overlap < 0.0 {
                        allowed - un
                    } else {
                        -(1.0 + e) * un
                    };
                    let [jn, stop] = div2([target, slide], [w, w]);
                    let mut impulse = n * jn;
                    if slide > 0.0 {
                        // Against what friction can give.
                        let [mu_s, mu_k] = sqrt2([p.mu_s[a] * p.mu_s[b], p.mu_k[a] * p.mu_k[b]]);
                        let jt = if stop <= mu_s * jn { stop } else { mu_k * jn };
                        impulse -= ut * (jt / slide);
                    }
                    vel[a] -= impulse * wa;
                    vel[b] += impulse * wb;
                    if pass == 0 && !resting {
                        self.impacts.push(Impact {
                            spheres: (ParticleId(q.a), ParticleId(q.b)),
                            t,
                            speed: -un,
                        });
                    }
                }
                if overlap > 0.0 {
                    largest = largest.max(overlap);
                    let [ka, kb] = div2([overlap * wa, overlap * wb], [w, w]);
                    pos[a] -= n * ka;
                    pos[b] += n * kb;
                }
                for i in [a, b] {
                    if held(i) && pos[i].y < p.radius[i] && p.inv_mass[i] != 0.0 {
                        pos[i].y = p.radius[i];
                        vel[i].y = vel[i].y.max(0.0);
                    }
                }
            }
            if largest <= SETTLED {
                break;
            }
        }
    }

    fn begin_step(&mut self) {
        self.impacts.clear();
        self.sleep.fresh = true;
    }

    fn is_passive(&self) -> bool {
        // Impulses with e ≤ 1 and friction never add kinetic energy; moving
        // the spheres apart can, against a force, by at most the work over
        // the overlap (bounded by the envelope).
        true
    }

    fn name(&self) -> &str {
        "sphere contact"
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn as_any_mut(&mut self) -> Option<&mut dyn std::any::Any> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::{div2, floor_i64, sqrt2};

    /// Two divisions or square roots in one instruction give each lane the
    /// bits of the scalar operation (so the handling keeps its results).
    #[test]
    fn paired_divisions_and_roots_are_the_scalar_ones() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut u = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            // Any sign, exponents over a wide range.
            f64::from_bits((s & 0x800f_ffff_ffff_ffff) | ((s >> 52) % 1400 + 330) << 52)
        };
        for _ in 0..100_000 {
            let (a, b, c, d) = (u(), u(), u(), u());
            let [p, q] = div2([a, b], [c, d]);
            assert_eq!(
                (p.to_bits(), q.to_bits()),
                ((a / c).to_bits(), (b / d).to_bits())
            );
            let [r, t] = sqrt2([a.abs(), b.abs()]);
            assert_eq!(
                (r.to_bits(), t.to_bits()),
                (a.abs().sqrt().to_bits(), b.abs().sqrt().to_bits())
            );
        }
        let [z, inf] = div2([0.0, 1.0], [0.0, 0.0]);
        assert!(z.is_nan() && inf == f64::INFINITY);
    }

    /// The grid's cells must be the ones `f64::floor` gives, or the pairs
    /// would be found in another order (other bits).
    #[test]
    fn floor_without_a_call_agrees_with_f64_floor() {
        let mut xs = vec![0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 1e12, -1e12, 1e12 - 0.5];
        xs.extend([f64::EPSILON, -f64::EPSILON, 1.0 - f64::EPSILON / 2.0]);
        xs.extend([
            -1.0 + f64::EPSILON / 2.0,
            -1e12 + 0.25,
            -(2f64.powi(39) + 0.5),
        ]);
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..100_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            // Uniform over ±2^k for k up to 40: many scales, both signs.
            let scale = (1u64 << (s % 41)) as f64;
            xs.push(((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * scale);
        }
        for x in xs {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x:e}");
        }
    }
}
