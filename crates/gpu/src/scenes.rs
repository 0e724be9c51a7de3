//! Scenes evaluated whole by the C (`kernel/eval.h`): a batch of scenes
//! ([`Batch::pack_scenes`]) holds, beside each world, its sensors, spring
//! muscles, brains and `[evolve]` rules, and [`Batch::evaluate_cpu`] (or
//! [`crate::Device::evaluate`]) runs each scene's evaluation as
//! `animats_scene::evaluate::evaluate` does, returning the same
//! [`Evaluation`] to the bit.
//!
//! Covered: `[[sensor]]`s (height, speed, touch, length, angle, tilt) and
//! the roobot's own (foot clearance, time till touchdown, leg angle, hip
//! speed), actuators (a spring's rest length, an angle joint's rest angle, a
//! torque joint's torque, a constant force's scale; with or without a
//! `rate`, gated or not) and the positive work they do, oscillator (sine or skewed), neural,
//! CTRNN and FSM brains, the roobot's hopping FSM and Raibert's
//! controller, the thesis's
//! jellyfish (its pulses and steering under its own FSM, after the scene's
//! controllers), the centre of the particles that count,
//! `fail_on_touch` and `fail_on_stretch`, the divergence guard of a driven
//! scene, the `[archive]` measures and `[evolve] terms`, and every term of
//! the fitness (time, distance, energy, target, measures). Anything else a
//! scene holds is refused when it is packed, with a message naming the
//! scene and the entry.

use crate::pack::{Batch, Shared, CHUNK};
use crate::Mode;
use animats_creatures::actuators::AnyActuator;
use animats_creatures::brains::ctrnn::Ctrnn;
use animats_creatures::brains::fsm::{Condition, Fsm};
use animats_creatures::brains::neural::Neural;
use animats_creatures::jellyfish::{Behaviour, Jellyfish};
use animats_creatures::nervous_system::{Inputs, NervousSystem, Wired};
use animats_creatures::roobot::raibert::RaibertSenses;
use animats_creatures::roobot::{FsmSenses, HopFsm, HopState, Raibert};
use animats_creatures::sensor::Sensor;
use animats_creatures::sensors::probe::{Probe, ScaledSensor};
use animats_creatures::sensors::{HeightSensor, SpeedSensor, TiltSensor, TouchdownSensor};
use animats_engine::{DVec3, ParticleId, World};
use animats_scene::archive::{Measure, Recorder};
use animats_scene::evaluate::{Batches, Ended, Evaluation};
use animats_scene::Scene;
use std::os::raw::c_longlong;

extern "C" {
    fn animats_evaluate_range(
        batch: *const crate::pack::Raw,
        first: c_longlong,
        last: c_longlong,
        local: std::os::raw::c_int,
    );
    fn animats_evaluate_range_fast(
        batch: *const crate::pack::Raw,
        first: c_longlong,
        last: c_longlong,
        local: std::os::raw::c_int,
    );
}

/// Whether this CPU can run the fast mode's C (`kernel/fast.c`, compiled
/// with FMA instructions on x86-64).
pub fn cpu_has_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        true
    }
}

/// Numbers of `eval_param` per creature (`kernel/step.h` says which).
const PARAMS: usize = 16;

/// Numbers of `result` per creature: fitness, distance, time, the
/// muscles' positive work, the distance from the target.
const RESULTS: usize = 5;

