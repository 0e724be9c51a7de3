//! `[[particle]]`: a named sphere.

use super::*;

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
