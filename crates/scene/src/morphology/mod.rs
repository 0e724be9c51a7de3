//! `[morphology]`: bodies that evolve. A scene with this table describes
//! not one body but a space of them (its budgets and caps) and how a body
//! is encoded; a body genome develops into ordinary scene entries
//! (`[[particle]]`, `[[spring]]`, `[[actuator]]`, a `[[controller]]`,
//! `[contacts]`), appended to the rest of the scene, so that everything
//! downstream (evaluate, simulate, view, render, Python, checkpoints) works
//! on an evolved creature unchanged. docs/BODIES.md says how.
//!
//! - [`genome`]: the graph genome ([`Body`]) and its `Vec<f64>` layout.
//! - [`lattice`]: a lattice of cells painted with materials, which develops
//!   into a [`Body`].
//! - [`develop`]: a body → the scene's text with the body written in.
//! - [`check`]: what every offspring must pass before it is evaluated.
//! - [`vary`]: random bodies, mutation and crossover.
//! - [`problem`]: [`MorphologyProblem`], genome → evaluation.

pub mod check;
pub mod develop;
pub mod genome;
pub mod lattice;
pub mod problem;
pub mod vary;

pub use check::Refusal;
pub use genome::{Body, Edge, Muscle, Node};
pub use problem::{BodyStats, MorphologyProblem};

use crate::build::At;
use crate::error::SceneError;
use serde::Deserialize;

/// `[morphology]` as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MorphologyEntry {
    /// `graph` (the particle/spring graph is the genome) or `lattice` (a
    /// grid of cells painted with materials); default `graph`.
    #[serde(default)]
    pub encoding: EncodingName,
    /// `random`, or a scene file whose particles, springs and spring
    /// actuators are the starting body (relative to this scene's folder,
    /// else to the working directory); default `random`.
    #[serde(default = "default_start")]
    pub start: String,
    /// The most particles a body may have; default 24.
    #[serde(default = "default_max_particles")]
    pub max_particles: usize,
    /// The most springs (muscles included); default 96.
    #[serde(default = "default_max_springs")]
    pub max_springs: usize,
    /// kg: the most the body may weigh; default 0.8.
    #[serde(default = "default_total_mass")]
    pub total_mass: f64,
    /// N/m: every spring's stiffness range; default [50, 800].
    #[serde(default = "default_stiffness")]
    pub stiffness: [f64; 2],
    /// A muscle's rest length moves within ± this fraction of its built
    /// length; default 0.3.
    #[serde(default = "default_muscle_strain")]
    pub muscle_strain: f64,
    /// A muscle's level changes by at most this per second (the actuator
    /// key `rate`); default 4.
    #[serde(default = "default_muscle_rate")]
    pub muscle_rate: f64,
    /// m: the body fits in a cube this big when it is built; default 0.4.
    #[serde(default = "default_size")]
    pub size: f64,
    /// `oscillator` (each muscle carries its amplitude, phase and offset
    /// genes; one shared frequency) or `neural` (a network from a touch
    /// sensor on every particle and a clock to every muscle; graph bodies
    /// only); default `oscillator`.
    #[serde(default)]
    pub controller: BrainName,
    /// `sine` (each muscle's level a sine) or `skewed` (each muscle also
    /// carries a duty gene in [`DUTY`]: the share of a cycle its level
    /// spends rising, the oscillator's `duty`; oscillator graph bodies
    /// only); default `sine`.
    #[serde(default)]
    pub waveform: WaveformName,
    /// The body's spheres that no spring joins collide with each other;
    /// default true.
    #[serde(default = "yes")]
    pub self_contact: bool,
    /// kg: each particle's mass range; default [0.02, 0.3].
    #[serde(default = "default_mass")]
    pub mass: [f64; 2],
    /// m: each sphere's radius range; default [0.015, 0.04].
    #[serde(default = "default_radius")]
    pub radius: [f64; 2],
    /// N s/m: every spring's damping; default 2.
    #[serde(default = "default_damping")]
    pub damping: f64,
    /// The spheres' friction and restitution (as `[[particle]]`'s keys);
    /// defaults 1.0, 0.8 and 0.1 (the soft walker's feet).
    #[serde(default = "default_mu_s")]
    pub mu_s: f64,
    /// See `mu_s`.
    #[serde(default = "default_mu_k")]
    pub mu_k: f64,
    /// See `mu_s`.
    #[serde(default = "default_restitution")]
    pub restitution: f64,
    /// m: where the bottom centre of the body's bounding box is built (the
    /// lowest sphere's lowest point at `origin[1]`); default [0, 0, 0].
    #[serde(default)]
    pub origin: [f64; 3],
    /// `lattice`: cells along x, y and z; default [5, 5, 2].
    pub cells: Option<[usize; 3]>,
    /// `lattice`: m, a cell's edge; default 0.08.
    pub cell: Option<f64>,
    /// `lattice`: an EvoGym robot's 2-D grid as the starting body (rows top
    /// to bottom; 0 empty, 1 rigid, 2 soft, 3 horizontal and 4 vertical
    /// muscle), extruded `cells[2]` cells deep.
    pub structure: Option<Vec<Vec<i64>>>,
}

