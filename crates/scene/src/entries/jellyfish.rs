//! `[[jellyfish]]`.

use super::*;

impl Build for JellyfishEntry {
    fn build(&self, k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let j = self;
        let name = j.name.clone().unwrap_or_else(|| format!("jellyfish{k}"));
        check_name(at, &name)?;
        let food = cx.names.ids.get(&j.food).copied().ok_or_else(|| {
            at.err(
                "food",
                format!(
                    "no particle `{}` to track: add a [[food]] entry named so",
                    j.food
                ),
            )
        })?;
        let position = at.vec3("position", j.position)?;
        let mut constants = JellyfishConstants::new(j.dome_mass, j.tentacle_mass);
        if let Some(f) = j.pulse_force {
            constants.pulse_force = at.positive("pulse_force", f)?;
        }
        if let Some(f) = j.steer_force {
            constants.steer_force = at.finite("steer_force", f)?.abs();
        }
        if let Some(c) = j.ceiling {
            constants.ceiling = at.positive("ceiling", c)?;
        }
        room(at, "", CREATURE_PARTICLES, &cx.world)?;
        let first = cx.world.len();
        let jelly = Jellyfish::build(&mut cx.world, &name, &constants, position, food)
            .map_err(|e| at.model(e))?;
        let mut parts: Vec<String> = (0..constants.tentacles)
            .map(|i| format!("{name}.dome{i}"))
            .collect();
        for i in 0..constants.tentacles {
            parts.extend((0..constants.segments).map(|s| format!("{name}.tentacle{i}.{s}")));
        }
        let domes = constants.tentacles;
        cx.add(at, first, &parts, |i| {
            if i < domes {
                PartKind::Dome
            } else {
                PartKind::Tentacle
            }
        })?;
        let bell = crate::Bell {
            dome: (first..first + domes).collect(),
            tentacles: (first + domes..first + parts.len()).collect(),
        };
        cx.creature(&name, first, parts.len(), Some(bell));
        cx.actors.push(Box::new(jelly));

        Ok(())
    }
}
