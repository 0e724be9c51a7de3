//! A column of rising bubbles (thesis §3.2.2.5, Appendix B `BubbleCollumn`):
//! a true particle system with a fixed pool of bubbles. At random intervals a
//! bubble is spawned at the column's base with a random volume by recycling
//! the topmost one (the thesis's scheme), and a bubble that leaves the water
//! is recycled at once; so the number of bubbles never changes.
//!
//! Appendix B constructs `BubbleCollumn(15, 0.1, 0.4, base)`; its class is
//! not in the appendix, so we read the numbers as 15 bubbles spawned every
//! 0.1–0.4 s. A bubble's particle mass includes the *added mass* of the water
//! it drags along (½ ρ_water V for a sphere), which an engine of point masses
//! does not model otherwise: with only the air's mass a bubble's drag time
//! constant would be tens of microseconds and no practical step could
//! integrate it. Its effective density is therefore about 500 kg/m³; it rises
//! at a few tens of cm/s, like a real bubble of a few millimetres.

use crate::controller::Actor;
use crate::random::Random;
use animats_engine::{DVec3, ModelError, ParticleDef, ParticleId, World};
use std::f64::consts::PI;

/// A bubble column's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BubbleConstants {
    /// Bubbles in the pool (thesis: 15).
    pub bubbles: usize,
    /// Time between spawns, uniform in this range, s (thesis: 0.1–0.4).
    pub interval: (f64, f64),
    /// Bubble radius, uniform in volume between these radii, m.
    pub radius: (f64, f64),
    /// Effective density including added mass, kg/m³.
    pub density: f64,
    /// Height of the water surface, m: bubbles above it are recycled.
    pub surface: f64,
    /// Horizontal scatter of spawn points around the base, m.
    pub spread: f64,
}

impl Default for BubbleConstants {
    fn default() -> Self {
        BubbleConstants {
            bubbles: 15,
            interval: (0.1, 0.4),
            radius: (0.002, 0.005),
            density: 500.0,
            surface: 1.5,
            spread: 0.01,
        }
    }
}

impl BubbleConstants {
    /// Checks the constants; the error names the field.
    pub fn validate(&self) -> Result<(), ModelError> {
        if self.bubbles == 0 {
            return Err(ModelError::new(
                "bubbles",
                "a column needs at least one bubble",
            ));
        }
        let range = |field: &str, (lo, hi): (f64, f64)| {
            if lo > 0.0 && hi >= lo && hi.is_finite() {
                Ok(())
            } else {
                Err(ModelError::new(
                    field,
                    format!("needs 0 < min <= max, got [{lo}, {hi}]"),
                ))
            }
        };
        range("interval", self.interval)?;
        range("radius", self.radius)?;
        if !(self.density > 0.0 && self.density.is_finite()) {
            return Err(ModelError::new(
                "density",
                format!("must be > 0, got {}", self.density),
            ));
        }
        if !(self.surface > 0.0 && self.surface.is_finite()) {
            return Err(ModelError::new(
                "surface",
                format!("must be > 0, got {}", self.surface),
            ));
        }
        if !(self.spread >= 0.0 && self.spread.is_finite()) {
            return Err(ModelError::new(
                "spread",
                format!("must be >= 0, got {}", self.spread),
            ));
        }
        Ok(())
    }
}

/// A bubble column in a world: an actor that spawns and recycles bubbles.
#[derive(Clone, Debug)]
pub struct BubbleColumn {
    /// Its bubbles.
    pub bubbles: Vec<ParticleId>,
    base: DVec3,
    c: BubbleConstants,
    random: Random,
    next_spawn: f64,
    recycled: u64,
}

impl BubbleColumn {
    /// Builds a column at `base` (on the floor), its bubbles spread up the
    /// column so it looks running from the start.
    pub fn build(
        world: &mut World,
        c: &BubbleConstants,
        base: DVec3,
        mut random: Random,
    ) -> Result<Self, ModelError> {
        c.validate()?;
        let mut bubbles = Vec::with_capacity(c.bubbles);
        for k in 0..c.bubbles {
            let (mass, volume) = Self::draw(c, &mut random);
            let y = c.surface * (k as f64 + random.uniform()) / c.bubbles as f64;
            let at = base + Self::scatter(c, &mut random) + DVec3::Y * y.min(c.surface * 0.999);
            let def = ParticleDef::new(mass)
                .with_volume(volume)
                .at(at)
                .with_restitution(0.0);
            bubbles.push(world.add_particle(def)?);
        }
        let next_spawn = world.time() + random.between(c.interval.0, c.interval.1);
        Ok(BubbleColumn {
            bubbles,
            base,
            c: *c,
            random,
            next_spawn,
            recycled: 0,
        })
    }

    /// Bubbles recycled so far.
    pub fn recycled(&self) -> u64 {
        self.recycled
    }

    fn draw(c: &BubbleConstants, random: &mut Random) -> (f64, f64) {
        let v = |r: f64| 4.0 / 3.0 * PI * r * r * r;
        let volume = random.between(v(c.radius.0), v(c.radius.1));
        (c.density * volume, volume)
    }

    fn scatter(c: &BubbleConstants, random: &mut Random) -> DVec3 {
        DVec3::new(
            random.between(-c.spread, c.spread),
            0.0,
            random.between(-c.spread, c.spread),
        )
    }

    /// Moves `bubble` back to the base with a fresh random volume.
    fn respawn(&mut self, world: &mut World, bubble: ParticleId) {
        let (mass, volume) = Self::draw(&self.c, &mut self.random);
        // The column's own bubble, with a mass and volume drawn from ranges
        // validated when it was built: these cannot be refused.
        let _ = world.set_mass(bubble, mass);
        let _ = world.set_volume(bubble, volume);
        let r = world.particles().radius[bubble.index()];
        let at = self.base + Self::scatter(&self.c, &mut self.random) + DVec3::Y * r;
        let _ = world.set_position(bubble, at);
        let _ = world.set_velocity(bubble, DVec3::ZERO);
        self.recycled += 1;
    }
}

impl Actor for BubbleColumn {
    /// Its random stream, when the next bubble rises, how many rose.
    fn save_state(&self) -> Option<crate::kept::Kept> {
        Some(crate::kept::Kept::new((
            self.random.clone(),
            self.next_spawn,
            self.recycled,
        )))
    }

    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        let (random, next, recycled) =
            crate::kept::required::<(Random, f64, u64)>(kept, "a bubble column")?;
        (self.random, self.next_spawn, self.recycled) = (random.clone(), *next, *recycled);
        Ok(())
    }

    fn act(&mut self, world: &mut World, _dt: f64) {
        // Bubbles that left the water go back to the base.
        for i in 0..self.bubbles.len() {
            let b = self.bubbles[i];
            if world.position(b).y > self.c.surface {
                self.respawn(world, b);
            }
        }
        // A new bubble: the topmost is recycled (Appendix B's scheme).
        while world.time() >= self.next_spawn {
            let top = self
                .bubbles
                .iter()
                .copied()
                .max_by(|a, b| world.position(*a).y.total_cmp(&world.position(*b).y));
            if let Some(top) = top {
                self.respawn(world, top);
            }
            self.next_spawn += self.random.between(self.c.interval.0, self.c.interval.1);
        }
    }
}
