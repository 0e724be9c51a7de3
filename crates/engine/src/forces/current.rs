//! The velocity of a fluid as a field over space and time (thesis §3.1.2.8):
//! still water or air, a uniform stream, or [`ReefWater`]'s swaying currents.

use glam::DVec3;
use std::f64::consts::TAU;

/// Velocity of the fluid at each point and time.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum Current {
    /// The fluid is at rest.
    #[default]
    Still,
    /// The fluid moves everywhere with this velocity, m/s.
    Uniform(DVec3),
    /// Swaying currents under passing waves.
    Reef(ReefWater),
}

impl Current {
    /// Fluid velocity at `p` and time `t`, m/s.
    #[inline]
    pub fn velocity(&self, p: DVec3, t: f64) -> DVec3 {
        match self {
            Current::Still => DVec3::ZERO,
            Current::Uniform(v) => *v,
            Current::Reef(r) => r.velocity(p, t),
        }
    }
}

/// Water some distance below a train of surface waves: each parcel of water
/// moves in a circle whose radius shrinks exponentially with depth, so the
/// current sways back and forth (and up and down) with the wave period and
/// varies along the direction the waves travel.
///
/// This is linear (Airy) deep-water wave theory: with wavenumber `k = 2π/λ`,
/// angular frequency `ω = 2π/T`, depth below the mean surface `d` and phase
/// `φ = k (ŝ·p) - ω t`, the velocity is
/// `u = A ω e^{-k d} (cos φ ŝ + sin φ ŷ) + drift`. The thesis's `ReefWater`
/// source is not in the thesis; this is our reading of "currents similar to
/// those found on a coral reef some distance below the waves".
#[derive(Clone, Debug, PartialEq)]
pub struct ReefWater {
    /// Height of the mean water surface, m (above it the decay factor is 1).
    pub surface: f64,
    /// Wave amplitude at the surface, m.
    pub amplitude: f64,
    /// Wavelength, m.
    pub wavelength: f64,
    /// Wave period, s.
    pub period: f64,
    /// Horizontal direction the waves travel (normalised on use).
    pub direction: DVec3,
    /// A steady current added everywhere, m/s.
    pub drift: DVec3,
}

impl ReefWater {
    /// The period of deep-water waves of this wavelength under gravity `g`
    /// (dispersion relation `ω² = g k`).
    pub fn deep_water_period(wavelength: f64, g: f64) -> f64 {
        TAU / (g * TAU / wavelength).sqrt()
    }

    /// Fluid velocity at `p` and time `t`, m/s.
    #[inline]
    pub fn velocity(&self, p: DVec3, t: f64) -> DVec3 {
        let k = TAU / self.wavelength;
        let omega = TAU / self.period;
        let dir = DVec3::new(self.direction.x, 0.0, self.direction.z).normalize_or_zero();
        let depth = (self.surface - p.y).max(0.0);
        // libm: the same bits on every platform, for reproducible runs.
        let speed = self.amplitude * omega * crate::math::exp(-k * depth);
        let (s, c) = crate::math::sincos(k * dir.dot(p) - omega * t);
        dir * (speed * c) + DVec3::Y * (speed * s) + self.drift
    }
}

impl Default for ReefWater {
    /// Waves 3 m long with 0.1 m amplitude over a surface at 1.5 m (period
    /// 1.39 s): the water sways at about 10 cm/s 0.75 m down and 2 cm/s at
    /// the sea floor, 1.5 m down.
    fn default() -> Self {
        ReefWater {
            surface: 1.5,
            amplitude: 0.1,
            wavelength: 3.0,
            period: ReefWater::deep_water_period(3.0, 9.8),
            direction: DVec3::X,
            drift: DVec3::ZERO,
        }
    }
}