/// The arrays of a scene's evaluation (the tail of the C's `an_batch`).
#[derive(Clone, Debug, Default)]
pub(crate) struct Rules {
    pub(crate) first_muscle: Vec<i64>,
    pub(crate) muscle_spring: Vec<i32>,
    pub(crate) muscle_param: Vec<f64>,
    pub(crate) muscle_level: Vec<f64>,
    pub(crate) first_osc: Vec<i64>,
    pub(crate) osc_frequency: Vec<f64>,
    pub(crate) first_output: Vec<i64>,
    pub(crate) output_muscle: Vec<i32>,
    pub(crate) output_gene: Vec<f64>,
    pub(crate) first_centre: Vec<i64>,
    pub(crate) centre_particle: Vec<i32>,
    pub(crate) first_touch: Vec<i64>,
    pub(crate) touch_particle: Vec<i32>,
    pub(crate) first_stretch: Vec<i64>,
    pub(crate) stretch_pair: Vec<i32>,
    pub(crate) stretch_length: Vec<f64>,
    pub(crate) fixed: Vec<i32>,
    pub(crate) eval_param: Vec<f64>,
    pub(crate) eval_count: Vec<i64>,
    pub(crate) result: Vec<f64>,
    pub(crate) ended: Vec<i64>,
    pub(crate) first_measure: Vec<i64>,
    pub(crate) measure_kind: Vec<i32>,
    pub(crate) measure_first_id: Vec<i64>,
    pub(crate) measure_id: Vec<i32>,
    pub(crate) measure_axis: Vec<f64>,
    pub(crate) measure_fixed: Vec<f64>,
    pub(crate) measure_weight: Vec<f64>,
    pub(crate) measure_sum: Vec<f64>,
    pub(crate) measure_start: Vec<f64>,
    pub(crate) first_sensor: Vec<i64>,
    pub(crate) sensor_kind: Vec<i32>,
    pub(crate) sensor_particle: Vec<i32>,
    pub(crate) sensor_param: Vec<f64>,
    pub(crate) sensor_level: Vec<f64>,
    pub(crate) first_ctrl: Vec<i64>,
    pub(crate) ctrl_kind: Vec<i32>,
    pub(crate) ctrl_index: Vec<i32>,
    pub(crate) net_first_layer: Vec<i64>,
    pub(crate) layer_size: Vec<i32>,
    pub(crate) net_first_weight: Vec<i64>,
    pub(crate) net_weight: Vec<f64>,
    pub(crate) net_clock: Vec<f64>,
    pub(crate) net_first_input: Vec<i64>,
    pub(crate) net_input: Vec<i32>,
    pub(crate) net_first_output: Vec<i64>,
    pub(crate) net_output_muscle: Vec<i32>,
    pub(crate) net_output_shift: Vec<f64>,
    pub(crate) net_first_scratch: Vec<i64>,
    pub(crate) net_scratch: Vec<f64>,
    pub(crate) net_first_neuron: Vec<i64>,
    pub(crate) neuron_param: Vec<f64>,
    pub(crate) neuron_state: Vec<f64>,
    pub(crate) muscle_work: Vec<f64>,
    pub(crate) muscle_kind: Vec<i32>,
    pub(crate) muscle_base: Vec<f64>,
    pub(crate) muscle_push: Vec<i32>,
    pub(crate) muscle_gate: Vec<f64>,
    /// Per creature: its `fail_on_touch` particles' names and its
    /// `fail_on_stretch` rules' names, for [`Ended`].
    names: Vec<(Vec<String>, Vec<String>)>,
    /// Packed from scenes, not yet evaluated.
    ready: bool,
}

impl Rules {
    /// Well-formed empty rules for `creatures` worlds (a batch of worlds,
    /// which is stepped, not evaluated); keeps `fixed`.
    pub(crate) fn no_rules(&mut self, creatures: usize) {
        let fixed = std::mem::take(&mut self.fixed);
        *self = Rules {
            fixed,
            ..Rules::default()
        };
        for offsets in [
            &mut self.first_muscle,
            &mut self.first_osc,
            &mut self.first_centre,
            &mut self.first_touch,
            &mut self.first_stretch,
            &mut self.first_measure,
            &mut self.first_sensor,
            &mut self.first_ctrl,
        ] {
            *offsets = vec![0; creatures + 1];
        }
        self.first_output = vec![0];
        self.measure_first_id = vec![0];
        for offsets in self.net_offsets() {
            *offsets = vec![0];
        }
        self.eval_param = vec![0.0; PARAMS * creatures];
        self.eval_count = vec![0; 3 * creatures];
        self.result = vec![0.0; RESULTS * creatures];
        self.ended = vec![0; 2 * creatures];
    }

    /// Room for `n` doubles of a network's scratch, zero.
    fn push_scratch(&mut self, n: usize) {
        self.net_scratch.resize(self.net_scratch.len() + n, 0.0);
        self.net_first_scratch.push(self.net_scratch.len() as i64);
    }

    /// The networks' offset arrays (over the batch: one more than networks).
    fn net_offsets(&mut self) -> [&mut Vec<i64>; 6] {
        [
            &mut self.net_first_neuron,
            &mut self.net_first_layer,
            &mut self.net_first_weight,
            &mut self.net_first_input,
            &mut self.net_first_output,
            &mut self.net_first_scratch,
        ]
    }

