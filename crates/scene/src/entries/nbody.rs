//! `[[nbody]]`: mutual gravitation.

use super::*;

/// `[[nbody]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NBodyEntry {
    /// Default: all particles.
    pub particles: Option<Vec<String>>,
    /// Gravitational constant; default 6.674e-11.
    #[serde(rename = "G", default = "default_big_g")]
    pub g: f64,
    /// m, default 0.
    #[serde(default)]
    pub softening: f64,
}

fn default_big_g() -> f64 {
    6.674e-11
}

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
