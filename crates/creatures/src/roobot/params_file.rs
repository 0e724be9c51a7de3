//! Parameter files of the roobot's hopping FSM (`params/`, `best.toml`): TOML with
//! `params = [14 numbers]`, one comment line per parameter naming it.
//! `animats evolve` also writes `best.toml` in this format, with the best
//! lane's set on top and every lane's in `[[lane_best]]` tables.
//!
//! ```toml
//! # Roobot hopping-FSM parameters (thesis Table 4).
//! params = [
//!     0.2,   # 0 target leg extension in stance
//!     0.55,  # 1 target leg angle in stance
//!     ...
//! ]
//! ```

use super::{HopParams, PARAM_COUNT, PARAM_NAMES};
use serde::Deserialize;
use std::fmt;
use std::path::Path;

/// Something wrong with a parameter file: the file, the line when known,
/// the field, and what.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamsError {
    /// The file, as the user named it (or `evolved (built in)`).
    pub file: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// The field at fault, e.g. `params[3]` or `lane_best`.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ParamsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        match &self.field {
            Some(k) if !k.is_empty() => write!(f, ": {k}: {}", self.message),
            _ => write!(f, ": {}", self.message),
        }
    }
}

impl std::error::Error for ParamsError {}

/// The most bytes a parameter file may hold (one is a few hundred; a
/// lanes file of thousands of lanes fits too).
const MAX_BYTES: u64 = 16 << 20;

/// The built-in parameter sets, by name.
pub const BUILT_IN: [&str; 2] = ["initial", "evolved"];

/// The shipped result of our own evolution (`params/evolved.toml`).
pub const EVOLVED_TOML: &str = include_str!("../../../../params/evolved.toml");

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamFile {
    params: Option<Vec<f64>>,
    lane: Option<usize>,
    fitness: Option<f64>,
    time_up: Option<f64>,
    distance: Option<f64>,
    #[serde(default, rename = "lane_best")]
    lanes: Vec<LaneEntry>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LaneEntry {
    lane: usize,
    params: Vec<f64>,
    fitness: Option<f64>,
    time_up: Option<f64>,
    distance: Option<f64>,
}

fn err(file: &str, field: &str, message: impl Into<String>) -> ParamsError {
    ParamsError {
        file: file.to_string(),
        line: None,
        field: Some(field.to_string()),
        message: message.into(),
    }
}

/// Checks a list of numbers is a parameter set: 14 finite numbers.
pub fn check(file: &str, field: &str, values: &[f64]) -> Result<HopParams, ParamsError> {
    if values.len() != PARAM_COUNT {
        return Err(err(
            file,
            field,
            format!("expected {PARAM_COUNT} numbers, got {}", values.len()),
        ));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(err(
            file,
            &format!("{field}[{i}]"),
            format!("must be a finite number, got {}", values[i]),
        ));
    }
    let mut p = HopParams::INITIAL;
    p.0.copy_from_slice(values);
    Ok(p)
}

/// Parses a parameter file's text; with `lane`, takes that lane's set from
/// its `[[lane_best]]` tables instead of the top-level `params`.
pub fn parse(text: &str, file: &str, lane: Option<usize>) -> Result<HopParams, ParamsError> {
    let parsed: ParamFile = toml::from_str(text).map_err(|e| {
        let offset = e.span().map(|s| s.start.min(text.len()));
        ParamsError {
            file: file.to_string(),
            line: offset.map(|o| text.as_bytes()[..o].iter().filter(|&&b| b == b'\n').count() + 1),
            field: None,
            message: e.message().trim().to_string(),
        }
    })?;
    let _ = (parsed.lane, parsed.fitness, parsed.time_up, parsed.distance);
    match lane {
        None => match &parsed.params {
            Some(v) => check(file, "params", v),
            None => Err(err(file, "params", "missing: give `params = [14 numbers]`")),
        },
        Some(k) => {
            let entry = parsed
                .lanes
                .iter()
                .find(|l| l.lane == k)
                .ok_or_else(|| err(file, "lane_best", format!("no entry for lane {k}")))?;
            let _ = (entry.fitness, entry.time_up, entry.distance);
            check(
                file,
                &format!("lane_best[lane = {k}].params"),
                &entry.params,
            )
        }
    }
}

/// Loads a parameter set: a built-in name (`initial`, `evolved`) or a file.
pub fn load(name_or_path: &str, lane: Option<usize>) -> Result<HopParams, ParamsError> {
    match name_or_path {
        "initial" if lane.is_none() => Ok(HopParams::INITIAL),
        "evolved" => parse(EVOLVED_TOML, "evolved (built in)", lane),
        path => {
            let text = animats_files::read_text(Path::new(path), MAX_BYTES).map_err(|e| {
                let hint = if Path::new(path).extension().is_none() {
                    format!(" (built-in sets: {})", BUILT_IN.join(", "))
                } else {
                    String::new()
                };
                ParamsError {
                    file: path.to_string(),
                    line: None,
                    field: None,
                    message: format!("cannot read the parameter file: {e}{hint}"),
                }
            })?;
            parse(&text, path, lane)
        }
    }
}

/// Writes `key = [ ... ]`, one number per line with its name as a comment;
/// `{:?}` prints the shortest form that reads back to the same f64.
fn params_block(out: &mut String, key: &str, p: &[f64], indent: &str) {
    out.push_str(&format!("{key} = [\n"));
    for (i, v) in p.iter().enumerate() {
        let item = format!("{indent}    {v:?},");
        out.push_str(&format!("{item:<32}# {i} {}\n", PARAM_NAMES[i]));
    }
    out.push_str(&format!("{indent}]\n"));
}

/// Formats one parameter set as a parameter file, with `comment` lines on top.
pub fn format(params: &HopParams, comment: &str) -> String {
    let mut out = String::new();
    for line in comment.lines() {
        out.push_str(&format!("# {line}\n"));
    }
    params_block(&mut out, "params", &params.0, "");
    out
}

/// One lane's best, for [`format_best`].
pub struct LaneBest {
    /// Lane, 0-based.
    pub lane: usize,
    /// Its best parameters.
    pub params: HopParams,
    /// Their fitness.
    pub fitness: f64,
    /// Time upright, s.
    pub time_up: f64,
    /// Distance, m.
    pub distance: f64,
}

/// Formats `best.toml`: the best lane's parameters on top (what `animats hop
/// best.toml` loads), then every lane's in `[[lane_best]]` tables
/// (`animats hop best.toml --lane K`).
pub fn format_best(lanes: &[LaneBest], comment: &str) -> String {
    let mut out = String::new();
    for line in comment.lines() {
        out.push_str(&format!("# {line}\n"));
    }
    if let Some(top) = lanes.iter().max_by(|a, b| a.fitness.total_cmp(&b.fitness)) {
        out.push_str(&format!(
            "lane = {}\nfitness = {:?}\ntime_up = {:?}\ndistance = {:?}\n",
            top.lane, top.fitness, top.time_up, top.distance
        ));
        params_block(&mut out, "params", &top.params.0, "");
    }
    for l in lanes {
        out.push_str(&format!(
            "\n[[lane_best]]\nlane = {}\nfitness = {:?}\ntime_up = {:?}\ndistance = {:?}\n",
            l.lane, l.fitness, l.time_up, l.distance
        ));
        params_block(&mut out, "params", &l.params.0, "");
    }
    out
}
