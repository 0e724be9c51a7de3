//! The underwater world of the jellyfish (thesis §3.2.2.5, Appendix B
//! `SeaWorld`): swaying seaweed, rising bubbles and sinking rocks, all moved by
//! the same `ReefWater` currents (the engine's `Current::Reef`).

pub mod bubble_column;
pub mod rocks;
pub mod seaweed;

pub use crate::random::Random;
pub use bubble_column::{BubbleColumn, BubbleConstants};
pub use rocks::RocksConstants;
pub use seaweed::{Seaweed, SeaweedConstants};