    /// Appends `scene`'s muscles, oscillators and rules (its creature's
    /// offsets pushed after them); `Err` names what the C does not cover.
    fn add(&mut self, scene: &Scene) -> Result<(), String> {
        let spec = scene
            .evolve
            .as_ref()
            .ok_or("it has no [evolve] table: nothing to evaluate")?;
        // Of the creatures that act by themselves, the jellyfish.
        let mut jellies = Vec::new();
        for a in scene.actors.iter().filter(|a| a.acts()) {
            let Some(j) = a.as_any().and_then(|x| x.downcast_ref::<Jellyfish>()) else {
                let who = a
                    .status()
                    .map_or("a creature that acts by itself".into(), |s| {
                        format!("the creature `{}`", s.name)
                    });
                return Err(format!(
                    "{who} (a bubble column, a quadruped with its scripted step) is not in the GPU evaluation yet"
                ));
            };
            jellies.push(j);
        }
        let nervous = &scene.nervous;
        let world = &scene.world;
        if nervous.is_empty() && scene.actors.is_empty() && world.is_passive() {
            return Err("the divergence guard's energy check of a scene nothing drives is not in the GPU evaluation yet".into());
        }
        // Each constant force's first push (the pushes are its particles,
        // force by force, as `pack` lays them out).
        let mut first_push = Vec::new();
        let mut pushes = 0usize;
        for cf in world.forces().constant_forces.iter() {
            first_push.push((pushes, cf.particles().len()));
            pushes += cf.particles().len();
        }
        for ((_, a), (gate, rate)) in nervous
            .actuators
            .iter()
            .zip(nervous.gates.iter().zip(&nervous.rates))
        {
            let (kind, index, (min, max), level) = match a {
                AnyActuator::Spring(a) => (0, a.target().0.index(), a.range(), a.level()),
                AnyActuator::AngleJoint(a) => (1, a.target().0.index(), a.range(), a.level()),
                AnyActuator::TorqueJoint(a) => (2, a.target().0.index(), a.range(), a.level()),
                AnyActuator::ConstantForce(a) => {
                    (3, a.target().force.index(), a.range(), a.level())
                }
            };
            let (base, push) = match a {
                AnyActuator::ConstantForce(a) => (a.target().base, first_push[index]),
                _ => (DVec3::ZERO, (0, 0)),
            };
            self.muscle_kind.push(kind);
            self.muscle_spring.push(index as i32);
            self.muscle_param.extend([min, max, rate.unwrap_or(-1.0)]);
            self.muscle_level.push(level);
            self.muscle_base.extend(base.to_array());
            self.muscle_push.extend([push.0 as i32, push.1 as i32]);
            self.muscle_gate.extend(match gate {
                Some(g) => [g.sensor as f64, g.threshold, f64::from(u8::from(g.above))],
                None => [-1.0, 0.0, 0.0],
            });
        }
        for (name, sensor) in &nervous.sensors {
            self.add_sensor(name, sensor.as_ref())?;
        }
        for c in &nervous.controllers {
            let shift = |o: usize| nervous.offsets.get(o).copied().unwrap_or(f64::NAN);
            if self.add_hop(c, nervous, &shift)? || self.add_raibert(c, nervous, &shift)? {
                continue;
            }
            if self.add_network(c, &shift)? {
                continue;
            }
            let kind = c.brain.kind();
            let g = c.brain.genome();
            let n = c.outputs.len();
            if kind != "oscillator" {
                return Err(format!(
                    "the controller `{}` ({kind}) is not in the GPU evaluation yet: only oscillators, neural networks, CTRNNs, FSMs and the roobot's hopping FSM are",
                    c.name
                ));
            }
            self.ctrl_kind.push(0);
            self.ctrl_index.push(self.osc_frequency.len() as i32);
            self.osc_frequency.push(g[0]);
            // A sine's genome is `[f, amplitude.., phase.., offset..]`; a
            // skewed wave's appends its duties (brains/oscillator.rs).
            let skewed = g.len() == 1 + 4 * n;
            for (j, &o) in c.outputs.iter().enumerate() {
                self.output_muscle.push(o as i32);
                let duty = if skewed { g[1 + 3 * n + j] } else { f64::NAN };
                self.output_gene
                    .extend([g[1 + j], g[1 + n + j], g[1 + 2 * n + j], shift(o), duty]);
            }
            self.first_output.push(self.output_muscle.len() as i64);
        }
        // The jellyfish act after the controllers (`Scene::step`).
        for j in jellies {
            self.add_jellyfish(j, &first_push)?;
        }
        self.centre_particle
            .extend(spec.particles.iter().map(|p| p.index() as i32));
        let mut touch = Vec::new();
        for (p, name) in &spec.fail_on_touch {
            self.touch_particle.push(p.index() as i32);
            touch.push(name.clone());
        }
        let mut stretch = Vec::new();
        for s in &spec.fail_on_stretch {
            self.stretch_pair
                .extend([s.a.index() as i32, s.b.index() as i32]);
            self.stretch_length.push(s.length);
            stretch.push(s.name.clone());
        }
        self.names.push((touch, stretch));
        let clock = world.snapshot();
        self.eval_param.extend(spec.axis.to_array());
        // The muscles' work is summed where the fitness or a measure
        // needs it (as `evaluate_with` decides).
        let work = spec.needs_work()
            || scene
                .archive
                .as_ref()
                .is_some_and(|a| a.measures.iter().any(|m| m.needs_work()));
        let (target, target_weight) = spec.target.unwrap_or((DVec3::ZERO, 0.0));
        self.eval_param.extend([
            spec.time_weight,
            spec.distance_weight,
            spec.touch_tolerance,
            clock.time,
            clock.time_carry,
            f64::from(u8::from(work)),
            spec.energy_weight,
            f64::from(u8::from(spec.target.is_some())),
            target.x,
            target.y,
            target.z,
            target_weight,
            f64::from(u8::from(nervous.gates.iter().any(Option::is_some))),
        ]);
        // The archive's measures, then the terms of the fitness.
        let archive: &[Measure] = scene.archive.as_ref().map_or(&[], |a| &a.measures);
        let muscles = nervous.actuators.len();
        for m in archive {
            self.add_measure(m, 0.0, spec, world, muscles)?;
        }
        for (w, m) in &spec.terms {
            self.add_measure(m, *w, spec, world, muscles)?;
        }
        let steps = (spec.duration / scene.dt).round() as u64;
        self.eval_count.extend([
            steps.min(i64::MAX as u64) as i64,
            world.stats().steps as i64,
            archive.len() as i64,
        ]);
        self.first_muscle.push(self.muscle_spring.len() as i64);
        self.first_osc.push(self.osc_frequency.len() as i64);
        self.first_centre.push(self.centre_particle.len() as i64);
        self.first_touch.push(self.touch_particle.len() as i64);
        self.first_stretch.push(self.stretch_length.len() as i64);
        self.first_measure.push(self.measure_kind.len() as i64);
        self.first_sensor.push(self.sensor_kind.len() as i64);
        self.first_ctrl.push(self.ctrl_kind.len() as i64);
        Ok(())
    }

