//! A scene's `[evolve]` evaluation: run the scene from its start for
//! `duration` seconds (or until one of `fail_on_touch` touches the floor,
//! two particles of `fail_on_stretch` are too far apart, or the simulation
//! blows up) and score it with the thesis's form (§3.2.1.6):
//! `fitness = time_weight × time survived + distance_weight × distance`,
//! the distance being how far the centre of mass of `particles` moved along
//! `axis`, less `energy_weight` × the actuators' positive work
//! ([`crate::work`]) and `target_weight` × the final distance from
//! `target`, plus each of `terms` (archive measures) times its weight;
//! [`score`] averages (or takes the worst of) `trials` perturbed runs. A run that blows up keeps the time it survived but no forward
//! distance (only a backward one), so that an optimiser cannot profit from
//! an explosion that flings the body ahead.
//!
//! [`SceneProblem`] evaluates genomes: it parses the scene once, and for
//! each genome builds the world afresh, writes the genome into the
//! `[evolve]` controller and runs the evaluation; [`SceneProblem::best_toml`]
//! writes a genome back into the scene's own text, where the brain's
//! [`animats_creatures::brain::GenomeKey`]s say.

use crate::build::{At, Names};
use crate::def::{AggregateName, EvolveEntry, LogName, MutationName, SceneDef};
use crate::error::SceneError;
use crate::source::Source;
use crate::Scene;
use animats_creatures::brain::GenomeKey;
use animats_creatures::sensors::probe::TOUCH_TOLERANCE;
use animats_creatures::NervousSystem;
use animats_engine::{DVec3, ParticleId, Shown, World};
use std::cell::RefCell;
use std::fmt;
use std::rc::Rc;

/// The longest evaluation, s (a simulated day).
pub const MAX_DURATION: f64 = 86_400.0;

/// The most steps an evaluation may take (as `animats simulate` allows).
pub const MAX_STEPS: f64 = 1e12;

