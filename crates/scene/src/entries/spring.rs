//! `[[spring]]`.

use super::*;

impl Build for SpringEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let s = self;
        let sdef = SpringDef {
            a: cx.names.one(at, "a", &s.a)?,
            b: cx.names.one(at, "b", &s.b)?,
            stiffness: s.stiffness,
            damping: s.damping,
            rest_length: s.rest_length,
        };
        let id = cx.world.add_spring(sdef).map_err(|e| at.model(e))?;
        crate::nervous::insert(&mut cx.handles.springs, at, "spring", &s.name, id)?;

        Ok(())
    }
}
