//! The WebSocket protocol, all JSON text messages.
//!
//! Server → client:
//! - `{"type":"scene", ...}` ([`Describe`]) on connecting and after a reset:
//!   what there is to draw;
//! - `{"type":"frame", ...}` ([`Frame`]) at the display rate: where it is
//!   now, with `error` set once the simulation has failed.
//!
//! Client → server ([`Command`]): `{"cmd":"pause"}`, `{"cmd":"resume"}`,
//! `{"cmd":"step"}`, `{"cmd":"speed","value":2.0}`, `{"cmd":"reset"}`,
//! `{"cmd":"food","x":0.1,"z":-0.3}`. Extra fields are ignored (room to
//! grow); anything else is logged and ignored.

use serde::{Deserialize, Serialize};

pub use animats_view::model::{CreatureState, Describe, Dome, Part};
pub use animats_view::BellShape;

/// Where everything is now.
#[derive(Clone, Debug, Serialize)]
pub struct Frame {
    /// Always `frame`.
    #[serde(rename = "type")]
    pub kind: &'static str,
    /// Simulated time, s.
    pub t: f64,
    /// Frames published per second (the display rate).
    pub fps: f64,
    /// Simulated seconds per wall second over the last second.
    pub rtf: f64,
    /// The real-time factor asked for.
    pub speed: f64,
    /// True while paused.
    pub paused: bool,
    /// Positions, x y z per particle, m (single precision is plenty to draw).
    pub p: Vec<f32>,
    /// Every creature's state.
    pub creatures: Vec<CreatureState>,
    /// Each jellyfish's bell now, in the order of the scene's
    /// `drawing.bells` (`null` where its dome is degenerate).
    pub bells: Vec<Option<BellShape>>,
    /// Each rod's colour now (0xRRGGBB, in the order of the scene's
    /// `drawing.rods`): muscles by their activation; empty when the scene
    /// has no muscles (the rods keep their drawn colours).
    pub rods: Vec<u32>,
    /// Each joint's axle now, its two ends (m, single precision as `p`),
    /// in the order of the scene's `drawing.axles`.
    pub axles: Vec<[[f32; 3]; 2]>,
    /// Each axle's colour now (0xRRGGBB): motors by their actuator's
    /// level; empty when no actuator drives a joint.
    pub axle_colours: Vec<u32>,
    /// A point the camera may follow (the creature an evolution shows).
    pub focus: Option<[f64; 3]>,
    /// Why the simulation stopped, if it failed (it is paused until reset).
    pub error: Option<String>,
    /// A line about the run for the overlay (an evolution's generation).
    pub note: Option<String>,
}

/// What a client may ask.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(tag = "cmd", rename_all = "lowercase")]
pub enum Command {
    /// Stop simulated time.
    Pause,
    /// Start it again.
    Resume,
    /// One step while paused.
    Step,
    /// Real-time factor, clamped to [0.01, 100]; 0 (or anything not
    /// positive) means flat out.
    Speed {
        /// Simulated seconds per wall second.
        value: f64,
    },
    /// Start the scene again.
    Reset,
    /// Move the food to (x, z), keeping its height.
    Food {
        /// m.
        x: f64,
        /// m.
        z: f64,
    },
}
