//! `[[roobot]]`: a hopping monopod with its FSM.

use super::*;

impl Build for RoobotEntry {
    fn build(&self, k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let r = self;
        let name = r.name.clone().unwrap_or_else(|| format!("roobot{k}"));
        check_name(at, &name)?;
        let position = at.vec3("position", r.position)?;
        let heading = at.finite("heading", r.heading)?;
        let params = match &r.params {
            None => crate::params::load("evolved", None),
            Some(ParamsEntry::Inline(v)) => crate::params::check(cx.src.file, "params", v),
            Some(ParamsEntry::Named(n)) if crate::params::BUILT_IN.contains(&n.as_str()) => {
                crate::params::load(n, None)
            }
            Some(ParamsEntry::Named(path)) => {
                let base = std::path::Path::new(cx.src.file)
                    .parent()
                    .unwrap_or(std::path::Path::new(""));
                crate::params::load(&base.join(path).to_string_lossy(), None)
            }
        }
        .map_err(|e| at.err("params", e.to_string()))?;
        room(at, "", CREATURE_PARTICLES, &cx.world)?;
        let first = cx.world.len();
        let roobot = Roobot::build(
            &mut cx.world,
            &name,
            &BodyConstants::STANDARD,
            position,
            heading,
            params,
        )
        .map_err(|e| at.model(e))?;
        for (i, part) in ["hip", "foot", "head", "tail1", "tail2"].iter().enumerate() {
            let full = format!("{name}.{part}");
            if cx.names.ids.contains_key(&full) {
                return Err(at.err("name", format!("duplicate particle name `{full}`")));
            }
            cx.names
                .ids
                .insert(full.clone(), ParticleId::from_index(first + i));
            cx.list.push(full);
            cx.kinds.push("roobot");
        }
        cx.actors.push(Box::new(roobot));

        Ok(())
    }
}
