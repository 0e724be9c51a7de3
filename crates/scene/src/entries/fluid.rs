//! `[fluid]`: drag, buoyancy and currents.

use super::*;

/// `[fluid]`: drag and buoyancy.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidEntry {
    /// kg/m³, default 1000 (water).
    #[serde(default = "default_density")]
    pub density: f64,
    /// Default 0.47 (a sphere).
    #[serde(default = "default_drag")]
    pub drag_coefficient: f64,
    /// The fluid's velocity field; default still.
    #[serde(default)]
    pub current: CurrentEntry,
    /// Default: all particles.
    pub particles: Option<Vec<String>>,
    /// `springs = { diameter = 0.02 }`: every spring whose two ends are in
    /// the fluid is also a thin rod the fluid pushes on across its length
    /// (`RodDrag`, Sims's water); default none, the thesis's fluid.
    pub springs: Option<RodsEntry>,
}

/// `[fluid] springs`: drag across the springs as rods.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RodsEntry {
    /// m: every rod's diameter.
    pub diameter: f64,
    /// A cylinder across the flow's; default 1.2.
    #[serde(default = "default_rod_drag")]
    pub drag_coefficient: f64,
}

fn default_rod_drag() -> f64 {
    1.2
}

fn default_density() -> f64 {
    1000.0
}

fn default_drag() -> f64 {
    0.47
}

/// `current = { kind = "..." ... }`.
#[derive(Clone, Debug, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum CurrentEntry {
    /// At rest.
    #[default]
    Still,
    /// The same velocity everywhere.
    Uniform {
        /// m/s.
        velocity: [f64; 3],
    },
    /// Swaying currents under passing waves (see `ReefWater`).
    Reef {
        /// Height of the mean water surface, m; default 1.5.
        surface: Option<f64>,
        /// Wave amplitude at the surface, m; default 0.1.
        amplitude: Option<f64>,
        /// m; default 3.
        wavelength: Option<f64>,
        /// s; default: deep-water waves of that wavelength.
        period: Option<f64>,
        /// Horizontal direction of travel; default `[1, 0, 0]`.
        direction: Option<[f64; 3]>,
        /// Steady current added everywhere, m/s; default 0.
        drift: Option<[f64; 3]>,
    },
}

impl Build for FluidEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let f = self;
        let current = current(at, &f.current, cx.gravity.length())?;
        let targets = cx.names.targets(at, &f.particles)?;
        let fluid = FluidMedium {
            density: f.density,
            drag_coefficient: f.drag_coefficient,
            current,
            targets,
        };
        cx.world.add_fluid(fluid).map_err(|e| at.model(e))?;

        Ok(())
    }
}

impl FluidEntry {
    /// After every entry is built: the springs' rods, if the fluid has
    /// them (the springs are not known when `[fluid]` is built).
    pub(crate) fn add_rods(&self, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let Some(rods) = &self.springs else {
            return Ok(());
        };
        at.positive("springs.diameter", rods.diameter)?;
        at.finite("springs.drag_coefficient", rods.drag_coefficient)?;
        if rods.drag_coefficient < 0.0 {
            return Err(at.err(
                "springs.drag_coefficient",
                format!("must be >= 0, got {}", rods.drag_coefficient),
            ));
        }
        let mut immersed = vec![false; cx.world.len()];
        cx.names
            .targets(at, &self.particles)?
            .for_each(immersed.len(), |i| immersed[i] = true);
        let current = current(at, &self.current, cx.gravity.length())?;
        let ends: Vec<(ParticleId, ParticleId)> = cx
            .world
            .forces()
            .springs
            .iter()
            .map(|s| s.ends())
            .filter(|&(a, b)| immersed[a.index()] && immersed[b.index()])
            .collect();
        let force = animats_engine::RodDrag::new(
            self.density,
            rods.drag_coefficient,
            rods.diameter,
            current,
            &ends,
        )
        .map_err(|e| at.model(e))?;
        cx.world.add_force(Box::new(force));
        Ok(())
    }
}

fn current(at: &At, c: &CurrentEntry, g: f64) -> Result<Current, SceneError> {
    Ok(match c {
        CurrentEntry::Still => Current::Still,
        CurrentEntry::Uniform { velocity } => {
            Current::Uniform(at.vec3("current.velocity", *velocity)?)
        }
        CurrentEntry::Reef {
            surface,
            amplitude,
            wavelength,
            period,
            direction,
            drift,
        } => {
            let d = ReefWater::default();
            let wavelength =
                at.positive("current.wavelength", wavelength.unwrap_or(d.wavelength))?;
            let period = match period {
                Some(p) => at.positive("current.period", *p)?,
                None if g > 0.0 => ReefWater::deep_water_period(wavelength, g),
                None => d.period,
            };
            let direction = match direction {
                Some(v) => at.vec3("current.direction", *v)?,
                None => d.direction,
            };
            if DVec3::new(direction.x, 0.0, direction.z).length() == 0.0 {
                return Err(at.err(
                    "current.direction",
                    "must have a horizontal (x or z) component",
                ));
            }
            let amplitude = at.finite("current.amplitude", amplitude.unwrap_or(d.amplitude))?;
            if amplitude < 0.0 {
                return Err(at.err(
                    "current.amplitude",
                    format!("must be >= 0, got {amplitude}"),
                ));
            }
            Current::Reef(ReefWater {
                surface: at.finite("current.surface", surface.unwrap_or(d.surface))?,
                amplitude,
                wavelength,
                period,
                direction,
                drift: match drift {
                    Some(v) => at.vec3("current.drift", *v)?,
                    None => d.drift,
                },
            })
        }
    })
}
