//! The sensors, one per file.

pub mod depth;
pub mod food;
pub mod height;
pub mod probe;
pub mod speed;
pub mod tilt;
pub mod touchdown;

pub use depth::DepthSensor;
pub use food::FoodSensor;
pub use height::HeightSensor;
pub use probe::{Probe, ScaledSensor, SensorEntry};
pub use speed::SpeedSensor;
pub use tilt::TiltSensor;
pub use touchdown::TouchdownSensor;
