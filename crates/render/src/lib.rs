//! # animats-render
//!
//! Pictures, without any system library or GPU:
//!
//! - `plot.rs`: line plots (fitness against generation) drawn with plotters
//!   and an embedded font;
//! - `camera.rs`, `picture.rs`, `raster.rs`: a software renderer that
//!   ray-casts spheres, springs and jellyfish bells over a checkered floor,
//!   in air or under water, deterministically;
//! - `image.rs`: RGB images, captions and frame sheets;
//! - `png_file.rs`, `gif_file.rs`, `video.rs`: PNG and GIF with the `png`
//!   and `gif` crates; MP4 through `ffmpeg` when it is installed.

#![warn(missing_docs)]

pub mod camera;
pub mod gif_file;
pub mod heatmap;
pub mod image;
pub mod picture;
pub mod plot;
pub mod png_file;
pub mod raster;
pub mod video;

pub use camera::Camera;
pub use heatmap::{heatmap_png, Heatmap};
pub use image::Image;
pub use picture::{picture, Bell, Picture, Rod, Sphere};
pub use plot::{step_plot_png, Plot, Series};
pub use raster::render;
