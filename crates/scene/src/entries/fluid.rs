//! `[fluid]`: drag, buoyancy and currents.

use super::*;

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
