//! `[[jellyfish]]`.

use super::*;

/// `[[jellyfish]]`: Appendix B's jellyfish.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JellyfishEntry {
    /// Prefix of its particles' names; default `jellyfish{k}`.
    pub name: Option<String>,
    /// Centre of its dome, m.
    pub position: [f64; 3],
    /// Mass of each dome mass, kg; default 0.2.
    #[serde(default = "default_dome_mass")]
    pub dome_mass: f64,
    /// Mass of each tentacle segment, kg; default 0.02.
    #[serde(default = "default_tentacle_mass")]
    pub tentacle_mass: f64,
    /// The particle it tracks; default `food`.
    #[serde(default = "default_food")]
    pub food: String,
    /// Pulse force range per dome mass, N; default 4.5× the submerged weight
    /// it carries (Appendix B: 5).
    pub pulse_force: Option<f64>,
    /// Steering force range per dome mass, N; default a tenth of the pulse's
    /// (Appendix B: 0.5).
    pub steer_force: Option<f64>,
    /// Height its depth sense reads as "too high", m; default 1.
    pub ceiling: Option<f64>,
}

fn default_dome_mass() -> f64 {
    0.2
}

fn default_tentacle_mass() -> f64 {
    0.02
}

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
