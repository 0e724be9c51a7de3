//! Rocks (thesis §3.2.2.5, Appendix B `SeaWorld`): dense spheres of random
//! size dropped at random places; they sink and come to rest on the floor.
//! Appendix B: masses uniform in [0.05, 0.3] kg, density 2000 kg/m³, static
//! friction 0.9, kinetic 0.7, restitution 0.4, dropped from x, z in
//! [−0.5, 0.5] and y in [0.2, 1.2].

use crate::random::Random;
use animats_engine::{DVec3, ModelError, ParticleDef, ParticleId, Shown, World};

/// How to scatter rocks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RocksConstants {
    /// How many.
    pub count: usize,
    /// Mass range, kg.
    pub mass: (f64, f64),
    /// Density, kg/m³.
    pub density: f64,
    /// Corner of the box they are dropped from (least x, y, z).
    pub from: DVec3,
    /// Opposite corner.
    pub to: DVec3,
}

impl Default for RocksConstants {
    fn default() -> Self {
        RocksConstants {
            count: 10,
            mass: (0.05, 0.3),
            density: 2000.0,
            from: DVec3::new(-0.5, 0.2, -0.5),
            to: DVec3::new(0.5, 1.2, 0.5),
        }
    }
}

/// Drops `c.count` rocks, drawing from `random`.
pub fn scatter(
    world: &mut World,
    c: &RocksConstants,
    random: &mut Random,
) -> Result<Vec<ParticleId>, ModelError> {
    if !(c.mass.0 > 0.0 && c.mass.1 >= c.mass.0 && c.mass.1.is_finite()) {
        return Err(ModelError::new(
            "mass",
            format!("needs 0 < min <= max, got {:?}", c.mass),
        ));
    }
    if !(c.density > 0.0 && c.density.is_finite()) {
        return Err(ModelError::new(
            "density",
            format!("must be > 0, got {}", Shown(c.density)),
        ));
    }
    for (axis, a, z) in [
        ("x", c.from.x, c.to.x),
        ("y", c.from.y, c.to.y),
        ("z", c.from.z, c.to.z),
    ] {
        // A box turned inside out, or one too wide for its width to be a
        // number (from -1e308 to 1e308), would drop rocks at NaN.
        if !(a <= z && (z - a).is_finite()) {
            return Err(ModelError::new(
                "to",
                format!(
                    "must be at or beyond `from` along {axis}, within a finite width: from {}, to {}",
                    Shown(a),
                    Shown(z)
                ),
            ));
        }
    }
    (0..c.count)
        .map(|_| {
            let mass = random.between(c.mass.0, c.mass.1);
            let at = DVec3::new(
                random.between(c.from.x, c.to.x),
                random.between(c.from.y, c.to.y),
                random.between(c.from.z, c.to.z),
            );
            let def = ParticleDef::new(mass)
                .with_volume(mass / c.density)
                .at(at)
                .with_friction(0.9, 0.7)
                .with_restitution(0.4);
            world.add_particle(def)
        })
        .collect()
}