    /// Appends controller `c` if it is a network entry (a neural network,
    /// a CTRNN or an FSM: sensors in, levels out, its numbers in
    /// `net_weight`, its working state in `net_scratch`): `Ok(false)` for
    /// another kind.
    fn add_network(&mut self, c: &Wired, shift: &dyn Fn(usize) -> f64) -> Result<bool, String> {
        let any = c.brain.as_any();
        let neural = any.and_then(|a| a.downcast_ref::<Neural>());
        let ctrnn = any.and_then(|a| a.downcast_ref::<Ctrnn>());
        let fsm = any.and_then(|a| a.downcast_ref::<Fsm>());
        if neural.is_none() && ctrnn.is_none() && fsm.is_none() {
            return Ok(false);
        }
        let Inputs::Sensors(inputs) = &c.inputs else {
            return Err(format!(
                "the controller `{}` reads a creature's own senses, not [[sensor]]s: not in the GPU evaluation yet",
                c.name
            ));
        };
        self.ctrl_index.push(self.net_clock.len() as i32);
        if let Some(net) = neural {
            self.ctrl_kind.push(1);
            self.layer_size.extend(net.sizes.iter().map(|&n| n as i32));
            self.net_weight.extend(&net.weights);
            self.net_clock.push(net.clock.unwrap_or(f64::NAN));
            let width = net.sizes.iter().copied().max().unwrap_or(0);
            self.push_scratch(2 * width);
        } else if let Some(ct) = ctrnn {
            // Its layers say neurons, inputs (the clock's two counted) and
            // outputs; its weights are the recurrent, then the input ones.
            let n = ct.neurons();
            let m = inputs.len() + if ct.clock.is_some() { 2 } else { 0 };
            if ct.weights.len() != n * n || ct.input_weights.len() != n * m {
                return Err(format!("the controller `{}`: malformed CTRNN", c.name));
            }
            self.ctrl_kind.push(2);
            self.layer_size
                .extend([n as i32, m as i32, ct.outputs as i32]);
            self.net_weight.extend(&ct.weights);
            self.net_weight.extend(&ct.input_weights);
            self.net_clock.push(ct.clock.unwrap_or(f64::NAN));
            self.push_scratch(m + n);
            for i in 0..n {
                self.neuron_param
                    .extend([ct.tau[i], ct.bias[i], ct.gain[i]]);
            }
            self.neuron_state.extend(&ct.state);
        } else if let Some(fsm) = fsm {
            self.ctrl_kind.push(3);
            // The states as numbers: their count, each one's offset, then
            // each: rate (NaN: none), transitions, levels, and per
            // transition to, condition (0 none, 1 above, 2 below), input,
            // threshold, after (NaN: none).
            let w0 = self.net_weight.len();
            let ns = fsm.states.len();
            self.net_weight.push(ns as f64);
            self.net_weight.resize(w0 + 1 + ns, 0.0);
            for (k, st) in fsm.states.iter().enumerate() {
                self.net_weight[w0 + 1 + k] = (self.net_weight.len() - w0) as f64;
                self.net_weight
                    .extend([st.rate.unwrap_or(f64::NAN), st.transitions.len() as f64]);
                self.net_weight.extend(&st.levels);
                for tr in &st.transitions {
                    let (kind, input, threshold) = match tr.condition {
                        Condition::None => (0.0, 0.0, 0.0),
                        Condition::Above { input, threshold } => (1.0, input as f64, threshold),
                        Condition::Below { input, threshold } => (2.0, input as f64, threshold),
                    };
                    self.net_weight.extend([
                        tr.to as f64,
                        kind,
                        input,
                        threshold,
                        tr.after.unwrap_or(f64::NAN),
                    ]);
                }
            }
            self.net_clock.push(f64::NAN);
            // Scratch: the inputs, then the machine's own state: its
            // levels, its current state, when it was entered, started.
            let (entered, started) = fsm.entered();
            self.net_scratch
                .resize(self.net_scratch.len() + inputs.len(), 0.0);
            self.net_scratch.extend(fsm.levels());
            self.net_scratch.extend([
                fsm.current() as f64,
                entered,
                if started { 1.0 } else { 0.0 },
            ]);
            self.net_first_scratch.push(self.net_scratch.len() as i64);
        }
        self.end_network(inputs.iter().copied(), &c.outputs, shift);
        Ok(true)
    }

