//! An evolution run: independent lanes, each a hill climber over the roobot's
//! 14 hopping parameters, advanced generation by generation, in parallel.
//!
//! A generation is one evaluation per lane (generation 1 evaluates the
//! starting parameters themselves, as in Table 6). Every improvement is
//! logged. Lanes advance in chunks; within a chunk each lane runs on its own
//! (in parallel), and its log rows are merged in (generation, lane) order, so
//! the log is the same whatever the number of threads.

use crate::hill_climber::HillClimber;
use crate::optimiser::Optimiser;
use animats_creatures::random::Random;
use animats_creatures::roobot::evaluate::{evaluate, EvalSettings, Evaluation};
use animats_creatures::roobot::{HopParams, PARAM_COUNT};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// What a run was asked to do; fixed for its lifetime (a resumed run keeps it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// Independent lanes.
    pub lanes: usize,
    /// Generations per lane to reach.
    pub generations: u64,
    /// Seed of every random stream.
    pub seed: u64,
    /// Starting parameters of every lane.
    pub start: Vec<f64>,
    /// Longest evaluation, s.
    pub seconds: f64,
    /// Integration step, s.
    pub dt: f64,
}

impl Config {
    /// The thesis's experiment: `lanes` lanes from Appendix B's initial
    /// parameters, 20 s evaluations at 8 ms.
    pub fn thesis(lanes: usize, generations: u64, seed: u64) -> Config {
        Config {
            lanes,
            generations,
            seed,
            start: HopParams::INITIAL.0.to_vec(),
            seconds: 20.0,
            dt: 0.008,
        }
    }

    /// Checks the configuration; the error names the field.
    pub fn validate(&self) -> Result<(), String> {
        if self.lanes == 0 || self.lanes > 1024 {
            return Err(format!(
                "lanes: must be between 1 and 1024, got {}",
                self.lanes
            ));
        }
        if self.start.len() != PARAM_COUNT || !self.start.iter().all(|p| p.is_finite()) {
            return Err(format!("start: must be {PARAM_COUNT} finite numbers"));
        }
        let positive = |x: f64| x > 0.0 && x.is_finite();
        if !positive(self.seconds) || !positive(self.dt) {
            return Err("seconds and dt must be positive".into());
        }
        Ok(())
    }

    /// The evaluation settings this run uses.
    pub fn settings(&self) -> EvalSettings {
        EvalSettings {
            seconds: self.seconds,
            dt: self.dt,
            ..EvalSettings::default()
        }
    }
}

/// One improvement: a row of `log.csv` (the shape of the thesis's Table 6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LogRow {
    /// Lane, 0-based.
    pub lane: usize,
    /// Generation, 1-based.
    pub generation: u64,
    /// Fitness: time_up + 50 × distance.
    pub fitness: f64,
    /// Time upright, s.
    pub time_up: f64,
    /// Forward distance, m.
    pub distance: f64,
    /// The 14 parameters.
    pub params: Vec<f64>,
}

/// Where one lane stands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Lane {
    /// Lane, 0-based.
    pub lane: usize,
    /// Generations completed.
    pub generation: u64,
    /// Best parameters so far.
    pub best: Vec<f64>,
    /// Their fitness (−∞ before the first evaluation, stored as null).
    pub best_fitness: Option<f64>,
    /// Their evaluation.
    pub best_time_up: f64,
    /// Their forward distance, m.
    pub best_distance: f64,
}

/// Everything needed to continue a run: what a checkpoint stores.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// The run's configuration.
    pub config: Config,
    /// Each lane.
    pub lanes: Vec<Lane>,
    /// Every improvement so far, in (generation, lane) order.
    pub log: Vec<LogRow>,
    /// Evaluations done so far.
    pub evaluations: u64,
}

impl State {
    /// A fresh run.
    pub fn new(config: Config) -> Result<State, String> {
        config.validate()?;
        let lanes = (0..config.lanes)
            .map(|lane| Lane {
                lane,
                generation: 0,
                best: config.start.clone(),
                best_fitness: None,
                best_time_up: 0.0,
                best_distance: 0.0,
            })
            .collect();
        Ok(State {
            config,
            lanes,
            log: Vec::new(),
            evaluations: 0,
        })
    }

