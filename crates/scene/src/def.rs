//! The scene file contract, as serde structures: one struct per table, every
//! default written once, unknown keys refused.
//!
//! SI units, y up, the floor is the plane y = 0. See `docs/SCENES.md` for the
//! whole format with an example of every entry.

pub use animats_creatures::brains::ControllerEntry;
pub use animats_creatures::sensors::SensorEntry;
use serde::Deserialize;
use toml::Spanned;

/// A whole scene file.
#[derive(Clone, Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SceneDef {
    /// `[world]`: gravity, step, integrator, duration.
    #[serde(default)]
    pub world: Option<Spanned<WorldDef>>,
    /// `[[particle]]` entries.
    #[serde(default)]
    pub particle: Vec<Spanned<ParticleEntry>>,
    /// `[floor]`: the plane y = 0.
    #[serde(default)]
    pub floor: Option<Spanned<FloorEntry>>,
    /// `[fluid]`: drag and buoyancy.
    #[serde(default)]
    pub fluid: Option<Spanned<FluidEntry>>,
    /// `[[spring]]` entries.
    #[serde(default)]
    pub spring: Vec<Spanned<SpringEntry>>,
    /// `[[angle_joint]]` entries.
    #[serde(default)]
    pub angle_joint: Vec<Spanned<AngleJointEntry>>,
    /// `[[torque_joint]]` entries.
    #[serde(default)]
    pub torque_joint: Vec<Spanned<TorqueJointEntry>>,
    /// `[[constant_force]]` entries.
    #[serde(default)]
    pub constant_force: Vec<Spanned<ConstantForceEntry>>,
    /// `[[nbody]]` entries.
    #[serde(default)]
    pub nbody: Vec<Spanned<NBodyEntry>>,
    /// `[[roobot]]` entries: hopping monopods with their controllers.
    #[serde(default)]
    pub roobot: Vec<Spanned<RoobotEntry>>,
    /// `[[food]]` entries: fixed particles that jellyfish smell.
    #[serde(default)]
    pub food: Vec<Spanned<FoodEntry>>,
    /// `[[jellyfish]]` entries.
    #[serde(default)]
    pub jellyfish: Vec<Spanned<JellyfishEntry>>,
    /// `[[seaweed]]` entries: fronds.
    #[serde(default)]
    pub seaweed: Vec<Spanned<SeaweedEntry>>,
    /// `[[bubble_column]]` entries.
    #[serde(default)]
    pub bubble_column: Vec<Spanned<BubbleColumnEntry>>,
    /// `[[rocks]]` entries: scattered sinking stones.
    #[serde(default)]
    pub rocks: Vec<Spanned<RocksEntry>>,
    /// `[[quadruped]]` entries: the thesis's three failed quadrupeds.
    #[serde(default)]
    pub quadruped: Vec<Spanned<QuadrupedEntry>>,
    /// `[contacts]`: sphere–sphere contact (opt-in).
    #[serde(default)]
    pub contacts: Option<Spanned<ContactsEntry>>,
    /// `[[actuator]]` entries: levels in [0, 1] onto a named spring, joint or force.
    #[serde(default)]
    pub actuator: Vec<Spanned<Typed<ActuatorEntry>>>,
    /// `[[sensor]]` entries: readings mapped onto [0, 1].
    #[serde(default)]
    pub sensor: Vec<Spanned<Typed<SensorEntry>>>,
    /// `[[controller]]` entries: brains from sensors to actuators.
    #[serde(default)]
    pub controller: Vec<Spanned<Typed<ControllerEntry>>>,
    /// `[evolve]`: the controller evolution tunes and how a run is scored.
    #[serde(default)]
    pub evolve: Option<Spanned<EvolveEntry>>,
}

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

/// `[[particle]]`: a sphere.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleEntry {
    /// Unique; forces refer to particles by name.
    pub name: String,
    /// kg, > 0.
    pub mass: f64,
    /// m.
    pub position: [f64; 3],
    /// m/s, default 0.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// m; or `volume`; at least one.
    pub radius: Option<f64>,
    /// m³; or `radius`; at least one.
    pub volume: Option<f64>,
    /// Default 0.5.
    #[serde(default = "default_mu_s")]
    pub mu_s: f64,
    /// Default 0.3.
    #[serde(default = "default_mu_k")]
    pub mu_k: f64,
    /// 0..=1, default 0.5.
    #[serde(default = "default_restitution")]
    pub restitution: f64,
    /// Nailed in place; default false.
    #[serde(default)]
    pub fixed: bool,
}

