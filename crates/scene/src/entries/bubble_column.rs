//! `[[bubble_column]]`.

use super::*;

/// `[[bubble_column]]`: a particle system of rising bubbles.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BubbleColumnEntry {
    /// Prefix of its particles' names; default `bubbles{k}`.
    pub name: Option<String>,
    /// Base of the column, m (y is ignored: on the floor).
    pub position: [f64; 3],
    /// Bubbles in the pool; default 15.
    pub bubbles: Option<usize>,
    /// Time between spawns, s; default [0.1, 0.4].
    pub interval: Option<[f64; 2]>,
    /// Bubble radius range, m; default [0.002, 0.005].
    pub radius: Option<[f64; 2]>,
    /// Effective density with added mass, kg/m³; default 500.
    pub density: Option<f64>,
    /// Water surface height, m; default 1.5.
    pub surface: Option<f64>,
}

impl Build for BubbleColumnEntry {
    fn build(&self, k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let b = self;
        let name = b.name.clone().unwrap_or_else(|| format!("bubbles{k}"));
        check_name(at, &name)?;
        let d = BubbleConstants::default();
        let c = BubbleConstants {
            bubbles: b.bubbles.unwrap_or(d.bubbles),
            interval: b.interval.map_or(d.interval, |[a, z]| (a, z)),
            radius: b.radius.map_or(d.radius, |[a, z]| (a, z)),
            density: b.density.unwrap_or(d.density),
            surface: b.surface.unwrap_or(d.surface),
            spread: d.spread,
        };
        let position = at.vec3("position", b.position)?;
        let base = DVec3::new(position.x, 0.0, position.z);
        room(at, "bubbles", c.bubbles, &cx.world)?;
        let first = cx.world.len();
        let column = BubbleColumn::build(
            &mut cx.world,
            &c,
            base,
            Random::for_entry(cx.seed, 1000 + k as u64),
        )
        .map_err(|e| at.model(e))?;
        let parts: Vec<String> = (0..c.bubbles).map(|i| format!("{name}.{i}")).collect();
        cx.add(at, first, &parts, |_| PartKind::Bubble)?;
        cx.actors.push(Box::new(column));

        Ok(())
    }
}
