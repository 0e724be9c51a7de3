//! From a parsed scene description to a world: every entry validated, every
//! particle name resolved, every mistake reported with its entry and field.

use crate::def::*;
use crate::error::SceneError;
use crate::source::Source;
use crate::Scene;
use animats_creatures::jellyfish::{Jellyfish, JellyfishConstants};
use animats_creatures::quadruped::{Demo, Model, Quadruped, QuadrupedConstants};
use animats_creatures::roobot::{BodyConstants, Roobot};
use animats_creatures::seaworld::{
    rocks, seaweed, BubbleColumn, BubbleConstants, Random, RocksConstants, SeaweedConstants,
};
use animats_creatures::Actor;
use animats_engine::DVec3;
use animats_engine::{
    AngleJointDef, Current, FloorDef, FluidMedium, Gravity, ModelError, NBodyGravity, ParticleDef,
    ParticleId, ReefWater, SpringDef, Targets, TorqueJointDef, World,
};
use std::collections::HashMap;
use toml::Spanned;

/// The most particles a scene may make, all its entries together: far past
/// any scene that runs at a useful speed (cloth-128 has 16,384), and small
/// enough that building it cannot exhaust memory (about 1 kB a particle with
/// its name, springs and scratch space).
pub const MAX_PARTICLES: usize = 1_000_000;

/// At least as many particles as any built-in creature has.
const CREATURE_PARTICLES: usize = 64;

/// Refuses a count that would take the world past [`MAX_PARTICLES`], before
/// anything is allocated for it.
fn room(at: &At, field: &str, count: usize, world: &World) -> Result<(), SceneError> {
    let left = MAX_PARTICLES.saturating_sub(world.len());
    if count > left {
        return Err(at.err(
            field,
            format!(
                "{} would take the scene past its limit of {MAX_PARTICLES} particles ({} before it)",
                if field.is_empty() {
                    "this entry".to_string()
                } else {
                    format!("{count}")
                },
                world.len()
            ),
        ));
    }
    Ok(())
}

/// Where an entry came from, for error messages.
pub(crate) struct At<'s> {
    src: &'s Source<'s>,
    entry: String,
    line: usize,
}

impl At<'_> {
    pub(crate) fn err(&self, field: &str, message: impl Into<String>) -> SceneError {
        SceneError {
            file: self.src.file.to_string(),
            line: Some(self.line),
            entry: Some(self.entry.clone()),
            field: (!field.is_empty()).then(|| field.to_string()),
            message: message.into(),
        }
    }

    pub(crate) fn model(&self, e: ModelError) -> SceneError {
        self.err(&e.field, e.reason)
    }

    pub(crate) fn finite(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be a finite number, got {x}")))
        }
    }

    pub(crate) fn positive(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        self.finite(field, x)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be > 0, got {x}")))
        }
    }

    pub(crate) fn vec3(&self, field: &str, v: [f64; 3]) -> Result<DVec3, SceneError> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(DVec3::from_array(v))
        } else {
            Err(self.err(field, format!("must be finite, got {v:?}")))
        }
    }
}

pub(crate) fn at<'s, T>(
    src: &'s Source<'s>,
    entry: impl Into<String>,
    spanned: &Spanned<T>,
) -> At<'s> {
    At {
        src,
        entry: entry.into(),
        line: src.line_of(spanned.span().start),
    }
}

/// Resolves particle names to handles.
pub(crate) struct Names {
    pub(crate) ids: HashMap<String, ParticleId>,
}

impl Names {
    pub(crate) fn one(&self, at: &At, field: &str, name: &str) -> Result<ParticleId, SceneError> {
        self.ids
            .get(name)
            .copied()
            .ok_or_else(|| at.err(field, format!("unknown particle `{name}`")))
    }