fn default_mu_s() -> f64 {
    0.5
}
fn default_mu_k() -> f64 {
    0.3
}
fn default_restitution() -> f64 {
    0.5
}

/// `[floor]`: the plane y = 0.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FloorEntry {
    /// m: deeper than this below the plane = missed; default 0.01.
    #[serde(default = "default_envelope")]
    pub envelope: f64,
    /// m/s: below this, static friction; default 0.01.
    #[serde(default = "default_static_speed")]
    pub static_speed: f64,
    /// m/s: impacts slower than this do not bounce; default 0.05.
    #[serde(default = "default_rest_speed")]
    pub rest_speed: f64,
    /// Default: all particles.
    pub particles: Option<Vec<String>>,
}

fn default_envelope() -> f64 {
    0.01
}
fn default_static_speed() -> f64 {
    0.01
}
fn default_rest_speed() -> f64 {
    0.05
}

/// `[contacts]`: the spheres collide with each other (not only with the
/// floor); pairs joined by a spring or a joint never do.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactsEntry {
    /// The spheres that collide; default all.
    pub particles: Option<Vec<String>>,
    /// The restitution of every contact, in [0, 1]; default the product of
    /// the two spheres' restitutions.
    pub restitution: Option<f64>,
    /// m: an overlap deeper than this = missed; default 0.01.
    #[serde(default = "default_envelope")]
    pub envelope: f64,
    /// m/s: approaches slower than this do not bounce; default 0.05.
    #[serde(default = "default_rest_speed")]
    pub rest_speed: f64,
    /// m/s: a sphere in contact that stays within `sleep_speed ·
    /// sleep_time` of one place for `sleep_time` falls asleep; default 0
    /// (never).
    #[serde(default)]
    pub sleep_speed: f64,
    /// s: default 0.5.
    #[serde(default = "default_sleep_time")]
    pub sleep_time: f64,
}

fn default_sleep_time() -> f64 {
    0.5
}

/// `[fluid]`: drag and buoyancy.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidEntry {
    /// kg/m³, default 1000 (water).
    #[serde(default = "default_density")]
    pub density: f64,
    /// Default 0.47 (a sphere).
    #[serde(default = "default_drag")]
    pub drag_coefficient: f64,
    /// The fluid's velocity field; default still.
    #[serde(default)]
    pub current: CurrentEntry,
    /// Default: all particles.
    pub particles: Option<Vec<String>>,
}

fn default_density() -> f64 {
    1000.0
}
fn default_drag() -> f64 {
    0.47
}

/// `current = { kind = "..." ... }`.
#[derive(Clone, Debug, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum CurrentEntry {
    /// At rest.
    #[default]
    Still,
    /// The same velocity everywhere.
    Uniform {
        /// m/s.
        velocity: [f64; 3],
    },
    /// Swaying currents under passing waves (see `ReefWater`).
    Reef {
        /// Height of the mean water surface, m; default 1.5.
        surface: Option<f64>,
        /// Wave amplitude at the surface, m; default 0.1.
        amplitude: Option<f64>,
        /// m; default 3.
        wavelength: Option<f64>,
        /// s; default: deep-water waves of that wavelength.
        period: Option<f64>,
        /// Horizontal direction of travel; default `[1, 0, 0]`.
        direction: Option<[f64; 3]>,
        /// Steady current added everywhere, m/s; default 0.
        drift: Option<[f64; 3]>,
    },
}

/// `[[spring]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringEntry {
    /// Optional, unique among its kind: actuators refer to it by name.
    pub name: Option<String>,
    /// One end (a particle name).
    pub a: String,
    /// The other end.
    pub b: String,
    /// N/m, >= 0.
    pub stiffness: f64,
    /// N s/m, >= 0, default 0.
    #[serde(default)]
    pub damping: f64,
    /// m, > 0; default the initial distance.
    pub rest_length: Option<f64>,
}

