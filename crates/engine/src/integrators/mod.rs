//! Integrators (thesis §3.1.4): each advances the state by one step `h`,
//! re-evaluating every force at each of its trial states (the thesis's
//! trial-integration structure). One file per method; [`IntegratorKind`]
//! chooses one at run time.
//!
//! All of them read the state at the start of the step (`from`) and write the
//! end of the step into a separate buffer (`to`), so a step that an event
//! rejects is thrown away without copying anything back.

pub mod euler;
pub mod implicit;
pub mod midpoint;
pub mod rk4;
pub mod symplectic;

use crate::event::EventState;
use crate::force_set::Forces;
use crate::particle::{Properties, State};
use glam::DVec3;
use std::fmt;
use std::str::FromStr;

#[cfg(test)]
pub(crate) use crate::simd::{on, Width};
pub use implicit::Solver;

/// The integration methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum IntegratorKind {
    /// Explicit (forward) Euler, first order.
    Euler,
    /// Explicit midpoint, second order.
    Midpoint,
    /// Classic fourth-order Runge–Kutta (the thesis's default).
    #[default]
    Rk4,
    /// Semi-implicit (symplectic) Euler: velocity first, then position with
    /// the new velocity. First order, but its energy error stays bounded.
    Symplectic,
    /// Implicit (backward) Euler, one Newton step per step: first order,
    /// stable at large steps on stiff springs, and damping every mode.
    Implicit,
}

impl IntegratorKind {
    /// Every kind, in order of the names.
    pub const ALL: [IntegratorKind; 5] = [
        IntegratorKind::Euler,
        IntegratorKind::Midpoint,
        IntegratorKind::Rk4,
        IntegratorKind::Symplectic,
        IntegratorKind::Implicit,
    ];

    /// The explicit kinds, whose step is limited by the stiffest spring.
    pub fn is_explicit(self) -> bool {
        self != IntegratorKind::Implicit
    }

    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Euler => "euler",
            IntegratorKind::Midpoint => "midpoint",
            IntegratorKind::Rk4 => "rk4",
            IntegratorKind::Symplectic => "symplectic",
            IntegratorKind::Implicit => "implicit",
        }
    }

    /// Order of accuracy (global error ~ h^order).
    pub fn order(self) -> u32 {
        match self {
            IntegratorKind::Euler | IntegratorKind::Symplectic | IntegratorKind::Implicit => 1,
            IntegratorKind::Midpoint => 2,
            IntegratorKind::Rk4 => 4,
        }
    }

    /// Under a constant acceleration `a`, steps of `h` conserve
    /// `½ (v + s a h)² − a·x` exactly, where `s` is this number: −½ for
    /// explicit Euler (which gains ½ a² h² of kinetic energy a step in free
    /// flight), +½ for symplectic and implicit Euler (the same step in free
    /// flight), 0 for midpoint and RK4 (exact for a
    /// constant force). Impacts use it so as not to feed an integrator's
    /// own drift back into the bounce.
    pub fn free_flight_shift(self) -> f64 {
        match self {
            IntegratorKind::Euler => -0.5,
            IntegratorKind::Symplectic | IntegratorKind::Implicit => 0.5,
            IntegratorKind::Midpoint | IntegratorKind::Rk4 => 0.0,
        }
    }

    /// The largest ω·h at which this method keeps an undamped spring's
    /// oscillation bounded: symplectic Euler 2, RK4 2√2 ≈ 2.83. Explicit
    /// Euler and midpoint let it grow at any step; they get symplectic
    /// Euler's 2 as a guide (their error still grows, only more slowly at
    /// smaller steps). Implicit Euler is stable at any step: infinity.
    pub fn stable_omega_h(self) -> f64 {
        match self {
            IntegratorKind::Rk4 => 2.0 * std::f64::consts::SQRT_2,
            IntegratorKind::Implicit => f64::INFINITY,
            _ => 2.0,
        }
    }

    /// Force evaluations per step.
    pub fn evaluations(self) -> u32 {
        match self {
            IntegratorKind::Euler | IntegratorKind::Symplectic | IntegratorKind::Implicit => 1,
            IntegratorKind::Midpoint => 2,
            IntegratorKind::Rk4 => 4,
        }
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for IntegratorKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        IntegratorKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                format!("unknown integrator `{s}` (expected euler, midpoint, rk4, symplectic or implicit)")
            })
    }
}

