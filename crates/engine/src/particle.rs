//! Point masses: the thesis's `SpherePointMass`, stored as a structure of arrays.
//!
//! A world's particles live in parallel arrays indexed by [`ParticleId`]: the hot
//! state (positions, velocities) in [`State`], the cold properties (mass, radius,
//! friction...) in [`Properties`]. Forces and integrators work on slices of these
//! arrays; nobody holds a reference to "a particle".

use crate::error::ModelError;
use glam::DVec3;
use std::f64::consts::PI;

/// A small copyable handle to one particle of a [`World`](crate::World).
///
/// Handles are indices: they stay valid for the life of the world that issued
/// them (particles are never removed, only recycled by their owners).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ParticleId(pub(crate) u32);

impl ParticleId {
    /// The index of this particle in the world's arrays.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// The handle of the particle at `index`; meaningful only for an index the
    /// world issued (`0..world.len()`).
    #[inline]
    pub fn from_index(index: usize) -> Self {
        ParticleId(index as u32)
    }
}

/// Everything needed to create a particle; build one with [`ParticleDef::new`]
/// and the `with_*` methods, then pass it to
/// [`World::add_particle`](crate::World::add_particle).
///
/// A particle is a sphere: give its radius or its volume and the other follows;
/// give both for a body whose drag area and buoyant volume are set apart. Give
/// neither and it is a point (radius and volume zero), which floats on nothing
/// and collides with the floor at its centre.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleDef {
    /// kg, > 0.
    pub mass: f64,
    /// m.
    pub position: DVec3,
    /// m/s.
    pub velocity: DVec3,
    /// m, >= 0.
    pub radius: Option<f64>,
    /// m^3, >= 0.
    pub volume: Option<f64>,
    /// Coefficient of static friction against the floor, >= 0.
    pub mu_s: f64,
    /// Coefficient of kinetic friction against the floor, >= 0.
    pub mu_k: f64,
    /// Coefficient of restitution against the floor, in 0..=1.
    pub restitution: f64,
    /// Nailed in place (the thesis's `WorldNail`): never moves.
    pub fixed: bool,
}

impl ParticleDef {
    /// A point of the given mass at the origin, at rest, with the defaults of
    /// the scene format (mu_s 0.5, mu_k 0.3, restitution 0.5).
    pub fn new(mass: f64) -> Self {
        ParticleDef {
            mass,
            position: DVec3::ZERO,
            velocity: DVec3::ZERO,
            radius: None,
            volume: None,
            mu_s: 0.5,
            mu_k: 0.3,
            restitution: 0.5,
            fixed: false,
        }
    }
    /// Sets the initial position.
    pub fn at(mut self, position: DVec3) -> Self {
        self.position = position;
        self
    }
    /// Sets the initial velocity.
    pub fn with_velocity(mut self, velocity: DVec3) -> Self {
        self.velocity = velocity;
        self
    }
    /// Sets the radius (the volume follows unless also given).
    pub fn with_radius(mut self, radius: f64) -> Self {
        self.radius = Some(radius);
        self
    }
    /// Sets the volume (the radius follows unless also given).
    pub fn with_volume(mut self, volume: f64) -> Self {
        self.volume = Some(volume);
        self
    }
    /// Sets the friction coefficients against the floor.
    pub fn with_friction(mut self, mu_s: f64, mu_k: f64) -> Self {
        self.mu_s = mu_s;
        self.mu_k = mu_k;
        self
    }
    /// Sets the coefficient of restitution against the floor.
    pub fn with_restitution(mut self, restitution: f64) -> Self {
        self.restitution = restitution;
        self
    }
    /// Nails the particle in place.
    pub fn fixed(mut self) -> Self {
        self.fixed = true;
        self
    }

    /// Checks every field; the error names the field at fault.
    pub fn validate(&self) -> Result<(), ModelError> {
        positive("mass", self.mass)?;
        finite_vec("position", self.position)?;
        finite_vec("velocity", self.velocity)?;
        if let Some(r) = self.radius {
            non_negative("radius", r)?;
        }
        if let Some(v) = self.volume {
            non_negative("volume", v)?;
        }
        non_negative("mu_s", self.mu_s)?;
        non_negative("mu_k", self.mu_k)?;
        finite("restitution", self.restitution)?;
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(ModelError::new(
                "restitution",
                format!("must be between 0 and 1, got {}", self.restitution),
            ));
        }
        Ok(())
    }

    /// Radius and volume, each following from the other where only one is given.
    pub fn radius_and_volume(&self) -> (f64, f64) {
        match (self.radius, self.volume) {
            (Some(r), Some(v)) => (r, v),
            (Some(r), None) => (r, sphere_volume(r)),
            (None, Some(v)) => (sphere_radius(v), v),
            (None, None) => (0.0, 0.0),
        }
    }
}