    /// Closes the network entry just appended: its layers', weights' and
    /// neurons' ends, its inputs (sensors within the creature) and its
    /// outputs (muscles, each with a trial's level offset).
    fn end_network(
        &mut self,
        inputs: impl Iterator<Item = usize>,
        outputs: &[usize],
        shift: &dyn Fn(usize) -> f64,
    ) {
        self.net_first_layer.push(self.layer_size.len() as i64);
        self.net_first_weight.push(self.net_weight.len() as i64);
        self.net_first_neuron.push(self.neuron_state.len() as i64);
        self.net_input.extend(inputs.map(|i| i as i32));
        self.net_first_input.push(self.net_input.len() as i64);
        for &o in outputs {
            self.net_output_muscle.push(o as i32);
            self.net_output_shift.push(shift(o));
        }
        self.net_first_output
            .push(self.net_output_muscle.len() as i64);
    }

    /// Appends the roobot's hopping FSM `c` (thesis §3.2.1.4, a network
    /// entry of kind 4): its inputs the roobot's four sensors; its numbers
    /// the 14 parameters, the forward direction, the hip (whose velocity
    /// along it the FSM reads) and the leg's, hip's and ankle's initial
    /// levels; its scratch the state. `Ok(false)` if `c` is not one.
    fn add_hop(
        &mut self,
        c: &Wired,
        nervous: &NervousSystem,
        shift: &dyn Fn(usize) -> f64,
    ) -> Result<bool, String> {
        let Some(hop) = c.brain.as_any().and_then(|a| a.downcast_ref::<HopFsm>()) else {
            return Ok(false);
        };
        let senses = match &c.inputs {
            Inputs::Senses(s) => s.as_any().and_then(|a| a.downcast_ref::<FsmSenses>()),
            Inputs::Sensors(_) => None,
        };
        let Some(senses) = senses.filter(|s| {
            c.outputs == [s.actuators, s.actuators + 1, s.actuators + 2]
                && s.sensors + 4 <= nervous.sensors.len()
        }) else {
            return Err(format!(
                "the controller `{}` (hop) reads senses other than a roobot's: not in the GPU evaluation yet",
                c.name
            ));
        };
        self.ctrl_kind.push(4);
        self.ctrl_index.push(self.net_clock.len() as i32);
        self.net_weight.extend(&hop.params.0);
        self.net_weight.extend(senses.speed.forward.to_array());
        self.net_weight.push(senses.speed.particle.index() as f64);
        for &o in &c.outputs {
            self.net_weight.push(nervous.actuators[o].1.initial_level());
        }
        self.net_clock.push(f64::NAN);
        self.net_scratch.push(match hop.state() {
            HopState::Stance => 0.0,
            HopState::Leap => 1.0,
            HopState::Launch => 2.0,
            HopState::Flight => 3.0,
        });
        self.net_first_scratch.push(self.net_scratch.len() as i64);
        self.end_network((0..4).map(|k| senses.sensors + k), &c.outputs, shift);
        Ok(true)
    }

    /// Appends Raibert's controller `c` for a roobot (a network entry of
    /// kind 6; creatures/src/roobot/raibert.rs): its numbers the 8 gains,
    /// the hip's and ankle's torques, then what its senses read: the foot
    /// height sensor (within the creature's sensors), the leg's tilt (its
    /// base, tip and forward direction), the hip, foot, head and tail, the
    /// forward direction; its scratch: in stance, thrusting, when the
    /// stance began, the last stance's duration, the last leg angle and
    /// pitch (NaN: none yet). `Ok(false)` if `c` is not one.
    fn add_raibert(
        &mut self,
        c: &Wired,
        nervous: &NervousSystem,
        shift: &dyn Fn(usize) -> f64,
    ) -> Result<bool, String> {
        let Some(r) = c.brain.as_any().and_then(|a| a.downcast_ref::<Raibert>()) else {
            return Ok(false);
        };
        let senses = match &c.inputs {
            Inputs::Senses(s) => s.as_any().and_then(|a| a.downcast_ref::<RaibertSenses>()),
            Inputs::Sensors(_) => None,
        };
        let Some(senses) =
            senses.filter(|s| c.outputs.len() == 3 && s.foot_height < nervous.sensors.len())
        else {
            return Err(format!(
                "the controller `{}` (raibert) reads senses other than a roobot's: not in the GPU evaluation yet",
                c.name
            ));
        };
        let i = |p: ParticleId| p.index() as f64;
        self.ctrl_kind.push(6);
        self.ctrl_index.push(self.net_clock.len() as i32);
        self.net_weight.extend(r.gains);
        self.net_weight.extend([
            r.hip_torque,
            r.ankle_torque,
            senses.foot_height as f64,
            i(senses.angle.base),
            i(senses.angle.tip),
        ]);
        self.net_weight.extend(senses.angle.forward.to_array());
        self.net_weight.extend([
            i(senses.hip),
            i(senses.foot),
            i(senses.head),
            i(senses.tail),
        ]);
        self.net_weight.extend(senses.forward.to_array());
        self.net_clock.push(f64::NAN);
        self.net_scratch.extend([
            f64::from(u8::from(r.in_stance)),
            f64::from(u8::from(r.thrusting)),
            r.stance_started,
            r.last_stance,
            r.last_angle.unwrap_or(f64::NAN),
            r.last_pitch.unwrap_or(f64::NAN),
        ]);
        self.net_first_scratch.push(self.net_scratch.len() as i64);
        self.end_network(std::iter::empty(), &c.outputs, shift);
        Ok(true)
    }

