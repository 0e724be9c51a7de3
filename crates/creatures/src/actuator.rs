//! The `Actuator` class (thesis §2.3.2.3, §4.2.1): maps an activation level in
//! [0, 1] onto a physical parameter in [min, max] — a spring's rest length, a
//! motor's torque, a force's magnitude — remembers the level matching the
//! parameter's initial value, and returns to it on `reset`.

use animats_engine::World;

/// A physical parameter of a world that an actuator drives (one file per kind
/// in `actuators/`).
pub trait Actuated {
    /// The parameter's current value.
    fn get(&self, world: &World) -> f64;
    /// Sets the parameter.
    fn set(&self, world: &mut World, value: f64);
}

/// Drives one parameter through a level in [0, 1] mapped linearly onto
/// [min, max].
#[derive(Clone, Debug, PartialEq)]
pub struct Actuator<T> {
    target: T,
    min: f64,
    max: f64,
    initial_level: f64,
    level: f64,
}

impl<T: Actuated> Actuator<T> {
    /// An actuator over [min, max] whose initial level matches the
    /// parameter's value in `world` now (clamped into the range).
    pub fn new(target: T, min: f64, max: f64, world: &World) -> Self {
        let span = max - min;
        let level = if span != 0.0 {
            (target.get(world) - min) / span
        } else {
            0.0
        };
        let level = crate::sensor::unit(level);
        Actuator {
            target,
            min,
            max,
            initial_level: level,
            level,
        }
    }

    /// An actuator over [min, max] that starts at `level` (clamped to
    /// [0, 1]) and drives the parameter there now; `reset` returns to it.
    pub fn with_level(target: T, min: f64, max: f64, level: f64, world: &mut World) -> Self {
        let level = crate::sensor::unit(level);
        let mut a = Actuator {
            target,
            min,
            max,
            initial_level: level,
            level,
        };
        a.reapply(world);
        a
    }

    /// Sets the level (clamped to [0, 1]) and drives the parameter.
    pub fn set_level(&mut self, world: &mut World, level: f64) {
        self.level = crate::sensor::unit(level);
        self.target.set(world, self.value());
    }

    /// The current level.
    pub fn level(&self) -> f64 {
        self.level
    }

    /// Sets the level without touching the world: for a snapshot's
    /// restore, whose world holds the value the level gave.
    pub fn set_level_alone(&mut self, level: f64) {
        self.level = crate::sensor::unit(level);
    }

    /// The level the actuator started at.
    pub fn initial_level(&self) -> f64 {
        self.initial_level
    }

    /// The parameter value of the current level.
    pub fn value(&self) -> f64 {
        self.min + self.level * (self.max - self.min)
    }

    /// Returns to the initial level.
    pub fn reset(&mut self, world: &mut World) {
        let l = self.initial_level;
        self.set_level(world, l);
    }

    /// The driven parameter.
    pub fn target(&self) -> &T {
        &self.target
    }

    /// The driven parameter, to change how it is driven (a force's axis);
    /// the new setting takes effect at the next `set_level` or `reapply`.
    pub fn target_mut(&mut self) -> &mut T {
        &mut self.target
    }

    /// Drives the parameter again at the current level (after `target_mut`).
    pub fn reapply(&mut self, world: &mut World) {
        self.target.set(world, self.value());
    }

    /// The range [min, max].
    pub fn range(&self) -> (f64, f64) {
        (self.min, self.max)
    }
}
