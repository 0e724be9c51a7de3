//! The scene file contract, as serde structures: one struct per table, every
//! default written once, unknown keys refused.
//!
//! SI units, y up, the floor is the plane y = 0. See `docs/SCENES.md` for the
//! whole format with an example of every entry.

pub use crate::entries::SceneDef;
pub use animats_creatures::brains::ControllerEntry;
pub use animats_creatures::sensors::SensorEntry;
use serde::Deserialize;

/// An entry of a kind chosen by one of its keys (`kind`, or the target of
/// an actuator), read in two steps: as a table, whose place in the file
/// is then known, and then as `T`. Read in one step, an error inside the
/// k-th entry of an array of tables would be reported at the array's
/// first; the builder reports this one's at its own entry.
#[derive(Clone, Debug)]
pub struct Typed<T>(pub Result<T, String>);

impl<'de, T: serde::de::DeserializeOwned> Deserialize<'de> for Typed<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let table = toml::Table::deserialize(d)?;
        Ok(Typed(
            toml::Value::Table(table)
                .try_into::<T>()
                .map_err(|e| e.message().trim().to_string()),
        ))
    }
}

impl<T> Typed<T> {
    /// The entry, or what is wrong with it: the key at fault where the
    /// message names one (`kind` for an unknown kind), and the message.
    pub fn get(&self) -> Result<&T, (&str, &str)> {
        self.0.as_ref().map_err(|m| {
            let named = |prefix: &str| {
                m.strip_prefix(prefix)
                    .and_then(|r| r.strip_prefix('`'))
                    .and_then(|r| r.split('`').next())
            };
            let field = if m.starts_with("unknown variant") {
                "kind"
            } else {
                named("unknown field ")
                    .or_else(|| named("missing field "))
                    .unwrap_or("")
            };
            (field, m.as_str())
        })
    }
}

/// Integration method names as written in files.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum IntegratorName {
    /// Explicit Euler.
    Euler,
    /// Explicit midpoint.
    Midpoint,
    /// Classic RK4.
    #[default]
    Rk4,
    /// Semi-implicit Euler.
    Symplectic,
    /// Implicit (backward) Euler.
    Implicit,
}

impl From<IntegratorName> for animats_engine::IntegratorKind {
    fn from(n: IntegratorName) -> Self {
        use animats_engine::IntegratorKind as K;
        match n {
            IntegratorName::Euler => K::Euler,
            IntegratorName::Midpoint => K::Midpoint,
            IntegratorName::Rk4 => K::Rk4,
            IntegratorName::Symplectic => K::Symplectic,
            IntegratorName::Implicit => K::Implicit,
        }
    }
}

/// `[world]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldDef {
    /// m/s², default `[0, -9.8, 0]`.
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// Step, s, > 0, or `"auto"`; default 0.001.
    #[serde(default = "default_dt")]
    pub dt: StepDef,
    /// Integration method; default RK4.
    #[serde(default)]
    pub integrator: IntegratorName,
    /// Simulated seconds, > 0; default 5.
    #[serde(default = "default_duration")]
    pub duration: f64,
    /// Largest stable step, s: real-time mode never steps longer; default `dt`.
    pub max_dt: Option<f64>,
    /// The implicit integrator's relative tolerance, in (0, 1); default 1e-9.
    pub implicit_tolerance: Option<f64>,
    /// The implicit integrator's most conjugate-gradient iterations a step;
    /// default 2000.
    pub implicit_max_iterations: Option<u32>,
    /// Seed of every random placement and spawn; default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            gravity: default_gravity(),
            dt: default_dt(),
            integrator: IntegratorName::default(),
            duration: default_duration(),
            max_dt: None,
            implicit_tolerance: None,
            implicit_max_iterations: None,
            seed: default_seed(),
        }
    }
}

fn default_seed() -> u64 {
    1
}

fn default_gravity() -> [f64; 3] {
    [0.0, -9.8, 0.0]
}
fn default_dt() -> StepDef {
    StepDef::Seconds(DEFAULT_DT)
}

/// The step a scene gets when it names none, s; also the longest `"auto"` gives.
pub const DEFAULT_DT: f64 = 0.001;

/// `[world] dt`: a step in seconds, or `"auto"`: the world's recommended
/// step for its integrator (`World::recommended_dt`), at most
/// [`DEFAULT_DT`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepDef {
    /// This many seconds.
    Seconds(f64),
    /// The recommended step.
    Auto,
}

