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

//!
//! - `grid.rs`: the broad phase (the grid, the pairs, the swept test);
//! - `sleep.rs`: sleeping and waking;
//! - `resolve.rs`: handling the contacts.

mod grid;
mod resolve;
mod sleep;

pub use sleep::SleepState;

use crate::error::ModelError;
use crate::event::{DiscreteEvent, EventContext, EventState};
use crate::force::Targets;
use crate::particle::{non_negative, ParticleId, Properties};
use glam::DVec3;
use grid::CellHasher;
use sleep::Sleep;
use std::collections::HashMap;
use std::hash::BuildHasherDefault;

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

/// A pair's key: `(min << 32) | max`.
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
        self.resolve(t, pos, vel, p);
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
}
