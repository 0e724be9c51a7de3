//! `[contacts]`: sphere–sphere contact among the scene's spheres, built
//! last, so that every spring and joint of every entry is known and the pairs
//! they join are excluded.

use super::*;

impl Build for ContactsEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let targets = cx.names.targets(at, &self.particles)?;
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
