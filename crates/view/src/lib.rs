//! # animats-view
//!
//! What there is to see of a running world, shared by the live view
//! (`animats-viewer`, which streams it to a browser) and the software
//! renderer (`animats-render`, which draws it to pictures), so that drawing a
//! PNG does not link a web server and both show the same thing:
//!
//! - `model.rs`: the description of a world to draw (particles and their
//!   kinds, springs, jellyfish domes, food, the camera's first framing) and a
//!   creature's state;
//! - `drawing.rs`: what is drawn (balls, rods, bells, floor, water), decided
//!   once for the page and the renderer;
//! - `ground.rs`: the ground's triangles when the floor has a terrain;
//! - `palette.rs`: the colour of each kind of part, the one source of colour
//!   (the page receives it from the server with the scene);
//! - `stage.rs`: a [`Stage`] advances a world and describes it;
//!   [`SceneStage`] plays a scene file.

#![warn(missing_docs)]

pub mod drawing;
pub mod ground;
pub mod model;
pub mod palette;
pub mod stage;

pub use drawing::{Axle, Ball, BellPlan, BellShape, Drawing, Look, Rod};
pub use ground::GroundMesh;
pub use model::{CreatureState, Describe, Dome, Part};
pub use stage::{framing, snug, snug_watched, SceneStage, Stage};
