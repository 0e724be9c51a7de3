//! `[[actuator]]`, `[[sensor]]` and `[[controller]]` entries → the scene's
//! [`NervousSystem`]: every name resolved, errors naming the entry and
//! field. Each kind checks its own keys where it lives
//! (`animats_creatures::brains`, `sensors::probe`, `actuators`).

use crate::build::{at, check_name, At, Names};
use crate::def::*;
use crate::error::SceneError;
use crate::source::Source;
use animats_creatures::actuator::{Actuated, Actuator};
use animats_creatures::actuators::{
    AnyActuator, ForceScale, JointRestAngle, JointTorque, SpringRestLength,
};
use animats_creatures::nervous_system::{Gate, Inputs, NervousSystem, Wired};
use animats_creatures::sensors::ScaledSensor;
use animats_engine::{
    AngleJointId, ConstantForceId, DVec3, ModelError, SpringId, TorqueJointId, World,
};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Named springs, joints and forces, for actuators to refer to.
#[derive(Default)]
pub(crate) struct Handles {
    pub springs: HashMap<String, SpringId>,
    pub angle_joints: HashMap<String, AngleJointId>,
    pub torque_joints: HashMap<String, TorqueJointId>,
    pub constant_forces: HashMap<String, (ConstantForceId, DVec3)>,
}

/// Records an entry's optional name, refusing duplicates within its kind.
pub(crate) fn insert<T>(
    map: &mut HashMap<String, T>,
    at: &At,
    kind: &str,
    name: &Option<String>,
    value: T,
) -> Result<(), SceneError> {
    let Some(name) = name else { return Ok(()) };
    check_name(at, name)?;
    if map.contains_key(name) {
        return Err(at.err("name", format!("duplicate {kind} name `{name}`")));
    }
    map.insert(name.clone(), value);
    Ok(())
}

fn lookup<T: Copy>(
    map: &HashMap<String, T>,
    at: &At,
    field: &str,
    kind: &str,
    name: &str,
) -> Result<T, SceneError> {
    map.get(name).copied().ok_or_else(|| {
        at.err(
            field,
            format!("no {kind} named `{name}` (give the {kind} entry `name = \"{name}\"`)"),
        )
    })
}

