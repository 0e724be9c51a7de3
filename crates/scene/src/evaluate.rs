//! A scene's `[evolve]` evaluation: run the scene from its start for
//! `duration` seconds (or until one of `fail_on_touch` touches the floor, or
//! the simulation blows up) and score it with the thesis's form (§3.2.1.6):
//! `fitness = time_weight × time survived + distance_weight × distance`,
//! the distance being how far the centre of mass of `particles` moved along
//! `axis`. A run that blows up keeps the time it survived but no forward
//! distance (only a backward one), so that an optimiser cannot profit from
//! an explosion that flings the body ahead.
//!
//! [`SceneProblem`] evaluates genomes: it parses the scene once, and for
//! each genome builds the world afresh, writes the genome into the
//! `[evolve]` controller and runs the evaluation; [`SceneProblem::best_toml`]
//! writes a genome back into the scene's own text.

use crate::build::{At, Names};
use crate::def::{ControllerEntry, EvolveEntry, SceneDef};
use crate::error::SceneError;
use crate::source::Source;
use crate::Scene;
use animats_creatures::sensors::probe::touches_floor;
use animats_creatures::NervousSystem;
use animats_engine::{DVec3, ParticleId, World};
use std::fmt;

/// The longest evaluation, s (a simulated day).
pub const MAX_DURATION: f64 = 86_400.0;

/// The most steps an evaluation may take (as `animats simulate` allows).
pub const MAX_STEPS: f64 = 1e12;

/// A scene's `[evolve]` table, resolved against its world.
#[derive(Clone, Debug, PartialEq)]
pub struct EvolveSpec {
    /// The controller's name.
    pub controller: String,
    /// Its index in [`NervousSystem::controllers`].
    pub index: usize,
    /// Seconds per evaluation.
    pub duration: f64,
    /// Whose centre of mass counts.
    pub particles: Vec<ParticleId>,
    /// Unit direction that counts.
    pub axis: DVec3,
    /// Weight of the distance.
    pub distance_weight: f64,
    /// Weight of the time survived.
    pub time_weight: f64,
    /// The evaluation ends when any of these touches the floor.
    pub fail_on_touch: Vec<(ParticleId, String)>,
}

impl EvolveSpec {
    pub(crate) fn build(
        at: &At,
        e: &EvolveEntry,
        names: &Names,
        nervous: &NervousSystem,
        world: &World,
        dt: f64,
    ) -> Result<EvolveSpec, SceneError> {
        let index = nervous.controller(&e.controller).ok_or_else(|| {
            at.err(
                "controller",
                format!("no controller named `{}`", e.controller),
            )
        })?;
        let duration = at.positive("duration", e.duration)?;
        if duration > MAX_DURATION {
            return Err(at.err(
                "duration",
                format!("must be at most {MAX_DURATION} s (a simulated day), got {duration}"),
            ));
        }
        if duration / dt > MAX_STEPS {
            return Err(at.err(
                "duration",
                format!(
                    "{duration} s at dt = {dt} s is {:.3e} steps, more than {MAX_STEPS:e}: raise dt or shorten the evaluation",
                    duration / dt
                ),
            ));
        }
        let particles = match &e.particles {
            None => world.particle_ids().collect(),
            Some(list) if list.is_empty() => {
                return Err(at.err(
                    "particles",
                    "name at least one particle (or leave it out: all)",
                ))
            }
            Some(list) => list
                .iter()
                .map(|n| names.one(at, "particles", n))
                .collect::<Result<_, _>>()?,
        };
        let axis = at.vec3("axis", e.axis)?;
        if axis.length() == 0.0 {
            return Err(at.err("axis", "must not be zero"));
        }
        let fail_on_touch = e
            .fail_on_touch
            .iter()
            .map(|n| Ok((names.one(at, "fail_on_touch", n)?, n.clone())))
            .collect::<Result<_, SceneError>>()?;
        if nervous.controllers[index].brain.genome().is_empty() {
            return Err(at.err(
                "controller",
                format!("controller `{}` has no parameters to evolve", e.controller),
            ));
        }
        Ok(EvolveSpec {
            controller: e.controller.clone(),
            index,
            duration,
            particles,
            axis: axis.normalize(),
            distance_weight: at.finite("distance_weight", e.distance_weight)?,
            time_weight: at.finite("time_weight", e.time_weight)?,
            fail_on_touch,
        })
    }