/// A scene's `[evolve]` table, resolved against its world.
#[derive(Clone, Debug, PartialEq)]
pub struct EvolveSpec {
    /// The controller evolved, if the table names one (a scene whose
    /// `[evolve]` names none is scored as it is, and cannot be evolved).
    pub controller: Option<String>,
    /// Every controller evolved (`controllers`, or the one `controller`):
    /// its index in [`NervousSystem::controllers`] and the table it was
    /// written in; the genome is theirs end to end, in this order.
    pub evolved: Vec<(usize, (&'static str, usize))>,
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
    /// How close to the floor counts as touching it, m.
    pub touch_tolerance: f64,
    /// The evaluation ends when these two are at least this far apart, m.
    pub fail_on_stretch: Vec<Stretch>,
    /// How the hill climber mutates.
    pub mutation: MutationName,
    /// What `log.csv` holds.
    pub log: LogName,
    /// Lanes to run unless told.
    pub lanes: Option<usize>,
    /// Each evaluation runs at the scene's step and at half of it; the
    /// worse counts.
    pub robust: bool,
    /// How many times a robust evaluation halves the step (1: the step and
    /// half of it; 2: a quarter too; ...), each finer run made where the
    /// worst so far could matter.
    pub robust_halvings: u32,
    /// The optimiser to use unless told, by its command-line name
    /// (checked by whoever runs the evolution).
    pub optimiser: Option<String>,
    /// Per joule of the actuators' positive work ([`crate::work`]),
    /// subtracted from the fitness.
    pub energy_weight: f64,
    /// Where the centre of `particles` should end up, and the weight per
    /// metre it ends from there, subtracted.
    pub target: Option<(DVec3, f64)>,
    /// Evaluations per genome.
    pub trials: u32,
    /// How much each trial's start and actuators are perturbed.
    pub noise: f64,
    /// What counts of the trials.
    pub aggregate: AggregateName,
    /// Measures added to the fitness, each times its weight: (weight,
    /// measure).
    pub terms: Vec<(f64, crate::archive::Measure)>,
}

impl EvolveSpec {
    /// Whether an evaluation must sum the actuators' work.
    pub fn needs_work(&self) -> bool {
        self.energy_weight != 0.0 || self.terms.iter().any(|(_, m)| m.needs_work())
    }
}

/// The most trials an evaluation may have.
pub const MAX_TRIALS: u32 = 1000;

/// The most times a robust evaluation may halve the step (a sixteenth:
/// 31 runs' time at the step for a candidate scored at every step).
pub const MAX_HALVINGS: u32 = 4;

/// The largest magnitude of a fitness weight (`distance_weight`,
/// `time_weight`, `energy_weight`, `target_weight`, each term's `weight`):
/// far above any useful weight, and far below those (10³⁰⁸) that made
/// every fitness infinite, which no optimiser can rank.
pub const MAX_WEIGHT: f64 = 1e12;

/// `x` as a fitness weight: finite and at most [`MAX_WEIGHT`] in magnitude.
fn weight(at: &At, field: &str, x: f64) -> Result<f64, SceneError> {
    let x = at.finite(field, x)?;
    if x.abs() > MAX_WEIGHT {
        return Err(at.err(
            field,
            format!("must be between -{MAX_WEIGHT:e} and {MAX_WEIGHT:e}, got {x:e}"),
        ));
    }
    Ok(x)
}

/// An `[evolve]` table's end rules, resolved.
struct EndRules {
    fail_on_touch: Vec<(ParticleId, String)>,
    touch_tolerance: f64,
    fail_on_stretch: Vec<Stretch>,
}

/// A `fail_on_stretch` rule.
#[derive(Clone, Debug, PartialEq)]
pub struct Stretch {
    /// One end.
    pub a: ParticleId,
    /// The other.
    pub b: ParticleId,
    /// The length that ends the run, m.
    pub length: f64,
    /// `a-b`, by their names.
    pub name: String,
}

impl EvolveSpec {
    /// The (first) evolved controller's index in
    /// [`NervousSystem::controllers`].
    pub fn index(&self) -> Option<usize> {
        self.evolved.first().map(|(i, _)| *i)
    }

    /// The table the (first) evolved controller was written in
    /// (`controller`, 2), where its genes are written back.
    pub fn table(&self) -> Option<(&'static str, usize)> {
        self.evolved.first().map(|(_, t)| *t)
    }

    pub(crate) fn build(
        at: &At,
        e: &EvolveEntry,
        names: &Names,
        nervous: &NervousSystem,
        origins: &[(&'static str, usize)],
        world: &World,
        dt: f64,
    ) -> Result<EvolveSpec, SceneError> {
        let (field, names_evolved): (&str, Vec<&String>) = match (&e.controller, &e.controllers) {
            (Some(_), Some(_)) => {
                return Err(at.err(
                    "controllers",
                    "give `controller` (one) or `controllers` (several), not both",
                ))
            }
            (Some(c), None) => ("controller", vec![c]),
            (None, Some(list)) if list.is_empty() => {
                return Err(at.err("controllers", "name at least one controller"))
            }
            (None, Some(list)) => ("controllers", list.iter().collect()),
            (None, None) => ("controller", Vec::new()),
        };
        let mut evolved = Vec::new();
        for c in &names_evolved {
            let i = nervous
                .controller(c)
                .ok_or_else(|| at.err(field, format!("no controller named `{c}`")))?;
            if evolved.iter().any(|(j, _)| *j == i) {
                return Err(at.err(field, format!("controller `{c}` is named twice")));
            }
            if nervous.controllers[i].brain.genome().is_empty() {
                return Err(at.err(
                    field,
                    format!("controller `{c}` has no parameters to evolve"),
                ));
            }
            evolved.push((i, origins[i]));
        }
        let duration = Self::duration(at, e, dt)?;
        let particles: Vec<ParticleId> = match &e.particles {
            None => world.particle_ids().collect(),
            Some(list) if list.is_empty() => {
                return Err(at.err(
                    "particles",
                    "name at least one particle (or leave it out: all)",
                ))
            }
            Some(list) => names.list(at, "particles", list)?,
        };
        let axis = at.vec3("axis", e.axis)?;
        if axis.length() == 0.0 {
            return Err(at.err("axis", "must not be zero"));
        }
        let EndRules {
            fail_on_touch,
            touch_tolerance,
            fail_on_stretch,
        } = Self::end_rules(at, e, names)?;
        let lanes = match e.lanes {
            Some(l) if !(1..=crate::evaluate::MAX_LANES).contains(&l) => {
                return Err(at.err(
                    "lanes",
                    format!("must be between 1 and {MAX_LANES}, got {l}"),
                ))
            }
            other => other,
        };
        let axis = axis.normalize();
        let target = match e.target {
            None => {
                if e.target_weight.is_some() {
                    return Err(at.err(
                        "target_weight",
                        "weighs the distance to `target`: give `target` too",
                    ));
                }
                None
            }
            Some(t) => Some((
                at.vec3("target", t)?,
                weight(at, "target_weight", e.target_weight.unwrap_or(1.0))?,
            )),
        };
        let trials = e.trials.unwrap_or(1);
        if !(1..=MAX_TRIALS).contains(&trials) {
            return Err(at.err(
                "trials",
                format!("must be between 1 and {MAX_TRIALS}, got {trials}"),
            ));
        }
        let noise = at.finite("noise", e.noise)?;
        if !(0.0..=1.0).contains(&noise) {
            return Err(at.err(
                "noise",
                format!("must be in [0, 1] (a fraction of each radius and of each actuator's range), got {noise}"),
            ));
        }
        let robust = e.robust.unwrap_or(false);
        let robust_halvings = match e.robust_halvings {
            None => 1,
            Some(h) if !robust => {
                return Err(at.err(
                    "robust_halvings",
                    format!(
                    "halves the step of a robust evaluation ({h} given): set `robust = true` too"
                ),
                ))
            }
            Some(h) if !(1..=MAX_HALVINGS).contains(&h) => {
                return Err(at.err(
                    "robust_halvings",
                    format!(
                        "must be between 1 (the step and half of it) and {MAX_HALVINGS}, got {h}"
                    ),
                ))
            }
            Some(h) => h,
        };
        let mut terms = Vec::with_capacity(e.terms.len());
        for (i, t) in e.terms.iter().enumerate() {
            let field = format!("terms[{i}]");
            let (weight, m) = t.0.as_ref().map_err(|msg| {
                at.err(&field, format!("{msg} (kinds: {})", crate::archive::KINDS))
            })?;
            let weight = self::weight(at, &format!("{field}.weight"), *weight)?;
            terms.push((weight, m.resolve(at, &field, names, &particles, axis)?));
        }
        Ok(EvolveSpec {
            controller: names_evolved.first().map(|c| c.to_string()),
            duration,
            particles,
            axis,
            distance_weight: weight(at, "distance_weight", e.distance_weight)?,
            time_weight: weight(at, "time_weight", e.time_weight)?,
            fail_on_touch,
            touch_tolerance,
            fail_on_stretch,
            evolved,
            mutation: e.mutation,
            log: e.log,
            lanes,
            robust,
            robust_halvings,
            optimiser: e.optimiser.clone(),
            energy_weight: weight(at, "energy_weight", e.energy_weight)?,
            target,
            trials,
            noise,
            aggregate: e.aggregate,
            terms,
        })
    }

    /// `duration`, checked against a day and against the steps it takes.
    fn duration(at: &At, e: &EvolveEntry, dt: f64) -> Result<f64, SceneError> {
        let duration = at.positive("duration", e.duration)?;
        if duration > MAX_DURATION {
            return Err(at.err(
                "duration",
                format!(
                    "must be at most {MAX_DURATION} s (a simulated day), got {}",
                    Shown(duration)
                ),
            ));
        }
        if (duration / dt).round() < 1.0 {
            return Err(at.err(
                "duration",
                format!(
                    "{duration} s is shorter than half a step ({} s, [world] dt): nothing to evaluate",
                    Shown(dt)
                ),
            ));
        }
        if duration / dt > MAX_STEPS {
            return Err(at.err(
                "duration",
                format!(
                    "{duration} s at dt = {} s is {:.3e} steps, more than {MAX_STEPS:e}: raise dt or shorten the evaluation",
                    Shown(dt),
                    duration / dt
                ),
            ));
        }
        Ok(duration)
    }

    /// The end rules: `fail_on_touch` (with `touch_tolerance`) and
    /// `fail_on_stretch`, resolved.
    fn end_rules(at: &At, e: &EvolveEntry, names: &Names) -> Result<EndRules, SceneError> {
        let fail_on_touch = e
            .fail_on_touch
            .iter()
            .map(|n| Ok((names.one(at, "fail_on_touch", n)?, n.clone())))
            .collect::<Result<_, SceneError>>()?;
        let touch_tolerance = match e.touch_tolerance {
            None => TOUCH_TOLERANCE,
            Some(t) => {
                let t = at.finite("touch_tolerance", t)?;
                if t < 0.0 {
                    return Err(at.err("touch_tolerance", format!("must be >= 0, got {t}")));
                }
                t
            }
        };
        let fail_on_stretch = e
            .fail_on_stretch
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let f = |k: &str| format!("fail_on_stretch[{i}].{k}");
                Ok(Stretch {
                    a: names.one(at, &f("a"), &s.a)?,
                    b: names.one(at, &f("b"), &s.b)?,
                    length: at.positive(&f("length"), s.length)?,
                    name: format!("{}-{}", s.a, s.b),
                })
            })
            .collect::<Result<_, SceneError>>()?;
        Ok(EndRules {
            fail_on_touch,
            touch_tolerance,
            fail_on_stretch,
        })
    }

    /// The centre of mass of the particles that count (of one particle:
    /// its position, exactly).
    pub fn centre(&self, world: &World) -> DVec3 {
        centre_of(world, &self.particles)
    }

    /// The end rule that holds now, if any: the first of `fail_on_touch`
    /// touching the floor, else the first of `fail_on_stretch` stretched.
    pub fn ending(&self, world: &World) -> Option<Ended> {
        let touch = self
            .fail_on_touch
            .iter()
            .find(|(p, _)| world.touches_ground(*p, self.touch_tolerance));
        if let Some((_, n)) = touch {
            return Some(Ended::Touch(n.clone()));
        }
        self.fail_on_stretch
            .iter()
            .find(|s| (world.position(s.a) - world.position(s.b)).length() >= s.length)
            .map(|s| Ended::Stretch(s.name.clone()))
    }
}

/// The centre of mass of `ids` (of one particle: its position, exactly;
/// of massless ones: their mean position).
pub fn centre_of(world: &World, ids: &[ParticleId]) -> DVec3 {
    centre_at(&world.state().pos, &world.particles().mass, ids)
}

/// [`centre_of`] with the particles at `positions` and of masses `mass`
/// (a recorded frame).
pub fn centre_at(positions: &[DVec3], mass: &[f64], ids: &[ParticleId]) -> DVec3 {
    if let [p] = ids {
        return positions[p.index()];
    }
    let (mut sum, mut m) = (DVec3::ZERO, 0.0);
    for p in ids {
        sum += positions[p.index()] * mass[p.index()];
        m += mass[p.index()];
    }
    if m > 0.0 {
        sum / m
    } else {
        sum / ids.len().max(1) as f64
    }
}

/// The most lanes a run may have.
pub const MAX_LANES: usize = 1024;

/// Why an evaluation ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Ended {
    /// It ran for the whole duration.
    Timeout,
    /// This particle of `fail_on_touch` touched the floor.
    Touch(String),
    /// These particles of `fail_on_stretch` (`a-b`) were too far apart.
    Stretch(String),
    /// The simulation blew up.
    BlowUp,
}

impl fmt::Display for Ended {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Ended::Timeout => f.write_str("timeout"),
            Ended::Touch(p) => write!(f, "touch {p}"),
            Ended::Stretch(p) => write!(f, "stretch {p}"),
            Ended::BlowUp => f.write_str("blow-up"),
        }
    }
}