/// `[[angle_joint]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngleJointEntry {
    /// Optional, unique among its kind: actuators refer to it by name.
    pub name: Option<String>,
    /// End of the first arm.
    pub a: String,
    /// Where the arms meet.
    pub joint: String,
    /// End of the second arm.
    pub b: String,
    /// N m/rad, >= 0.
    pub stiffness: f64,
    /// N m s/rad, >= 0, default 0.
    #[serde(default)]
    pub damping: f64,
    /// rad in [0, π]; default the initial angle.
    pub rest_angle: Option<f64>,
}

/// `[[torque_joint]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueJointEntry {
    /// Optional, unique among its kind: actuators refer to it by name.
    pub name: Option<String>,
    /// The mass turned.
    pub end: String,
    /// The mass it turns about.
    pub joint: String,
    /// Default `[0, 0, 1]`.
    #[serde(default = "default_axis")]
    pub axis: [f64; 3],
    /// N m, default 0.
    #[serde(default)]
    pub torque: f64,
}

fn default_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// `[[constant_force]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantForceEntry {
    /// Optional, unique among its kind: actuators refer to it by name.
    pub name: Option<String>,
    /// Default: all particles.
    pub particles: Option<Vec<String>>,
    /// N, on each.
    pub force: [f64; 3],
}

/// `[[nbody]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NBodyEntry {
    /// Default: all particles.
    pub particles: Option<Vec<String>>,
    /// Gravitational constant; default 6.674e-11.
    #[serde(rename = "G", default = "default_big_g")]
    pub g: f64,
    /// m, default 0.
    #[serde(default)]
    pub softening: f64,
}

fn default_big_g() -> f64 {
    6.674e-11
}

/// Where a creature's parameters come from: a built-in name or file path, or
/// the numbers themselves.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum ParamsEntry {
    /// `"evolved"`, `"initial"`, or a parameter file (relative to the scene file).
    Named(String),
    /// The 14 numbers inline.
    Inline(Vec<f64>),
}

/// `[[roobot]]`: a hopping monopod with its brain. Its sensors, actuators
/// and brain join the scene's (`NAME.foot_height`..., `NAME.leg`...,
/// controller `NAME`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoobotEntry {
    /// Prefix of its particles' names (`NAME.hip`...); default `roobot{k}`.
    pub name: Option<String>,
    /// Where its foot stands, m (y is ignored: the foot rests on the floor).
    #[serde(default)]
    pub position: [f64; 3],
    /// Direction it faces, rad from +x, counter-clockwise seen from above.
    #[serde(default)]
    pub heading: f64,
    /// `hop` (the thesis's FSM), `raibert` or `none`; default `hop`.
    #[serde(default)]
    pub brain: RoobotBrainName,
    /// `hop`: its hopping parameters; default `"evolved"`.
    pub params: Option<ParamsEntry>,
    /// `raibert`: its 8 gains; default the hand-set ones.
    pub gains: Option<Vec<f64>>,
}

/// A roobot's brain, as written in files.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum RoobotBrainName {
    /// The thesis's hopping FSM.
    #[default]
    Hop,
    /// Raibert's three-part controller.
    Raibert,
    /// None: a program or a scene's controller drives its actuators.
    None,
}

/// `[[food]]`: a fixed particle that jellyfish track.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FoodEntry {
    /// Default `food`.
    #[serde(default = "default_food")]
    pub name: String,
    /// m.
    pub position: [f64; 3],
    /// m; default 0.062 (Appendix B's volume of 1 litre).
    pub radius: Option<f64>,
}

fn default_food() -> String {
    "food".into()
}

