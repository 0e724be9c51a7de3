//! `[[constant_force]]`.

use super::*;

/// `[[constant_force]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantForceEntry {
    /// Optional, unique among its kind: actuators refer to it by name.
    pub name: Option<String>,
    /// Default: all particles.
    pub particles: Option<Vec<String>>,
    /// N, on each.
    pub force: [f64; 3],
}

impl Build for ConstantForceEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let c = self;
        let ids = match cx.names.targets(at, &c.particles)? {
            Targets::All => cx.world.particle_ids().collect(),
            Targets::Only(ids) => ids,
        };
        let force = at.vec3("force", c.force)?;
        let id = cx
            .world
            .add_constant_force(ids, force)
            .map_err(|e| at.model(e))?;
        crate::nervous::insert(
            &mut cx.handles.constant_forces,
            at,
            "constant force",
            &c.name,
            (id, force),
        )?;

        Ok(())
    }
}