impl std::str::FromStr for Ended {
    type Err = String;
    /// Reads what [`Ended`]'s `Display` writes.
    fn from_str(s: &str) -> Result<Ended, String> {
        match s.split_once(' ') {
            None if s == "timeout" => Ok(Ended::Timeout),
            None if s == "blow-up" => Ok(Ended::BlowUp),
            Some(("touch", p)) if !p.is_empty() => Ok(Ended::Touch(p.to_string())),
            Some(("stretch", p)) if !p.is_empty() => Ok(Ended::Stretch(p.to_string())),
            _ => Err(format!(
                "`{s}` is not an ending: timeout, touch PARTICLE, stretch A-B or blow-up"
            )),
        }
    }
}

/// The outcome of one evaluation: what every front end reports and every
/// optimiser is told.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// `time_weight × time + distance_weight × distance − energy_weight ×
    /// energy − target_weight × target distance + Σ weight × term`.
    pub fitness: f64,
    /// Distance along the axis, m.
    pub distance: f64,
    /// Time survived, s.
    pub time: f64,
    /// Why it ended.
    pub ended: Ended,
    /// The scene's `[archive]` measures, in order (empty without one),
    /// computed during this evaluation.
    pub measures: Vec<f64>,
    /// The actuators' positive work, J, when the scene's fitness or
    /// measures need it.
    pub energy: Option<f64>,
    /// The final distance of the centre from `[evolve] target`, m, when
    /// the scene has one.
    pub target_distance: Option<f64>,
    /// The values of `[evolve] terms`, in order (before their weights).
    pub terms: Vec<f64>,
}