/// `[[jellyfish]]`: Appendix B's jellyfish.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JellyfishEntry {
    /// Prefix of its particles' names; default `jellyfish{k}`.
    pub name: Option<String>,
    /// Centre of its dome, m.
    pub position: [f64; 3],
    /// Mass of each dome mass, kg; default 0.2.
    #[serde(default = "default_dome_mass")]
    pub dome_mass: f64,
    /// Mass of each tentacle segment, kg; default 0.02.
    #[serde(default = "default_tentacle_mass")]
    pub tentacle_mass: f64,
    /// The particle it tracks; default `food`.
    #[serde(default = "default_food")]
    pub food: String,
    /// Pulse force range per dome mass, N; default 4.5× the submerged weight
    /// it carries (Appendix B: 5).
    pub pulse_force: Option<f64>,
    /// Steering force range per dome mass, N; default a tenth of the pulse's
    /// (Appendix B: 0.5).
    pub steer_force: Option<f64>,
    /// Height its depth sense reads as "too high", m; default 1.
    pub ceiling: Option<f64>,
}

fn default_dome_mass() -> f64 {
    0.2
}
fn default_tentacle_mass() -> f64 {
    0.02
}

/// `[[seaweed]]`: a frond nailed to the floor.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeaweedEntry {
    /// Prefix of its particles' names; default `seaweed{k}`.
    pub name: Option<String>,
    /// Where its base is nailed, m (y is ignored: on the floor).
    pub position: [f64; 3],
    /// Default 12.
    pub segments: Option<usize>,
    /// m; default 0.06.
    pub segment_length: Option<f64>,
    /// kg per segment; default 0.004.
    pub mass: Option<f64>,
    /// kg/m³; default 980.
    pub density: Option<f64>,
    /// N/m; default 10.
    pub stiffness: Option<f64>,
    /// N s/m; default 0.02.
    pub damping: Option<f64>,
}

/// `[[bubble_column]]`: a particle system of rising bubbles.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BubbleColumnEntry {
    /// Prefix of its particles' names; default `bubbles{k}`.
    pub name: Option<String>,
    /// Base of the column, m (y is ignored: on the floor).
    pub position: [f64; 3],
    /// Bubbles in the pool; default 15.
    pub bubbles: Option<usize>,
    /// Time between spawns, s; default [0.1, 0.4].
    pub interval: Option<[f64; 2]>,
    /// Bubble radius range, m; default [0.002, 0.005].
    pub radius: Option<[f64; 2]>,
    /// Effective density with added mass, kg/m³; default 500.
    pub density: Option<f64>,
    /// Water surface height, m; default 1.5.
    pub surface: Option<f64>,
}

/// `[[rocks]]`: stones scattered at random.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RocksEntry {
    /// Prefix of their names; default `rock` (`rock0`, `rock1`...).
    pub name: Option<String>,
    /// How many; default 10.
    pub count: Option<usize>,
    /// Mass range, kg; default [0.05, 0.3].
    pub mass: Option<[f64; 2]>,
    /// kg/m³; default 2000.
    pub density: Option<f64>,
    /// Least corner of the drop box, m; default [-0.5, 0.2, -0.5].
    pub from: Option<[f64; 3]>,
    /// Greatest corner, m; default [0.5, 1.2, 0.5].
    pub to: Option<[f64; 3]>,
}

/// `[[quadruped]]`: one of the thesis's three quadruped models.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadrupedEntry {
    /// Prefix of its particles' names; default `quadruped{k}`.
    pub name: Option<String>,
    /// 1, 2 or 3 (thesis §3.2.3).
    pub model: u32,
    /// Where the centre of its torso stands, m (y ignored).
    #[serde(default)]
    pub position: [f64; 3],
    /// rad from +x, counter-clockwise seen from above.
    #[serde(default)]
    pub heading: f64,
    /// When to run the thesis's failing experiment, s (model 2 raises its
    /// front feet, model 3 tries a step); default 2; a negative time never.
    #[serde(default = "default_demo")]
    pub demo_at: f64,
}

fn default_demo() -> f64 {
    2.0
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
    /// The initial level, default 0.5.
    pub level: f64,
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
    #[serde(default = "default_level")]
    level: f64,
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

fn default_level() -> f64 {
    0.5
}

/// `[evolve]`: what `animats evolve SCENE` tunes and how an evaluation
/// (`animats evaluate SCENE`) is scored:
/// `fitness = time_weight × time survived + distance_weight × distance`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvolveEntry {
    /// The controller whose parameters form the genome.
    pub controller: String,
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
