//! Each kind of scene entry builds itself: one file per kind, each an
//! `impl Build for ...Entry` that validates its entry and adds it to the
//! world, naming what it adds. `build.rs` calls them in a fixed order
//! (particles and food first, so that the rest can name them; creatures
//! after forces). Adding an entry kind: its struct in `def.rs`, a file here,
//! and one line in `build.rs`.

pub(crate) mod angle_joint;
pub(crate) mod bubble_column;
pub(crate) mod constant_force;
pub(crate) mod contacts;
pub(crate) mod floor;
pub(crate) mod fluid;
pub(crate) mod food;
pub(crate) mod jellyfish;
pub(crate) mod nbody;
pub(crate) mod particle;
pub(crate) mod quadruped;
pub(crate) mod rocks;
pub(crate) mod roobot;
pub(crate) mod seaweed;
pub(crate) mod spring;
pub(crate) mod torque_joint;

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

/// Builds every entry of one kind (`[[kind]]`), in order.
pub(crate) fn each<T: Build>(
    entries: &[Spanned<T>],
    kind: &str,
    cx: &mut Builder,
) -> Result<(), SceneError> {
    for (k, e) in entries.iter().enumerate() {
        let at = at(cx.src, format!("{kind}[{k}]"), e);
        e.get_ref().build(k, &at, cx)?;
    }
    Ok(())
}

/// Builds a single table (`[kind]`), if the scene has one.
pub(crate) fn one<T: Build>(
    entry: &Option<Spanned<T>>,
    kind: &str,
    cx: &mut Builder,
) -> Result<(), SceneError> {
    if let Some(e) = entry {
        let at = at(cx.src, kind, e);
        e.get_ref().build(0, &at, cx)?;
    }
    Ok(())
}
