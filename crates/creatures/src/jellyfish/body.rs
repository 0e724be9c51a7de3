//! The jellyfish's body (thesis §3.2.2.1, Appendix B `Jellyfish`): a dome ring
//! of three masses joined by springs, and a four-segment tentacle hanging from
//! each dome mass; a pulse force shared by the dome masses and a steering
//! force on each. All constants are Appendix B's, with one reading:
//!
//! **Spring damping per step.** Appendix B damps the ring springs with 5 and
//! the tentacle springs with 1. Read as N s/m (damping proportional to the
//! rate of extension, as the engine's springs are), the lightest SeaWorld
//! jellyfish's tentacles (0.011 kg segments) have a damped mode with
//! λh ≈ −3.6 at the thesis's own 10 ms RK4 step, beyond RK4's stability
//! limit (−2.78): the thesis's SeaWorld could not have run. The thesis's
//! Eq. 11 calls the damped quantity "dl, the rate of extension (change of
//! length)"; read as the change of length *per step*, the constants are
//! Appendix B's values × 0.01 s in SI, which is what we use.
//!
//! **Pulses in proportion to the jellyfish's weight.** Appendix B's actuators
//! range over ±5 N (pulse) and ±0.5 N (steering) per dome mass, whatever the
//! jellyfish's size. With textbook drag and buoyancy those launch a SeaWorld
//! jellyfish about 0.6 m per one-second pulse (1.5 m/s at the peak): it
//! overshoots its 1 m ceiling on every pulse, idles there long enough to
//! recharge, and never tires, so Table 5's cycle of tracking and hovering
//! never happens (measured: over 120 s of SeaWorld no jellyfish hovered and
//! energy never fell below 0.87). Climbing at all needs the mean pulse force
//! to beat the submerged weight each dome mass carries (its own and its
//! tentacle's: 0.21, 0.31 and 0.46 N for the three SeaWorld jellyfish), so a
//! single fixed force suits one size only. Our pulse peaks at 4.5 times that
//! load (0.93–2.08 N), and steering ranges over a tenth of the pulse, as in
//! Appendix B: every size then rises to food above it, steers to food beside
//! it, and goes through tracking, tiring, hovering and recovering. The scene
//! keys `pulse_force` and `steer_force` set Appendix B's absolute values.
//! See docs/SEAWORLD.md for the measurements.

use animats_engine::math;
use animats_engine::{
    ConstantForceId, DVec3, ModelError, ParticleDef, ParticleId, SpringDef, SpringId, World,
};
use std::f64::consts::TAU;

/// The thesis's SeaWorld step, s: Appendix B's spring damping is per step.
pub const THESIS_STEP: f64 = 0.01;

/// Peak pulse force per dome mass, as a multiple of the submerged weight the
/// dome mass carries (see the module notes).
pub const PULSE_STRENGTH: f64 = 4.5;

/// Appendix B's constants (the masses are per jellyfish).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JellyfishConstants {
    /// Mass of each dome mass, kg (SeaWorld: 0.2, 0.3, 0.15).
    pub dome_mass: f64,
    /// Mass of each tentacle segment, kg (SeaWorld: 0.02, 0.03, 0.011).
    pub tentacle_mass: f64,
    /// Dome tissue density, kg/m³ (1100: a little denser than water).
    pub dome_density: f64,
    /// Tentacle density, kg/m³ (1200).
    pub tentacle_density: f64,
    /// Radius of the dome ring, m (0.03).
    pub dome_radius: f64,
    /// Dome ring springs: stiffness N/m, damping N s/m (50, 0.05: Appendix
    /// B's 5 per 10 ms step; see the module notes).
    pub dome_spring: (f64, f64),
    /// Tentacle springs: stiffness N/m, damping N s/m (20, 0.01: Appendix
    /// B's 1 per 10 ms step).
    pub tentacle_spring: (f64, f64),
    /// Tentacle segment length, m (0.1).
    pub tentacle_segment: f64,
    /// Tentacles (one per dome mass) and segments per tentacle (3, 4).
    pub tentacles: usize,
    /// Segments per tentacle (4).
    pub segments: usize,
    /// Pulse force range per dome mass, N (Appendix B: ±5; ours: ±4.5× the
    /// submerged weight the dome mass carries, see the module notes).
    pub pulse_force: f64,
    /// Steering force range per dome mass, N (a tenth of the pulse's, as in
    /// Appendix B's ±0.5 against ±5).
    pub steer_force: f64,
    /// Duration of one pulse, s (1).
    pub pulse_period: f64,
    /// Height its depth sense reads as 1 ("too high"), m: Appendix B's 1 m,
    /// or the water surface.
    pub ceiling: f64,
}

impl JellyfishConstants {
    /// Appendix B's jellyfish with the given masses.
    pub fn new(dome_mass: f64, tentacle_mass: f64) -> Self {
        let mut c = JellyfishConstants {
            dome_mass,
            tentacle_mass,
            dome_density: 1100.0,
            tentacle_density: 1200.0,
            dome_radius: 0.03,
            dome_spring: (50.0, 5.0 * THESIS_STEP),
            tentacle_spring: (20.0, 1.0 * THESIS_STEP),
            tentacle_segment: 0.1,
            tentacles: 3,
            segments: 4,
            pulse_force: 0.0,
            steer_force: 0.0,
            pulse_period: 1.0,
            ceiling: 1.0,
        };
        c.pulse_force = PULSE_STRENGTH * c.load(9.8, 1000.0);
        c.steer_force = 0.1 * c.pulse_force;
        c
    }