    /// Appends jellyfish `j` (a network entry of kind 5, acting after the
    /// scene's controllers as `Scene::step` has it; creatures/src/jellyfish):
    /// its numbers the dome's count n, the depth sense's ceiling, the
    /// dome's radius, the pulse's period, the balance and wobble factors,
    /// the depth sense's particle; per dome mass its particle, its food
    /// sensor's particle and the food; per actuator (the pulse, then each
    /// steering force) its range, initial level and constant force's
    /// pushes (first, count). Its scratch: the FSM's behaviour and
    /// previous one (0 idle, 1 track, 2 hover), energy, phase and the depth
    /// it holds (NaN: none), then room for its n food levels and n leans.
    fn add_jellyfish(
        &mut self,
        j: &Jellyfish,
        first_push: &[(usize, usize)],
    ) -> Result<(), String> {
        let n = j.body.dome.len();
        if n < 3 || j.food.len() != n || j.steer.len() != n {
            return Err(format!(
                "the jellyfish `{}` has {n} dome masses, {} food senses and {} steering forces: not in the GPU evaluation",
                j.name,
                j.food.len(),
                j.steer.len()
            ));
        }
        let fsm = &j.fsm;
        self.ctrl_kind.push(5);
        self.ctrl_index.push(self.net_clock.len() as i32);
        self.net_weight.extend([
            n as f64,
            j.depth.ceiling,
            j.dome_radius(),
            fsm.pulse_period,
            fsm.balance,
            fsm.wobble,
            j.depth.particle.index() as f64,
        ]);
        for (d, f) in j.body.dome.iter().zip(&j.food) {
            self.net_weight.extend([
                d.index() as f64,
                f.sensor.index() as f64,
                f.food.index() as f64,
            ]);
        }
        for a in std::iter::once(&j.pulse).chain(&j.steer) {
            let (lo, hi) = a.range();
            let (first, count) = first_push[a.target().force.index()];
            self.net_weight
                .extend([lo, hi, a.initial_level(), first as f64, count as f64]);
        }
        self.net_clock.push(f64::NAN);
        let code = |b: Behaviour| match b {
            Behaviour::Idle => 0.0,
            Behaviour::Track => 1.0,
            Behaviour::Hover => 2.0,
        };
        self.net_scratch.extend([
            code(fsm.behaviour()),
            code(fsm.previous()),
            fsm.energy(),
            fsm.phase(),
            fsm.hover_depth().unwrap_or(f64::NAN),
        ]);
        self.push_scratch(2 * n);
        self.end_network(std::iter::empty(), &[], &|_| f64::NAN);
        Ok(())
    }

