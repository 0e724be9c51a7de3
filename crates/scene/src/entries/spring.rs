//! `[[spring]]`.

use super::*;

/// `[[spring]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringEntry {
    /// Optional, unique among its kind: actuators refer to it by name.
    pub name: Option<String>,
    /// One end (a particle name).
    pub a: String,
    /// The other end.
    pub b: String,
    /// N/m, >= 0.
    pub stiffness: f64,
    /// N s/m, >= 0, default 0.
    #[serde(default)]
    pub damping: f64,
    /// m, > 0; default the initial distance.
    pub rest_length: Option<f64>,
}

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
