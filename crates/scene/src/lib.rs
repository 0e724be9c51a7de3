//! # animats-scene
//!
//! Scene files (TOML) → worlds. The data flows one way: a file is parsed into
//! [`def::SceneDef`] (unknown keys refused), every entry is validated and
//! built into an [`animats_engine::World`], and mistakes come back as a
//! [`SceneError`] naming the file, line, entry (`spring[3]`) and field.
//!
//! ```
//! let scene = animats_scene::parse(r#"
//!     [world]
//!     dt = 0.002
//!     [[particle]]
//!     name = "ball"
//!     mass = 1.0
//!     position = [0.0, 1.0, 0.0]
//!     radius = 0.05
//!     [floor]
//! "#, "inline.toml")?;
//! assert_eq!(scene.names, ["ball"]);
//! assert_eq!(scene.dt, 0.002);
//! # Ok::<(), animats_scene::SceneError>(())
//! ```

#![warn(missing_docs)]

pub mod archive;
pub mod build;
pub mod def;
pub mod entries;
pub mod env;
pub mod error;
pub mod evaluate;
pub mod morphology;
pub(crate) mod nervous;
pub mod params;
pub mod source;
pub mod work;

pub use error::SceneError;

use animats_engine::{DivergenceGuard, ParticleId, SimError, StepReport, World};
use source::Source;
use std::path::Path;

/// A world built from a scene file, with the names of its particles and the
/// run settings of its `[world]` table.
pub struct Scene {
    /// The world, ready to step.
    pub world: World,
    /// Name of each particle, indexed by [`ParticleId::index`].
    pub names: Vec<String>,
    /// What each particle is part of, for drawing.
    pub kinds: Vec<PartKind>,
    /// The creatures, as data: their names and particles (what a camera
    /// follows), and a jellyfish's dome and tentacles (what its bell wraps).
    pub creatures: Vec<Creature>,
    /// Step, s.
    pub dt: f64,
    /// Largest stable step, s (real-time mode never exceeds it).
    pub max_dt: f64,
    /// Simulated seconds to run.
    pub duration: f64,
    /// Everything that acts once per step: creatures with their controllers,
    /// and environment processes (bubble columns).
    pub actors: Vec<Box<dyn animats_creatures::Actor>>,
    /// The sensors, actuators and controllers the scene declares; they act
    /// before the other actors every step.
    pub nervous: animats_creatures::NervousSystem,
    /// The scene's `[evolve]` table, resolved.
    pub evolve: Option<evaluate::EvolveSpec>,
    /// The scene's `[archive]` table, resolved: the measures each
    /// evaluation returns.
    pub archive: Option<archive::ArchiveSpec>,
    /// Watches for a run that diverges without going non-finite.
    pub guard: DivergenceGuard,
    /// Things that are allowed but probably not meant (a particle that
    /// starts inside the floor, a nail given a velocity, a step far past the
    /// stiffest spring's stability limit): front ends print them.
    pub warnings: Vec<String>,
    /// The scene's seed (`[world] seed`): what its random entries and its
    /// evaluation's trials are drawn from.
    pub seed: u64,
}

/// What a particle is part of, for drawing (its colour and look).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PartKind {
    /// A `[[particle]]`.
    Particle,
    /// A `[[food]]`.
    Food,
    /// A roobot.
    Roobot,
    /// A jellyfish's dome mass.
    Dome,
    /// A jellyfish's tentacle segment.
    Tentacle,
    /// A seaweed frond's segment.
    Seaweed,
    /// A bubble.
    Bubble,
    /// A rock.
    Rock,
    /// A quadruped.
    Quadruped,
}

impl PartKind {
    /// Its name, as the palette and the live view's page know it.
    pub fn name(self) -> &'static str {
        match self {
            PartKind::Particle => "particle",
            PartKind::Food => "food",
            PartKind::Roobot => "roobot",
            PartKind::Dome => "dome",
            PartKind::Tentacle => "tentacle",
            PartKind::Seaweed => "seaweed",
            PartKind::Bubble => "bubble",
            PartKind::Rock => "rock",
            PartKind::Quadruped => "quadruped",
        }
    }
}

/// A creature of a scene, as data.
#[derive(Clone, Debug, PartialEq)]
pub struct Creature {
    /// Its name (the prefix of its particles' names).
    pub name: String,
    /// Indices of its particles.
    pub particles: Vec<usize>,
    /// A jellyfish's bell: its dome masses and its tentacles' masses.
    pub bell: Option<Bell>,
}

/// The masses a jellyfish's bell is drawn over.
#[derive(Clone, Debug, PartialEq)]
pub struct Bell {
    /// Indices of the dome masses.
    pub dome: Vec<usize>,
    /// Indices of the tentacle masses (the bell opens towards them).
    pub tentacles: Vec<usize>,
}