    /// Appends sensor `name`: a scene's `[[sensor]]`, or one of a
    /// roobot's own (its foot's height and time till touchdown, its leg's
    /// angle, its hip's forward speed).
    fn add_sensor(&mut self, name: &str, sensor: &dyn Sensor) -> Result<(), String> {
        let any = sensor.as_any();
        let own =
            |kind: i32, particles: [i32; 3], axis: DVec3, p: [f64; 2]| (kind, particles, axis, p);
        let roobot = if let Some(h) = any.and_then(|a| a.downcast_ref::<HeightSensor>()) {
            Some(own(
                6,
                [h.particle.index() as i32, 0, 0],
                DVec3::ZERO,
                [0.0; 2],
            ))
        } else if let Some(t) = any.and_then(|a| a.downcast_ref::<TiltSensor>()) {
            let ends = [t.base.index() as i32, t.tip.index() as i32, 0];
            Some(own(7, ends, t.forward, [t.gain, 0.0]))
        } else if let Some(v) = any.and_then(|a| a.downcast_ref::<SpeedSensor>()) {
            // A speed probe mapped from [0, 1]: (v - 0) / (1 - 0) is v.
            Some(own(
                1,
                [v.particle.index() as i32, 0, 0],
                v.forward,
                [0.0, 1.0],
            ))
        } else if let Some(t) = any.and_then(|a| a.downcast_ref::<TouchdownSensor>()) {
            let foot = [t.height.particle.index() as i32, 0, 0];
            Some(own(8, foot, DVec3::ZERO, [t.g, 0.0]))
        } else {
            None
        };
        if let Some((kind, particles, axis, p)) = roobot {
            self.sensor_kind.push(kind);
            self.sensor_particle.extend(particles);
            self.sensor_param.extend(axis.to_array());
            self.sensor_param.extend(p);
            return Ok(());
        }
        let Some(s) = any.and_then(|a| a.downcast_ref::<ScaledSensor>()) else {
            return Err(format!(
                "the sensor `{name}` (a creature's own) is not in the GPU evaluation yet"
            ));
        };
        let i = |p: &ParticleId| p.index() as i32;
        let (kind, particles, axis) = match &s.probe {
            Probe::Height(p) => (0, [i(p), 0, 0], DVec3::ZERO),
            Probe::Speed(p, axis) => (1, [i(p), 0, 0], *axis),
            Probe::Touch(p) => (2, [i(p), 0, 0], DVec3::ZERO),
            Probe::Length(a, b) => (3, [i(a), i(b), 0], DVec3::ZERO),
            Probe::Angle { a, joint, b } => (4, [i(a), i(joint), i(b)], DVec3::ZERO),
            Probe::Tilt(a, b) => (5, [i(a), i(b), 0], DVec3::ZERO),
        };
        self.sensor_kind.push(kind);
        self.sensor_particle.extend(particles);
        self.sensor_param.extend(axis.to_array());
        self.sensor_param.extend([s.min, s.max]);
        Ok(())
    }

    /// Appends measure `m` (of weight `w` in the fitness, for a term).
    fn add_measure(
        &mut self,
        m: &Measure,
        w: f64,
        spec: &animats_scene::evaluate::EvolveSpec,
        world: &World,
        muscles: usize,
    ) -> Result<(), String> {
        let (kind, ids, axis): (i32, &[ParticleId], DVec3) = match m {
            Measure::ContactFraction(p) => (0, std::slice::from_ref(p), DVec3::ZERO),
            Measure::Feet => (1, &[], DVec3::ZERO),
            Measure::Displacement(ids, axis) => (2, ids, *axis),
            Measure::MeanHeight(ids) => (3, ids, DVec3::ZERO),
            Measure::Speed(ids, axis) => (4, ids, *axis),
            Measure::Particles | Measure::Muscles | Measure::Mass | Measure::Size => {
                (5, &[], DVec3::ZERO)
            }
            Measure::Energy => (6, &[], DVec3::ZERO),
        };
        // A measure fixed when built: the engine's own value.
        let fixed = if kind == 5 {
            Recorder::new(std::slice::from_ref(m), spec, world, muscles).finish(world, 0.0, 0.0)[0]
        } else {
            0.0
        };
        self.measure_kind.push(kind);
        self.measure_id.extend(ids.iter().map(|p| p.index() as i32));
        self.measure_first_id.push(self.measure_id.len() as i64);
        self.measure_axis.extend(axis.to_array());
        self.measure_fixed.push(fixed);
        self.measure_weight.push(w);
        Ok(())
    }
}

impl Batch {
    /// The scenes' worlds packed as [`Batch::pack`] packs them, with their
    /// evaluations: spring muscles, oscillators, the centre and the end
    /// rules of `[evolve]`. Every scene must share the first one's step,
    /// gravity, floor and integrator; whatever the C does not evaluate is
    /// refused with a message naming the scene and the entry.
    pub fn pack_scenes(scenes: &[&Scene]) -> Result<Batch, String> {
        let Some(first) = scenes.first() else {
            return Err("no scenes to pack".into());
        };
        let dt = first.dt;
        if let Some(k) = scenes.iter().position(|s| s.dt.to_bits() != dt.to_bits()) {
            return Err(format!(
                "scene {k}: a batch shares one step; scene 0 has dt = {dt}, this one {}",
                scenes[k].dt
            ));
        }
        let worlds: Vec<&World> = scenes.iter().map(|s| &s.world).collect();
        let mut b = Batch::pack(&worlds, dt)?;
        // Rules for no scene yet (every offset array at [0]), the
        // particles' fixed flags kept; each scene appends its own.
        let mut r = std::mem::take(&mut b.ev);
        r.no_rules(0);
        for (k, s) in scenes.iter().enumerate() {
            r.add(s).map_err(|e| format!("scene {k}: {e}"))?;
        }
        r.measure_sum = vec![0.0; r.measure_kind.len()];
        r.sensor_level = vec![0.0; r.sensor_kind.len()];
        r.measure_start = vec![0.0; 3 * r.measure_kind.len()];
        r.result = vec![0.0; RESULTS * scenes.len()];
        r.muscle_work = vec![0.0; 3 * r.muscle_spring.len()];
        r.ended = vec![0; 2 * scenes.len()];
        r.ready = true;
        b.ev = r;
        Ok(b)
    }