/// Volume of a sphere of radius `r`.
pub fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * PI * r * r * r
}

/// Radius of a sphere of volume `v`.
pub fn sphere_radius(v: f64) -> f64 {
    crate::math::cbrt(3.0 * v / (4.0 * PI))
}

pub(crate) fn finite(field: &'static str, x: f64) -> Result<(), ModelError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(ModelError::new(
            field,
            format!("must be a finite number, got {}", crate::Shown(x)),
        ))
    }
}

pub(crate) fn finite_vec(field: &'static str, v: DVec3) -> Result<(), ModelError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ModelError::new(
            field,
            format!("must be finite, got [{}, {}, {}]", v.x, v.y, v.z),
        ))
    }
}

pub(crate) fn positive(field: &'static str, x: f64) -> Result<(), ModelError> {
    finite(field, x)?;
    if x > 0.0 {
        Ok(())
    } else {
        Err(ModelError::new(
            field,
            format!("must be > 0, got {}", crate::Shown(x)),
        ))
    }
}

pub(crate) fn non_negative(field: &'static str, x: f64) -> Result<(), ModelError> {
    finite(field, x)?;
    if x >= 0.0 {
        Ok(())
    } else {
        Err(ModelError::new(
            field,
            format!("must be >= 0, got {}", crate::Shown(x)),
        ))
    }
}

/// The dynamic state of every particle: what an integrator advances and what a
/// backtrack throws away.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct State {
    /// Positions, m.
    pub pos: Vec<DVec3>,
    /// Velocities, m/s.
    pub vel: Vec<DVec3>,
}

impl State {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.pos.len()
    }
    /// True when there are no particles.
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }
    /// Makes room for `n` particles (a test inlined into the step; the
    /// growing is out of line).
    #[inline(always)]
    pub(crate) fn resize(&mut self, n: usize) {
        if self.pos.len() != n || self.vel.len() != n {
            self.grow(n);
        }
    }

    #[cold]
    fn grow(&mut self, n: usize) {
        self.pos.resize(n, DVec3::ZERO);
        self.vel.resize(n, DVec3::ZERO);
    }
}

/// The constant (or rarely changed) properties of every particle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Properties {
    /// kg.
    pub mass: Vec<f64>,
    /// 1/kg; zero for a fixed particle, so integrators never move it.
    pub inv_mass: Vec<f64>,
    /// m.
    pub radius: Vec<f64>,
    /// m^3.
    pub volume: Vec<f64>,
    /// Static friction coefficient.
    pub mu_s: Vec<f64>,
    /// Kinetic friction coefficient.
    pub mu_k: Vec<f64>,
    /// Coefficient of restitution.
    pub restitution: Vec<f64>,
    /// Nailed in place.
    pub fixed: Vec<bool>,
    /// `inv_mass` repeated for each of x, y, z, so the integrators' updates
    /// run over positions, velocities and forces as flat arrays.
    pub(crate) inv_mass3: Vec<f64>,
}

impl Properties {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.mass.len()
    }
    /// True when there are no particles.
    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }
    /// Sets particle `i`'s inverse mass (and its three copies).
    pub(crate) fn set_inv_mass(&mut self, i: usize, w: f64) {
        self.inv_mass[i] = w;
        self.inv_mass3[3 * i..3 * i + 3].fill(w);
    }

    /// Cross-sectional area of particle `i` (a sphere).
    #[inline]
    pub fn area(&self, i: usize) -> f64 {
        PI * self.radius[i] * self.radius[i]
    }

    pub(crate) fn push(&mut self, def: &ParticleDef) {
        let (radius, volume) = def.radius_and_volume();
        self.mass.push(def.mass);
        let w = if def.fixed { 0.0 } else { 1.0 / def.mass };
        self.inv_mass.push(w);
        self.inv_mass3.extend([w; 3]);
        self.radius.push(radius);
        self.volume.push(volume);
        self.mu_s.push(def.mu_s);
        self.mu_k.push(def.mu_k);
        self.restitution.push(def.restitution);
        self.fixed.push(def.fixed);
    }
}
