//! The description of what there is to draw, sent to the page as JSON
//! (`{"type":"scene", ...}`) and read by the renderer.

use serde::Serialize;

/// One particle to draw.
#[derive(Clone, Debug, Serialize)]
pub struct Part {
    /// Its name.
    pub name: String,
    /// Its radius, m.
    pub radius: f64,
    /// What it is part of (`animats_scene::PartKind::name`).
    pub kind: &'static str,
}

/// A jellyfish's dome, drawn as a pulsing bell over its three dome masses.
#[derive(Clone, Debug, Serialize)]
pub struct Dome {
    /// The jellyfish's name (its status carries the pulse phase).
    pub name: String,
    /// Indices of the dome masses.
    pub particles: Vec<usize>,
    /// Indices of its tentacle masses (the bell opens towards them).
    pub tentacles: Vec<usize>,
}

/// What there is to draw.
#[derive(Clone, Debug, Serialize)]
pub struct Describe {
    /// Always `scene`.
    #[serde(rename = "type")]
    pub kind: &'static str,
    /// A title.
    pub title: String,
    /// Every particle, by index.
    pub particles: Vec<Part>,
    /// Springs as index pairs.
    pub springs: Vec<[usize; 2]>,
    /// Density of the fluid, kg/m³, if there is one (water is tinted).
    pub fluid: Option<f64>,
    /// Whether there is a floor.
    pub floor: bool,
    /// Jellyfish domes.
    pub domes: Vec<Dome>,
    /// Index of the food particle, if any (clicking the floor moves it).
    pub food: Option<usize>,
    /// Where to aim the camera first, and from how far, m.
    pub target: [f64; 3],
    /// Camera distance, m.
    pub distance: f64,
    /// The colour of each kind of part, 0xRRGGBB (see `palette.rs`).
    pub palette: std::collections::BTreeMap<&'static str, u32>,
    /// Text drawn over the 3-D view above particles (an evolution's lanes).
    pub labels: Vec<Label>,
    /// Whether the camera orbits what it follows until the user takes over
    /// (an evolution's exhibition, as the thesis showed it).
    pub orbit: bool,
    /// What is drawn: the page draws these and computes no shape itself.
    pub drawing: crate::drawing::Drawing,
}

/// A caption that stays above a particle in the 3-D view.
#[derive(Clone, Debug, Serialize)]
pub struct Label {
    /// What it says.
    pub text: String,
    /// The particle it hangs above.
    pub particle: usize,
}

/// A creature's state, for the overlay.
#[derive(Clone, Debug, Serialize)]
pub struct CreatureState {
    /// Its name.
    pub name: String,
    /// Its controller state.
    pub state: String,
    /// Its energy, if it has one.
    pub energy: Option<f64>,
    /// Its pulse phase, if it has one.
    pub phase: Option<f64>,
}
