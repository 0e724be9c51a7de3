//! What to draw: spheres, rods, jellyfish bells, the floor and the water,
//! and how each part of a creature or its world is coloured (the same
//! palette as the live view's page).

use glam::DVec3;

/// An RGB colour, components in [0, 1].
pub type Colour = DVec3;

/// A colour from 0xRRGGBB.
pub fn hex(c: u32) -> Colour {
    DVec3::new(
        f64::from((c >> 16) & 0xff),
        f64::from((c >> 8) & 0xff),
        f64::from(c & 0xff),
    ) / 255.0
}

/// The colour of a particle of kind `kind` (see `animats_scene::Scene::kinds`),
/// from the palette the live view uses too (`animats_view::palette`).
pub fn kind_colour(kind: &str) -> Colour {
    hex(animats_view::palette::colour_of(kind))
}

/// A solid sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre, m.
    pub centre: DVec3,
    /// Radius, m.
    pub radius: f64,
    /// Colour.
    pub colour: Colour,
    /// Whether it casts a shadow on the floor.
    pub shadow: bool,
}

/// A solid cylinder between two points (a spring).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rod {
    /// One end, m.
    pub a: DVec3,
    /// The other end, m.
    pub b: DVec3,
    /// Radius, m.
    pub radius: f64,
    /// Colour.
    pub colour: Colour,
}

/// A translucent half-ellipsoid (a jellyfish's bell): its rim is a circle
/// of `radius` around `centre` square to `axis`, its crown `height` along it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bell {
    /// Centre of the rim, m.
    pub centre: DVec3,
    /// Unit vector from the rim to the crown.
    pub axis: DVec3,
    /// Rim radius, m.
    pub radius: f64,
    /// Crown height, m.
    pub height: f64,
    /// Colour.
    pub colour: Colour,
}

/// Everything in one picture.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Picture {
    /// Spheres.
    pub spheres: Vec<Sphere>,
    /// Rods.
    pub rods: Vec<Rod>,
    /// Bells, drawn translucent over the rest.
    pub bells: Vec<Bell>,
    /// The floor at y = 0, checkered in squares of this size, m.
    pub floor: Option<f64>,
    /// Under water (tinted and fogged) rather than in air.
    pub water: bool,
    /// A caption for the top-left corner.
    pub caption: Option<String>,
}

/// A jellyfish's dome for [`Parts`]: its dome and tentacle particles, and
/// how far through a pulse it is (0 relaxed, 1 fully contracted).
#[derive(Clone, Debug, PartialEq)]
pub struct DomeParts {
    /// Indices of the dome masses (three or more).
    pub dome: Vec<usize>,
    /// Indices of its tentacle masses (the bell opens towards them).
    pub tentacles: Vec<usize>,
    /// Contraction in [0, 1].
    pub squeeze: f64,
}

/// A world described for drawing: what each particle is and how big.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Parts {
    /// Each particle's kind (`roobot`, `dome`, `rock`, ...).
    pub kinds: Vec<String>,
    /// Each particle's radius, m.
    pub radii: Vec<f64>,
    /// Springs as index pairs.
    pub springs: Vec<[usize; 2]>,
    /// Jellyfish domes.
    pub domes: Vec<DomeParts>,
    /// Whether there is a floor.
    pub floor: bool,
    /// Whether the world is under water.
    pub water: bool,
    /// Size of the floor's squares, m.
    pub cell: f64,
}

impl Parts {
    /// The picture of these parts at `positions`.
    pub fn picture(&self, positions: &[DVec3]) -> Picture {
        let at = |i: usize| positions.get(i).copied().unwrap_or(DVec3::ZERO);
        let spheres = self
            .kinds
            .iter()
            .enumerate()
            .map(|(i, kind)| Sphere {
                centre: at(i),
                radius: self.radii.get(i).copied().unwrap_or(0.0).max(0.001),
                colour: kind_colour(kind),
                shadow: kind != "bubble",
            })
            .collect();
        let rods = self
            .springs
            .iter()
            .map(|&[a, b]| {
                let r = self
                    .radii
                    .get(a)
                    .copied()
                    .unwrap_or(0.0)
                    .min(self.radii.get(b).copied().unwrap_or(0.0));
                Rod {
                    a: at(a),
                    b: at(b),
                    radius: (0.3 * r).clamp(0.0015, 0.012),
                    colour: kind_colour(self.kinds.get(a).map_or("", String::as_str)) * 0.8,
                }
            })
            .collect();
        let bells = self
            .domes
            .iter()
            .filter_map(|d| {
                let size = d
                    .dome
                    .iter()
                    .map(|&i| self.radii.get(i).copied().unwrap_or(0.0))
                    .sum::<f64>()
                    / d.dome.len().max(1) as f64;
                bell(d, &at, size)
            })
            .collect();
        Picture {
            spheres,
            rods,
            bells,
            floor: self.floor.then_some(self.cell),
            water: self.water,
            caption: None,
        }
    }
}

/// The bell over a dome: wrapping the dome masses (of radius `size`),
/// opening towards the tentacles, narrower and taller as it contracts (as
/// the live view draws it).
fn bell(d: &DomeParts, at: &impl Fn(usize) -> DVec3, size: f64) -> Option<Bell> {
    if d.dome.len() < 3 {
        return None;
    }
    let p: Vec<DVec3> = d.dome.iter().map(|&i| at(i)).collect();
    let centre = p.iter().sum::<DVec3>() / p.len() as f64;
    let mut axis = (p[0] - p[1]).cross(p[2] - p[0]).try_normalize()?;
    if !d.tentacles.is_empty() {
        let t = d.tentacles.iter().map(|&i| at(i)).sum::<DVec3>() / d.tentacles.len() as f64;
        if axis.dot(centre - t) < 0.0 {
            axis = -axis;
        }
    }
    let radius = p.iter().map(|x| x.distance(centre)).sum::<f64>() / p.len() as f64 + size;
    let s = d.squeeze.clamp(0.0, 1.0);
    Some(Bell {
        centre: centre - axis * (0.5 * size),
        axis,
        radius: radius * (1.08 - 0.28 * s),
        height: radius * (0.75 + 0.45 * s),
        colour: hex(animats_view::palette::colour_of("bell")),
    })
}