/// What an evaluation stopped under [`stoppable`] returns as its error.
pub const INTERRUPTED: &str = "interrupted";

/// Steps between two of [`stoppable`]'s questions.
const STOP_EVERY: u64 = 256;

thread_local! {
    /// What the evaluations on this thread ask whether to stop ([`stoppable`]).
    static STOP: RefCell<Option<Rc<dyn Fn() -> bool>>> = const { RefCell::new(None) };
}

/// Runs `f` with every evaluation it makes on this thread asking `stop`
/// every 256 steps whether to stop: once it says yes, the evaluation ends
/// with the error [`INTERRUPTED`] (Python's Ctrl-C during one long
/// evaluation). An evaluation never stopped gives the same bits as
/// without. Evaluations of a scene's trials that run on other threads of
/// the pool do not ask; nor does anything outside `f` (an evolution, which
/// must stand at whole generations, never calls this).
pub fn stoppable<T>(stop: Rc<dyn Fn() -> bool>, f: impl FnOnce() -> T) -> T {
    /// Puts the thread's earlier question back, even if `f` panics.
    struct Restore(Option<Rc<dyn Fn() -> bool>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let earlier = self.0.take();
            STOP.with(|s| *s.borrow_mut() = earlier);
        }
    }
    let _restore = Restore(STOP.with(|s| s.replace(Some(stop))));
    f()
}

/// Whether this thread's [`stoppable`] question says stop. (Asked with
/// the thread's cell released: the question may run Python, which may
/// evaluate again.) Out of line and cold: inlined and asked with a test
/// of the step count in every step, it cost the roobot's evaluation 2.4 %
/// (1.605 -> 1.644 ms).
#[cold]
#[inline(never)]
fn stop_asked() -> bool {
    let stop = STOP.with(|s| s.borrow().clone());
    stop.is_some_and(|f| f())
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
    let archive = scene.archive.clone();
    let muscles = scene.nervous.actuators.len();
    let mut recorder = archive
        .as_ref()
        .map(|a| crate::archive::Recorder::new(&a.measures, &spec, &scene.world, muscles));
    let term_measures: Vec<_> = spec.terms.iter().map(|(_, m)| m.clone()).collect();
    let mut terms = (!term_measures.is_empty())
        .then(|| crate::archive::Recorder::new(&term_measures, &spec, &scene.world, muscles));
    let needs_work = spec.needs_work()
        || archive
            .as_ref()
            .is_some_and(|a| a.measures.iter().any(|m| m.needs_work()));
    let mut work = needs_work.then(crate::work::Work::default);
    observe(&scene);
    if let Some(end) = spec.ending(&scene.world) {
        ended = end;
    } else {
        // In runs of `STOP_EVERY` steps, asking between them whether to
        // stop: no test in the step's own loop.
        'run: while done < steps {
            if stop_asked() {
                return Err(INTERRUPTED.into());
            }
            let until = steps.min(done + STOP_EVERY);
            while done < until {
                if let Some(w) = &mut work {
                    w.before(&scene);
                }
                if scene.step(dt).is_err() {
                    ended = Ended::BlowUp;
                    break 'run;
                }
                if let Some(w) = &mut work {
                    w.after(&scene, dt);
                }
                done += 1;
                observe(&scene);
                if let Some(r) = &mut recorder {
                    r.step(&scene.world);
                }
                if let Some(r) = &mut terms {
                    r.step(&scene.world);
                }
                let c = spec.centre(&scene.world);
                if !c.is_finite() {
                    ended = Ended::BlowUp;
                    break 'run;
                }
                last = c;
                if let Some(end) = spec.ending(&scene.world) {
                    ended = end;
                    break 'run;
                }
            }
        }
    }
    let time = done as f64 * dt;
    let mut distance = (last - start).dot(spec.axis);
    if ended == Ended::BlowUp {
        distance = distance.min(0.0);
    }
    let energy = work.map(|w| w.positive);
    let joules = energy.unwrap_or(0.0);
    let measures = recorder.map_or_else(Vec::new, |r| r.finish(&scene.world, time, joules));
    let terms = terms.map_or_else(Vec::new, |r| r.finish(&scene.world, time, joules));
    let mut fitness = spec.time_weight * time + spec.distance_weight * distance;
    if spec.energy_weight != 0.0 {
        fitness -= spec.energy_weight * joules;
    }
    // A blow-up's last centre is the last finite one: no profit from it.
    let target_distance = spec.target.map(|(t, _)| (last - t).length());
    if let (Some((_, w)), Some(d)) = (spec.target, target_distance) {
        fitness -= w * d;
    }
    for ((w, _), v) in spec.terms.iter().zip(&terms) {
        fitness += w * v;
    }
    Ok(Evaluation {
        fitness,
        distance,
        time,
        ended,
        measures,
        energy,
        target_distance,
        terms,
    })
}