/// What an integrator needs besides the state: the forces, the particles, and
/// scratch buffers it may use freely.
pub struct Dynamics<'a> {
    /// The forces to evaluate.
    pub forces: &'a mut Forces,
    /// Particle properties (mass, inverse mass...).
    pub particles: &'a Properties,
    /// Scratch buffers, each as long as the state.
    pub scratch: &'a mut Scratch,
    /// How the implicit step solves its linear system.
    pub solver: Solver,
}

/// Scratch buffers shared by the integrators.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    /// Net forces of the current trial state.
    pub force: Vec<DVec3>,
    /// Accumulated position increments (RK4).
    pub dx: Vec<DVec3>,
    /// Accumulated velocity increments (RK4).
    pub dv: Vec<DVec3>,
    /// The implicit step's linear system.
    pub implicit: implicit::Buffers,
}

impl Scratch {
    /// Makes room for `n` particles (the same `n` every step but the
    /// first: a test inlined into the step).
    #[inline(always)]
    pub(crate) fn resize(&mut self, n: usize) {
        if self.force.len() != n {
            self.grow(n);
        }
    }

    #[cold]
    fn grow(&mut self, n: usize) {
        for v in [&mut self.force, &mut self.dx, &mut self.dv] {
            v.resize(n, DVec3::ZERO);
        }
    }
}

/// Worlds with fewer particles update particle by particle in RK4, as
/// vectors (`DVec3`; symplectic Euler's small step runs over the flat
/// coordinates, which measured faster with a force that does something,
/// `symplectic::step_small`): the positions are then stored as
/// the force loops read them (x and y together, then z), so each read is
/// served from the store just made instead of waiting for it to reach the
/// cache, and finiteness is checked as they are written. From about this
/// size the flat loops over coordinates, which the compiler vectorises, are
/// faster (chain-64: 0.55-0.59 ms flat, 0.65 ms by particle).
pub(crate) const SMALL: usize = 16;

/// What the integrators' update loops need of what they update: one
/// coordinate (`f64`, the flat loops) or a whole vector (`DVec3`, small
/// worlds). The loops are written once over it, with the same operations
/// on each coordinate either way, so both give the same bits.
pub(crate) trait Coord:
    Copy + std::ops::Add<Output = Self> + std::ops::AddAssign + std::ops::Mul<f64, Output = Self>
{
    /// A word whose top bit is set if a coordinate is infinite or NaN:
    /// the loops OR these together and test the top bit once at the end
    /// ([`all_finite`]). An OR of integers is associative, so it adds
    /// three cheap vector operations to a vectorised loop, where
    /// `finite &= x.is_finite()` compared, then packed and extracted the
    /// comparison's lanes every iteration (`perf`: `World::step` 18.9 →
    /// 17.0 % of `animats bench nbody5 --quick`'s samples).
    fn not_finite(self) -> u64;
}

/// The top bit of `x`'s exponent field plus one: set exactly when every
/// bit of the exponent is (an infinity or a NaN).
#[inline(always)]
fn exponent_carry(x: f64) -> u64 {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    const ONE: u64 = 0x0010_0000_0000_0000;
    (x.to_bits() & EXPONENT).wrapping_add(ONE)
}

/// Whether an OR of [`Coord::not_finite`] words says every coordinate was
/// finite.
#[inline(always)]
pub(crate) fn all_finite(not_finite: u64) -> bool {
    not_finite >> 63 == 0
}

impl Coord for f64 {
    #[inline(always)]
    fn not_finite(self) -> u64 {
        exponent_carry(self)
    }
}

impl Coord for DVec3 {
    #[inline(always)]
    fn not_finite(self) -> u64 {
        exponent_carry(self.x) | exponent_carry(self.y) | exponent_carry(self.z)
    }
}

/// Asserts that `run` gives the same results compiled for every
/// instruction set this CPU has as for the baseline.
#[cfg(test)]
pub(crate) fn assert_same_on_every_width<T: PartialEq + fmt::Debug>(run: impl Fn(Width) -> T) {
    let base = run(Width::Base);
    for width in Width::available() {
        assert_eq!(run(width), base, "{width:?}");
    }
}

/// The bits of each number of each array, to compare exactly.
#[cfg(test)]
pub(crate) fn bits<const K: usize>(arrays: [Vec<f64>; K]) -> [Vec<u64>; K] {
    arrays.map(|a| a.iter().map(|x| x.to_bits()).collect())
}

