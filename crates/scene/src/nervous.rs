//! `[[actuator]]`, `[[sensor]]` and `[[controller]]` entries → the scene's
//! [`NervousSystem`]: every name resolved, every key checked against its
//! kind, errors naming the entry and field.

use crate::build::{at, check_name, At, Names};
use crate::def::*;
use crate::error::SceneError;
use crate::source::Source;
use animats_creatures::actuator::Actuator;
use animats_creatures::actuators::{
    AnyActuator, ForceScale, JointRestAngle, JointTorque, SpringRestLength,
};
use animats_creatures::brain::Brain;
use animats_creatures::brains::{Condition, Fsm, FsmState, Neural, Oscillator, Transition};
use animats_creatures::nervous_system::{Gate, Inputs, NervousSystem, Wired};
use animats_creatures::sensors::{Probe, ScaledSensor};
use animats_engine::{AngleJointId, ConstantForceId, DVec3, SpringId, TorqueJointId, World};
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
/// the table it was written in, and gains the scene's own.
pub(crate) fn build(
    def: &SceneDef,
    src: &Source,
    names: &Names,
    handles: &Handles,
    world: &mut World,
    ns: &mut NervousSystem,
    origins: &mut Vec<(&'static str, usize)>,
) -> Result<(), SceneError> {
    let mut gated = Vec::new();
    for (k, entry) in def.actuator.iter().enumerate() {
        let at = at(src, format!("actuator[{k}]"), entry);
        let e = entry.get_ref();
        let a = actuator(&at, e, handles, world)?;
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
    for (k, entry) in def.sensor.iter().enumerate() {
        let at = at(src, format!("sensor[{k}]"), entry);
        let s = sensor(&at, entry.get_ref(), names)?;
        if ns.sensor(&entry.get_ref().name).is_some() {
            return Err(at.err(
                "name",
                format!("duplicate sensor name `{}`", entry.get_ref().name),
            ));
        }
        ns.sensors.push((entry.get_ref().name.clone(), Box::new(s)));
    }
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
    let mut driven_by: Vec<Option<String>> = vec![None; ns.actuators.len()];
    for c in &ns.controllers {
        for &o in &c.outputs {
            driven_by[o] = Some(c.name.clone());
        }
    }
    for (k, entry) in def.controller.iter().enumerate() {
        let c = entry.get_ref();
        let at = at(src, format!("controller[{k}]"), entry);
        check_name(&at, &c.name)?;
        if ns.controller(&c.name).is_some() {
            return Err(at.err("name", format!("duplicate controller name `{}`", c.name)));
        }
        let inputs = c
            .inputs
            .iter()
            .map(|n| {
                ns.sensor(n)
                    .ok_or_else(|| at.err("inputs", format!("no sensor named `{n}`")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        if c.outputs.is_empty() {
            return Err(at.err("outputs", "a controller must drive at least one actuator"));
        }
        let mut outputs = Vec::with_capacity(c.outputs.len());
        for n in &c.outputs {
            let i = ns
                .actuator(n)
                .ok_or_else(|| at.err("outputs", format!("no actuator named `{n}`")))?;
            if let Some(other) = &driven_by[i] {
                return Err(at.err(
                    "outputs",
                    format!("actuator `{n}` is already driven by controller `{other}`: an actuator takes one controller"),
                ));
            }
            driven_by[i] = Some(c.name.clone());
            outputs.push(i);
        }
        let levels: Vec<f64> = outputs.iter().map(|&i| ns.actuators[i].1.level()).collect();
        let brain = brain(&at, c, levels)?;
        ns.controllers.push(Wired::new(
            c.name.clone(),
            brain,
            Inputs::Sensors(inputs),
            outputs,
        ));
        origins.push(("controller", k));
    }
    Ok(())
}

fn actuator(
    at: &At,
    a: &ActuatorEntry,
    h: &Handles,
    world: &mut World,
) -> Result<AnyActuator, SceneError> {
    check_name(at, &a.name)?;
    let (min, max) = (at.finite("min", a.min)?, at.finite("max", a.max)?);
    let level = at.finite("level", a.level)?;
    if !(0.0..=1.0).contains(&level) {
        return Err(at.err("level", format!("must be in [0, 1], got {level}")));
    }
    let targets = [
        a.spring.is_some(),
        a.angle_joint.is_some(),
        a.torque_joint.is_some(),
        a.constant_force.is_some(),
    ];
    if targets.iter().filter(|t| **t).count() != 1 {
        return Err(at.err(
            "",
            "give exactly one target: `spring`, `angle_joint`, `torque_joint` or `constant_force`",
        ));
    }
    Ok(if let Some(n) = &a.spring {
        let id = lookup(&h.springs, at, "spring", "spring", n)?;
        if min <= 0.0 || max <= 0.0 {
            return Err(at.err(
                if min <= 0.0 { "min" } else { "max" },
                "a spring's rest length must stay > 0: give min and max > 0",
            ));
        }
        AnyActuator::Spring(Actuator::with_level(
            SpringRestLength(id),
            min,
            max,
            level,
            world,
        ))
    } else if let Some(n) = &a.angle_joint {
        let id = lookup(&h.angle_joints, at, "angle_joint", "angle joint", n)?;
        for (field, v) in [("min", min), ("max", max)] {
            if !(0.0..=PI).contains(&v) {
                return Err(at.err(field, format!("a rest angle must be in [0, π], got {v}")));
            }
        }
        AnyActuator::AngleJoint(Actuator::with_level(
            JointRestAngle(id),
            min,
            max,
            level,
            world,
        ))
    } else if let Some(n) = &a.torque_joint {
        let id = lookup(&h.torque_joints, at, "torque_joint", "torque joint", n)?;
        AnyActuator::TorqueJoint(Actuator::with_level(
            JointTorque(id),
            min,
            max,
            level,
            world,
        ))
    } else {
        let n = a.constant_force.as_deref().unwrap_or_default();
        let (force, base) = lookup(
            &h.constant_forces,
            at,
            "constant_force",
            "constant force",
            n,
        )?;
        AnyActuator::ConstantForce(Actuator::with_level(
            ForceScale { force, base },
            min,
            max,
            level,
            world,
        ))
    })
}

fn sensor(at: &At, s: &SensorEntry, names: &Names) -> Result<ScaledSensor, SceneError> {
    check_name(at, &s.name)?;
    let need = |field: &str, v: &Option<String>| {
        v.as_deref()
            .ok_or_else(|| at.err(field, format!("a `{}` sensor needs `{field}`", s.kind)))
            .and_then(|n| names.one(at, field, n))
    };
    // Keys that do not apply to the kind are refused, not ignored.
    let given = [
        ("particle", s.particle.is_some()),
        ("axis", s.axis.is_some()),
        ("a", s.a.is_some()),
        ("b", s.b.is_some()),
        ("joint", s.joint.is_some()),
    ];
    let (probe, allowed, max): (Probe, &[&str], f64) = match s.kind.as_str() {
        "height" => (
            Probe::Height(need("particle", &s.particle)?),
            &["particle"],
            1.0,
        ),
        "touch" => (
            Probe::Touch(need("particle", &s.particle)?),
            &["particle"],
            1.0,
        ),
        "speed" => {
            let axis = at.vec3("axis", s.axis.unwrap_or([1.0, 0.0, 0.0]))?;
            if axis.length() == 0.0 {
                return Err(at.err("axis", "must not be zero"));
            }
            (
                Probe::Speed(need("particle", &s.particle)?, axis.normalize()),
                &["particle", "axis"],
                1.0,
            )
        }
        "length" => (
            Probe::Length(need("a", &s.a)?, need("b", &s.b)?),
            &["a", "b"],
            1.0,
        ),
        "angle" => (
            Probe::Angle {
                a: need("a", &s.a)?,
                joint: need("joint", &s.joint)?,
                b: need("b", &s.b)?,
            },
            &["a", "joint", "b"],
            PI,
        ),
        "tilt" => (
            Probe::Tilt(need("a", &s.a)?, need("b", &s.b)?),
            &["a", "b"],
            PI,
        ),
        other => {
            return Err(at.err(
                "kind",
                format!(
                "unknown sensor kind `{other}`: use height, speed, touch, length, angle or tilt"
            ),
            ))
        }
    };
    for (key, present) in given {
        if present && !allowed.contains(&key) {
            return Err(at.err(key, format!("a `{}` sensor has no `{key}`", s.kind)));
        }
    }
    let min = at.finite("min", s.min.unwrap_or(0.0))?;
    let max = at.finite("max", s.max.unwrap_or(max))?;
    if min == max {
        return Err(at.err("max", format!("must differ from min ({min})")));
    }
    Ok(ScaledSensor { probe, min, max })
}

/// Refuses the keys of other controller kinds.
fn only(at: &At, c: &ControllerEntry, allowed: &[&str]) -> Result<(), SceneError> {
    let given = [
        ("frequency", c.frequency.is_some()),
        ("amplitude", c.amplitude.is_some()),
        ("phase", c.phase.is_some()),
        ("offset", c.offset.is_some()),
        ("hidden", c.hidden.is_some()),
        ("clock", c.clock.is_some()),
        ("weights", c.weights.is_some()),
        ("seed", c.seed.is_some()),
        ("initial", c.initial.is_some()),
        ("state", c.state.is_some()),
        ("inputs", !c.inputs.is_empty()),
    ];
    for (key, present) in given {
        if present && !allowed.contains(&key) {
            return Err(at.err(key, format!("an `{}` controller has no `{key}`", c.kind)));
        }
    }
    Ok(())
}

fn per_output(
    at: &At,
    field: &str,
    v: &Option<Vec<f64>>,
    n: usize,
    default: f64,
) -> Result<Vec<f64>, SceneError> {
    match v {
        None => Ok(vec![default; n]),
        Some(v) if v.len() != n => Err(at.err(
            field,
            format!("needs one number per output ({n}), got {}", v.len()),
        )),
        Some(v) => {
            for x in v {
                at.finite(field, *x)?;
            }
            Ok(v.clone())
        }
    }
}

/// The brain a controller entry describes; `levels` are its outputs'
/// initial levels.
pub(crate) fn brain(
    at: &At,
    c: &ControllerEntry,
    levels: Vec<f64>,
) -> Result<Box<dyn Brain>, SceneError> {
    let n = c.outputs.len();
    match c.kind.as_str() {
        "oscillator" => {
            only(at, c, &["frequency", "amplitude", "phase", "offset"])?;
            let frequency = at.finite("frequency", c.frequency.unwrap_or(1.0))?;
            if frequency < 0.0 {
                return Err(at.err("frequency", format!("must be >= 0, got {frequency}")));
            }
            Ok(Box::new(Oscillator {
                frequency,
                amplitude: per_output(at, "amplitude", &c.amplitude, n, 0.25)?,
                phase: per_output(at, "phase", &c.phase, n, 0.0)?,
                offset: per_output(at, "offset", &c.offset, n, 0.5)?,
            }))
        }
        "neural" => {
            only(at, c, &["inputs", "hidden", "clock", "weights", "seed"])?;
            let hidden = c.hidden.clone().unwrap_or_default();
            if hidden.iter().any(|h| *h == 0 || *h > 4096) || hidden.len() > 16 {
                return Err(at.err("hidden", "up to 16 layers of 1 to 4096 neurons each"));
            }
            let clock = match c.clock {
                Some(f) => Some(at.positive("clock", f)?),
                None => None,
            };
            if c.inputs.is_empty() && clock.is_none() {
                return Err(at.err(
                    "inputs",
                    "a neural controller needs inputs, a clock, or both",
                ));
            }
            // Counted before anything is allocated.
            let mut sizes = vec![c.inputs.len() + if clock.is_some() { 2 } else { 0 }];
            sizes.extend(&hidden);
            sizes.push(n);
            let count = Neural::weight_count(&sizes);
            if count > 1_000_000 {
                return Err(at.err(
                    "hidden",
                    format!("{count} weights and biases: more than the limit of 1,000,000"),
                ));
            }
            let mut net = Neural::new(c.inputs.len(), &hidden, n, clock);
            match &c.weights {
                Some(w) => {
                    net.set_genome(w).map_err(|_| {
                        at.err(
                            "weights",
                            format!(
                                "needs {} finite numbers (layers {:?}: every weight, then the biases, layer by layer), got {}",
                                net.weights.len(),
                                net.sizes,
                                w.len()
                            ),
                        )
                    })?;
                }
                None => net.randomise(c.seed.unwrap_or(1)),
            }
            Ok(Box::new(net))
        }
        "fsm" => {
            only(at, c, &["inputs", "initial", "state"])?;
            let states =
                c.state.as_ref().filter(|s| !s.is_empty()).ok_or_else(|| {
                    at.err("state", "an FSM needs at least one [[controller.state]]")
                })?;
            let index = |field: &str, name: &str| {
                states
                    .iter()
                    .position(|s| s.name == name)
                    .ok_or_else(|| at.err(field, format!("no state named `{name}`")))
            };
            let mut built = Vec::with_capacity(states.len());
            for (i, s) in states.iter().enumerate() {
                let f = |k: &str| format!("state[{i}].{k}");
                if states[..i].iter().any(|o| o.name == s.name) {
                    return Err(at.err(&f("name"), format!("duplicate state name `{}`", s.name)));
                }
                if s.levels.len() != n {
                    return Err(at.err(
                        &f("levels"),
                        format!("needs one level per output ({n}), got {}", s.levels.len()),
                    ));
                }
                for l in &s.levels {
                    if !(0.0..=1.0).contains(l) {
                        return Err(at.err(&f("levels"), format!("levels are in [0, 1], got {l}")));
                    }
                }
                let rate = match s.rate {
                    Some(r) => Some(at.positive(&f("rate"), r)?),
                    None => None,
                };
                let mut transitions = Vec::with_capacity(s.transition.len());
                for (j, t) in s.transition.iter().enumerate() {
                    let g = |k: &str| format!("state[{i}].transition[{j}].{k}");
                    let to = index(&g("to"), &t.to)?;
                    let input = match &t.sensor {
                        Some(name) => {
                            Some(c.inputs.iter().position(|x| x == name).ok_or_else(|| {
                                at.err(
                                    &g("sensor"),
                                    format!("`{name}` is not one of this controller's inputs"),
                                )
                            })?)
                        }
                        None => None,
                    };
                    let condition = match (input, t.above, t.below) {
                        (Some(input), Some(th), None) => Condition::Above {
                            input,
                            threshold: at.finite(&g("above"), th)?,
                        },
                        (Some(input), None, Some(th)) => Condition::Below {
                            input,
                            threshold: at.finite(&g("below"), th)?,
                        },
                        (Some(_), _, _) => {
                            return Err(at.err(
                                &g("sensor"),
                                "give exactly one of `above` and `below` with a sensor",
                            ))
                        }
                        (None, None, None) => Condition::None,
                        (None, _, _) => {
                            return Err(at.err(&g("sensor"), "`above` and `below` need a `sensor`"))
                        }
                    };
                    let after = match t.after {
                        Some(a) => {
                            let a = at.finite(&g("after"), a)?;
                            if a < 0.0 {
                                return Err(at.err(&g("after"), format!("must be >= 0, got {a}")));
                            }
                            Some(a)
                        }
                        None => None,
                    };
                    if condition == Condition::None && after.is_none() {
                        return Err(at.err(
                            &g("after"),
                            "a transition needs a sensor condition, `after`, or both",
                        ));
                    }
                    transitions.push(Transition {
                        to,
                        condition,
                        after,
                    });
                }
                built.push(FsmState {
                    name: s.name.clone(),
                    levels: s.levels.clone(),
                    rate,
                    transitions,
                });
            }
            let initial = match &c.initial {
                Some(name) => index("initial", name)?,
                None => 0,
            };
            Ok(Box::new(Fsm::new(built, initial, levels)))
        }
        other => Err(at.err(
            "kind",
            format!("unknown controller kind `{other}`: use oscillator, neural or fsm"),
        )),
    }
}