use animats_creatures::kept::Kept;

/// The state of a scene at one instant (see [`Scene::snapshot`]).
#[derive(Clone, Debug)]
pub struct SceneSnapshot {
    /// The world's state.
    pub world: animats_engine::Snapshot,
    /// Each actuator's level, in the scene's order.
    pub levels: Vec<f64>,
    /// Each controller's brain's own state, in the scene's order.
    pub brains: Vec<Option<Kept>>,
    /// Each creature's and other actor's own state, in the scene's order.
    pub actors: Vec<Option<Kept>>,
}

/// Steps between the divergence guard's checks (it sums the energy).
const GUARD_EVERY: u64 = 64;

impl Scene {
    /// The particle called `name`.
    pub fn particle(&self, name: &str) -> Option<ParticleId> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(ParticleId::from_index)
    }

    /// The name of particle `p`.
    pub fn name(&self, p: ParticleId) -> &str {
        &self.names[p.index()]
    }

    /// Advances the scene by `dt`: every actor acts, then the world steps.
    /// A blow-up is an error: a non-finite state, or (checked every few
    /// steps) a run-away that [`DivergenceGuard`] catches.
    pub fn step(&mut self, dt: f64) -> Result<StepReport, SimError> {
        self.nervous.act(&mut self.world, dt);
        self.advance(dt)
    }

    /// `n` steps of `dt`, each a [`Scene::step`]; a world that splits its
    /// work over threads enters the global rayon pool once for all of them
    /// ([`animats_engine::on_pool_if`]) instead of at every step. Stops at the
    /// first blow-up.
    pub fn steps(&mut self, n: u64, dt: f64) -> Result<(), SimError> {
        self.steps_while(n, dt, || true).map(drop)
    }

    /// [`Scene::steps`], asking `more()` after every 64 steps and stopping
    /// there when it says no: how many steps it took (`n` unless stopped).
    /// The same steps, bit for bit, however it is cut: a caller that
    /// must answer meanwhile (Python's Ctrl-C) takes a long run in slices.
    pub fn steps_while(
        &mut self,
        n: u64,
        dt: f64,
        more: impl Fn() -> bool + Sync,
    ) -> Result<u64, SimError> {
        animats_engine::on_pool_if(self.world.steps_on_pool(), || {
            let mut done = 0;
            while done < n {
                let k = (n - done).min(64);
                (0..k).try_for_each(|_| self.step(dt).map(drop))?;
                done += k;
                if done < n && !more() {
                    break;
                }
            }
            Ok(done)
        })
    }

    /// Like [`Scene::step`], but a program is the brain: every actuator is
    /// driven towards `levels` (scene order, each at most its `rate`
    /// allows) and no controller runs. The other actors act as usual.
    pub fn step_driven(&mut self, levels: &[f64], dt: f64) -> Result<StepReport, String> {
        self.nervous.drive(&mut self.world, levels, dt)?;
        self.advance(dt).map_err(|e| e.to_string())
    }

    /// Everything that changes as the scene runs: the world's
    /// [`animats_engine::Snapshot`], the actuators' levels, and the
    /// controllers' and creatures' own state (an FSM's state, a recurrent
    /// network's activations, a timer, a random stream).
    pub fn snapshot(&self) -> SceneSnapshot {
        SceneSnapshot {
            world: self.world.snapshot(),
            levels: self.nervous.actuator_levels(),
            brains: self.nervous.brain_states(),
            actors: self.actors.iter().map(|a| a.save_state()).collect(),
        }
    }

    /// Puts back a [`Scene::snapshot`] of this scene (or of one built from
    /// the same file): it steps on as the scene did from there, bit for
    /// bit. A snapshot of another scene is refused, and this one left as
    /// it was.
    pub fn restore(&mut self, s: &SceneSnapshot) -> Result<(), String> {
        if s.actors.len() != self.actors.len() {
            return Err(format!(
                "the snapshot holds {} creatures' and actors' states for {}",
                s.actors.len(),
                self.actors.len()
            ));
        }
        let (brains, levels) = (self.nervous.brain_states(), self.nervous.actuator_levels());
        let actors: Vec<_> = self.actors.iter().map(|a| a.save_state()).collect();
        if let Err(e) = self.load_parts(&s.brains, &s.actors, &s.levels) {
            // Put back (its own parts always fit).
            let _ = self.load_parts(&brains, &actors, &levels);
            return Err(e);
        }
        // The world last: its actuated values are the exact ones, and a
        // world's restore changes nothing when it refuses.
        if let Err(e) = self.world.restore(&s.world) {
            let _ = self.load_parts(&brains, &actors, &levels);
            return Err(e.to_string());
        }
        Ok(())
    }

    /// The brains', actors' and actuators' parts of a snapshot; the world
    /// untouched.
    fn load_parts(
        &mut self,
        brains: &[Option<Kept>],
        actors: &[Option<Kept>],
        levels: &[f64],
    ) -> Result<(), String> {
        self.nervous.set_brain_states(brains)?;
        for (a, k) in self.actors.iter_mut().zip(actors) {
            a.load_state(k.as_ref())?;
        }
        self.nervous.set_levels_alone(levels)
    }

    /// The state was set by hand (positions, velocities): the divergence
    /// guard measures the world's energy from here on, not from the build.
    pub fn rearm_guard(&mut self) {
        let driven = !self.actors.is_empty() || !self.nervous.is_empty();
        self.guard = animats_engine::DivergenceGuard::new(&self.world, driven);
    }

    fn advance(&mut self, dt: f64) -> Result<StepReport, SimError> {
        for a in &mut self.actors {
            a.act(&mut self.world, dt);
        }
        let report = self.world.step(dt)?;
        if self.world.stats().steps.is_multiple_of(GUARD_EVERY) {
            self.guard.check(&self.world)?;
        }
        Ok(report)
    }
}