/// Runs `scene`'s `[evolve]` evaluation once, at the scene's step (see
/// [`score`] for a scene's trials and robust evaluations).
pub fn evaluate(scene: Scene) -> Result<Evaluation, String> {
    evaluate_with(scene, |_| {})
}

/// The check a winner must pass before it is believed: `scene`'s
/// `[evolve]` evaluation once (no trials, not robust) at a quarter of its
/// step with another integrator: RK4, or symplectic Euler for a scene on
/// RK4; implicit Euler is kept (an explicit step may not hold its stiff
/// springs). Returns the integrator, the step and the evaluation.
pub fn check_finer(
    scene: Scene,
) -> Result<(animats_engine::IntegratorKind, f64, Evaluation), String> {
    use animats_engine::IntegratorKind as K;
    let kind = match scene.world.integrator() {
        K::Rk4 => K::Symplectic,
        K::Implicit => K::Implicit,
        _ => K::Rk4,
    };
    check_with(scene, kind)
}

/// Both checks a winner must pass before it is believed, each `scene`'s
/// `[evolve]` evaluation once (no trials, not robust) at a quarter of its
/// step: with its own integrator (a gait tuned to where in a step its feet
/// land fails it), then with another ([`check_finer`]); one run when the
/// two are the same (implicit Euler); `make` builds the scene afresh for
/// each. The two runs are independent and run side by side (at the end
/// of an evolution they are all there is to do: one after the other they
/// were a fifth of a 16-lane quadruped run's 1-thread time, and most of
/// its 16-thread time; on the caller's rayon pool). Returns each run's integrator, step and
/// evaluation.
pub fn checks_finer(
    make: impl Fn() -> Result<Scene, String> + Sync,
) -> Result<Vec<(animats_engine::IntegratorKind, f64, Evaluation)>, String> {
    let scene = make()?;
    let own = scene.world.integrator();
    if own == animats_engine::IntegratorKind::Implicit {
        return Ok(vec![check_finer(scene)?]);
    }
    let (first, other) = rayon::join(
        || make().and_then(|s| check_with(s, own)),
        || check_finer(scene),
    );
    Ok(vec![first?, other?])
}

/// `scene` evaluated once at a quarter of its step with `kind`.
fn check_with(
    mut scene: Scene,
    kind: animats_engine::IntegratorKind,
) -> Result<(animats_engine::IntegratorKind, f64, Evaluation), String> {
    scene.world.set_integrator(kind);
    scene.dt *= 0.25;
    let dt = scene.dt;
    Ok((kind, dt, evaluate(scene)?))
}

/// The worse of two evaluations (the first of equals; NaN is worst).
fn worse(first: Evaluation, second: Evaluation) -> Evaluation {
    let sane = |f: f64| if f.is_nan() { f64::NEG_INFINITY } else { f };
    if sane(second.fitness) < sane(first.fitness) {
        second
    } else {
        first
    }
}

/// Scores the scene `make()` builds as its `[evolve]` table says: once, or
/// `trials` times, trial `k` perturbed by `noise` from the scene's seed and
/// `k` ([`perturb`]: the same perturbations for every genome; without
/// noise every trial is the same run, evaluated once); with `robust = true`
/// each trial also at half the scene's step, the worse counting (the first
/// of equals; NaN is worst: a gait tuned to the step's errors scores as it
/// would at the finer step); the mean of the trials counts (every figure
/// averaged, the ending the worst trial's), or with `aggregate = "worst"`
/// the worst trial.
pub fn score(make: impl Fn() -> Result<Scene, String> + Sync) -> Result<Evaluation, String> {
    score_screened(make, &|_| true)
}

/// [`score`], except that a robust scene's run at half the step is made
/// only where `fine` says the run at the scene's step could matter: where
/// it says not, that run's evaluation is the score. Evolution asks it of
/// a candidate whose score at the step cannot enter the population or
/// its cell (the robust score is never above it). A scene with `trials`
/// and `noise` is always scored in full.
pub fn score_screened(
    make: impl Fn() -> Result<Scene, String> + Sync,
    fine: &dyn Fn(&Evaluation) -> bool,
) -> Result<Evaluation, String> {
    let make: &Make<'_> = &make;
    let mut all = score_all(&[make], &|_, e| fine(e), &engine_runs)?;
    all.pop().ok_or_else(|| "no evaluation".to_string())
}

