//! `[contacts]`: sphere–sphere contact among the scene's spheres, built
//! last, so that every spring and joint of every entry is known and the pairs
//! they join are excluded.

use super::*;

/// `[contacts]`: the spheres collide with each other (not only with the
/// floor); pairs joined by a spring or a joint never do.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactsEntry {
    /// The spheres that collide; default all.
    pub particles: Option<Vec<String>>,
    /// `impulse` (the event: overlaps removed, impulses with restitution
    /// and friction; for rigid rocks and balls) or `penalty` (a force
    /// `k δ − c u` along the line of centres, with no friction: for soft
    /// bodies, whose springs would otherwise store the event's
    /// displacements; what `[morphology]` bodies use); default `impulse`.
    #[serde(default)]
    pub model: ContactModel,
    /// `penalty`: N/m; default 5000.
    pub stiffness: Option<f64>,
    /// `penalty`: N s/m; default 2.
    pub damping: Option<f64>,
    /// The restitution of every contact, in [0, 1]; default the product of
    /// the two spheres' restitutions.
    pub restitution: Option<f64>,
    /// m: an overlap deeper than this = missed; default 0.01.
    #[serde(default = "default_envelope")]
    pub envelope: f64,
    /// m/s: approaches slower than this do not bounce; default 0.05.
    #[serde(default = "default_rest_speed")]
    pub rest_speed: f64,
    /// m/s: a sphere in contact that stays within `sleep_speed ·
    /// sleep_time` of one place for `sleep_time` falls asleep; default 0
    /// (never).
    #[serde(default)]
    pub sleep_speed: f64,
    /// s: default 0.5.
    #[serde(default = "default_sleep_time")]
    pub sleep_time: f64,
}

fn default_sleep_time() -> f64 {
    0.5
}

/// `[contacts] model`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum ContactModel {
    /// The sphere-contact event.
    #[default]
    Impulse,
    /// A penalty force.
    Penalty,
}

impl Build for ContactsEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let targets = cx.names.targets(at, &self.particles)?;
        if self.model == ContactModel::Penalty {
            let spheres: Vec<ParticleId> = match targets {
                Targets::All => cx.world.particle_ids().collect(),
                Targets::Only(ids) => ids,
            };
            let force = animats_engine::SoftContact::new(
                self.stiffness.unwrap_or(5000.0),
                self.damping.unwrap_or(2.0),
                &spheres,
                &cx.world.joined_pairs(),
            )
            .map_err(|e| at.model(e))?;
            cx.world.add_force(Box::new(force));
            return Ok(());
        }
        if self.stiffness.is_some() || self.damping.is_some() {
            return Err(at.err(
                if self.stiffness.is_some() { "stiffness" } else { "damping" },
                "is for model = \"penalty\"",
            ));
        }
        cx.world
            .add_sphere_contact(animats_engine::SphereContactDef {
                envelope: self.envelope,
                rest_speed: self.rest_speed,
                restitution: self.restitution,
                targets,
                excluded: Vec::new(),
                sleep_speed: self.sleep_speed,
                sleep_time: self.sleep_time,
            })
            .map_err(|e| at.model(e))?;
        Ok(())
    }
}