/// A slice of vectors as one flat array, x, y, z of each in turn.
#[inline(always)]
pub(crate) fn flat(v: &[DVec3]) -> &[f64] {
    // SAFETY: `DVec3` is `#[repr(C)]` with fields x, y, z: f64 (glam's
    // scalar vector), so n of them are 3n contiguous, aligned f64s; the
    // borrow is carried over.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<f64>(), 3 * v.len()) }
}

/// [`flat`], mutably.
#[inline(always)]
pub(crate) fn flat_mut(v: &mut [DVec3]) -> &mut [f64] {
    // SAFETY: as in `flat`; the exclusive borrow is carried over.
    unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<f64>(), 3 * v.len()) }
}

/// Advances `from` by `h` into `to` with the method `kind`, starting at time
/// `t`. True if the integrator knows every coordinate of `to` to be finite
/// (a small world's update checks as it writes); false if it does not know,
/// and the caller must look.
pub fn integrate(
    kind: IntegratorKind,
    d: &mut Dynamics,
    t: f64,
    h: f64,
    from: &State,
    to: &mut State,
) -> bool {
    integrate_then(kind, d, t, h, from, to, None).finite()
}

/// What the pieces of a trial said once settled ([`Finish`]), combined:
/// whether every coordinate is finite, and the worst event state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Settled {
    pub finite: bool,
    pub worst: EventState,
}

impl Settled {
    /// Finite, no event: what nothing to settle answers.
    pub const FINE: Settled = Settled {
        finite: true,
        worst: EventState::None,
    };

    /// Both pieces' answers.
    #[inline]
    pub fn and(self, other: Settled) -> Settled {
        Settled {
            finite: self.finite & other.finite,
            worst: self.worst.max(other.worst),
        }
    }
}

/// Work the caller wants done on each piece of the trial state
/// (`first`, its positions, its velocities) right after an integrator has
/// written it, by the thread that wrote it, while the piece is in its
/// cache: the world's events and the finiteness scan (`World::trial`).
pub(crate) type Finish<'a> = &'a (dyn Fn(usize, &mut [DVec3], &mut [DVec3]) -> Settled + Sync);

/// What an integrator did with a [`Finish`].
pub(crate) enum Written {
    /// Not run (the integrator writes its trial in one go); true if it
    /// knows every coordinate to be finite, as [`integrate`] answers.
    Known(bool),
    /// Run on every piece: their answers.
    Settled(Settled),
}

impl Written {
    /// Whether the new state is known to be finite.
    pub fn finite(self) -> bool {
        match self {
            Written::Known(finite) => finite,
            Written::Settled(s) => s.finite,
        }
    }
}

/// [`integrate`], then `finish` on every piece of `to` where the
/// integrator writes its last loop by pieces (symplectic Euler, RK4).
pub(crate) fn integrate_then(
    kind: IntegratorKind,
    d: &mut Dynamics,
    t: f64,
    h: f64,
    from: &State,
    to: &mut State,
    finish: Option<Finish>,
) -> Written {
    if d.particles.inv_mass3.len() != 3 * d.particles.inv_mass.len() {
        // Properties filled in by hand rather than by a World: make the
        // per-coordinate copies of the inverse masses for this step.
        let mut particles = d.particles.clone();
        particles.inv_mass3 = particles.inv_mass.iter().flat_map(|&w| [w; 3]).collect();
        let mut own = Dynamics {
            forces: &mut *d.forces,
            particles: &particles,
            scratch: &mut *d.scratch,
            solver: d.solver,
        };
        return integrate_then(kind, &mut own, t, h, from, to, finish);
    }
    match kind {
        IntegratorKind::Euler => Written::Known(euler::step(d, t, h, from, to)),
        IntegratorKind::Midpoint => Written::Known(midpoint::step(d, t, h, from, to)),
        IntegratorKind::Rk4 => rk4::step_then(d, t, h, from, to, finish),
        IntegratorKind::Symplectic => symplectic::step_then(d, t, h, from, to, finish),
        IntegratorKind::Implicit => Written::Known(implicit::step(d, t, h, from, to)),
    }
}

