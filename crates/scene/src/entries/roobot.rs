//! `[[roobot]]`: a hopping monopod; its sensors, actuators and brain join
//! the scene's nervous system under its name.

use super::*;
use animats_creatures::roobot::raibert;

impl Build for RoobotEntry {
    fn build(&self, k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let r = self;
        let name = r.name.clone().unwrap_or_else(|| format!("roobot{k}"));
        check_name(at, &name)?;
        let position = at.vec3("position", r.position)?;
        let heading = at.finite("heading", r.heading)?;
        let brain = match r.brain {
            RoobotBrainName::Hop => {
                if r.gains.is_some() {
                    return Err(
                        at.err("gains", "`gains` are Raibert's: give `brain = \"raibert\"`")
                    );
                }
                RoobotBrain::Hop(self.params(at, cx.src)?)
            }
            RoobotBrainName::Raibert => {
                if r.params.is_some() {
                    return Err(at.err(
                        "params",
                        "`params` are the hopping FSM's: give `brain = \"hop\"`",
                    ));
                }
                let gains = match &r.gains {
                    None => raibert::START,
                    Some(g) => {
                        let mut out = [0.0; raibert::GAIN_COUNT];
                        if g.len() != out.len() {
                            return Err(at.err(
                                "gains",
                                format!("expected {} numbers, got {}", out.len(), g.len()),
                            ));
                        }
                        for (o, &x) in out.iter_mut().zip(g) {
                            *o = at.finite("gains", x)?;
                        }
                        out
                    }
                };
                RoobotBrain::Raibert(gains)
            }
            RoobotBrainName::None => {
                for (key, given) in [("params", r.params.is_some()), ("gains", r.gains.is_some())] {
                    if given {
                        return Err(at.err(
                            key,
                            format!("a roobot with `brain = \"none\"` has no `{key}`"),
                        ));
                    }
                }
                RoobotBrain::None
            }
        };
        room(at, "", CREATURE_PARTICLES, &cx.world)?;
        let first = cx.world.len();
        let installed = roobot_kit::install(
            &mut cx.world,
            &mut cx.nervous,
            &name,
            &BodyConstants::STANDARD,
            position,
            heading,
            brain,
        )
        .map_err(|e| at.model(e))?;
        if installed.controller.is_some() {
            cx.origins.push(("roobot", k));
        }
        let parts: Vec<String> = ["hip", "foot", "head", "tail1", "tail2"]
            .iter()
            .map(|p| format!("{name}.{p}"))
            .collect();
        cx.add(at, first, &parts, |_| PartKind::Roobot)?;
        cx.creature(&name, first, parts.len(), None);
        Ok(())
    }
}

impl RoobotEntry {
    /// The hopping FSM's parameters: a built-in set, a file (relative to
    /// the scene file) or the numbers inline.
    fn params(&self, at: &At, src: &Source) -> Result<HopParams, SceneError> {
        match &self.params {
            None => crate::params::load("evolved", None),
            Some(ParamsEntry::Inline(v)) => crate::params::check(src.file, "params", v),
            Some(ParamsEntry::Named(n)) if crate::params::BUILT_IN.contains(&n.as_str()) => {
                crate::params::load(n, None)
            }
            Some(ParamsEntry::Named(path)) => {
                let base = std::path::Path::new(src.file)
                    .parent()
                    .unwrap_or(std::path::Path::new(""));
                crate::params::load(&base.join(path).to_string_lossy(), None)
            }
        }
        .map_err(|e| at.err("params", e.to_string()))
    }
}