    fn targets(&self, at: &At, names: &Option<Vec<String>>) -> Result<Targets, SceneError> {
        match names {
            None => Ok(Targets::All),
            Some(list) => Ok(Targets::Only(
                list.iter()
                    .map(|n| self.one(at, "particles", n))
                    .collect::<Result<_, _>>()?,
            )),
        }
    }
}

/// A particle name: non-empty, and safe to write unquoted in CSV and JSON.
pub(crate) fn check_name(at: &At, name: &str) -> Result<(), SceneError> {
    let ok = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | ':' | '#' | '/'));
    if ok {
        Ok(())
    } else {
        Err(at.err(
            "name",
            format!("`{name}` is not a valid name: use letters, digits and _ - . : # /"),
        ))
    }
}

/// Builds the world a scene describes.
pub fn build(def: &SceneDef, src: &Source) -> Result<Scene, SceneError> {
    let mut world = World::new();

    // [world]
    let wd = def
        .world
        .as_ref()
        .map(|w| w.get_ref().clone())
        .unwrap_or_default();
    let wat = match &def.world {
        Some(w) => at(src, "world", w),
        None => At {
            src,
            entry: "world".into(),
            line: 1,
        },
    };
    let gravity = wat.vec3("gravity", wd.gravity)?;
    let dt = wat.positive("dt", wd.dt)?;
    let duration = wat.positive("duration", wd.duration)?;
    world.set_integrator(wd.integrator.into());
    if gravity != DVec3::ZERO {
        world
            .set_gravity_force(Some(Gravity::new(gravity)))
            .map_err(|e| wat.model(e))?;
    }

    // [[particle]]
    let mut names = Names {
        ids: HashMap::new(),
    };
    let mut name_list = Vec::with_capacity(def.particle.len());
    let mut kinds: Vec<&'static str> = Vec::with_capacity(def.particle.len());
    for (k, entry) in def.particle.iter().enumerate() {
        let p = entry.get_ref();
        let at = at(src, format!("particle[{k}]"), entry);
        room(&at, "", 1, &world)?;
        check_name(&at, &p.name)?;
        if names.ids.contains_key(&p.name) {
            return Err(at.err("name", format!("duplicate particle name `{}`", p.name)));
        }
        if p.radius.is_none() && p.volume.is_none() {
            return Err(at.err(
                "radius",
                "give the particle a `radius` or a `volume` (or both)",
            ));
        }
        let pdef = ParticleDef {
            mass: p.mass,
            position: DVec3::from_array(p.position),
            velocity: DVec3::from_array(p.velocity),
            radius: p.radius,
            volume: p.volume,
            mu_s: p.mu_s,
            mu_k: p.mu_k,
            restitution: p.restitution,
            fixed: p.fixed,
        };
        let id = world.add_particle(pdef).map_err(|e| at.model(e))?;
        names.ids.insert(p.name.clone(), id);
        name_list.push(p.name.clone());
        kinds.push("particle");
    }

    // [[food]]: before the creatures that smell it.
    for (k, entry) in def.food.iter().enumerate() {
        let f = entry.get_ref();
        let at = at(src, format!("food[{k}]"), entry);
        room(&at, "", 1, &world)?;
        check_name(&at, &f.name)?;
        if names.ids.contains_key(&f.name) {
            return Err(at.err("name", format!("duplicate particle name `{}`", f.name)));
        }
        let position = at.vec3("position", f.position)?;
        let radius = match f.radius {
            Some(r) => at.positive("radius", r)?,
            None => animats_engine::particle::sphere_radius(1e-3),
        };
        // Appendix B's food is 1 kg in a litre; it is nailed in place (the
        // thesis never simulates it) and moved by hand.
        let id = world
            .add_particle(
                ParticleDef::new(1.0)
                    .with_radius(radius)
                    .at(position)
                    .fixed(),
            )
            .map_err(|e| at.model(e))?;
        names.ids.insert(f.name.clone(), id);
        name_list.push(f.name.clone());
        kinds.push("food");
    }

    // [floor]
    if let Some(entry) = &def.floor {
        let f = entry.get_ref();
        let at = at(src, "floor", entry);
        let targets = names.targets(&at, &f.particles)?;
        world
            .add_floor(FloorDef {
                envelope: f.envelope,
                static_speed: f.static_speed,
                rest_speed: f.rest_speed,
                targets,
                ..FloorDef::default()
            })
            .map_err(|e| at.model(e))?;
    }

    // [fluid]
    if let Some(entry) = &def.fluid {
        let f = entry.get_ref();
        let at = at(src, "fluid", entry);
        let current = current(&at, &f.current, gravity.length())?;
        let targets = names.targets(&at, &f.particles)?;
        let fluid = FluidMedium {
            density: f.density,
            drag_coefficient: f.drag_coefficient,
            current,
            targets,
        };
        world.add_fluid(fluid).map_err(|e| at.model(e))?;
    }

    let mut handles = crate::nervous::Handles::default();

    // [[spring]]
    for (k, entry) in def.spring.iter().enumerate() {
        let s = entry.get_ref();
        let at = at(src, format!("spring[{k}]"), entry);
        let sdef = SpringDef {
            a: names.one(&at, "a", &s.a)?,
            b: names.one(&at, "b", &s.b)?,
            stiffness: s.stiffness,
            damping: s.damping,
            rest_length: s.rest_length,
        };
        let id = world.add_spring(sdef).map_err(|e| at.model(e))?;
        crate::nervous::insert(&mut handles.springs, &at, "spring", &s.name, id)?;
    }

    // [[angle_joint]]
    for (k, entry) in def.angle_joint.iter().enumerate() {
        let j = entry.get_ref();
        let at = at(src, format!("angle_joint[{k}]"), entry);
        let jdef = AngleJointDef {
            a: names.one(&at, "a", &j.a)?,
            joint: names.one(&at, "joint", &j.joint)?,
            b: names.one(&at, "b", &j.b)?,
            stiffness: j.stiffness,
            damping: j.damping,
            rest_angle: j.rest_angle,
        };
        let id = world.add_angle_joint(jdef).map_err(|e| at.model(e))?;
        crate::nervous::insert(&mut handles.angle_joints, &at, "angle joint", &j.name, id)?;
    }

    // [[torque_joint]]
    for (k, entry) in def.torque_joint.iter().enumerate() {
        let j = entry.get_ref();
        let at = at(src, format!("torque_joint[{k}]"), entry);
        let jdef = TorqueJointDef {
            end: names.one(&at, "end", &j.end)?,
            joint: names.one(&at, "joint", &j.joint)?,
            axis: DVec3::from_array(j.axis),
            torque: j.torque,
        };
        let id = world.add_torque_joint(jdef).map_err(|e| at.model(e))?;
        crate::nervous::insert(&mut handles.torque_joints, &at, "torque joint", &j.name, id)?;
    }

    // [[constant_force]]
    for (k, entry) in def.constant_force.iter().enumerate() {
        let c = entry.get_ref();
        let at = at(src, format!("constant_force[{k}]"), entry);
        let ids = match names.targets(&at, &c.particles)? {
            Targets::All => world.particle_ids().collect(),
            Targets::Only(ids) => ids,
        };
        let force = at.vec3("force", c.force)?;
        let id = world
            .add_constant_force(ids, force)
            .map_err(|e| at.model(e))?;
        crate::nervous::insert(
            &mut handles.constant_forces,
            &at,
            "constant force",
            &c.name,
            (id, force),
        )?;
    }

    // [[nbody]]
    for (k, entry) in def.nbody.iter().enumerate() {
        let n = entry.get_ref();
        let at = at(src, format!("nbody[{k}]"), entry);
        let targets = names.targets(&at, &n.particles)?;
        world
            .add_nbody(NBodyGravity::new(n.g, n.softening, targets))
            .map_err(|e| at.model(e))?;
    }

    // [[roobot]]
    let mut actors: Vec<Box<dyn Actor>> = Vec::new();
    for (k, entry) in def.roobot.iter().enumerate() {
        let r = entry.get_ref();
        let at = at(src, format!("roobot[{k}]"), entry);
        let name = r.name.clone().unwrap_or_else(|| format!("roobot{k}"));
        check_name(&at, &name)?;
        let position = at.vec3("position", r.position)?;
        let heading = at.finite("heading", r.heading)?;
        let params = match &r.params {
            None => crate::params::load("evolved", None),
            Some(ParamsEntry::Inline(v)) => crate::params::check(src.file, "params", v),
            Some(ParamsEntry::Named(n)) if crate::params::BUILT_IN.contains(&n.as_str()) => {
                crate::params::load(n, None)
            }
            Some(ParamsEntry::Named(path)) => {
                let base = std::path::Path::new(src.file)
                    .parent()
                    .unwrap_or(std::path::Path::new(""));
                crate::params::load(&base.join(path).to_string_lossy(), None)
            }
        }
        .map_err(|e| at.err("params", e.to_string()))?;
        room(&at, "", CREATURE_PARTICLES, &world)?;
        let first = world.len();
        let roobot = Roobot::build(
            &mut world,
            &name,
            &BodyConstants::STANDARD,
            position,
            heading,
            params,
        )
        .map_err(|e| at.model(e))?;
        for (i, part) in ["hip", "foot", "head", "tail1", "tail2"].iter().enumerate() {
            let full = format!("{name}.{part}");
            if names.ids.contains_key(&full) {
                return Err(at.err("name", format!("duplicate particle name `{full}`")));
            }
            names
                .ids
                .insert(full.clone(), ParticleId::from_index(first + i));
            name_list.push(full);
            kinds.push("roobot");
        }
        actors.push(Box::new(roobot));
    }

    let mut namer = Namer {
        names: &mut names,
        list: &mut name_list,
        kinds: &mut kinds,
    };
    let seed = wd.seed;

    // [[jellyfish]]
    for (k, entry) in def.jellyfish.iter().enumerate() {
        let j = entry.get_ref();
        let at = at(src, format!("jellyfish[{k}]"), entry);
        let name = j.name.clone().unwrap_or_else(|| format!("jellyfish{k}"));
        check_name(&at, &name)?;
        let food = namer.names.ids.get(&j.food).copied().ok_or_else(|| {
            at.err(
                "food",
                format!(
                    "no particle `{}` to track: add a [[food]] entry named so",
                    j.food
                ),
            )
        })?;
        let position = at.vec3("position", j.position)?;
        let mut constants = JellyfishConstants::new(j.dome_mass, j.tentacle_mass);
        if let Some(f) = j.pulse_force {
            constants.pulse_force = at.positive("pulse_force", f)?;
        }
        if let Some(f) = j.steer_force {
            constants.steer_force = at.finite("steer_force", f)?.abs();
        }
        if let Some(c) = j.ceiling {
            constants.ceiling = at.positive("ceiling", c)?;
        }
        room(&at, "", CREATURE_PARTICLES, &world)?;
        let first = world.len();
        let jelly = Jellyfish::build(&mut world, &name, &constants, position, food)
            .map_err(|e| at.model(e))?;
        let mut parts: Vec<String> = (0..constants.tentacles)
            .map(|i| format!("{name}.dome{i}"))
            .collect();
        for i in 0..constants.tentacles {
            parts.extend((0..constants.segments).map(|s| format!("{name}.tentacle{i}.{s}")));
        }
        let domes = constants.tentacles;
        namer.add(&at, first, &parts, |i| {
            if i < domes {
                "dome"
            } else {
                "tentacle"
            }
        })?;
        actors.push(Box::new(jelly));
    }

    // [[seaweed]]
    for (k, entry) in def.seaweed.iter().enumerate() {
        let w = entry.get_ref();
        let at = at(src, format!("seaweed[{k}]"), entry);
        let name = w.name.clone().unwrap_or_else(|| format!("seaweed{k}"));
        check_name(&at, &name)?;
        let d = SeaweedConstants::default();
        let c = SeaweedConstants {
            segments: w.segments.unwrap_or(d.segments),
            segment_length: w.segment_length.unwrap_or(d.segment_length),
            mass: w.mass.unwrap_or(d.mass),
            density: w.density.unwrap_or(d.density),
            stiffness: w.stiffness.unwrap_or(d.stiffness),
            damping: w.damping.unwrap_or(d.damping),
        };
        let position = at.vec3("position", w.position)?;
        room(&at, "segments", c.segments.saturating_add(1), &world)?;
        let first = world.len();
        seaweed::build(&mut world, &c, position).map_err(|e| at.model(e))?;
        let parts: Vec<String> = (0..=c.segments).map(|i| format!("{name}.{i}")).collect();
        namer.add(&at, first, &parts, |_| "seaweed")?;
    }

    // [[bubble_column]]
    for (k, entry) in def.bubble_column.iter().enumerate() {
        let b = entry.get_ref();
        let at = at(src, format!("bubble_column[{k}]"), entry);
        let name = b.name.clone().unwrap_or_else(|| format!("bubbles{k}"));
        check_name(&at, &name)?;
        let d = BubbleConstants::default();
        let c = BubbleConstants {
            bubbles: b.bubbles.unwrap_or(d.bubbles),
            interval: b.interval.map_or(d.interval, |[a, z]| (a, z)),
            radius: b.radius.map_or(d.radius, |[a, z]| (a, z)),
            density: b.density.unwrap_or(d.density),
            surface: b.surface.unwrap_or(d.surface),
            spread: d.spread,
        };
        let position = at.vec3("position", b.position)?;
        let base = DVec3::new(position.x, 0.0, position.z);
        room(&at, "bubbles", c.bubbles, &world)?;
        let first = world.len();
        let column = BubbleColumn::build(
            &mut world,
            &c,
            base,
            Random::for_entry(seed, 1000 + k as u64),
        )
        .map_err(|e| at.model(e))?;
        let parts: Vec<String> = (0..c.bubbles).map(|i| format!("{name}.{i}")).collect();
        namer.add(&at, first, &parts, |_| "bubble")?;
        actors.push(Box::new(column));
    }

    // [[rocks]]
    for (k, entry) in def.rocks.iter().enumerate() {
        let r = entry.get_ref();
        let at = at(src, format!("rocks[{k}]"), entry);
        let name = r.name.clone().unwrap_or_else(|| "rock".into());
        check_name(&at, &name)?;
        let d = RocksConstants::default();
        let c = RocksConstants {
            count: r.count.unwrap_or(d.count),
            mass: r.mass.map_or(d.mass, |[a, z]| (a, z)),
            density: r.density.unwrap_or(d.density),
            from: r.from.map_or(Ok(d.from), |v| at.vec3("from", v))?,
            to: r.to.map_or(Ok(d.to), |v| at.vec3("to", v))?,
        };
        room(&at, "count", c.count, &world)?;
        let first = world.len();
        rocks::scatter(
            &mut world,
            &c,
            &mut Random::for_entry(seed, 2000 + k as u64),
        )
        .map_err(|e| at.model(e))?;
        let parts: Vec<String> = (0..c.count).map(|i| format!("{name}{i}")).collect();
        namer.add(&at, first, &parts, |_| "rock")?;
    }

    // [[quadruped]]
    for (k, entry) in def.quadruped.iter().enumerate() {
        let q = entry.get_ref();
        let at = at(src, format!("quadruped[{k}]"), entry);
        let name = q.name.clone().unwrap_or_else(|| format!("quadruped{k}"));
        check_name(&at, &name)?;
        let model = Model::from_number(q.model)
            .ok_or_else(|| at.err("model", format!("must be 1, 2 or 3, got {}", q.model)))?;
        let position = at.vec3("position", q.position)?;
        let heading = at.finite("heading", q.heading)?;
        let demo_at = at.finite("demo_at", q.demo_at)?;
        room(&at, "", CREATURE_PARTICLES, &world)?;
        let first = world.len();
        let mut quad = Quadruped::build(
            &mut world,
            &name,
            model,
            &QuadrupedConstants::default(),
            position,
            heading,
        )
        .map_err(|e| at.model(e))?;
        quad.demo = (demo_at >= 0.0).then_some(Demo { at: demo_at });
        // Its leg springs by name, for actuators: `NAME.legI` (corner or
        // knee to foot) and, for model 3, `NAME.legI.back` / `NAME.legI.side`
        // (foot to the front–back and left–right neighbouring corners).
        for (i, leg) in quad.legs.iter().enumerate() {
            let named = |suffix: &str| Some(format!("{name}.leg{i}{suffix}"));
            crate::nervous::insert(&mut handles.springs, &at, "spring", &named(""), leg.spring)?;
            if let Some((back, side)) = leg.supports {
                crate::nervous::insert(&mut handles.springs, &at, "spring", &named(".back"), back)?;
                crate::nervous::insert(&mut handles.springs, &at, "spring", &named(".side"), side)?;
            }
        }
        let mut parts: Vec<String> = (0..4).map(|i| format!("{name}.corner{i}")).collect();
        for i in 0..4 {
            if model == Model::TwoSegment {
                parts.push(format!("{name}.knee{i}"));
            }
            parts.push(format!("{name}.foot{i}"));
        }
        namer.add(&at, first, &parts, |_| "quadruped")?;
        actors.push(Box::new(quad));
    }

    let nervous = crate::nervous::build(def, src, &names, &handles, &mut world)?;
    let evolve = match &def.evolve {
        Some(entry) => Some(crate::evaluate::EvolveSpec::build(
            &at(src, "evolve", entry),
            entry.get_ref(),
            &names,
            &nervous,
            &world,
        )?),
        None => None,
    };

    let max_dt = match wd.max_dt {
        Some(m) => wat.positive("max_dt", m)?,
        None => dt,
    };
    let guard =
        animats_engine::DivergenceGuard::new(&world, !actors.is_empty() || !nervous.is_empty());
    let warnings = warnings(def, &world, &name_list, dt, def.floor.is_some());
    Ok(Scene {
        world,
        guard,
        warnings,
        names: name_list,
        kinds,
        dt,
        max_dt,
        duration,
        actors,
        nervous,
        evolve,
    })
}

