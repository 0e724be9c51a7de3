//! `[[rocks]]`: scattered sinking stones.

use super::*;

/// `[[rocks]]`: stones scattered at random.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RocksEntry {
    /// Prefix of their names; default `rock` (`rock0`, `rock1`...).
    pub name: Option<String>,
    /// How many; default 10.
    pub count: Option<usize>,
    /// Mass range, kg; default [0.05, 0.3].
    pub mass: Option<[f64; 2]>,
    /// kg/m³; default 2000.
    pub density: Option<f64>,
    /// Least corner of the drop box, m; default [-0.5, 0.2, -0.5].
    pub from: Option<[f64; 3]>,
    /// Greatest corner, m; default [0.5, 1.2, 0.5].
    pub to: Option<[f64; 3]>,
}

impl Build for RocksEntry {
    fn build(&self, k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let r = self;
        let name = r.name.clone().unwrap_or_else(|| "rock".into());
        check_name(at, &name)?;
        let d = RocksConstants::default();
        let c = RocksConstants {
            count: r.count.unwrap_or(d.count),
            mass: r.mass.map_or(d.mass, |[a, z]| (a, z)),
            density: r.density.unwrap_or(d.density),
            from: r.from.map_or(Ok(d.from), |v| at.vec3("from", v))?,
            to: r.to.map_or(Ok(d.to), |v| at.vec3("to", v))?,
        };
        room(at, "count", c.count, &cx.world)?;
        let first = cx.world.len();
        rock_field::scatter(
            &mut cx.world,
            &c,
            &mut Random::for_entry(cx.seed, 2000 + k as u64),
        )
        .map_err(|e| at.model(e))?;
        let parts: Vec<String> = (0..c.count).map(|i| format!("{name}{i}")).collect();
        cx.add(at, first, &parts, |_| PartKind::Rock)?;

        Ok(())
    }
}
