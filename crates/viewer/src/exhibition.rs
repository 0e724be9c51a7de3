//! Watching an evolution (`animats evolve [SCENE] --view`): the best
//! brain found so far, over all lanes, drives the scene from its start, as
//! its fitness was measured — the scene's own brain only until the first
//! generation has a best. In a `[morphology]` scene the best genome is a
//! body and its brain, developed into a scene as `best.toml` is; until the
//! first best, the starting body (the scene's `start`, or a random body
//! that passes the checks). When the run ends (the evaluation's duration,
//! a `fail_on_touch` particle on the floor, a blow-up) it starts again with
//! whatever the best is by then. The overlay gives the run shown's
//! distance and fitness so far. The evolution publishes through a
//! [`BestBrain`].

use crate::protocol::{CreatureState, Describe};
use animats_creatures::random::Random;
use animats_scene::evaluate::SceneProblem;
use animats_scene::morphology::MorphologyProblem;
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

/// What an evolution's genomes are.
enum Evolved {
    /// A scene's `[evolve]` controller: the genome drives its brain.
    Brain(Box<SceneProblem>),
    /// A `[morphology]` scene's bodies: the genome is a body and its brain.
    Body(Box<MorphologyProblem>),
}

/// Random bodies drawn, at most, to find one that passes the checks to
/// show before the first best (the last one drawn is shown if none does).
const RANDOM_TRIES: u64 = 20;

impl Evolved {
    fn file(&self) -> &str {
        match self {
            Evolved::Brain(p) => p.file(),
            Evolved::Body(p) => p.file(),
        }
    }

    /// The genome shown before the evolution has a best.
    fn start(&self) -> Vec<f64> {
        match self {
            Evolved::Brain(p) => p.start().to_vec(),
            Evolved::Body(p) => match p.start() {
                Some(g) => g.to_vec(),
                None => {
                    let mut genes = Vec::new();
                    for k in 0..RANDOM_TRIES {
                        genes = p.random(&mut Random::for_entry(0, k));
                        if p.check(&genes).is_ok() {
                            break;
                        }
                    }
                    genes
                }
            },
        }
    }

    /// The scene with `genome` in it, from its start.
    fn scene(&self, genome: &[f64]) -> Result<animats_scene::Scene, String> {
        match self {
            Evolved::Brain(p) => p.scene(genome),
            Evolved::Body(p) => {
                let text = p.develop(genome, "")?;
                animats_scene::parse(&text, p.file()).map_err(|e| e.to_string())
            }
        }
    }
}

/// The stage: the scene, driven by the best brain (or built with the best
/// body).
pub struct Exhibition {
    problem: Evolved,
    /// The genome shown until the evolution has a best.
    start: Vec<f64>,
    board: BestBrain,
    stage: SceneStage,
    /// The fitness and lane of the brain being shown (`None`: the scene's own).
    shown: Option<(f64, usize)>,
}

impl Exhibition {
    /// Starts with the scene's own brain until the evolution has a best.
    pub fn new(problem: SceneProblem, board: BestBrain) -> Result<Exhibition, String> {
        Self::of(Evolved::Brain(Box::new(problem)), board)
    }

    /// Watches a `[morphology]` scene's bodies evolve: starts with its
    /// starting body (or a random one that passes the checks) until the
    /// evolution has a best.
    pub fn bodies(problem: MorphologyProblem, board: BestBrain) -> Result<Exhibition, String> {
        Self::of(Evolved::Body(Box::new(problem)), board)
    }

    fn of(problem: Evolved, board: BestBrain) -> Result<Exhibition, String> {
        let start = problem.start();
        let (stage, shown) = Self::best_stage(&problem, &start, &board)?;
        Ok(Exhibition {
            problem,
            start,
            board,
            stage,
            shown,
        })
    }

    /// The scene from its start with the best genome now, and which genome
    /// that is.
    fn best_stage(
        problem: &Evolved,
        start: &[f64],
        board: &BestBrain,
    ) -> Result<(SceneStage, Option<(f64, usize)>), String> {
        let best = board.board().best.clone();
        let (genome, shown) = match best {
            Some((g, f, lane)) => (g, Some((f, lane))),
            None => (start.to_vec(), None),
        };
        let scene = problem.scene(&genome)?;
        let stage = SceneStage::from_scene(PathBuf::from(problem.file()), scene, None)?;
        Ok((stage, shown))
    }

    /// Starts the scene again with the best brain now.
    fn restart(&mut self) -> Result<(), String> {
        (self.stage, self.shown) = Self::best_stage(&self.problem, &self.start, &self.board)?;
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
        let what = match self.problem {
            Evolved::Brain(_) => "brain",
            Evolved::Body(_) => "body and brain",
        };
        d.title = format!("evolution: the best {what} for {}", self.problem.file());
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
            None => match &self.problem {
                Evolved::Brain(_) => "showing the scene's own brain".to_string(),
                Evolved::Body(p) if p.start().is_some() => "showing the starting body".to_string(),
                Evolved::Body(_) => "showing a random body".to_string(),
            },
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