    /// The submerged weight each dome mass carries (its own and its
    /// tentacle's, minus buoyancy) in water of density `rho` under gravity
    /// `g`, N.
    pub fn load(&self, g: f64, rho: f64) -> f64 {
        let wet = |m: f64, density: f64| m * g * (1.0 - rho / density);
        wet(self.dome_mass, self.dome_density)
            + self.segments as f64 * wet(self.tentacle_mass, self.tentacle_density)
    }

    /// Checks the constants; the error names the field.
    pub fn validate(&self) -> Result<(), ModelError> {
        let positive = |field: &str, x: f64| {
            if x > 0.0 && x.is_finite() {
                Ok(())
            } else {
                Err(ModelError::new(field, format!("must be > 0, got {x}")))
            }
        };
        positive("dome_mass", self.dome_mass)?;
        positive("tentacle_mass", self.tentacle_mass)?;
        positive("dome_density", self.dome_density)?;
        positive("tentacle_density", self.tentacle_density)?;
        positive("dome_radius", self.dome_radius)?;
        positive("tentacle_segment", self.tentacle_segment)?;
        positive("pulse_period", self.pulse_period)?;
        positive("ceiling", self.ceiling)?;
        if !(self.pulse_force >= 0.0 && self.steer_force >= 0.0 && self.steer_force.is_finite()) {
            return Err(ModelError::new(
                "pulse_force",
                "force ranges must be finite and >= 0",
            ));
        }
        if self.tentacles < 3 {
            return Err(ModelError::new(
                "tentacles",
                "a dome needs at least 3 masses",
            ));
        }
        if self.segments == 0 {
            return Err(ModelError::new(
                "segments",
                "a tentacle needs at least one segment",
            ));
        }
        Ok(())
    }
}

/// Handles to one jellyfish's parts.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// The dome masses, around the ring.
    pub dome: Vec<ParticleId>,
    /// Tentacle masses, tentacle by tentacle, top to bottom.
    pub tentacles: Vec<ParticleId>,
    /// The ring springs, `dome[i]`–`dome[i+1]`.
    pub ring: Vec<SpringId>,
    /// The pulse force on every dome mass.
    pub pulse: ConstantForceId,
    /// One steering force per dome mass.
    pub steer: Vec<ConstantForceId>,
}

impl Body {
    /// Centre of the dome.
    pub fn centre(&self, world: &World) -> DVec3 {
        self.dome.iter().map(|p| world.position(*p)).sum::<DVec3>() / self.dome.len() as f64
    }

    /// Unit normal of the dome (up for an upright jellyfish), from its first
    /// three masses as Appendix B computes it.
    pub fn normal(&self, world: &World) -> DVec3 {
        let p = |i: usize| world.position(self.dome[i]);
        // (p0 − p1) × (p2 − p0): the first and last ring spring vectors.
        (p(0) - p(1)).cross(p(2) - p(0)).normalize_or_zero()
    }
}

/// Builds a jellyfish with its dome centred at `at`.
pub fn build(world: &mut World, c: &JellyfishConstants, at: DVec3) -> Result<Body, ModelError> {
    c.validate()?;
    let sphere = |mass: f64, density: f64, x: DVec3| {
        ParticleDef::new(mass)
            .with_volume(mass / density)
            .at(x)
            .with_friction(0.6, 0.5)
            .with_restitution(0.6)
    };
    let n = c.tentacles;
    let mut dome = Vec::with_capacity(n);
    for i in 0..n {
        let a = TAU * i as f64 / n as f64;
        let x = at + DVec3::new(math::cos(a), 0.0, math::sin(a)) * c.dome_radius;
        dome.push(world.add_particle(sphere(c.dome_mass, c.dome_density, x))?);
    }
    let mut ring = Vec::with_capacity(n);
    for i in 0..n {
        let s = SpringDef::new(dome[i], dome[(i + 1) % n], c.dome_spring.0, c.dome_spring.1);
        ring.push(world.add_spring(s)?);
    }
    let mut tentacles = Vec::with_capacity(n * c.segments);
    for &top in &dome {
        let mut above = top;
        for j in 0..c.segments {
            let x = world.position(top) - DVec3::Y * (c.tentacle_segment * (j + 1) as f64);
            let seg = world.add_particle(sphere(c.tentacle_mass, c.tentacle_density, x))?;
            world.add_spring(
                SpringDef::new(seg, above, c.tentacle_spring.0, c.tentacle_spring.1)
                    .with_rest_length(c.tentacle_segment),
            )?;
            tentacles.push(seg);
            above = seg;
        }
    }
    let pulse = world.add_constant_force(dome.clone(), DVec3::ZERO)?;
    let steer = dome
        .iter()
        .map(|p| world.add_constant_force(vec![*p], DVec3::ZERO))
        .collect::<Result<_, _>>()?;
    Ok(Body {
        dome,
        tentacles,
        ring,
        pulse,
        steer,
    })
}
