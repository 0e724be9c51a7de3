//! `[floor]`: the plane y = 0 (collision and contact), or the shape
//! `[terrain]` gives it.

use super::*;

/// `[floor]`: the plane y = 0.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FloorEntry {
    /// m: deeper than this below the plane = missed; default 0.01.
    #[serde(default = "default_envelope")]
    pub envelope: f64,
    /// m/s: below this, static friction; default 0.01.
    #[serde(default = "default_static_speed")]
    pub static_speed: f64,
    /// m/s: impacts slower than this do not bounce; default 0.05.
    #[serde(default = "default_rest_speed")]
    pub rest_speed: f64,
    /// Default: all particles.
    pub particles: Option<Vec<String>>,
}

fn default_static_speed() -> f64 {
    0.01
}

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
                terrain: cx.terrain.take().unwrap_or_default(),
                ..FloorDef::default()
            })
            .map_err(|e| at.model(e))?;

        Ok(())
    }
}
