//! A frond of seaweed (thesis §3.2.2.5): a chain of point masses on springs,
//! each a little less dense than water so the frond floats upright, nailed
//! at its base; the current sways it. The thesis's `Seaweed` class is not in
//! its appendix; these constants are ours (docs/SEAWORLD.md).

use animats_engine::{DVec3, ModelError, ParticleDef, ParticleId, SpringDef, SpringId, World};

/// A frond's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeaweedConstants {
    /// Segments above the base (thesis: 12).
    pub segments: usize,
    /// Segment length, m.
    pub segment_length: f64,
    /// Mass of each segment, kg.
    pub mass: f64,
    /// Density of each segment, kg/m³ (slightly under water's 1000).
    pub density: f64,
    /// Spring stiffness, N/m.
    pub stiffness: f64,
    /// Spring damping, N s/m.
    pub damping: f64,
}

impl Default for SeaweedConstants {
    fn default() -> Self {
        SeaweedConstants {
            segments: 12,
            segment_length: 0.06,
            mass: 0.004,
            density: 980.0,
            stiffness: 10.0,
            damping: 0.02,
        }
    }
}

impl SeaweedConstants {
    /// Checks the constants; the error names the field.
    pub fn validate(&self) -> Result<(), ModelError> {
        if self.segments == 0 {
            return Err(ModelError::new(
                "segments",
                "a frond needs at least one segment",
            ));
        }
        for (field, x) in [
            ("segment_length", self.segment_length),
            ("mass", self.mass),
            ("density", self.density),
        ] {
            if !(x > 0.0 && x.is_finite()) {
                return Err(ModelError::new(field, format!("must be > 0, got {x}")));
            }
        }
        for (field, x) in [("stiffness", self.stiffness), ("damping", self.damping)] {
            if !(x >= 0.0 && x.is_finite()) {
                return Err(ModelError::new(field, format!("must be >= 0, got {x}")));
            }
        }
        Ok(())
    }
}

/// One frond in a world.
#[derive(Clone, Debug, PartialEq)]
pub struct Seaweed {
    /// The nailed base, then the segments bottom to top.
    pub particles: Vec<ParticleId>,
    /// The springs, bottom to top.
    pub springs: Vec<SpringId>,
}

impl Seaweed {
    /// The base (nailed to the floor).
    pub fn base(&self) -> ParticleId {
        self.particles[0]
    }
    /// The tip.
    pub fn tip(&self) -> ParticleId {
        self.particles[self.particles.len() - 1]
    }
}

/// Builds a frond standing straight up from `base` (on the floor).
pub fn build(world: &mut World, c: &SeaweedConstants, base: DVec3) -> Result<Seaweed, ModelError> {
    c.validate()?;
    let volume = c.mass / c.density;
    let part = |y: f64| {
        ParticleDef::new(c.mass)
            .with_volume(volume)
            .at(DVec3::new(base.x, y, base.z))
            .with_restitution(0.1)
    };
    let r = animats_engine::particle::sphere_radius(volume);
    let mut particles = vec![world.add_particle(part(r).fixed())?];
    let mut springs = Vec::with_capacity(c.segments);
    for k in 1..=c.segments {
        let p = world.add_particle(part(r + c.segment_length * k as f64))?;
        let below = particles[k - 1];
        springs.push(world.add_spring(SpringDef::new(below, p, c.stiffness, c.damping))?);
        particles.push(p);
    }
    Ok(Seaweed { particles, springs })
}
