//! # animats-render
//!
//! Pictures: plots (fitness against generation) encoded as PNG without any
//! system library — the font is embedded and PNGs are written with the `png`
//! crate.

pub mod plot;
pub mod png_file;

pub use plot::{step_plot_png, Plot, Series};