/// `[morphology] encoding`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum EncodingName {
    /// The particle/spring graph is the genome.
    #[default]
    Graph,
    /// A lattice of painted cells.
    Lattice,
}

/// `[morphology] waveform`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum WaveformName {
    /// Each muscle's level is a sine.
    #[default]
    Sine,
    /// Each muscle's wave rises for its own share of a cycle (a duty gene)
    /// and falls for the rest: a fast stroke and a slow return.
    Skewed,
}

/// `[morphology] controller`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum BrainName {
    /// A sine per muscle at one shared frequency.
    #[default]
    Oscillator,
    /// Touch sensors on every particle and a clock, to every muscle: a
    /// one-layer network whose weights are the muscles' genes.
    Neural,
}

fn default_start() -> String {
    "random".into()
}
fn default_max_particles() -> usize {
    24
}
fn default_max_springs() -> usize {
    96
}
fn default_total_mass() -> f64 {
    0.8
}
fn default_stiffness() -> [f64; 2] {
    [50.0, 800.0]
}
fn default_muscle_strain() -> f64 {
    0.3
}
fn default_muscle_rate() -> f64 {
    4.0
}
fn default_size() -> f64 {
    0.4
}
fn yes() -> bool {
    true
}
fn default_mass() -> [f64; 2] {
    [0.02, 0.3]
}
fn default_radius() -> [f64; 2] {
    [0.015, 0.04]
}
fn default_damping() -> f64 {
    2.0
}
fn default_mu_s() -> f64 {
    1.0
}
fn default_mu_k() -> f64 {
    0.8
}
fn default_restitution() -> f64 {
    0.1
}

/// The most cells a lattice may have.
pub const MAX_CELLS: usize = 10_000;

/// The largest `size`, m: a body within a cube of a kilometre (far past
/// it, its built lengths overflow).
pub const MAX_SIZE: f64 = 1000.0;

/// The most particles any body may have (a cap past this is refused).
pub const MAX_BODY_PARTICLES: usize = 10_000;

/// `[morphology]`, checked: the space of bodies evolution searches.
#[derive(Clone, Debug, PartialEq)]
pub struct Morphology {
    /// How bodies are encoded.
    pub encoding: EncodingName,
    /// Caps: particles, springs.
    pub max_particles: usize,
    /// See `max_particles`.
    pub max_springs: usize,
    /// kg.
    pub total_mass: f64,
    /// N/m, (lo, hi).
    pub stiffness: (f64, f64),
    /// Fraction of the built length.
    pub muscle_strain: f64,
    /// Level per second.
    pub muscle_rate: f64,
    /// m.
    pub size: f64,
    /// Spheres collide with each other.
    pub self_contact: bool,
    /// kg, (lo, hi).
    pub mass: (f64, f64),
    /// m, (lo, hi).
    pub radius: (f64, f64),
    /// N s/m.
    pub damping: f64,
    /// Friction and restitution.
    pub mu_s: f64,
    /// See `mu_s`.
    pub mu_k: f64,
    /// See `mu_s`.
    pub restitution: f64,
    /// m.
    pub origin: animats_engine::DVec3,
    /// A lattice's shape, if the encoding is one.
    pub lattice: Option<lattice::Shape>,
    /// `controller = "neural"`: muscles feel touch.
    pub neural: bool,
    /// `waveform = "skewed"`: each muscle carries a duty gene.
    pub skewed: bool,
}

/// Frequency bounds of the muscles' shared oscillator, Hz.
pub const FREQUENCY: (f64, f64) = (0.2, 5.0);
/// A muscle's amplitude bounds.
pub const AMPLITUDE: (f64, f64) = (0.0, 0.5);
/// A `neural` muscle's touch weight bounds.
pub const TOUCH: (f64, f64) = (-1.0, 1.0);
/// A `skewed` muscle's duty bounds: the share of a cycle its level rises.
pub const DUTY: (f64, f64) = (0.1, 0.9);

