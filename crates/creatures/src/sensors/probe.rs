//! The sensors a scene file declares (`[[sensor]]`): a physical reading
//! mapped linearly from [min, max] onto [0, 1] and clamped.

use crate::brain::finite;
use crate::sensor::{unit, Sensor};
use animats_engine::{DVec3, ModelError, ParticleId, World};
use serde::Deserialize;
use std::f64::consts::PI;

/// How close to the floor a sphere's lowest point must be to touch it, m.
/// Resting spheres sit within a micrometre of the plane; a sphere that hits
/// it is put back on it by the collision.
pub const TOUCH_TOLERANCE: f64 = 1e-3;

/// True while `p`'s surface is on or inside the floor (within
/// [`TOUCH_TOLERANCE`]; on terrain, of the terrain's surface).
pub fn touches_floor(world: &World, p: ParticleId) -> bool {
    world.touches_ground(p, TOUCH_TOLERANCE)
}

/// What is read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Probe {
    /// The y of a particle, m.
    Height(ParticleId),
    /// The velocity of a particle along a unit axis, m/s.
    Speed(ParticleId, DVec3),
    /// 1 while the particle touches the floor, else 0.
    Touch(ParticleId),
    /// The distance between two particles, m.
    Length(ParticleId, ParticleId),
    /// The angle at `joint` between `a` and `b`, rad in [0, π].
    Angle {
        /// End of the first arm.
        a: ParticleId,
        /// The vertex.
        joint: ParticleId,
        /// End of the second arm.
        b: ParticleId,
    },
    /// The angle of `a → b` from the vertical, rad in [0, π].
    Tilt(ParticleId, ParticleId),
}

impl Probe {
    /// The raw reading, in SI units.
    pub fn read(&self, world: &World) -> f64 {
        let p = |id: ParticleId| world.position(id);
        match *self {
            Probe::Height(q) => p(q).y,
            Probe::Speed(q, axis) => world.velocity(q).dot(axis),
            Probe::Touch(q) => {
                if touches_floor(world, q) {
                    1.0
                } else {
                    0.0
                }
            }
            Probe::Length(a, b) => p(a).distance(p(b)),
            Probe::Angle { a, joint, b } => {
                animats_engine::forces::angle_joint::angle_at(p(a), p(joint), p(b))
            }
            Probe::Tilt(a, b) => {
                let v = p(b) - p(a);
                let horizontal = (v.x * v.x + v.z * v.z).sqrt();
                animats_engine::math::atan2(horizontal, v.y)
            }
        }
    }
}

/// A probe whose reading maps from [min, max] onto [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaledSensor {
    /// What is read.
    pub probe: Probe,
    /// The reading that gives level 0.
    pub min: f64,
    /// The reading that gives level 1.
    pub max: f64,
}

impl Sensor for ScaledSensor {
    fn level(&self, world: &World) -> f64 {
        unit((self.probe.read(world) - self.min) / (self.max - self.min))
    }
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

/// `[[sensor]]`: a reading mapped linearly from [`min`, `max`] onto [0, 1],
/// of the kind its `kind` key names. Every kind takes `name`, `min`
/// (default 0) and `max` (default 1; π for `angle` and `tilt`).
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum SensorEntry {
    /// The y of `particle`, m.
    Height(OneParticle),
    /// 1 while `particle` touches the floor, else 0.
    Touch(OneParticle),
    /// The velocity of `particle` along `axis` (default `[1, 0, 0]`), m/s.
    Speed(SpeedEntry),
    /// The distance between `a` and `b`, m.
    Length(TwoParticles),
    /// The angle at `joint` between `a` and `b`, rad.
    Angle(AngleEntry),
    /// The angle of `a → b` from the vertical, rad.
    Tilt(TwoParticles),
}

/// A sensor of one particle.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OneParticle {
    /// Unique among sensors.
    pub name: String,
    /// The particle read.
    pub particle: String,
    /// The reading at level 0.
    pub min: Option<f64>,
    /// The reading at level 1.
    pub max: Option<f64>,
}

/// `kind = "speed"`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedEntry {
    /// Unique among sensors.
    pub name: String,
    /// The particle read.
    pub particle: String,
    /// The direction; default `[1, 0, 0]`.
    pub axis: Option<[f64; 3]>,
    /// The reading at level 0.
    pub min: Option<f64>,
    /// The reading at level 1.
    pub max: Option<f64>,
}

/// A sensor of two particles.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoParticles {
    /// Unique among sensors.
    pub name: String,
    /// The first particle.
    pub a: String,
    /// The second.
    pub b: String,
    /// The reading at level 0.
    pub min: Option<f64>,
    /// The reading at level 1.
    pub max: Option<f64>,
}

/// `kind = "angle"`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngleEntry {
    /// Unique among sensors.
    pub name: String,
    /// End of the first arm.
    pub a: String,
    /// The vertex.
    pub joint: String,
    /// End of the second arm.
    pub b: String,
    /// The reading at level 0.
    pub min: Option<f64>,
    /// The reading at level 1.
    pub max: Option<f64>,
}

impl SensorEntry {
    /// Its name.
    pub fn name(&self) -> &str {
        match self {
            SensorEntry::Height(e) | SensorEntry::Touch(e) => &e.name,
            SensorEntry::Speed(e) => &e.name,
            SensorEntry::Length(e) | SensorEntry::Tilt(e) => &e.name,
            SensorEntry::Angle(e) => &e.name,
        }
    }

    /// The sensor it describes; `particle` resolves a particle's name
    /// given in `field`.
    pub fn build(
        &self,
        particle: impl Fn(&str, &str) -> Result<ParticleId, ModelError>,
    ) -> Result<ScaledSensor, ModelError> {
        let p = |field: &str, name: &String| particle(field, name);
        let (probe, min, max, full) = match self {
            SensorEntry::Height(e) => (
                Probe::Height(p("particle", &e.particle)?),
                e.min,
                e.max,
                1.0,
            ),
            SensorEntry::Touch(e) => (Probe::Touch(p("particle", &e.particle)?), e.min, e.max, 1.0),
            SensorEntry::Speed(e) => {
                let axis = e.axis.unwrap_or([1.0, 0.0, 0.0]);
                if !axis.iter().all(|x| x.is_finite()) {
                    return Err(ModelError::new(
                        "axis",
                        format!("must be finite, got {axis:?}"),
                    ));
                }
                let axis = DVec3::from_array(axis);
                if axis.length() == 0.0 {
                    return Err(ModelError::new("axis", "must not be zero"));
                }
                let probe = Probe::Speed(p("particle", &e.particle)?, axis.normalize());
                (probe, e.min, e.max, 1.0)
            }
            SensorEntry::Length(e) => (
                Probe::Length(p("a", &e.a)?, p("b", &e.b)?),
                e.min,
                e.max,
                1.0,
            ),
            SensorEntry::Angle(e) => {
                let probe = Probe::Angle {
                    a: p("a", &e.a)?,
                    joint: p("joint", &e.joint)?,
                    b: p("b", &e.b)?,
                };
                (probe, e.min, e.max, PI)
            }
            SensorEntry::Tilt(e) => (Probe::Tilt(p("a", &e.a)?, p("b", &e.b)?), e.min, e.max, PI),
        };
        let min = finite("min", min.unwrap_or(0.0))?;
        let max = finite("max", max.unwrap_or(full))?;
        if min == max {
            return Err(ModelError::new(
                "max",
                format!("must differ from min ({min})"),
            ));
        }
        Ok(ScaledSensor { probe, min, max })
    }
}
