//! `[[food]]`: a nailed particle that jellyfish smell.

use super::*;

/// `[[food]]`: a fixed particle that jellyfish track.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FoodEntry {
    /// Default `food`.
    #[serde(default = "default_food")]
    pub name: String,
    /// m.
    pub position: [f64; 3],
    /// m; default 0.062 (Appendix B's volume of 1 litre).
    pub radius: Option<f64>,
}

impl Build for FoodEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let f = self;
        room(at, "", 1, &cx.world)?;
        check_name(at, &f.name)?;
        if cx.names.ids.contains_key(&f.name) {
            return Err(at.err("name", format!("duplicate particle name `{}`", f.name)));
        }
        let position = at.vec3("position", f.position)?;
        let radius = match f.radius {
            Some(r) => at.positive("radius", r)?,
            None => animats_engine::particle::sphere_radius(1e-3),
        };
        // Appendix B's food is 1 kg in a litre; it is nailed in place (the
        // thesis never simulates it) and moved by hand.
        let id = cx
            .world
            .add_particle(
                ParticleDef::new(1.0)
                    .with_radius(radius)
                    .at(position)
                    .fixed(),
            )
            .map_err(|e| at.model(e))?;
        cx.names.ids.insert(f.name.clone(), id);
        cx.list.push(f.name.clone());
        cx.kinds.push(PartKind::Food);

        Ok(())
    }
}