    /// The centre of mass of the particles that count.
    pub fn centre(&self, world: &World) -> DVec3 {
        let (mut sum, mut m) = (DVec3::ZERO, 0.0);
        let mass = &world.particles().mass;
        for p in &self.particles {
            sum += world.position(*p) * mass[p.index()];
            m += mass[p.index()];
        }
        if m > 0.0 {
            sum / m
        } else {
            sum / self.particles.len().max(1) as f64
        }
    }

    /// The first of `fail_on_touch` touching the floor now.
    pub fn touching(&self, world: &World) -> Option<&str> {
        self.fail_on_touch
            .iter()
            .find(|(p, _)| touches_floor(world, *p))
            .map(|(_, n)| n.as_str())
    }
}

/// Why an evaluation ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Ended {
    /// It ran for the whole duration.
    Timeout,
    /// This particle of `fail_on_touch` touched the floor.
    Touch(String),
    /// The simulation blew up.
    BlowUp,
}

impl fmt::Display for Ended {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Ended::Timeout => f.write_str("timeout"),
            Ended::Touch(p) => write!(f, "touch {p}"),
            Ended::BlowUp => f.write_str("blow-up"),
        }
    }
}

/// The outcome of one evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// `time_weight × time + distance_weight × distance`.
    pub fitness: f64,
    /// Distance along the axis, m.
    pub distance: f64,
    /// Time survived, s.
    pub time: f64,
    /// Why it ended.
    pub ended: Ended,
}

/// Runs `scene`'s `[evolve]` evaluation; `observe` sees the scene before
/// the first step and after every step.
pub fn evaluate_with(
    mut scene: Scene,
    mut observe: impl FnMut(&Scene),
) -> Result<Evaluation, String> {
    let spec = scene
        .evolve
        .clone()
        .ok_or("the scene has no [evolve] table: nothing to evaluate")?;
    let dt = scene.dt;
    let steps = (spec.duration / dt).round() as u64;
    let start = spec.centre(&scene.world);
    let mut done = 0u64;
    let mut ended = Ended::Timeout;
    let mut last = start;
    observe(&scene);
    if let Some(p) = spec.touching(&scene.world) {
        ended = Ended::Touch(p.to_string());
    } else {
        while done < steps {
            if scene.step(dt).is_err() {
                ended = Ended::BlowUp;
                break;
            }
            done += 1;
            observe(&scene);
            let c = spec.centre(&scene.world);
            if !c.is_finite() {
                ended = Ended::BlowUp;
                break;
            }
            last = c;
            if let Some(p) = spec.touching(&scene.world) {
                ended = Ended::Touch(p.to_string());
                break;
            }
        }
    }
    let time = done as f64 * dt;
    let mut distance = (last - start).dot(spec.axis);
    if ended == Ended::BlowUp {
        distance = distance.min(0.0);
    }
    Ok(Evaluation {
        fitness: spec.time_weight * time + spec.distance_weight * distance,
        distance,
        time,
        ended,
    })
}

/// Runs `scene`'s `[evolve]` evaluation.
pub fn evaluate(scene: Scene) -> Result<Evaluation, String> {
    evaluate_with(scene, |_| {})
}

/// A scene whose `[evolve]` controller is evolved: genome → evaluation.
#[derive(Clone, Debug)]
pub struct SceneProblem {
    file: String,
    text: String,
    def: SceneDef,
    controller: usize,
    start: Vec<f64>,
    bounds: Vec<(f64, f64)>,
}

impl SceneProblem {
    /// Parses and checks a scene that has an `[evolve]` table.
    pub fn parse(text: &str, file: &str) -> Result<SceneProblem, SceneError> {
        let src = Source { file, text };
        let def = crate::parse_def(&src)?;
        let scene = crate::build::build(&def, &src)?;
        let spec = scene.evolve.as_ref().ok_or_else(|| {
            SceneError::file(
                file,
                "the scene has no [evolve] table: add one naming the controller to evolve (docs/SCENES.md)",
            )
        })?;
        let brain = &scene.nervous.controllers[spec.index].brain;
        // Controllers are built in the order written: the same index.
        let controller = spec.index;
        Ok(SceneProblem {
            file: file.to_string(),
            text: text.to_string(),
            start: brain.genome(),
            bounds: brain.bounds(),
            def,
            controller,
        })
    }

    /// Reads and parses a scene file.
    pub fn load(path: &std::path::Path) -> Result<SceneProblem, SceneError> {
        let file = path.display().to_string();
        let text = crate::read(path)?;
        SceneProblem::parse(&text, &file)
    }

