//! The roobot's parameter files as a scene sees them: the format lives with
//! the roobot (`animats_creatures::roobot::params_file`); here its errors
//! become [`SceneError`]s.

use crate::error::SceneError;
use animats_creatures::roobot::params_file::{self, ParamsError};
use animats_creatures::roobot::HopParams;

pub use params_file::{format, format_best, LaneBest, BUILT_IN, EVOLVED_TOML};

fn scene_error(e: ParamsError) -> SceneError {
    SceneError {
        file: e.file,
        line: e.line,
        entry: None,
        field: e.field,
        message: e.message,
    }
}

/// Checks a list of numbers is a parameter set (14 finite numbers).
pub fn check(file: &str, field: &str, values: &[f64]) -> Result<HopParams, SceneError> {
    params_file::check(file, field, values).map_err(scene_error)
}

/// Loads a parameter set: a built-in name (`initial`, `evolved`) or a file.
pub fn load(name_or_path: &str, lane: Option<usize>) -> Result<HopParams, SceneError> {
    params_file::load(name_or_path, lane).map_err(scene_error)
}
