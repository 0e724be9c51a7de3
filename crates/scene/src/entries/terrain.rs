//! `[terrain]`: the floor's shape — a slope, a flight of steps, or a
//! heightfield (given, or generated from a seed with a roughness).

use super::*;
use animats_engine::{Heightfield, Slope, Steps, Terrain};

/// `[terrain]`: shapes the floor (a scene with `[terrain]` and no
/// `[floor]` gets the floor's defaults).
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum TerrainEntry {
    /// A plane through the origin rising along `direction`.
    Slope {
        /// Degrees, in [0, 90).
        angle: f64,
        /// The horizontal direction it rises along; default `[1, 0, 0]`.
        #[serde(default = "default_direction")]
        direction: [f64; 3],
    },
    /// Flat up to `start` along `direction`, `count` steps, flat on top.
    Steps {
        /// Rise of each step, m (negative: steps down).
        height: f64,
        /// Tread of each step, m.
        depth: f64,
        /// Number of steps; default 10.
        #[serde(default = "default_count")]
        count: u32,
        /// Where the first riser stands, m along `direction`; default 0.5.
        #[serde(default = "default_start")]
        start: f64,
        /// The horizontal direction the steps go along; default `[1, 0, 0]`.
        #[serde(default = "default_direction")]
        direction: [f64; 3],
    },
    /// Heights on a square grid, given or generated.
    Heightfield {
        /// Grid spacing, m.
        cell: f64,
        /// x and z of the first height, m; default: the grid centred on
        /// the origin.
        origin: Option<[f64; 2]>,
        /// The heights, m: one row per z, each row along x.
        heights: Option<Vec<Vec<f64>>>,
        /// Generated instead: vertices along x and z.
        size: Option<[usize; 2]>,
        /// Generated heights are uniform in [−roughness, roughness], m.
        roughness: Option<f64>,
        /// Seed of the generated heights; default the scene's.
        seed: Option<u64>,
    },
}

fn default_direction() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}

fn default_count() -> u32 {
    10
}

fn default_start() -> f64 {
    0.5
}

/// The most heights a heightfield may have.
const MOST_HEIGHTS: usize = 4_000_000;

/// `direction` as a horizontal unit vector.
fn horizontal(at: &At, d: [f64; 3]) -> Result<DVec3, SceneError> {
    let v = DVec3::from(d);
    let flat = DVec3::new(v.x, 0.0, v.z);
    if !v.is_finite() || v.y != 0.0 || flat.length() == 0.0 {
        return Err(at.err(
            "direction",
            format!("must be horizontal and non-zero ([x, 0, z]), got {d:?}"),
        ));
    }
    Ok(flat.normalize())
}

impl TerrainEntry {
    /// The engine's terrain this entry describes (`seed`: the scene's).
    pub(crate) fn terrain(&self, at: &At, seed: u64) -> Result<Terrain, SceneError> {
        let terrain = match self {
            TerrainEntry::Slope { angle, direction } => Terrain::Slope(Slope {
                angle: angle.to_radians(),
                uphill: horizontal(at, *direction)?,
            }),
            TerrainEntry::Steps {
                height,
                depth,
                count,
                start,
                direction,
            } => Terrain::Steps(Steps {
                direction: horizontal(at, *direction)?,
                start: *start,
                height: *height,
                depth: *depth,
                count: *count,
            }),
            TerrainEntry::Heightfield {
                cell,
                origin,
                heights,
                size,
                roughness,
                seed: own_seed,
            } => {
                let (nx, nz, values) = match (heights, size) {
                    (Some(_), Some(_)) => {
                        return Err(at.err(
                            "size",
                            "give `heights` or `size` (with `roughness`), not both",
                        ))
                    }
                    (Some(rows), None) => {
                        if roughness.is_some() || own_seed.is_some() {
                            return Err(at.err(
                                "roughness",
                                "`roughness` and `seed` generate heights: drop them, or `heights`",
                            ));
                        }
                        let nx = rows.first().map_or(0, Vec::len);
                        if let Some(k) = rows.iter().position(|r| r.len() != nx) {
                            return Err(at.err(
                                "heights",
                                format!(
                                    "row {k} has {} heights, row 0 has {nx}: every row needs as many",
                                    rows[k].len()
                                ),
                            ));
                        }
                        (nx, rows.len(), rows.concat())
                    }
                    (None, Some([nx, nz])) => {
                        let Some(r) = roughness else {
                            return Err(at.err(
                                "roughness",
                                "a generated heightfield needs `roughness` (m)",
                            ));
                        };
                        if !(r.is_finite() && *r >= 0.0) {
                            return Err(at.err(
                                "roughness",
                                format!("must be >= 0, got {r}"),
                            ));
                        }
                        if nx.saturating_mul(*nz) > MOST_HEIGHTS {
                            return Err(at.err(
                                "size",
                                format!("{nx} × {nz} heights: at most {MOST_HEIGHTS}"),
                            ));
                        }
                        let mut random = Random::for_entry(own_seed.unwrap_or(seed), 3000);
                        let values = (0..nx * nz).map(|_| random.between(-r, *r)).collect();
                        (*nx, *nz, values)
                    }
                    (None, None) => {
                        return Err(at.err(
                            "heights",
                            "a heightfield needs `heights` (rows of heights), or `size` and `roughness` to generate them",
                        ))
                    }
                };
                if nx.saturating_mul(nz) > MOST_HEIGHTS {
                    return Err(at.err(
                        "heights",
                        format!("{nx} × {nz} heights: at most {MOST_HEIGHTS}"),
                    ));
                }
                let origin = match origin {
                    Some(o) => animats_engine::DVec2::from(*o),
                    None => {
                        let half = |n: usize| -0.5 * n.saturating_sub(1) as f64 * cell;
                        animats_engine::DVec2::new(half(nx), half(nz))
                    }
                };
                Terrain::Heightfield(Heightfield::new(origin, *cell, nx, nz, values))
            }
        };
        terrain.validate().map_err(|e| at.model(e))?;
        Ok(terrain)
    }
}

impl Build for TerrainEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        // The floor (`[floor]`, or the defaults if the scene has none)
        // takes it.
        cx.terrain = Some(self.terrain(at, cx.seed)?);
        Ok(())
    }
}
