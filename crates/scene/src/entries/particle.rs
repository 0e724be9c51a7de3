//! `[[particle]]`: a named sphere.

use super::*;

/// `[[particle]]`: a sphere.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleEntry {
    /// Unique; forces refer to particles by name.
    pub name: String,
    /// kg, > 0.
    pub mass: f64,
    /// m.
    pub position: [f64; 3],
    /// m/s, default 0.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// m; or `volume`; at least one.
    pub radius: Option<f64>,
    /// m³; or `radius`; at least one.
    pub volume: Option<f64>,
    /// Default 0.5.
    #[serde(default = "default_mu_s")]
    pub mu_s: f64,
    /// Default 0.3.
    #[serde(default = "default_mu_k")]
    pub mu_k: f64,
    /// 0..=1, default 0.5.
    #[serde(default = "default_restitution")]
    pub restitution: f64,
    /// Nailed in place; default false.
    #[serde(default)]
    pub fixed: bool,
}

fn default_mu_s() -> f64 {
    0.5
}

fn default_mu_k() -> f64 {
    0.3
}

fn default_restitution() -> f64 {
    0.5
}

impl Build for ParticleEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let p = self;
        room(at, "", 1, &cx.world)?;
        check_name(at, &p.name)?;
        if cx.names.ids.contains_key(&p.name) {
            return Err(at.err("name", format!("duplicate particle name `{}`", p.name)));
        }
        if p.radius.is_none() && p.volume.is_none() {
            return Err(at.err(
                "radius",
                "give the particle a `radius` or a `volume` (or both)",
            ));
        }
        let pdef = ParticleDef {
            mass: p.mass,
            position: DVec3::from_array(p.position),
            velocity: DVec3::from_array(p.velocity),
            radius: p.radius,
            volume: p.volume,
            mu_s: p.mu_s,
            mu_k: p.mu_k,
            restitution: p.restitution,
            fixed: p.fixed,
        };
        let id = cx.world.add_particle(pdef).map_err(|e| at.model(e))?;
        cx.names.ids.insert(p.name.clone(), id);
        cx.list.push(p.name.clone());
        cx.kinds.push(PartKind::Particle);

        Ok(())
    }
}