/// Builds every actuator, sensor and controller of the scene into `ns`,
/// which holds what creatures brought; `origins` says, for each controller,
/// the table it was written in, and gains the scene's own. Returns the
/// warnings: actuators whose range misses their target's built value.
pub(crate) fn build(
    def: &SceneDef,
    src: &Source,
    names: &Names,
    handles: &Handles,
    world: &mut World,
    ns: &mut NervousSystem,
    origins: &mut Vec<(&'static str, usize)>,
) -> Result<Vec<String>, SceneError> {
    let mut warnings = Vec::new();
    let gated = actuators(def, src, handles, world, ns, &mut warnings)?;
    for (k, entry) in def.sensor.iter().enumerate() {
        let at = at(src, format!("sensor[{k}]"), entry);
        let e = entry.get_ref().get().map_err(|(f, m)| at.err(f, m))?;
        let s = sensor(&at, e, names)?;
        if ns.sensor(e.name()).is_some() {
            return Err(at.err("name", format!("duplicate sensor name `{}`", e.name())));
        }
        ns.sensors.push((e.name().to_string(), Box::new(s)));
    }
    // Gates name sensors: resolved once the sensors are known.
    for (index, at, g) in gated {
        let sensor = ns
            .sensor(&g.sensor)
            .ok_or_else(|| at.err("gate.sensor", format!("no sensor named `{}`", g.sensor)))?;
        let (threshold, above) = match (g.above, g.at_most) {
            (Some(x), None) => (at.finite("gate.above", x)?, true),
            (None, Some(x)) => (at.finite("gate.at_most", x)?, false),
            _ => return Err(at.err("gate", "give exactly one of `above` and `at_most`")),
        };
        ns.gates[index] = Some(Gate {
            sensor,
            threshold,
            above,
        });
    }
    controllers(def, src, ns, origins)?;
    Ok(warnings)
}

/// The scene's `[[actuator]]` entries, into `ns`; returns those with a
/// gate (its index, where it was written, the gate), to resolve once the
/// sensors are known.
fn actuators<'d, 's>(
    def: &'d SceneDef,
    src: &'s Source<'s>,
    handles: &Handles,
    world: &mut World,
    ns: &mut NervousSystem,
    warnings: &mut Vec<String>,
) -> Result<Vec<(usize, At<'s>, &'d GateEntry)>, SceneError> {
    let mut gated = Vec::new();
    for (k, entry) in def.actuator.iter().enumerate() {
        let at = at(src, format!("actuator[{k}]"), entry);
        let e = entry.get_ref().get().map_err(|(f, m)| at.err(f, m))?;
        let a = actuator(&at, e, handles, world, warnings)?;
        if ns.actuator(&e.name).is_some() {
            return Err(at.err("name", format!("duplicate actuator name `{}`", e.name)));
        }
        let rate = match e.rate {
            Some(r) => Some(at.positive("rate", r)?),
            None => None,
        };
        if e.gate.is_some() && !a.can_gate() {
            return Err(at.err(
                "gate",
                "only a torque joint's torque or a constant force can be gated (a rest length or angle has no \"off\")",
            ));
        }
        let index = ns.add_actuator(e.name.clone(), a, rate, None);
        if let Some(g) = &e.gate {
            gated.push((index, at, g));
        }
    }
    Ok(gated)
}

/// The scene's `[[controller]]` entries, wired into `ns`.
fn controllers(
    def: &SceneDef,
    src: &Source,
    ns: &mut NervousSystem,
    origins: &mut Vec<(&'static str, usize)>,
) -> Result<(), SceneError> {
    let mut driven_by: Vec<Option<String>> = vec![None; ns.actuators.len()];
    for c in &ns.controllers {
        for &o in &c.outputs {
            driven_by[o] = Some(c.name.clone());
        }
    }
    for (k, entry) in def.controller.iter().enumerate() {
        let at = at(src, format!("controller[{k}]"), entry);
        let c = entry.get_ref().get().map_err(|(f, m)| at.err(f, m))?;
        check_name(&at, c.name())?;
        if ns.controller(c.name()).is_some() {
            return Err(at.err("name", format!("duplicate controller name `{}`", c.name())));
        }
        let inputs = c
            .inputs()
            .iter()
            .map(|n| {
                ns.sensor(n)
                    .ok_or_else(|| at.err("inputs", format!("no sensor named `{n}`")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        if c.outputs().is_empty() {
            return Err(at.err("outputs", "a controller must drive at least one actuator"));
        }
        let mut outputs = Vec::with_capacity(c.outputs().len());
        for n in c.outputs() {
            let i = ns
                .actuator(n)
                .ok_or_else(|| at.err("outputs", format!("no actuator named `{n}`")))?;
            if let Some(other) = &driven_by[i] {
                return Err(at.err(
                    "outputs",
                    format!("actuator `{n}` is already driven by controller `{other}`: an actuator takes one controller"),
                ));
            }
            driven_by[i] = Some(c.name().to_string());
            outputs.push(i);
        }
        let levels: Vec<f64> = outputs.iter().map(|&i| ns.actuators[i].1.level()).collect();
        let brain = c.build(levels).map_err(|e| at.model(e))?;
        ns.controllers.push(Wired::new(
            c.name().to_string(),
            brain,
            Inputs::Sensors(inputs),
            outputs,
        ));
        origins.push(("controller", k));
    }
    Ok(())
}

/// An actuator's starting level: the one written, else the one that gives
/// the target's value as built (`built`) — exactly 0.5 when the middle of
/// the range is that value to 0.1 % of the range (a range written with
/// rounded numbers around the built length: the level would differ from
/// 0.5 by less than 0.001) — else, when `built` lies
/// outside [min, max], 0.5 and a warning: the parameter jumps at t = 0.
fn default_level(
    a: &ActuatorEntry,
    min: f64,
    max: f64,
    built: f64,
    warnings: &mut Vec<String>,
) -> f64 {
    if let Some(level) = a.level {
        return level;
    }
    let span = max - min;
    let middle = min + 0.5 * span;
    if (middle - built).abs() <= 1e-3 * span.abs() {
        return 0.5;
    }
    let (lo, hi) = (min.min(max), min.max(max));
    if (lo..=hi).contains(&built) && span != 0.0 {
        return (built - min) / span;
    }
    warnings.push(format!(
        "actuator `{}`: its target is built at {built} but its range is [{min}, {max}]; with no `level` it starts at 0.5 ({middle}), a jump at t = 0 — give `level`, or a range that holds {built}",
        a.name
    ));
    0.5
}

fn actuator(
    at: &At,
    a: &ActuatorEntry,
    h: &Handles,
    world: &mut World,
    warnings: &mut Vec<String>,
) -> Result<AnyActuator, SceneError> {
    check_name(at, &a.name)?;
    let (min, max) = (at.finite("min", a.min)?, at.finite("max", a.max)?);
    if let Some(level) = a.level {
        let level = at.finite("level", level)?;
        if !(0.0..=1.0).contains(&level) {
            return Err(at.err("level", format!("must be in [0, 1], got {level}")));
        }
    }
    let mut level = |built: f64| default_level(a, min, max, built, warnings);
    Ok(match &a.target {
        Target::Spring(n) => {
            let id = lookup(&h.springs, at, "spring", "spring", n)?;
            if min <= 0.0 || max <= 0.0 {
                return Err(at.err(
                    if min <= 0.0 { "min" } else { "max" },
                    "a spring's rest length must stay > 0: give min and max > 0",
                ));
            }
            let target = SpringRestLength(id);
            let level = level(target.get(world));
            AnyActuator::Spring(Actuator::with_level(target, min, max, level, world))
        }
        Target::AngleJoint(n) => {
            let id = lookup(&h.angle_joints, at, "angle_joint", "angle joint", n)?;
            for (field, v) in [("min", min), ("max", max)] {
                if !(0.0..=PI).contains(&v) {
                    return Err(at.err(field, format!("a rest angle must be in [0, π], got {v}")));
                }
            }
            let target = JointRestAngle(id);
            let level = level(target.get(world));
            AnyActuator::AngleJoint(Actuator::with_level(target, min, max, level, world))
        }
        Target::TorqueJoint(n) => {
            let id = lookup(&h.torque_joints, at, "torque_joint", "torque joint", n)?;
            let target = JointTorque(id);
            let level = level(target.get(world));
            AnyActuator::TorqueJoint(Actuator::with_level(target, min, max, level, world))
        }
        Target::ConstantForce(n) => {
            let (force, base) = lookup(
                &h.constant_forces,
                at,
                "constant_force",
                "constant force",
                n,
            )?;
            let target = ForceScale { force, base };
            let level = level(target.get(world));
            AnyActuator::ConstantForce(Actuator::with_level(target, min, max, level, world))
        }
    })
}

fn sensor(at: &At, s: &SensorEntry, names: &Names) -> Result<ScaledSensor, SceneError> {
    check_name(at, s.name())?;
    s.build(|field, name| {
        names
            .one(at, field, name)
            .map_err(|e| ModelError::new(field, e.message))
    })
    .map_err(|e| at.model(e))
}
