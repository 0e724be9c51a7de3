//! `[[seaweed]]`: a frond nailed to the floor.

use super::*;

/// `[[seaweed]]`: a frond nailed to the floor.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeaweedEntry {
    /// Prefix of its particles' names; default `seaweed{k}`.
    pub name: Option<String>,
    /// Where its base is nailed, m (y is ignored: on the floor).
    pub position: [f64; 3],
    /// Default 12.
    pub segments: Option<usize>,
    /// m; default 0.06.
    pub segment_length: Option<f64>,
    /// kg per segment; default 0.004.
    pub mass: Option<f64>,
    /// kg/m³; default 980.
    pub density: Option<f64>,
    /// N/m; default 10.
    pub stiffness: Option<f64>,
    /// N s/m; default 0.02.
    pub damping: Option<f64>,
}

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