impl Morphology {
    /// Checks every key, naming the field.
    pub(crate) fn from_entry(at: &At, e: &MorphologyEntry) -> Result<Morphology, SceneError> {
        let neural = e.controller == BrainName::Neural;
        // A range of positive numbers (not subnormal: a reciprocal of one
        // is infinite).
        let range = |field: &str, r: [f64; 2]| -> Result<(f64, f64), SceneError> {
            let (lo, hi) = (at.finite(field, r[0])?, at.finite(field, r[1])?);
            if lo < f64::MIN_POSITIVE || lo > hi {
                return Err(at.err(
                    field,
                    format!("must be [lo, hi] with 0 < lo <= hi, got [{lo}, {hi}]"),
                ));
            }
            Ok((lo, hi))
        };
        let stiffness = range("stiffness", e.stiffness)?;
        let mass = range("mass", e.mass)?;
        let radius = range("radius", e.radius)?;
        let total_mass = at.positive("total_mass", e.total_mass)?;
        if total_mass < 2.0 * mass.0 {
            return Err(at.err(
                "total_mass",
                format!(
                    "{total_mass} kg is less than the smallest body (two particles of {} kg)",
                    mass.0
                ),
            ));
        }
        if e.max_particles < 2 || e.max_particles > MAX_BODY_PARTICLES {
            return Err(at.err(
                "max_particles",
                format!(
                    "must be between 2 (the smallest body: two particles and a muscle) and {MAX_BODY_PARTICLES}, got {}",
                    e.max_particles
                ),
            ));
        }
        let most = animats_engine::forces::soft_contact::MAX_SPHERES;
        if e.self_contact && e.max_particles > most {
            return Err(at.err(
                "max_particles",
                format!(
                    "{} particles with self_contact: penalty contact tests every pair, at most {most} spheres; lower the cap or set self_contact = false",
                    e.max_particles
                ),
            ));
        }
        let most_springs = e.max_particles * (e.max_particles - 1) / 2;
        if e.max_springs < 1 || e.max_springs > most_springs.max(1) {
            return Err(at.err(
                "max_springs",
                format!(
                    "must be between 1 and {most_springs} (every pair of {} particles), got {}",
                    e.max_particles, e.max_springs
                ),
            ));
        }
        let strain = at.positive("muscle_strain", e.muscle_strain)?;
        if strain >= 0.9 {
            return Err(at.err(
                "muscle_strain",
                format!("must be below 0.9, got {}", animats_engine::Shown(strain)),
            ));
        }
        let size = at.positive("size", e.size)?;
        if size > MAX_SIZE {
            return Err(at.err(
                "size",
                format!(
                    "must be at most {MAX_SIZE} m, got {}",
                    animats_engine::Shown(size)
                ),
            ));
        }
        if size < 4.0 * radius.0 {
            return Err(at.err(
                "size",
                format!(
                    "{size} m cannot hold two spheres of the smallest radius, {} m",
                    radius.0
                ),
            ));
        }
        let unit = |field: &str, x: f64| -> Result<f64, SceneError> {
            let x = at.finite(field, x)?;
            if !(0.0..=1.0).contains(&x) && field == "restitution" {
                return Err(at.err(field, format!("must be in [0, 1], got {x}")));
            }
            if x < 0.0 {
                return Err(at.err(field, format!("must be >= 0, got {x}")));
            }
            Ok(x)
        };
        let lattice = match e.encoding {
            EncodingName::Graph => {
                if e.cells.is_some() || e.cell.is_some() || e.structure.is_some() {
                    return Err(at.err(
                        "cells",
                        "`cells`, `cell` and `structure` are for encoding = \"lattice\"",
                    ));
                }
                None
            }
            EncodingName::Lattice => {
                let shape = lattice::Shape::from_entry(at, e)?;
                // Its particles are the cells' corners: as many as a full
                // lattice has, at most.
                let corners: usize = shape.cells.iter().map(|c| c + 1).product();
                if e.self_contact && corners > most {
                    return Err(at.err(
                        "cells",
                        format!(
                            "{:?}: up to {corners} particles (the cells' corners) with self_contact: penalty contact tests every pair, at most {most} spheres; fewer cells or set self_contact = false",
                            shape.cells
                        ),
                    ));
                }
                Some(shape)
            }
        };
        let skewed = e.waveform == WaveformName::Skewed;
        if skewed && (neural || lattice.is_some()) {
            return Err(at.err(
                "waveform",
                "`skewed` is for encoding = \"graph\" bodies driven by controller = \"oscillator\"",
            ));
        }
        Ok(Morphology {
            encoding: e.encoding,
            max_particles: e.max_particles,
            max_springs: e.max_springs,
            total_mass,
            stiffness,
            muscle_strain: strain,
            muscle_rate: at.positive("muscle_rate", e.muscle_rate)?,
            size,
            self_contact: e.self_contact,
            mass,
            radius,
            damping: unit("damping", e.damping)?,
            mu_s: unit("mu_s", e.mu_s)?,
            mu_k: unit("mu_k", e.mu_k)?,
            restitution: unit("restitution", e.restitution)?,
            origin: at.vec3("origin", e.origin)?,
            lattice,
            neural,
            skewed,
        })
    }
}
