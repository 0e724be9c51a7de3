//! Each kind of scene entry is one file here: its struct (the keys a scene
//! file gives it, checked by serde) and its `impl Build`, which validates
//! it and adds it to the world, naming what it adds. Adding an entry kind:
//! its file, and its line in the [`entries!`] list below.

/// Declares every kind of entry once, in the order they are built (the
/// order written): its module (the file `entries/NAME.rs`, holding its
/// struct and its [`Build`]), and its field of [`SceneDef`], a `[[NAME]]`
/// array (`Vec`) or a `[NAME]` table (`Option`). Particles and food come
/// first, so that everything else can name them; creatures after forces.
macro_rules! entries {
    ($($(#[doc = $doc:literal])* $field:ident: $many:ident<$entry:ident>,)*) => {
        $(pub mod $field;)*
        $(pub use $field::$entry;)*

        /// A whole scene file.
        #[derive(Clone, Debug, Deserialize, Default)]
        #[serde(deny_unknown_fields)]
        pub struct SceneDef {
            /// `[world]`: gravity, step, integrator, duration.
            #[serde(default)]
            pub world: Option<Spanned<WorldDef>>,
            $(
                $(#[doc = $doc])*
                #[serde(default)]
                pub $field: $many<Spanned<$entry>>,
            )*
            /// `[[actuator]]` entries: levels in [0, 1] onto a named spring,
            /// joint or force.
            #[serde(default)]
            pub actuator: Vec<Spanned<Typed<ActuatorEntry>>>,
            /// `[[sensor]]` entries: readings mapped onto [0, 1].
            #[serde(default)]
            pub sensor: Vec<Spanned<Typed<SensorEntry>>>,
            /// `[[controller]]` entries: brains from sensors to actuators.
            #[serde(default)]
            pub controller: Vec<Spanned<Typed<ControllerEntry>>>,
            /// `[evolve]`: the controller evolution tunes and how a run is
            /// scored.
            #[serde(default)]
            pub evolve: Option<Spanned<EvolveEntry>>,
            /// `[morphology]`: the bodies evolution searches
            /// ([`crate::morphology`]).
            #[serde(default)]
            pub morphology: Option<Spanned<crate::morphology::MorphologyEntry>>,
            /// `[archive]`: the measures that describe an evaluation and the
            /// grid a quality-diversity search fills ([`crate::archive`]).
            #[serde(default)]
            pub archive: Option<Spanned<crate::archive::ArchiveEntry>>,
        }

        /// Builds every entry of the scene, in the order declared.
        pub(crate) fn build_all(def: &SceneDef, cx: &mut Builder) -> Result<(), SceneError> {
            $(Entries::build_all(&def.$field, stringify!($field), cx)?;)*
            Ok(())
        }
    };
}

entries! {
    /// `[[particle]]` entries.
    particle: Vec<ParticleEntry>,
    /// `[[food]]` entries: fixed particles that jellyfish smell.
    food: Vec<FoodEntry>,
    /// `[terrain]`: the floor's shape (slope, steps, heightfield).
    terrain: Option<TerrainEntry>,
    /// `[floor]`: the plane y = 0.
    floor: Option<FloorEntry>,
    /// `[fluid]`: drag and buoyancy.
    fluid: Option<FluidEntry>,
    /// `[[spring]]` entries.
    spring: Vec<SpringEntry>,
    /// `[[angle_joint]]` entries.
    angle_joint: Vec<AngleJointEntry>,
    /// `[[torque_joint]]` entries.
    torque_joint: Vec<TorqueJointEntry>,
    /// `[[constant_force]]` entries.
    constant_force: Vec<ConstantForceEntry>,
    /// `[[nbody]]` entries.
    nbody: Vec<NBodyEntry>,
    /// `[[roobot]]` entries: hopping monopods with their brains.
    roobot: Vec<RoobotEntry>,
    /// `[[jellyfish]]` entries.
    jellyfish: Vec<JellyfishEntry>,
    /// `[[seaweed]]` entries: fronds.
    seaweed: Vec<SeaweedEntry>,
    /// `[[bubble_column]]` entries.
    bubble_column: Vec<BubbleColumnEntry>,
    /// `[[rocks]]` entries: scattered sinking stones.
    rocks: Vec<RocksEntry>,
    /// `[[quadruped]]` entries: the thesis's three failed quadrupeds.
    quadruped: Vec<QuadrupedEntry>,
    /// `[contacts]`: sphere–sphere contact (opt-in).
    contacts: Option<ContactsEntry>,
}

pub(crate) use crate::build::{at, check_name, room, At, Names, CREATURE_PARTICLES};
pub(crate) use crate::def::*;
pub(crate) use crate::error::SceneError;
pub(crate) use crate::nervous::Handles;
pub(crate) use crate::source::Source;
pub(crate) use crate::PartKind;
pub(crate) use animats_creatures::jellyfish::{Jellyfish, JellyfishConstants};
pub(crate) use animats_creatures::quadruped::{Demo, Model, Quadruped, QuadrupedConstants};
pub(crate) use animats_creatures::roobot::{
    self as roobot_kit, BodyConstants, HopParams, RoobotBrain,
};
pub(crate) use animats_creatures::seaworld::{
    rocks as rock_field, seaweed as seaweed_frond, BubbleColumn, BubbleConstants, Random,
    RocksConstants, SeaweedConstants,
};
pub(crate) use animats_creatures::Actor;
pub(crate) use animats_creatures::NervousSystem;
pub(crate) use animats_engine::{
    AngleJointDef, Current, DVec3, FloorDef, FluidMedium, NBodyGravity, ParticleDef, ParticleId,
    ReefWater, SpringDef, Targets, TorqueJointDef, World,
};
pub(crate) use serde::Deserialize;
pub(crate) use toml::Spanned;

/// What entries build into, and the names they have given so far.
pub(crate) struct Builder<'s> {
    /// The scene file, for errors and relative paths.
    pub src: &'s Source<'s>,
    /// The world being built.
    pub world: World,
    /// Particle names → handles.
    pub names: Names,
    /// Each particle's name, by index.
    pub list: Vec<String>,
    /// What each particle is part of, by index.
    pub kinds: Vec<crate::PartKind>,
    /// The creatures built so far.
    pub creatures: Vec<crate::Creature>,
    /// Named springs, joints and forces, for actuators.
    pub handles: Handles,
    /// Creatures and processes that act every step beside the nervous system.
    pub actors: Vec<Box<dyn Actor>>,
    /// Sensors, actuators and brains creatures bring (the scene's own
    /// `[[sensor]]`, `[[actuator]]` and `[[controller]]` entries follow).
    pub nervous: NervousSystem,
    /// For each controller in `nervous`, the table it was written in
    /// (`roobot`, 0): where evolution writes its genes back.
    pub origins: Vec<(&'static str, usize)>,
    /// The scene's seed.
    pub seed: u64,
    /// The scene's gravity.
    pub gravity: DVec3,
    /// The floor's shape, from `[terrain]`, until the floor takes it.
    pub terrain: Option<animats_engine::Terrain>,
}

impl Builder<'_> {
    /// Names the particles an entry just added (`first` onwards), of the
    /// kinds `kind` gives by position.
    pub fn add(
        &mut self,
        at: &At,
        first: usize,
        parts: &[String],
        kind: impl Fn(usize) -> crate::PartKind,
    ) -> Result<(), SceneError> {
        for (i, full) in parts.iter().enumerate() {
            self.kinds.push(kind(i));
            if self.names.ids.contains_key(full) {
                return Err(at.err("name", format!("duplicate particle name `{full}`")));
            }
            self.names
                .ids
                .insert(full.clone(), ParticleId::from_index(first + i));
            self.list.push(full.clone());
        }
        Ok(())
    }
}

impl Builder<'_> {
    /// Records the creature `name` whose particles are `first..first + count`.
    pub fn creature(&mut self, name: &str, first: usize, count: usize, bell: Option<crate::Bell>) {
        self.creatures.push(crate::Creature {
            name: name.to_string(),
            particles: (first..first + count).collect(),
            bell,
        });
    }
}

/// An entry that validates itself and adds itself to the world.
pub(crate) trait Build {
    /// Builds entry `k` of its kind, found at `at`.
    fn build(&self, k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError>;
}

/// The entries of one kind: a `[[kind]]` array's, or a `[kind]` table's if
/// the scene has one.
pub(crate) trait Entries {
    /// Builds them, in order.
    fn build_all(&self, kind: &str, cx: &mut Builder) -> Result<(), SceneError>;
}

impl<T: Build> Entries for Vec<Spanned<T>> {
    fn build_all(&self, kind: &str, cx: &mut Builder) -> Result<(), SceneError> {
        for (k, e) in self.iter().enumerate() {
            let at = at(cx.src, format!("{kind}[{k}]"), e);
            e.get_ref().build(k, &at, cx)?;
        }
        Ok(())
    }
}

impl<T: Build> Entries for Option<Spanned<T>> {
    fn build_all(&self, kind: &str, cx: &mut Builder) -> Result<(), SceneError> {
        if let Some(e) = self {
            let at = at(cx.src, kind, e);
            e.get_ref().build(0, &at, cx)?;
        }
        Ok(())
    }
}
