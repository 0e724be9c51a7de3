//! Watching an evolution (`animats evolve [SCENE] --view`): the best
//! brain found so far, over all lanes, drives the scene from its start, as
//! its fitness was measured — the scene's own brain only until the first
//! generation has a best. When the run ends (the evaluation's duration,
//! a `fail_on_touch` particle on the floor, a blow-up) it starts again with
//! whatever the best is by then. The overlay gives the run shown's
//! distance and fitness so far. The evolution publishes through a
//! [`BestBrain`].

use crate::protocol::{CreatureState, Describe};
use animats_scene::evaluate::SceneProblem;
use animats_view::{SceneStage, Stage};
use std::path::PathBuf;
use std::sync::{Arc, Mutex, PoisonError};

#[derive(Clone, Debug, Default)]
struct Board {
    best: Option<(Vec<f64>, f64, usize)>,
    generation: u64,
    generations: u64,
}

/// The best genome so far, shared between the evolving thread and the viewer.
#[derive(Clone, Debug, Default)]
pub struct BestBrain(Arc<Mutex<Board>>);

impl BestBrain {
    fn board(&self) -> std::sync::MutexGuard<'_, Board> {
        // Every field is assigned whole: a poisoned lock holds no half-write.
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Records the best genome so far, its fitness and its lane.
    pub fn set_best(&self, genome: &[f64], fitness: f64, lane: usize) {
        self.board().best = Some((genome.to_vec(), fitness, lane));
    }

    /// Records the progress of the run.
    pub fn set_generation(&self, generation: u64, generations: u64) {
        let mut b = self.board();
        b.generation = generation;
        b.generations = generations;
    }
}

/// The stage: the scene, driven by the best brain.
pub struct Exhibition {
    problem: SceneProblem,
    board: BestBrain,
    stage: SceneStage,
    /// The fitness and lane of the brain being shown (`None`: the scene's own).
    shown: Option<(f64, usize)>,
}

impl Exhibition {
    /// Starts with the scene's own brain until the evolution has a best.
    pub fn new(problem: SceneProblem, board: BestBrain) -> Result<Exhibition, String> {
        let (stage, shown) = Self::best_stage(&problem, &board)?;
        Ok(Exhibition {
            problem,
            board,
            stage,
            shown,
        })
    }

    /// The scene from its start with the best brain now, and which brain
    /// that is.
    fn best_stage(
        problem: &SceneProblem,
        board: &BestBrain,
    ) -> Result<(SceneStage, Option<(f64, usize)>), String> {
        let best = board.board().best.clone();
        let (genome, shown) = match best {
            Some((g, f, lane)) => (g, Some((f, lane))),
            None => (problem.start().to_vec(), None),
        };
        let scene = problem.scene(&genome)?;
        let stage = SceneStage::from_scene(PathBuf::from(problem.file()), scene, None)?;
        Ok((stage, shown))
    }

    /// Starts the scene again with the best brain now.
    fn restart(&mut self) -> Result<(), String> {
        (self.stage, self.shown) = Self::best_stage(&self.problem, &self.board)?;
        Ok(())
    }

    /// Whether the run shown has ended as an evaluation would.
    fn ended(&self) -> bool {
        let scene = self.stage.scene();
        match &scene.evolve {
            Some(spec) => {
                scene.world.time() >= spec.duration - 0.5 * scene.dt
                    || spec.ending(&scene.world).is_some()
            }
            None => false,
        }
    }
}

impl Stage for Exhibition {
    fn describe(&self) -> Describe {
        let mut d = self.stage.describe();
        d.title = format!("evolution: the best brain for {}", self.problem.file());
        d
    }

    fn dt(&self) -> f64 {
        self.stage.dt()
    }

    fn time(&self) -> f64 {
        self.stage.time()
    }

    fn step(&mut self, dt: f64) -> Result<(), String> {
        // The first best replaces the scene's own brain at once; later ones
        // wait for the run shown to end.
        if self.ended() || (self.shown.is_none() && self.board.board().best.is_some()) {
            return self.restart();
        }
        // A run that blows up ends too: the next best starts.
        if self.stage.step(dt).is_err() {
            return self.restart();
        }
        Ok(())
    }

    fn positions(&self, out: &mut Vec<f32>) {
        self.stage.positions(out);
    }

    fn creatures(&self) -> Vec<CreatureState> {
        self.stage.creatures()
    }

    fn levels(&self) -> Vec<f64> {
        self.stage.levels()
    }

    fn focus(&self) -> Option<[f64; 3]> {
        self.stage.focus()
    }

    fn note(&self) -> Option<String> {
        let b = self.board.board();
        let showing = match self.shown {
            Some((f, lane)) => format!("showing fitness {f:.2} (lane {lane})"),
            None => "showing the scene's own brain".to_string(),
        };
        let now = self.stage.progress_note().map_or(String::new(), |p| {
            format!(" · {p} at {:.1} s", self.stage.time())
        });
        Some(format!(
            "generation {} of {}: best fitness {}; {showing}{now}",
            b.generation,
            b.generations,
            b.best
                .as_ref()
                .map_or("none yet".to_string(), |(_, f, lane)| format!(
                    "{f:.2} (lane {lane})"
                ))
        ))
    }

    fn reset(&mut self) -> Result<(), String> {
        self.restart()
    }
}