/// Runs many scenes' evaluations and returns them in order: the engine's
/// [`evaluate`] one by one ([`engine_runs`]), or a batch on another device
/// (the GPU's, `animats-gpu`), which must give the same bits.
pub type Runner = dyn Fn(Vec<Scene>) -> Result<Vec<Evaluation>, String> + Send + Sync;

/// Builds one genome's scene, from any thread.
pub type Make<'a> = dyn Fn() -> Result<Scene, String> + Sync + 'a;

/// The engine's [`Runner`]: [`evaluate`] on each scene, in order, on the
/// calling thread.
pub fn engine_runs(scenes: Vec<Scene>) -> Result<Vec<Evaluation>, String> {
    scenes.into_iter().map(evaluate).collect()
}

/// [`score_screened`] for many genomes at once, each `makes[g]` building
/// genome `g`'s scene and `fine(g, e)` its screen: every run at the scenes' step handed to `run` in one
/// batch, then every run at half the step that a robust scene needs in a
/// second one, and so on for each further halving (a batch shares one
/// step). The same scores as
/// [`score_screened`] on each genome, where `run` gives the engine's bits.
pub fn score_all(
    makes: &[&Make<'_>],
    fine: &dyn Fn(usize, &Evaluation) -> bool,
    run: &dyn Fn(Vec<Scene>) -> Result<Vec<Evaluation>, String>,
) -> Result<Vec<Evaluation>, String> {
    use rayon::prelude::*;
    // Every trial of every genome, at the scenes' step, built on the
    // current rayon pool; the first build of each genome is its first
    // trial.
    let built = makes
        .par_iter()
        .map(|make| -> Result<(EvolveSpec, Vec<Scene>), String> {
            let first = make()?;
            let spec = first
                .evolve
                .clone()
                .ok_or("the scene has no [evolve] table: nothing to evaluate")?;
            // Without noise every trial is the same run: one is enough.
            let perturbed = spec.noise > 0.0;
            let trials = if perturbed { spec.trials } else { 1 };
            let mut first = Some(first);
            let mut scenes = Vec::with_capacity(trials as usize);
            for k in 0..trials {
                let mut s = match first.take() {
                    Some(s) => s,
                    None => make()?,
                };
                if perturbed {
                    perturb(&mut s, k)?;
                }
                scenes.push(s);
            }
            Ok((spec, scenes))
        })
        // (Collected first, so that of several failures the first genome's
        // is reported, whichever thread failed first.)
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<Vec<_>, String>>()?;
    let (mut specs, mut coarse, mut trial) = (Vec::new(), Vec::new(), Vec::new());
    for (g, (spec, scenes)) in built.into_iter().enumerate() {
        for (k, s) in scenes.into_iter().enumerate() {
            coarse.push(s);
            trial.push((g, k as u32));
        }
        specs.push(spec);
    }
    let mut runs = run_checked(run, coarse)?;
    // Robust: again at half the step where it could matter, the worse
    // counting; then, for a scene that halves it more than once, at each
    // finer step where the worst so far could still matter.
    let mut at: Vec<usize> = (0..trial.len()).collect();
    for halving in 1..=specs.iter().map(|s| s.robust_halvings).max().unwrap_or(1) {
        at.retain(|&i| {
            let spec = &specs[trial[i].0];
            spec.robust
                && halving <= spec.robust_halvings
                && (spec.noise > 0.0 || fine(trial[i].0, &runs[i]))
        });
        if at.is_empty() {
            break;
        }
        let finer = at
            .par_iter()
            .map(|&i| {
                let (g, k) = trial[i];
                let mut s = makes[g]()?;
                if specs[g].noise > 0.0 {
                    perturb(&mut s, k)?;
                }
                for _ in 0..halving {
                    s.dt *= 0.5;
                }
                Ok(s)
            })
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<Vec<_>, String>>()?;
        for (&i, e) in at.iter().zip(run_checked(run, finer)?) {
            let sofar = std::mem::replace(&mut runs[i], e.clone());
            runs[i] = worse(sofar, e);
        }
    }
    // Each genome's trials, aggregated.
    let mut runs = runs.into_iter();
    let mut out = Vec::with_capacity(makes.len());
    for spec in &specs {
        if spec.noise > 0.0 {
            let trials: Vec<Evaluation> = runs.by_ref().take(spec.trials as usize).collect();
            if trials.is_empty() {
                return Err("no trial".into());
            }
            out.push(aggregate(trials, spec.aggregate));
        } else {
            out.push(runs.next().ok_or("no trial")?);
        }
    }
    Ok(out)
}

/// `run` on `scenes`, which must give one evaluation each (none asked of
/// an empty batch).
fn run_checked(
    run: &dyn Fn(Vec<Scene>) -> Result<Vec<Evaluation>, String>,
    scenes: Vec<Scene>,
) -> Result<Vec<Evaluation>, String> {
    if scenes.is_empty() {
        return Ok(Vec::new());
    }
    let n = scenes.len();
    let got = run(scenes)?;
    if got.len() != n {
        return Err(format!("{} evaluations for {n} scenes", got.len()));
    }
    Ok(got)
}

/// The trials' evaluations as `aggregate` says.
fn aggregate(trials: Vec<Evaluation>, how: AggregateName) -> Evaluation {
    let mut it = trials.into_iter();
    let Some(first) = it.next() else {
        unreachable!("at least one trial")
    };
    match how {
        AggregateName::Worst => it.fold(first, worse),
        AggregateName::Mean => {
            let mut n = 1.0;
            let mut sum = first.clone();
            let mut worst = first;
            for e in it {
                n += 1.0;
                sum.fitness += e.fitness;
                sum.distance += e.distance;
                sum.time += e.time;
                for (a, b) in sum.measures.iter_mut().zip(&e.measures) {
                    *a += b;
                }
                for (a, b) in sum.terms.iter_mut().zip(&e.terms) {
                    *a += b;
                }
                if let (Some(a), Some(b)) = (&mut sum.energy, e.energy) {
                    *a += b;
                }
                if let (Some(a), Some(b)) = (&mut sum.target_distance, e.target_distance) {
                    *a += b;
                }
                worst = worse(worst, e);
            }
            let mean = |x: f64| x / n;
            Evaluation {
                fitness: mean(sum.fitness),
                distance: mean(sum.distance),
                time: mean(sum.time),
                ended: worst.ended,
                measures: sum.measures.into_iter().map(mean).collect(),
                energy: sum.energy.map(mean),
                target_distance: sum.target_distance.map(mean),
                terms: sum.terms.into_iter().map(mean).collect(),
            }
        }
    }
}

/// Perturbs `scene` for trial `k` of its `[evolve] trials` by `noise`:
/// every free particle's start moves by a uniform offset of up to `noise`
/// × its radius along each axis (lifted out of the floor if that puts it
/// in), and every actuator's level is offset by a uniform amount in
/// [−`noise`, `noise`] for the whole trial; drawn from the scene's seed and
/// `k`, so the same for every genome.
pub fn perturb(scene: &mut Scene, k: u32) -> Result<(), String> {
    let Some(spec) = &scene.evolve else {
        return Ok(());
    };
    let noise = spec.noise;
    if noise == 0.0 {
        return Ok(());
    }
    let mut random =
        animats_creatures::seaworld::Random::for_entry(scene.seed, 5000 + u64::from(k));
    let w = &mut scene.world;
    let floor = w.terrain().is_some();
    for id in w.particle_ids().collect::<Vec<_>>() {
        let p = w.particles();
        let (r, fixed) = (p.radius[id.index()], p.fixed[id.index()]);
        if fixed {
            continue;
        }
        let mut step = || random.between(-noise, noise) * r;
        let offset = DVec3::new(step(), step(), step());
        let x = w.position(id) + offset;
        w.set_position(id, x).map_err(|e| e.to_string())?;
        if floor {
            let inside = -w.clearance(id);
            if inside > 0.0 {
                w.set_position(id, x + DVec3::Y * inside)
                    .map_err(|e| e.to_string())?;
            }
        }
    }
    let offsets = (0..scene.nervous.actuators.len())
        .map(|_| random.between(-noise, noise))
        .collect();
    scene.nervous.offsets = offsets;
    scene.rearm_guard();
    Ok(())
}

/// A scene whose `[evolve]` controller is evolved: genome → evaluation.
#[derive(Clone, Debug)]
pub struct SceneProblem {
    file: String,
    text: String,
    def: SceneDef,
    spec: EvolveSpec,
    start: Vec<f64>,
    bounds: Vec<(f64, f64)>,
    /// Per evolved controller, in genome order: its genome's keys.
    keys: Vec<Vec<GenomeKey>>,
    grid: Option<crate::archive::Grid>,
    /// Where its evaluations run in batches, if not on the engine here.
    batches: Option<Batches>,
}

/// A [`Runner`] that a problem hands its evaluations to in batches (one
/// per generation and step): the GPU's, in place of the engine's one by
/// one.
#[derive(Clone)]
pub struct Batches(pub std::sync::Arc<Runner>);

impl fmt::Debug for Batches {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Batches(..)")
    }
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
        if spec.evolved.is_empty() {
            return Err(SceneError::file(
                file,
                "[evolve] names no controller: the scene can be evaluated as it is, not evolved; add `controller = \"NAME\"` (docs/SCENES.md)",
            ));
        }
        let (mut start, mut bounds, mut keys) = (Vec::new(), Vec::new(), Vec::new());
        for (i, _) in &spec.evolved {
            let brain = &scene.nervous.controllers[*i].brain;
            start.extend(brain.genome());
            bounds.extend(brain.bounds());
            keys.push(brain.genome_keys());
        }
        Ok(SceneProblem {
            file: file.to_string(),
            text: text.to_string(),
            start,
            bounds,
            keys,
            spec: spec.clone(),
            grid: scene.archive.as_ref().map(|a| a.grid.clone()),
            def,
            batches: None,
        })
    }

    /// The problem with its evaluations run in `batches`.
    pub fn on(mut self, batches: Option<Batches>) -> SceneProblem {
        self.batches = batches;
        self
    }

    /// Where its evaluations run in batches, if not on the engine here.
    pub fn batches(&self) -> Option<&Batches> {
        self.batches.as_ref()
    }

    /// [`SceneProblem::evaluate_screened`] on every genome of `genomes`
    /// (genome `g` screened by `fine(g, …)`), in batches run by `run`
    /// ([`score_all`]).
    pub fn evaluate_all(
        &self,
        genomes: &[Vec<f64>],
        fine: &dyn Fn(usize, &Evaluation) -> bool,
        run: &Runner,
    ) -> Result<Vec<Evaluation>, String> {
        let makes: Vec<_> = genomes.iter().map(|g| move || self.scene(g)).collect();
        let makes: Vec<&Make<'_>> = makes.iter().map(|m| m as &Make<'_>).collect();
        score_all(&makes, fine, run)
    }

    /// The scene's `[evolve]` table, resolved.
    pub fn spec(&self) -> &EvolveSpec {
        &self.spec
    }

    /// The `[archive]` table's grid and settings, if the scene has one.
    pub fn grid(&self) -> Option<&crate::archive::Grid> {
        self.grid.as_ref()
    }

    /// The scene's text, as given.
    pub fn text(&self) -> &str {
        &self.text
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
        if genome.len() != self.start.len() {
            return Err(format!(
                "a genome for this scene has {} numbers, got {}",
                self.start.len(),
                genome.len()
            ));
        }
        let mut at = 0;
        for ((i, _), keys) in self.spec.evolved.iter().zip(&self.keys) {
            let n: usize = keys.iter().map(GenomeKey::genes).sum();
            scene.nervous.controllers[*i]
                .brain
                .set_genome(&genome[at..at + n])?;
            at += n;
        }
        Ok(scene)
    }

    /// Evaluates `genome` as the scene's `[evolve]` says ([`score`]): once,
    /// at the scene's step and half of it for a robust scene
    /// ([`EvolveSpec::robust`]), over its trials.
    pub fn evaluate(&self, genome: &[f64]) -> Result<Evaluation, String> {
        score(|| self.scene(genome))
    }

    /// [`SceneProblem::evaluate`], a robust scene's half-step run made only
    /// where `fine` says ([`score_screened`]).
    pub fn evaluate_screened(
        &self,
        genome: &[f64],
        fine: &dyn Fn(&Evaluation) -> bool,
    ) -> Result<Evaluation, String> {
        score_screened(|| self.scene(genome), fine)
    }

    /// The scene's text with `genome` written into the `[evolve]`
    /// controller's keys (comments and layout kept), preceded by `comment`
    /// as `#` lines.
    pub fn best_toml(&self, genome: &[f64], comment: &str) -> Result<String, String> {
        let mut doc: toml_edit::DocumentMut = self
            .text
            .parse()
            .map_err(|e| format!("{}: {e}", self.file))?;
        if genome.len() != self.start.len() {
            return Err(format!(
                "a genome of {} numbers for a scene whose controllers hold {}",
                genome.len(),
                self.start.len()
            ));
        }
        let mut at = 0;
        for ((_, (kind, k)), keys) in self.spec.evolved.iter().zip(&self.keys) {
            let table = doc
                .get_mut(kind)
                .and_then(|c| c.as_array_of_tables_mut())
                .and_then(|a| a.get_mut(*k))
                .ok_or_else(|| format!("{kind}[{k}] is not where the scene had it"))?;
            let n: usize = keys.iter().map(GenomeKey::genes).sum();
            write_genome(table, keys, &genome[at..at + n])?;
            at += n;
        }
        Ok(commented(comment, &doc))
    }
}

