//! `[[quadruped]]`: one of the thesis's three quadrupeds, its leg springs named for actuators.

use super::*;

/// `[[quadruped]]`: one of the thesis's three quadruped models.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadrupedEntry {
    /// Prefix of its particles' names; default `quadruped{k}`.
    pub name: Option<String>,
    /// 1, 2 or 3 (thesis §3.2.3).
    pub model: u32,
    /// Where the centre of its torso stands, m (y ignored).
    #[serde(default)]
    pub position: [f64; 3],
    /// rad from +x, counter-clockwise seen from above.
    #[serde(default)]
    pub heading: f64,
    /// When to run the thesis's failing experiment, s (model 2 raises its
    /// front feet, model 3 tries a step); default 2; a negative time never.
    #[serde(default = "default_demo")]
    pub demo_at: f64,
}

fn default_demo() -> f64 {
    2.0
}

impl Build for QuadrupedEntry {
    fn build(&self, k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let q = self;
        let name = q.name.clone().unwrap_or_else(|| format!("quadruped{k}"));
        check_name(at, &name)?;
        let model = Model::from_number(q.model)
            .ok_or_else(|| at.err("model", format!("must be 1, 2 or 3, got {}", q.model)))?;
        let position = at.vec3("position", q.position)?;
        let heading = at.finite("heading", q.heading)?;
        let demo_at = at.finite("demo_at", q.demo_at)?;
        room(at, "", CREATURE_PARTICLES, &cx.world)?;
        let first = cx.world.len();
        let mut quad = Quadruped::build(
            &mut cx.world,
            &name,
            model,
            &QuadrupedConstants::default(),
            position,
            heading,
        )
        .map_err(|e| at.model(e))?;
        quad.demo = (demo_at >= 0.0).then_some(Demo { at: demo_at });
        // Its leg springs by name, for actuators: `NAME.legI` (corner or
        // knee to foot) and, for model 3, `NAME.legI.back` / `NAME.legI.side`
        // (foot to the front–back and left–right neighbouring corners).
        for (i, leg) in quad.legs.iter().enumerate() {
            let named = |suffix: &str| Some(format!("{name}.leg{i}{suffix}"));
            crate::nervous::insert(
                &mut cx.handles.springs,
                at,
                "spring",
                &named(""),
                leg.spring,
            )?;
            if let Some((back, side)) = leg.supports {
                crate::nervous::insert(
                    &mut cx.handles.springs,
                    at,
                    "spring",
                    &named(".back"),
                    back,
                )?;
                crate::nervous::insert(
                    &mut cx.handles.springs,
                    at,
                    "spring",
                    &named(".side"),
                    side,
                )?;
            }
        }
        let mut parts: Vec<String> = (0..4).map(|i| format!("{name}.corner{i}")).collect();
        for i in 0..4 {
            if model == Model::TwoSegment {
                parts.push(format!("{name}.knee{i}"));
            }
            parts.push(format!("{name}.foot{i}"));
        }
        cx.add(at, first, &parts, |_| PartKind::Quadruped)?;
        cx.creature(&name, first, parts.len(), None);
        cx.actors.push(Box::new(quad));

        Ok(())
    }
}