    /// Runs every scene's evaluation with the C compiled for this CPU, on
    /// the threads of the current rayon pool (the same bits on any number),
    /// from the state it was packed in: once (`Err` after the first).
    pub fn evaluate_cpu(&mut self) -> Result<Vec<Evaluation>, String> {
        self.evaluate_cpu_with(Mode::Strict)
    }

    /// [`Batch::evaluate_cpu`] in `mode`: [`Mode::Fast`] lets the C
    /// contract multiply-adds into FMAs (`Err` on a CPU without FMA), as a
    /// GPU's fast mode does; not the engine's bits.
    pub fn evaluate_cpu_with(&mut self, mode: Mode) -> Result<Vec<Evaluation>, String> {
        use rayon::prelude::*;
        if mode == Mode::Fast && !cpu_has_fma() {
            return Err("fast mode: this CPU has no fused multiply-add (FMA)".into());
        }
        self.take_ready()?;
        let shared = Shared(self.raw());
        let local = self.layout().flag();
        let n = self.creatures();
        (0..n.div_ceil(CHUNK)).into_par_iter().for_each(|k| {
            let (first, last) = (k * CHUNK, ((k + 1) * CHUNK).min(n));
            // SAFETY: `shared` points into this batch's vectors, which
            // live until the loop ends; the C reads and writes within the
            // bounds the offsets give (as packed), and creatures
            // first..last, with their springs, muscles and results, are
            // this task's alone.
            let (first, last) = (first as c_longlong, last as c_longlong);
            match mode {
                Mode::Strict => unsafe { animats_evaluate_range(shared.get(), first, last, local) },
                // SAFETY: as above; the same C, compiled with contraction
                // (FMA instructions, which the CPU has: checked above).
                Mode::Fast => unsafe {
                    animats_evaluate_range_fast(shared.get(), first, last, local)
                },
            }
        });
        Ok(self.evaluations())
    }

    /// Checks that the batch holds scenes not yet evaluated, and marks it
    /// evaluated.
    pub(crate) fn take_ready(&mut self) -> Result<(), String> {
        if !self.ev.ready {
            return Err(
                "this batch holds no evaluations to run: pack scenes (Batch::pack_scenes), once per evaluation"
                    .into(),
            );
        }
        self.ev.ready = false;
        Ok(())
    }

    /// Results, endings and measures written back (from a GPU).
    pub(crate) fn set_results(&mut self, result: &[f64], ended: &[i64], measures: &[f64]) {
        let (r, e, m) = (
            self.ev.result.len(),
            self.ev.ended.len(),
            self.ev.measure_sum.len(),
        );
        self.ev.result.copy_from_slice(&result[..r]);
        self.ev.ended.copy_from_slice(&ended[..e]);
        self.ev.measure_sum.copy_from_slice(&measures[..m]);
    }

    /// The evaluations the C wrote.
    pub(crate) fn evaluations(&self) -> Vec<Evaluation> {
        (0..self.creatures())
            .map(|c| {
                let r = &self.ev.result[RESULTS * c..RESULTS * (c + 1)];
                let param = &self.ev.eval_param[PARAMS * c..PARAMS * (c + 1)];
                let (why, which) = (self.ev.ended[2 * c], self.ev.ended[2 * c + 1] as usize);
                let (touch, stretch) = &self.ev.names[c];
                let name = |names: &[String]| names.get(which).cloned().unwrap_or_default();
                let ended = match why {
                    1 => Ended::Touch(name(touch)),
                    2 => Ended::Stretch(name(stretch)),
                    3 => Ended::BlowUp,
                    _ => Ended::Timeout,
                };
                let (m0, m1) = (
                    self.ev.first_measure[c] as usize,
                    self.ev.first_measure[c + 1] as usize,
                );
                let split = m0 + self.ev.eval_count[3 * c + 2] as usize;
                Evaluation {
                    fitness: r[0],
                    distance: r[1],
                    time: r[2],
                    ended,
                    measures: self.ev.measure_sum[m0..split].to_vec(),
                    energy: (param[8] != 0.0).then_some(r[3]),
                    target_distance: (param[10] != 0.0).then_some(r[4]),
                    terms: self.ev.measure_sum[split..m1].to_vec(),
                }
            })
            .collect()
    }
}

/// The C compiled for this CPU as a runner of scenes' evaluations
/// ([`animats_scene::evaluate::Runner`]): each batch packed and evaluated
/// on the current rayon pool. What the GPU's runner does, on the CPU: the
/// tests evolve with it to show that a generation evaluated in batches by
/// the C gives the engine's log.
pub fn c_runs(scenes: Vec<Scene>) -> Result<Vec<Evaluation>, String> {
    let refs: Vec<&Scene> = scenes.iter().collect();
    Batch::pack_scenes(&refs)?.evaluate_cpu()
}

/// [`c_runs`] as a problem's [`Batches`].
pub fn c_batches() -> Batches {
    Batches(std::sync::Arc::new(c_runs))
}
