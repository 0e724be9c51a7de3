//! `[[seaweed]]`: a frond nailed to the floor.

use super::*;

impl Build for SeaweedEntry {
    fn build(&self, k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let w = self;
        let name = w.name.clone().unwrap_or_else(|| format!("seaweed{k}"));
        check_name(at, &name)?;
        let d = SeaweedConstants::default();
        let c = SeaweedConstants {
            segments: w.segments.unwrap_or(d.segments),
            segment_length: w.segment_length.unwrap_or(d.segment_length),
            mass: w.mass.unwrap_or(d.mass),
            density: w.density.unwrap_or(d.density),
            stiffness: w.stiffness.unwrap_or(d.stiffness),
            damping: w.damping.unwrap_or(d.damping),
        };
        let position = at.vec3("position", w.position)?;
        room(at, "segments", c.segments.saturating_add(1), &cx.world)?;
        let first = cx.world.len();
        seaweed_frond::build(&mut cx.world, &c, position).map_err(|e| at.model(e))?;
        let parts: Vec<String> = (0..=c.segments).map(|i| format!("{name}.{i}")).collect();
        cx.add(at, first, &parts, |_| PartKind::Seaweed)?;

        Ok(())
    }
}