impl<'de> Deserialize<'de> for StepDef {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = StepDef;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a step in seconds or \"auto\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<StepDef, E> {
                Ok(StepDef::Seconds(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<StepDef, E> {
                Ok(StepDef::Seconds(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<StepDef, E> {
                Ok(StepDef::Seconds(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<StepDef, E> {
                match v {
                    "auto" => Ok(StepDef::Auto),
                    _ => Err(E::custom(format!(
                        "expected a step in seconds or \"auto\", got \"{v}\""
                    ))),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}
fn default_duration() -> f64 {
    5.0
}

pub(crate) fn default_envelope() -> f64 {
    0.01
}
pub(crate) fn default_rest_speed() -> f64 {
    0.05
}

pub(crate) fn default_food() -> String {
    "food".into()
}

/// `[[actuator]]`: a level in [0, 1] mapped linearly onto [min, max] of one
/// target's parameter (thesis §2.3.2.3). The target is one of the keys
/// `spring`, `angle_joint`, `torque_joint` or `constant_force`, checked
/// while the file is read.
#[derive(Clone, Debug, Deserialize)]
#[serde(try_from = "ActuatorKeys")]
pub struct ActuatorEntry {
    /// Unique among actuators.
    pub name: String,
    /// What it drives.
    pub target: Target,
    /// The value at level 0.
    pub min: f64,
    /// The value at level 1.
    pub max: f64,
    /// The initial level; default: the level that gives the target's
    /// value as built (0.5 when that is the middle of the range), or 0.5
    /// with a warning when the built value lies outside [min, max].
    pub level: Option<f64>,
    /// The most the level may change per second (a muscle's top speed);
    /// default: no limit.
    pub rate: Option<f64>,
    /// A motor or force that acts only while a sensor's level is above a
    /// threshold (or at most it); default: always.
    pub gate: Option<GateEntry>,
}

/// What an actuator drives, by the name of a spring, joint or force.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// `spring = "..."`: its rest length, m.
    Spring(String),
    /// `angle_joint = "..."`: its rest angle, rad.
    AngleJoint(String),
    /// `torque_joint = "..."`: its torque, N m.
    TorqueJoint(String),
    /// `constant_force = "..."`: a scale on its vector.
    ConstantForce(String),
}

/// The keys of `[[actuator]]` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ActuatorKeys {
    name: String,
    spring: Option<String>,
    angle_joint: Option<String>,
    torque_joint: Option<String>,
    constant_force: Option<String>,
    min: f64,
    max: f64,
    level: Option<f64>,
    rate: Option<f64>,
    gate: Option<GateEntry>,
}

impl TryFrom<ActuatorKeys> for ActuatorEntry {
    type Error = String;
    fn try_from(k: ActuatorKeys) -> Result<ActuatorEntry, String> {
        let targets = [
            k.spring.map(Target::Spring),
            k.angle_joint.map(Target::AngleJoint),
            k.torque_joint.map(Target::TorqueJoint),
            k.constant_force.map(Target::ConstantForce),
        ];
        let mut given = targets.into_iter().flatten();
        let (Some(target), None) = (given.next(), given.next()) else {
            return Err("give exactly one target: `spring`, `angle_joint`, `torque_joint` or `constant_force`".into());
        };
        Ok(ActuatorEntry {
            name: k.name,
            target,
            min: k.min,
            max: k.max,
            level: k.level,
            rate: k.rate,
            gate: k.gate,
        })
    }
}

/// `gate = { sensor = "...", above = x }` or `{ sensor = "...", at_most = x }`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GateEntry {
    /// The sensor read, by name.
    pub sensor: String,
    /// Open while the level is above this.
    pub above: Option<f64>,
    /// Open while the level is at most this.
    pub at_most: Option<f64>,
}

/// `[evolve]`: what `animats evolve SCENE` tunes and how an evaluation
/// (`animats evaluate SCENE`) is scored:
/// `fitness = time_weight × time survived + distance_weight × distance
/// − energy_weight × work − target_weight × distance to target + Σ weight ×
/// term`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvolveEntry {
    /// The controller whose parameters form the genome (a `[morphology]`
    /// scene's is its body's own, `body`: left out).
    pub controller: Option<String>,
    /// Several controllers evolved at once, their genomes end to end in
    /// this order (instead of `controller`).
    pub controllers: Option<Vec<String>>,
    /// Seconds per evaluation; default 20.
    #[serde(default = "default_eval_duration")]
    pub duration: f64,
    /// Whose centre of mass travels; default all particles.
    pub particles: Option<Vec<String>>,
    /// The direction that counts; default `[1, 0, 0]`.
    #[serde(default = "default_x")]
    pub axis: [f64; 3],
    /// Default 50.
    #[serde(default = "default_distance_weight")]
    pub distance_weight: f64,
    /// Default 1.
    #[serde(default = "default_time_weight")]
    pub time_weight: f64,
    /// The evaluation ends when any of these touches the floor; default none.
    #[serde(default)]
    pub fail_on_touch: Vec<String>,
    /// m: how close to the floor a sphere's lowest point counts as touching
    /// it, for `fail_on_touch`; default 0.001.
    pub touch_tolerance: Option<f64>,
    /// The evaluation ends when two particles are this far apart or more.
    #[serde(default)]
    pub fail_on_stretch: Vec<StretchEntry>,
    /// How the hill climber mutates: `bounded` (steps in units of each
    /// gene's bounds) or `relative` (Appendix B's: by a fraction of the
    /// gene's value, ignoring bounds); default `bounded`.
    #[serde(default)]
    pub mutation: MutationName,
    /// What `log.csv` holds: `generations` (a row per lane per generation)
    /// or `improvements` (a row per improvement, with its genes: the
    /// thesis's Table 6); default `generations`.
    #[serde(default)]
    pub log: LogName,
    /// Lanes `animats evolve` runs unless told; default 1.
    pub lanes: Option<usize>,
    /// Score each evaluation at the scene's step and at half of it and
    /// keep the worse; default false (true in a `[morphology]` scene).
    pub robust: Option<bool>,
    /// How many times a robust evaluation halves the step: 1 (the step
    /// and half of it) or more (2: a quarter too; at most 4); a finer run
    /// is made only where the worst so far could still matter. Default 1.
    pub robust_halvings: Option<u32>,
    /// The optimiser `animats evolve` uses unless told (`hill-climber`,
    /// `cma-es`, ...); default `cma-es` (`body-ga` in a `[morphology]`
    /// scene).
    pub optimiser: Option<String>,
    /// Per joule of the actuators' positive work, subtracted; default 0.
    #[serde(default)]
    pub energy_weight: f64,
    /// Where the centre of `particles` should end up, m; default none.
    pub target: Option<[f64; 3]>,
    /// Per metre of the final distance to `target`, subtracted; default 1.
    pub target_weight: Option<f64>,
    /// Evaluations per genome, each from a start perturbed by `noise`;
    /// default 1.
    pub trials: Option<u32>,
    /// How much each trial is perturbed: every free particle's start moves
    /// by up to `noise` × its radius along each axis, every actuator's
    /// level by up to ±`noise`; default 0.
    #[serde(default)]
    pub noise: f64,
    /// What counts of the trials: `mean` or `worst`; default `mean`.
    #[serde(default)]
    pub aggregate: AggregateName,
    /// Measures (the archive's kinds, `{ kind = "...", weight = w }`)
    /// added to the fitness, each times its weight.
    #[serde(default)]
    pub terms: Vec<crate::archive::TermEntry>,
}

/// `[evolve] aggregate`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum AggregateName {
    /// The mean of the trials' fitness (and of every other figure).
    #[default]
    Mean,
    /// The trial with the lowest fitness.
    Worst,
}

/// `fail_on_stretch = [{ a = "...", b = "...", length = 1.0 }]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StretchEntry {
    /// One particle.
    pub a: String,
    /// The other.
    pub b: String,
    /// m: the run ends once they are at least this far apart.
    pub length: f64,
}

/// `[evolve] mutation`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum MutationName {
    /// In units of the genes' bounds.
    #[default]
    Bounded,
    /// By a fraction of each gene's value (Appendix B).
    Relative,
}

/// `[evolve] log`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum LogName {
    /// A row per lane per generation.
    #[default]
    Generations,
    /// A row per improvement, with its genes.
    Improvements,
}

fn default_eval_duration() -> f64 {
    20.0
}
fn default_x() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}
fn default_distance_weight() -> f64 {
    50.0
}
fn default_time_weight() -> f64 {
    1.0
}