    /// Checks a state read back from a checkpoint is consistent.
    pub fn validate(&self) -> Result<(), String> {
        self.config.validate()?;
        if self.lanes.len() != self.config.lanes {
            return Err(format!(
                "{} lanes stored for a run of {}",
                self.lanes.len(),
                self.config.lanes
            ));
        }
        for (i, l) in self.lanes.iter().enumerate() {
            if l.lane != i || l.best.len() != PARAM_COUNT || !l.best.iter().all(|p| p.is_finite()) {
                return Err(format!("lane {i} is malformed"));
            }
            if l.generation > 0 && l.best_fitness.is_none() {
                return Err(format!("lane {i} has generations but no fitness"));
            }
        }
        for r in &self.log {
            if r.lane >= self.lanes.len() || r.params.len() != PARAM_COUNT {
                return Err(format!(
                    "log row for lane {} generation {} is malformed",
                    r.lane, r.generation
                ));
            }
        }
        Ok(())
    }

    /// Generations completed by every lane.
    pub fn generation(&self) -> u64 {
        self.lanes.iter().map(|l| l.generation).min().unwrap_or(0)
    }

    /// True when every lane has reached the configured generations.
    pub fn done(&self) -> bool {
        self.generation() >= self.config.generations
    }

    /// Best fitness over all lanes so far.
    pub fn best_fitness(&self) -> Option<f64> {
        self.lanes
            .iter()
            .filter_map(|l| l.best_fitness)
            .max_by(f64::total_cmp)
    }

    /// Advances every lane by up to `generations` generations (not past the
    /// configured total), lanes in parallel on the current rayon pool.
    pub fn advance(&mut self, generations: u64) -> Result<(), String> {
        let config = self.config.clone();
        let settings = config.settings();
        let target = config.generations;
        let results: Vec<Result<(Vec<LogRow>, u64), String>> = self
            .lanes
            .par_iter_mut()
            .map(|lane| {
                advance_lane(
                    lane,
                    &config,
                    &settings,
                    generations.min(target.saturating_sub(lane.generation)),
                )
            })
            .collect();
        let mut rows = Vec::new();
        for r in results {
            let (lane_rows, evaluations) = r?;
            rows.extend(lane_rows);
            self.evaluations += evaluations;
        }
        rows.sort_by_key(|r| (r.generation, r.lane));
        self.log.extend(rows);
        Ok(())
    }

    /// `log.csv`: a header, then one row per improvement, numbers in their
    /// shortest round-trip form.
    pub fn log_csv(&self) -> String {
        let mut out = String::from("lane,generation,fitness,time_up,distance");
        for i in 0..PARAM_COUNT {
            out.push_str(&format!(",p{i}"));
        }
        out.push('\n');
        let mut b = ryu::Buffer::new();
        for r in &self.log {
            out.push_str(&format!("{},{}", r.lane, r.generation));
            for x in [r.fitness, r.time_up, r.distance].iter().chain(&r.params) {
                out.push(',');
                out.push_str(b.format(*x));
            }
            out.push('\n');
        }
        out
    }

    /// Best fitness of each lane after each generation 1..=n (a step function
    /// of the log), for plots.
    pub fn fitness_curves(&self) -> Vec<Vec<(u64, f64)>> {
        let mut curves = vec![Vec::new(); self.lanes.len()];
        for r in &self.log {
            curves[r.lane].push((r.generation, r.fitness));
        }
        for (curve, lane) in curves.iter_mut().zip(&self.lanes) {
            if let (Some(&(_, f)), true) = (curve.last(), lane.generation > 0) {
                curve.push((lane.generation, f));
            }
        }
        curves
    }
}

fn advance_lane(
    lane: &mut Lane,
    config: &Config,
    settings: &EvalSettings,
    n: u64,
) -> Result<(Vec<LogRow>, u64), String> {
    let mut climber = match lane.best_fitness {
        Some(f) => HillClimber::resume(lane.best.clone(), f, lane.lane),
        None => HillClimber::new(lane.best.clone(), lane.lane),
    };
    let mut rows = Vec::new();
    for _ in 0..n {
        let generation = lane.generation + 1;
        let mut rng = Random::for_evaluation(config.seed, lane.lane, generation);
        let candidate = climber.ask(&mut rng);
        let mut params = HopParams::INITIAL;
        params.0.copy_from_slice(&candidate);
        let e: Evaluation = evaluate(params, settings).map_err(|e| e.to_string())?;
        if climber.tell(&candidate, e.fitness) {
            lane.best = candidate.clone();
            lane.best_fitness = Some(e.fitness);
            lane.best_time_up = e.time_up;
            lane.best_distance = e.distance;
            rows.push(LogRow {
                lane: lane.lane,
                generation,
                fitness: e.fitness,
                time_up: e.time_up,
                distance: e.distance,
                params: candidate,
            });
        }
        lane.generation = generation;
    }
    Ok((rows, n))
}