/// The thesis's evolution of hopping gaits as a scene
/// (`scenes/hop_evolver.toml`), built in: what `animats evolve` runs
/// without a scene, and what `roobot` names on the command line and in
/// Python.
pub const HOP_EVOLVER: &str = include_str!("../../../scenes/hop_evolver.toml");

/// The name [`HOP_EVOLVER`] goes by in messages.
pub const HOP_EVOLVER_FILE: &str = "scenes/hop_evolver.toml";

/// The largest scene file read, bytes (a scene at the particle limit,
/// [`build::MAX_PARTICLES`], comes from a few short entries, not megabytes).
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// Reads and builds the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let text = read(path)?;
    parse(&text, &file)
}

/// Reads a scene file's text, refusing one past [`MAX_FILE_BYTES`].
pub fn read(path: &Path) -> Result<String, SceneError> {
    let file = path.display().to_string();
    let size = std::fs::metadata(path)
        .map_err(|e| SceneError::file(&file, format!("cannot read the scene file: {e}")))?
        .len();
    if size > MAX_FILE_BYTES {
        return Err(SceneError::file(
            &file,
            format!("the scene file is {size} bytes, more than the limit of {MAX_FILE_BYTES}"),
        ));
    }
    // Bounded as it reads too: a device or a pipe states no size.
    animats_files::read_text(path, MAX_FILE_BYTES).map_err(|e| {
        let why = match e.kind() {
            std::io::ErrorKind::FileTooLarge => {
                format!("the scene file is more than the limit of {MAX_FILE_BYTES} bytes")
            }
            _ => format!("cannot read the scene file: {e}"),
        };
        SceneError::file(&file, why)
    })
}

/// Parses and builds a scene from its text; `file` names it in errors. A
/// `[morphology]` scene is built with its starting body (the `start`
/// scene's, or the first random body of seed 1) developed into it, and
/// warns of a step too long for the bodies its budgets allow.
pub fn parse(text: &str, file: &str) -> Result<Scene, SceneError> {
    let src = Source { file, text };
    let def = parse_def(&src)?;
    if def.morphology.is_some() {
        let problem = morphology::MorphologyProblem::parse(text, file)?;
        let genes = match problem.start() {
            Some(g) => g.to_vec(),
            None => problem.random(&mut animats_creatures::random::Random::for_evaluation(
                1, 0, 0,
            )),
        };
        let developed = problem
            .develop(&genes, "")
            .map_err(|m| SceneError::file(file, m))?;
        let mut scene = parse(&developed, file)?;
        let kind = scene.world.integrator();
        scene.warnings.extend(problem.step_warning(scene.dt, kind));
        return Ok(scene);
    }
    build::build(&def, &src)
}

/// Parses a scene's text into its description without building it.
pub fn parse_def(src: &Source) -> Result<def::SceneDef, SceneError> {
    toml::from_str::<def::SceneDef>(src.text).map_err(|e| {
        let offset = e.span().map(|s| s.start);
        let message = e.message().trim().to_string();
        SceneError {
            file: src.file.to_string(),
            line: offset.map(|o| src.line_of(o)),
            entry: offset.and_then(|o| src.entry_at(o)),
            field: offset
                .and_then(|o| src.key_at(o))
                .filter(|k| !message.contains(&format!("`{k}`"))),
            message,
        }
    })
}
