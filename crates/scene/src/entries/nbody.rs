//! `[[nbody]]`: mutual gravitation.

use super::*;

impl Build for NBodyEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let n = self;
        let targets = cx.names.targets(at, &n.particles)?;
        cx.world
            .add_nbody(NBodyGravity::new(n.g, n.softening, targets))
            .map_err(|e| at.model(e))?;

        Ok(())
    }
}
