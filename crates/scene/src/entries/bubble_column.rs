//! `[[bubble_column]]`.

use super::*;

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