/// `doc`'s text preceded by `comment` as `#` lines: how `best.toml` opens.
pub(crate) fn commented(comment: &str, doc: &toml_edit::DocumentMut) -> String {
    let mut out = String::new();
    for line in comment.lines() {
        out.push_str("# ");
        out.push_str(line);
        out.push('\n');
    }
    out.push_str(&doc.to_string());
    out
}

/// Writes `genome` into a brain's `table`, key by key as the brain's
/// [`GenomeKey`]s lay it out.
fn write_genome(
    table: &mut toml_edit::Table,
    keys: &[GenomeKey],
    genome: &[f64],
) -> Result<(), String> {
    let need: usize = keys.iter().map(GenomeKey::genes).sum();
    if need != genome.len() {
        return Err(format!(
            "a genome of {} numbers for a brain whose table holds {need}",
            genome.len()
        ));
    }
    let mut at = 0;
    for key in keys {
        let genes = &genome[at..at + key.genes()];
        at += key.genes();
        let value = match key.len {
            None => toml_edit::value(genes[0]),
            Some(_) => {
                let mut a = toml_edit::Array::new();
                for v in genes {
                    a.push(*v);
                }
                toml_edit::value(a)
            }
        };
        *slot(table, &key.path)? = value;
    }
    Ok(())
}

/// The item at `path` (`state[1].transition[0].above`) below `table`,
/// made if its last key is missing.
fn slot<'t>(
    table: &'t mut toml_edit::Table,
    path: &str,
) -> Result<&'t mut toml_edit::Item, String> {
    let (parents, last) = match path.rsplit_once('.') {
        Some((p, l)) => (Some(p), l),
        None => (None, path),
    };
    let mut here = table;
    for part in parents.into_iter().flat_map(|p| p.split('.')) {
        let (name, index) = part
            .strip_suffix(']')
            .and_then(|p| p.split_once('['))
            .and_then(|(n, i)| Some((n, i.parse::<usize>().ok()?)))
            .ok_or_else(|| format!("`{path}`: `{part}` is not a table array's entry"))?;
        here = here
            .get_mut(name)
            .and_then(|t| t.as_array_of_tables_mut())
            .and_then(|a| a.get_mut(index))
            .ok_or_else(|| format!("`{path}`: the scene has no `{part}`"))?;
    }
    Ok(&mut here[last])
}
