//! `[floor]`: the plane y = 0 (collision and contact).

use super::*;

impl Build for FloorEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let f = self;
        let targets = cx.names.targets(at, &f.particles)?;
        cx.world
            .add_floor(FloorDef {
                envelope: f.envelope,
                static_speed: f.static_speed,
                rest_speed: f.rest_speed,
                targets,
                ..FloorDef::default()
            })
            .map_err(|e| at.model(e))?;

        Ok(())
    }
}