/// Gives names to the particles a builder just added.
struct Namer<'a> {
    names: &'a mut Names,
    list: &'a mut Vec<String>,
    kinds: &'a mut Vec<&'static str>,
}

impl Namer<'_> {
    fn add(
        &mut self,
        at: &At,
        first: usize,
        parts: &[String],
        kind: impl Fn(usize) -> &'static str,
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

fn current(at: &At, c: &CurrentEntry, g: f64) -> Result<Current, SceneError> {
    Ok(match c {
        CurrentEntry::Still => Current::Still,
        CurrentEntry::Uniform { velocity } => {
            Current::Uniform(at.vec3("current.velocity", *velocity)?)
        }
        CurrentEntry::Reef {
            surface,
            amplitude,
            wavelength,
            period,
            direction,
            drift,
        } => {
            let d = ReefWater::default();
            let wavelength =
                at.positive("current.wavelength", wavelength.unwrap_or(d.wavelength))?;
            let period = match period {
                Some(p) => at.positive("current.period", *p)?,
                None if g > 0.0 => ReefWater::deep_water_period(wavelength, g),
                None => d.period,
            };
            let direction = match direction {
                Some(v) => at.vec3("current.direction", *v)?,
                None => d.direction,
            };
            if DVec3::new(direction.x, 0.0, direction.z).length() == 0.0 {
                return Err(at.err(
                    "current.direction",
                    "must have a horizontal (x or z) component",
                ));
            }
            let amplitude = at.finite("current.amplitude", amplitude.unwrap_or(d.amplitude))?;
            if amplitude < 0.0 {
                return Err(at.err(
                    "current.amplitude",
                    format!("must be >= 0, got {amplitude}"),
                ));
            }
            Current::Reef(ReefWater {
                surface: at.finite("current.surface", surface.unwrap_or(d.surface))?,
                amplitude,
                wavelength,
                period,
                direction,
                drift: match drift {
                    Some(v) => at.vec3("current.drift", *v)?,
                    None => d.drift,
                },
            })
        }
    })
}

/// Largest ω·h at which a lone undamped spring stays bounded under each
/// explicit integrator: symplectic Euler 2, RK4 2√2 ≈ 2.83; explicit Euler
/// and midpoint grow at any step, and get the symplectic bound as a guide.
fn stable_omega_h(kind: animats_engine::IntegratorKind) -> f64 {
    match kind {
        animats_engine::IntegratorKind::Rk4 => 2.0 * std::f64::consts::SQRT_2,
        _ => 2.0,
    }
}

/// What is allowed but probably a mistake: see [`Scene::warnings`].
fn warnings(def: &SceneDef, world: &World, names: &[String], dt: f64, floor: bool) -> Vec<String> {
    let mut out = Vec::new();
    let (p, s) = (world.particles(), world.state());
    if floor {
        for (i, name) in names.iter().enumerate() {
            let depth = p.radius[i] - s.pos[i].y;
            if depth > 1e-9 && !p.fixed[i] {
                out.push(format!(
                    "particle `{name}` starts {depth:.4} m inside the floor (its lowest point is below y = 0): the floor will push it out at once",
                ));
            }
        }
    }
    for (k, entry) in def.particle.iter().enumerate() {
        let q = entry.get_ref();
        if q.fixed && q.velocity.iter().any(|v| *v != 0.0) {
            out.push(format!(
                "particle[{k}] `{}` is fixed, so its velocity {:?} is ignored",
                q.name, q.velocity
            ));
        }
    }
    // The fastest spring mode is bounded (Gershgorin) by the largest
    // ω² ≤ 2 Σ k / m over the springs meeting at one particle; a nail
    // takes none. Name that particle's stiffest spring.
    let n = world.len();
    let mut load = vec![0.0f64; n];
    let mut stiffest: Vec<Option<(f64, usize)>> = vec![None; n];
    for (k, sp) in world.forces().springs.iter().enumerate() {
        let (a, b) = sp.ends();
        for i in [a.index(), b.index()] {
            load[i] += sp.stiffness;
            if stiffest[i].map_or(true, |(kk, _)| sp.stiffness > kk) {
                stiffest[i] = Some((sp.stiffness, k));
            }
        }
    }
    let worst = (0..n)
        .map(|i| (2.0 * load[i] * p.inv_mass[i], i))
        .max_by(|x, y| x.0.total_cmp(&y.0));
    if let Some((w2, i)) = worst.filter(|w| w.0 > 0.0) {
        let omega = w2.sqrt();
        let kind = world.integrator();
        let limit = stable_omega_h(kind) / omega;
        if let (true, Some((_, k))) = (dt > limit, stiffest[i]) {
            let (a, b) = world.forces().springs.iter().nth(k).map_or((0, 0), |sp| {
                let (a, b) = sp.ends();
                (a.index(), b.index())
            });
            out.push(format!(
                "dt = {dt} s is {:.1} times the step at which {kind} can stay stable with the springs at particle `{}` (ω up to {omega:.1} rad/s; stable below {limit:.3e} s; the stiffest is `{}`–`{}`): expect a blow-up",
                dt / limit,
                names[i],
                names[a],
                names[b]
            ));
        }
    }
    out
}
