//! `[[roobot]]`: a hopping monopod; its sensors, actuators and brain join
//! the scene's nervous system under its name.

use super::*;

/// Where a creature's parameters come from: a built-in name or file path, or
/// the numbers themselves.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum ParamsEntry {
    /// `"evolved"`, `"initial"`, or a parameter file (relative to the scene file).
    Named(String),
    /// The 14 numbers inline.
    Inline(Vec<f64>),
}

/// `[[roobot]]`: a hopping monopod with its brain. Its sensors, actuators
/// and brain join the scene's (`NAME.foot_height`..., `NAME.leg`...,
/// controller `NAME`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoobotEntry {
    /// Prefix of its particles' names (`NAME.hip`...); default `roobot{k}`.
    pub name: Option<String>,
    /// Where its foot stands, m (y is ignored: the foot rests on the floor).
    #[serde(default)]
    pub position: [f64; 3],
    /// Direction it faces, rad from +x, counter-clockwise seen from above.
    #[serde(default)]
    pub heading: f64,
    /// `hop` (the thesis's FSM), `raibert` or `none`; default `hop`.
    #[serde(default)]
    pub brain: RoobotBrainName,
    /// `hop`: its hopping parameters; default `"evolved"`.
    pub params: Option<ParamsEntry>,
    /// `raibert`: its 8 gains; default the hand-set ones.
    pub gains: Option<Vec<f64>>,
}

/// A roobot's brain, as written in files.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum RoobotBrainName {
    /// The thesis's hopping FSM.
    #[default]
    Hop,
    /// Raibert's three-part controller.
    Raibert,
    /// None: a program or a scene's controller drives its actuators.
    None,
}
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