    /// The scene's own parameters (where evolution starts).
    pub fn start(&self) -> &[f64] {
        &self.start
    }

    /// The genome's bounds.
    pub fn bounds(&self) -> &[(f64, f64)] {
        &self.bounds
    }

    /// The scene file's name.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The scene built afresh, as its file has it.
    pub fn fresh(&self) -> Result<Scene, String> {
        let src = Source {
            file: &self.file,
            text: &self.text,
        };
        crate::build::build(&self.def, &src).map_err(|e| e.to_string())
    }

    /// The scene built afresh with `genome` in its `[evolve]` controller.
    pub fn scene(&self, genome: &[f64]) -> Result<Scene, String> {
        let mut scene = self.fresh()?;
        let index = scene.evolve.as_ref().map_or(0, |s| s.index);
        scene.nervous.controllers[index].brain.set_genome(genome)?;
        Ok(scene)
    }

    /// Evaluates `genome`.
    pub fn evaluate(&self, genome: &[f64]) -> Result<Evaluation, String> {
        evaluate(self.scene(genome)?)
    }

    /// The scene's text with `genome` written into the `[evolve]`
    /// controller's keys (comments and layout kept), preceded by `comment`
    /// as `#` lines.
    pub fn best_toml(&self, genome: &[f64], comment: &str) -> Result<String, String> {
        let mut doc: toml_edit::DocumentMut = self
            .text
            .parse()
            .map_err(|e| format!("{}: {e}", self.file))?;
        let entry = self.def.controller[self.controller].get_ref();
        let table = doc
            .get_mut("controller")
            .and_then(|c| c.as_array_of_tables_mut())
            .and_then(|a| a.get_mut(self.controller))
            .ok_or("the controller table is not where the scene had it")?;
        write_genome(table, entry, genome)?;
        let mut out = String::new();
        for line in comment.lines() {
            out.push_str("# ");
            out.push_str(line);
            out.push('\n');
        }
        out.push_str(&doc.to_string());
        Ok(out)
    }
}

fn array(values: &[f64]) -> toml_edit::Item {
    let mut a = toml_edit::Array::new();
    for v in values {
        a.push(*v);
    }
    toml_edit::value(a)
}

/// Writes `genome` into a controller's table in the layout its kind's
/// brain documents (`crates/creatures/src/brains/`).
fn write_genome(
    table: &mut toml_edit::Table,
    c: &ControllerEntry,
    g: &[f64],
) -> Result<(), String> {
    let n = c.outputs.len();
    match c.kind.as_str() {
        "oscillator" if g.len() == 1 + 3 * n => {
            table["frequency"] = toml_edit::value(g[0]);
            table["amplitude"] = array(&g[1..1 + n]);
            table["phase"] = array(&g[1 + n..1 + 2 * n]);
            table["offset"] = array(&g[1 + 2 * n..]);
        }
        "neural" => {
            table["weights"] = array(g);
        }
        "fsm" => {
            let states = c.state.as_deref().unwrap_or_default();
            let tables = table
                .get_mut("state")
                .and_then(|s| s.as_array_of_tables_mut())
                .ok_or("the FSM's states are not an array of tables")?;
            let mut k = 0;
            let mut take = |count: usize| -> Result<&[f64], String> {
                let s = g
                    .get(k..k + count)
                    .ok_or("the genome is too short for this FSM")?;
                k += count;
                Ok(s)
            };
            for (i, s) in states.iter().enumerate() {
                let st = tables.get_mut(i).ok_or("an FSM state is missing")?;
                st["levels"] = array(take(n)?);
                if s.rate.is_some() {
                    st["rate"] = toml_edit::value(take(1)?[0]);
                }
                if s.transition.is_empty() {
                    continue;
                }
                let trs = st
                    .get_mut("transition")
                    .and_then(|t| t.as_array_of_tables_mut())
                    .ok_or("an FSM state's transitions are not an array of tables")?;
                for (j, t) in s.transition.iter().enumerate() {
                    let tt = trs.get_mut(j).ok_or("an FSM transition is missing")?;
                    if t.sensor.is_some() {
                        let key = if t.above.is_some() { "above" } else { "below" };
                        tt[key] = toml_edit::value(take(1)?[0]);
                    }
                    if t.after.is_some() {
                        tt["after"] = toml_edit::value(take(1)?[0]);
                    }
                }
            }
        }
        _ => {
            return Err(format!(
                "cannot write a genome of {} numbers into a `{}` controller",
                g.len(),
                c.kind
            ))
        }
    }
    Ok(())
}