/// Test data: `n` numbers of many magnitudes and both signs, the same
/// every run.
#[cfg(test)]
pub(crate) fn test_numbers(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed | 1;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let unit = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            unit * 2f64.powi((s % 40) as i32 - 20)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ParticleDef, SpringDef, World};

    /// The top bit of `not_finite` is set exactly for infinities and NaNs:
    /// every special value, the largest and smallest of each exponent, and
    /// a million random bit patterns, alone and ORed in a vector's place.
    #[test]
    fn the_not_finite_word_is_is_finite() {
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            f64::from_bits(1),
            f64::from_bits(0x000f_ffff_ffff_ffff),
            f64::from_bits(0x7fef_ffff_ffff_ffff),
            f64::from_bits(0x7ff0_0000_0000_0001),
            f64::from_bits(0xfff8_0000_0000_0000),
            f64::from_bits(u64::MAX),
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for e in 0..2048u64 {
            values.push(f64::from_bits(e << 52));
            values.push(f64::from_bits(
                (e << 52) | 0x000f_ffff_ffff_ffff | (1 << 63),
            ));
        }
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..1_000_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            values.push(f64::from_bits(s));
        }
        let mut non_finite = 0;
        for (k, &x) in values.iter().enumerate() {
            assert_eq!(
                all_finite(x.not_finite()),
                x.is_finite(),
                "{:#x}",
                x.to_bits()
            );
            non_finite += usize::from(!x.is_finite());
            let y = values[(k * 7 + 3) % values.len()];
            for v in [
                DVec3::new(x, 1.0, y),
                DVec3::new(y, x, 2.0),
                DVec3::new(-3.0, y, x),
            ] {
                assert_eq!(all_finite(v.not_finite()), v.is_finite(), "{v:?}");
                // ORed with a finite coordinate's word, as the loops do.
                assert_eq!(all_finite(v.not_finite() | 5.0.not_finite()), v.is_finite());
            }
        }
        // About one random pattern in 2,048 is not finite.
        assert!(
            non_finite > 400,
            "the patterns hold {non_finite} infinities and NaNs"
        );
    }

    /// Properties written field by field (not by a World) lack the
    /// per-coordinate inverse masses; `integrate` makes them, and the step is
    /// a World's, to the bit.
    #[test]
    fn properties_filled_in_by_hand_step_as_a_worlds() {
        let mut w = World::new();
        w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
        let a = w.add_particle(ParticleDef::new(2.0)).unwrap();
        let b = w
            .add_particle(ParticleDef::new(0.5).at(DVec3::new(0.3, 0.1, 0.0)))
            .unwrap();
        w.add_spring(SpringDef::new(a, b, 30.0, 0.1)).unwrap();
        let p = w.particles();
        let hand = Properties {
            mass: p.mass.clone(),
            inv_mass: p.inv_mass.clone(),
            radius: p.radius.clone(),
            volume: p.volume.clone(),
            fixed: p.fixed.clone(),
            ..Properties::default()
        };
        for kind in IntegratorKind::ALL {
            let from = w.state().clone();
            let mut forces = w.forces().clone();
            let mut scratch = Scratch::default();
            scratch.resize(2);
            let mut to = from.clone();
            let mut d = Dynamics {
                forces: &mut forces,
                particles: &hand,
                scratch: &mut scratch,
                solver: Solver::default(),
            };
            integrate(kind, &mut d, 0.0, 1e-3, &from, &mut to);
            let mut stepped = w.clone();
            stepped.set_integrator(kind);
            stepped.step(1e-3).unwrap();
            assert_eq!(&to, stepped.state(), "{kind}");
            // Each integrator's own `step` too (the small worlds' updates
            // read the per-coordinate inverse masses).
            let mut by_own = from.clone();
            match kind {
                IntegratorKind::Euler => euler::step(&mut d, 0.0, 1e-3, &from, &mut by_own),
                IntegratorKind::Midpoint => midpoint::step(&mut d, 0.0, 1e-3, &from, &mut by_own),
                IntegratorKind::Rk4 => rk4::step(&mut d, 0.0, 1e-3, &from, &mut by_own),
                IntegratorKind::Symplectic => {
                    symplectic::step(&mut d, 0.0, 1e-3, &from, &mut by_own)
                }
                IntegratorKind::Implicit => implicit::step(&mut d, 0.0, 1e-3, &from, &mut by_own),
            };
            assert_eq!(&by_own, stepped.state(), "{kind}, its own step");
        }
    }
}
