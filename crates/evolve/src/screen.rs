//! Which candidates of a generation need a robust scene's second run.
//!
//! A robust scene (`[evolve] robust = true`, the default for bodies) scores
//! a candidate at its step and at half of it, the worse counting: the
//! half-step run costs twice the first, and most candidates of a late
//! generation could not enter the population (or their cell of an archive)
//! whatever it gave, since the robust score is never above the score at the
//! step. A [`Screen`] says, from the run at the step, whether the second
//! run could matter; where it could not, that run's evaluation is the
//! candidate's score (an upper bound of its robust score).
//!
//! - The body GA: a child survives only above the worst parent (parents
//!   win ties), so a child at or below it is not run again, and the run is
//!   the same as with every child scored in full: the same survivors, the
//!   same best and `best.toml`. Only the log's `fitness` of a generation
//!   whose best child did not survive may show its score at the step.
//! - MAP-Elites over bodies: a candidate enters only above its cell's
//!   threshold; the cell is taken from the run at the step's measures (a
//!   body's measures barely move with the step: a screen, not a proof,
//!   for measures the run computes; exact for measures of the body as
//!   built).
//! - Every other optimiser ranks every candidate, and MAP-Elites over a
//!   fixed genome is pyribs's search: [`Screen::All`].
//!
//! The screen is part of a generation (see [`crate::run::Generation`]),
//! so evaluations elsewhere (Python, Ray) apply the same one and write the
//! same log.

use crate::archive::{index_of, GridArchive};
use crate::problem::Outcome;
use animats_scene::archive::Grid;
use serde::{Deserialize, Serialize};

/// Which candidates get a robust scene's half-step run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Screen {
    /// Every one.
    #[default]
    All,
    /// Those scoring above `bar` at the step.
    Above {
        /// The worst survivor's fitness.
        #[serde(with = "animats_scene::archive::minus_infinity_as_null")]
        bar: f64,
    },
    /// Those scoring above the threshold of the cell their measures at the
    /// step fall in.
    Cells {
        /// The archive's grid.
        grid: Grid,
        /// (cell, threshold) of every occupied cell, by cell.
        thresholds: Vec<(u64, f64)>,
        /// The threshold of an empty cell.
        #[serde(with = "animats_scene::archive::minus_infinity_as_null")]
        empty: f64,
        /// s: a candidate that survived less enters no cell.
        min_time: f64,
    },
}

impl Screen {
    /// The screen of `archive` as it is now.
    pub fn cells(archive: &GridArchive) -> Screen {
        let mut thresholds: Vec<(u64, f64)> = archive
            .elites()
            .iter()
            .map(|e| (e.index, e.threshold))
            .collect();
        thresholds.sort_by_key(|t| t.0);
        Screen::Cells {
            grid: archive.grid.clone(),
            thresholds,
            empty: archive.grid.threshold_min,
            min_time: archive.grid.min_time,
        }
    }

    /// The screen as JSON (to send with genomes evaluated elsewhere).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|_| "{\"kind\":\"all\"}".into())
    }

    /// A screen read back from [`Screen::to_json`].
    pub fn from_json(text: &str) -> Result<Screen, String> {
        serde_json::from_str(text).map_err(|e| format!("not a screen: {e}"))
    }

    /// Whether a candidate whose run at the step gave `coarse` needs the
    /// run at half the step.
    pub fn fine(&self, coarse: &Outcome) -> bool {
        let f = coarse.fitness;
        match self {
            Screen::All => true,
            // NaN is worst: it needs nothing more.
            Screen::Above { bar } => f > *bar,
            Screen::Cells {
                grid,
                thresholds,
                empty,
                min_time,
            } => {
                let k = grid.bins.len();
                if !f.is_finite()
                    || coarse.time < *min_time
                    || coarse.measures.len() != k
                    || coarse.measures.iter().any(|m| !m.is_finite())
                {
                    return false;
                }
                let cell = index_of(grid, &coarse.measures);
                let t = thresholds
                    .binary_search_by_key(&cell, |t| t.0)
                    .map_or(*empty, |i| thresholds[i].1);
                f > t
            }
        }
    }
}
