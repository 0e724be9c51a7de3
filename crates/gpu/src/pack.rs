//! Worlds laid out for the C step (`kernel/step.h`): structure of arrays,
//! each creature's particles and springs a contiguous run found through
//! per-creature offsets, so one batch holds bodies of any sizes.

use animats_engine::{
    DVec3, FloorCollision, IntegratorKind, NBodyGravity, PlaneConstraint, RodDrag, SoftContact,
    Solver, SphereContact, Terrain, World,
};
use std::os::raw::{c_double, c_int, c_longlong, c_uint};
use std::sync::Arc;

/// The C's `an_batch`: pointers into a [`Batch`]'s vectors (or into their
/// copies on a GPU).
#[repr(C)]
pub(crate) struct Raw {
    first_particle: *const c_longlong,
    first_spring: *const c_longlong,
    inv_mass: *const c_double,
    mass: *const c_double,
    pos: *mut c_double,
    vel: *mut c_double,
    spring_a: *const c_int,
    spring_b: *const c_int,
    stiffness: *const c_double,
    damping: *const c_double,
    rest_length: *mut c_double,
    scratch: *mut c_double,
    first_joint: *const c_longlong,
    joint_a: *const c_int,
    joint_j: *const c_int,
    joint_b: *const c_int,
    joint_stiffness: *const c_double,
    joint_damping: *const c_double,
    joint_rest: *mut c_double,
    first_motor: *const c_longlong,
    motor_end: *const c_int,
    motor_joint: *const c_int,
    motor_axis: *const c_double,
    motor_torque: *mut c_double,
    first_fluid: *const c_longlong,
    fluid_drag: *const c_double,
    fluid_density: *const c_double,
    radius: *const c_double,
    volume: *const c_double,
    restitution: *const c_double,
    mu_s: *const c_double,
    mu_k: *const c_double,
    failed: *mut c_longlong,
    steps_before: c_longlong,
    first_push: *const c_longlong,
    push_particle: *const c_int,
    push_force: *mut c_double,
    gx: c_double,
    gy: c_double,
    gz: c_double,
    gravity: c_int,
    integrator: c_int,
    dt: c_double,
    floor: c_int,
    floor_contact: c_int,
    envelope: c_double,
    rest_speed: c_double,
    static_speed: c_double,
    contact_tolerance: c_double,
    flight_shift: c_double,
    first_pair: *const c_longlong,
    pair_a: *const c_int,
    pair_b: *const c_int,
    pair_stiffness: *const c_double,
    pair_damping: *const c_double,
    first_muscle: *const c_longlong,
    muscle_spring: *const c_int,
    muscle_param: *const c_double,
    muscle_level: *mut c_double,
    first_osc: *const c_longlong,
    osc_frequency: *const c_double,
    first_output: *const c_longlong,
    output_muscle: *const c_int,
    output_gene: *const c_double,
    first_centre: *const c_longlong,
    centre_particle: *const c_int,
    first_touch: *const c_longlong,
    touch_particle: *const c_int,
    first_stretch: *const c_longlong,
    stretch_pair: *const c_int,
    stretch_length: *const c_double,
    fixed: *const c_int,
    eval_param: *const c_double,
    eval_count: *const c_longlong,
    result: *mut c_double,
    ended: *mut c_longlong,
    first_measure: *const c_longlong,
    measure_kind: *const c_int,
    measure_first_id: *const c_longlong,
    measure_id: *const c_int,
    measure_axis: *const c_double,
    measure_fixed: *const c_double,
    measure_weight: *const c_double,
    measure_sum: *mut c_double,
    measure_start: *mut c_double,
    first_sensor: *const c_longlong,
    sensor_kind: *const c_int,
    sensor_particle: *const c_int,
    sensor_param: *const c_double,
    sensor_level: *mut c_double,
    first_ctrl: *const c_longlong,
    ctrl_kind: *const c_int,
    ctrl_index: *const c_int,
    net_first_layer: *const c_longlong,
    layer_size: *const c_int,
    net_first_weight: *const c_longlong,
    net_weight: *const c_double,
    net_clock: *const c_double,
    net_first_input: *const c_longlong,
    net_input: *const c_int,
    net_first_output: *const c_longlong,
    net_output_muscle: *const c_int,
    net_output_shift: *const c_double,
    net_first_scratch: *const c_longlong,
    net_scratch: *mut c_double,
    net_first_neuron: *const c_longlong,
    neuron_param: *const c_double,
    neuron_state: *mut c_double,
    muscle_work: *mut c_double,
    muscle_kind: *const c_int,
    muscle_base: *const c_double,
    muscle_push: *const c_int,
    muscle_gate: *const c_double,
    first_rod: *const c_longlong,
    rod_a: *const c_int,
    rod_b: *const c_int,
    rod_drag: *const c_double,
    fluid_current: *const c_double,
    rod_current: *const c_double,
    first_plane: *const c_longlong,
    plane_param: *const c_double,
    plane_first_particle: *const c_longlong,
    plane_particle: *const c_int,
    terrain_param: *const c_double,
    terrain_height: *const c_double,
    terrain: c_int,
    first_excluded: *const c_longlong,
    excluded: *const c_longlong,
    contact_param: *const c_double,
    first_slot: *const c_longlong,
    contact_slot: *mut c_longlong,
    first_nbody: *const c_longlong,
    nbody_param: *const c_double,
    nbody_first_body: *const c_longlong,
    nbody_body: *const c_int,
    nbody_first_range: *const c_longlong,
    nbody_range: *const c_longlong,
    clock: *mut c_double,
    implicit: *mut c_double,
    solver_tolerance: c_double,
    solver_iterations: c_longlong,
    absent: c_uint,
}

extern "C" {
    fn animats_step_range(
        batch: *const Raw,
        first: c_longlong,
        last: c_longlong,
        steps: c_longlong,
        local: c_int,
    );
}

/// Where a thread keeps the state (positions, velocities, the step's
/// scratch, the particles' and springs' constants) of the creature it
/// steps or evaluates. Either gives the same bits: the same operations on the same
/// numbers, only stored elsewhere.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Layout {
    /// In the batch's arrays, each creature's particles one contiguous run
    /// (on a GPU, a warp's 32 threads read 32 scattered places at once).
    Batch,
    /// In arrays of the thread's own, with the particles' inverse masses,
    /// masses and radii and the springs' ends, stiffness and damping, for
    /// creatures of at most 32 particles and 128 springs
    /// (on a GPU, its local memory, which the hardware interleaves thread
    /// by thread, so that a warp's reads of its creatures' k-th
    /// coordinates are one transaction); larger creatures as `Batch`.
    #[default]
    Local,
}

impl Layout {
    /// The C's flag (`local` of `an_step_in`).
    pub(crate) fn flag(self) -> c_int {
        c_int::from(self == Layout::Local)
    }
}

/// Creatures a thread of [`Batch::run_cpu`] takes at a time.
pub(crate) const CHUNK: usize = 64;

/// The C's struct shared by the threads of [`Batch::run_cpu`].
pub(crate) struct Shared(pub(crate) Raw);

// SAFETY: the threads read the shared arrays and write only the positions,
// velocities, scratch (sphere contact's room among it) and evaluation state
// of their own creatures: disjoint ranges.
unsafe impl Sync for Shared {}

impl Shared {
    /// (A method, so that closures capture the whole, which is `Sync`.)
    pub(crate) fn get(&self) -> *const Raw {
        &self.0
    }
}

/// Doubles of implicit Euler's room per particle, per spring and per
/// angle joint (`AN_IMPLICIT_ROOM`, `AN_IMPLICIT_SPRING` and
/// `AN_IMPLICIT_JOINT` in `kernel/step.h`).
const IMPLICIT: [usize; 3] = [39, 6, 55];

/// Doubles of scratch per particle the C step uses.
const SCRATCH: usize = 15;

/// Controller kinds the C evaluates (`ctrl_kind`, `kernel/eval.h`'s
/// `an_act`: oscillator, network, CTRNN, FSM, hopper, jellyfish, Raibert's).
const CONTROL_KINDS: i32 = 7;

/// Numbers a fluid's or rods' current takes (`current`; `AN_CURRENT` in
/// `kernel/step.h`).
const CURRENT: usize = 11;

/// Many worlds (creatures) as one batch of the C step's arrays.
#[derive(Clone, Debug)]
pub struct Batch {
    first_particle: Vec<i64>,
    first_spring: Vec<i64>,
    inv_mass: Vec<f64>,
    mass: Vec<f64>,
    pos: Vec<f64>,
    vel: Vec<f64>,
    spring_a: Vec<i32>,
    spring_b: Vec<i32>,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    rest_length: Vec<f64>,
    scratch: Vec<f64>,
    first_joint: Vec<i64>,
    joint_a: Vec<i32>,
    joint_j: Vec<i32>,
    joint_b: Vec<i32>,
    joint_stiffness: Vec<f64>,
    joint_damping: Vec<f64>,
    joint_rest: Vec<f64>,
    first_motor: Vec<i64>,
    motor_end: Vec<i32>,
    motor_joint: Vec<i32>,
    motor_axis: Vec<f64>,
    motor_torque: Vec<f64>,
    first_fluid: Vec<i64>,
    fluid_drag: Vec<f64>,
    fluid_density: Vec<f64>,
    radius: Vec<f64>,
    volume: Vec<f64>,
    restitution: Vec<f64>,
    mu_s: Vec<f64>,
    mu_k: Vec<f64>,
    failed: Vec<i64>,
    /// Steps taken by earlier runs (`failed` counts from the first).
    steps_run: u64,
    /// Where a thread keeps the state of the creature it steps.
    layout: Layout,
    first_push: Vec<i64>,
    push_particle: Vec<i32>,
    push_force: Vec<f64>,
    floor: Option<Floor>,
    g: DVec3,
    gravity: bool,
    integrator: IntegratorKind,
    dt: f64,
    first_pair: Vec<i64>,
    pair_a: Vec<i32>,
    pair_b: Vec<i32>,
    pair_stiffness: Vec<f64>,
    pair_damping: Vec<f64>,
    /// Drag across springs (`[fluid] springs`): per creature its rods, each
    /// rod's ends and `-½ C ρ D`.
    first_rod: Vec<i64>,
    rod_a: Vec<i32>,
    rod_b: Vec<i32>,
    rod_drag: Vec<f64>,
    /// Each fluid's and each rod's uniform current, 3 numbers each (0 in
    /// still water).
    fluid_current: Vec<f64>,
    rod_current: Vec<f64>,
    /// Plane constraints (events/plane_constraint.rs): per creature its
    /// planes, each one's point, unit normal and 1 if it comes before the
    /// floor's collisions among the world's events (7 numbers), and its
    /// particles.
    first_plane: Vec<i64>,
    plane_param: Vec<f64>,
    plane_first_particle: Vec<i64>,
    plane_particle: Vec<i32>,
    /// The floor's shape (`kernel/terrain.h`): its kind, its numbers and a
    /// heightfield's heights.
    terrain: c_int,
    terrain_param: Vec<f64>,
    terrain_height: Vec<f64>,
    /// Sphere contact (events/sphere_contact, `kernel/spheres.h`): per
    /// creature its excluded pairs as sorted keys (`min << 32 | max`), 4
    /// numbers (1 if it has sphere contact, the envelope, the rest speed,
    /// the restitution or NaN for the spheres' own) and its room for the
    /// check's sorting and pairs (`4 n + n (n − 1) / 2`).
    first_excluded: Vec<i64>,
    excluded: Vec<i64>,
    contact_param: Vec<f64>,
    first_slot: Vec<i64>,
    contact_slot: Vec<i64>,
    /// N-body gravity (forces/nbody.rs): per creature its groups, each
    /// one's G and softening squared, its bodies in its order, and the
    /// first rows of the ranges its pairs are summed in
    /// (`NBodyGravity::row_ranges`).
    first_nbody: Vec<i64>,
    nbody_param: Vec<f64>,
    nbody_first_body: Vec<i64>,
    nbody_body: Vec<i32>,
    nbody_first_range: Vec<i64>,
    nbody_range: Vec<i64>,
    /// Each world's clock: its time and the rounding carry of its
    /// compensated sum (`World::time`, `World::time_carry`), for the forces
    /// that ask the time (a reef's currents). A scene's evaluation keeps its
    /// own clock (`Rules`).
    clock: Vec<f64>,
    /// Implicit Euler's room (`IMPLICIT` doubles a particle, a spring and
    /// an angle joint; empty under the other integrators) and its solver, which the batch's worlds share.
    implicit: Vec<f64>,
    solver: Solver,
    /// A scene's evaluation: its muscles, oscillators and rules.
    pub(crate) ev: crate::scenes::Rules,
}

impl Batch {
    /// The worlds' current states and models, to be stepped by `dt`. Every
    /// world must share the first one's gravity, floor and integrator, and
    /// hold only what the C steps (particles, gravity on every particle,
    /// damped springs, angle joints, torque joints at their present
    /// torques, constant forces, fluids about every particle (still, in a
    /// uniform current or under a reef's waves, at each world's own time),
    /// n-body gravity, soft contact, drag
    /// across springs, the floor under every particle, flat or shaped,
    /// plane constraints, sphere contact among every particle): anything
    /// else is refused with a message naming the world and what it holds.
    pub fn pack(worlds: &[&World], dt: f64) -> Result<Batch, String> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(format!(
                "dt = {dt}: the step must be a positive number of seconds"
            ));
        }
        let Some(first) = worlds.first() else {
            return Err("no worlds to pack".into());
        };
        let (g, gravity, integrator) = (
            first.forces().g(),
            first.forces().gravity().is_some(),
            first.integrator(),
        );
        let mut b = Batch {
            first_particle: vec![0],
            first_spring: vec![0],
            inv_mass: Vec::new(),
            mass: Vec::new(),
            pos: Vec::new(),
            vel: Vec::new(),
            spring_a: Vec::new(),
            spring_b: Vec::new(),
            stiffness: Vec::new(),
            damping: Vec::new(),
            rest_length: Vec::new(),
            scratch: Vec::new(),
            first_joint: vec![0],
            joint_a: Vec::new(),
            joint_j: Vec::new(),
            joint_b: Vec::new(),
            joint_stiffness: Vec::new(),
            joint_damping: Vec::new(),
            joint_rest: Vec::new(),
            first_motor: vec![0],
            motor_end: Vec::new(),
            motor_joint: Vec::new(),
            motor_axis: Vec::new(),
            motor_torque: Vec::new(),
            first_fluid: vec![0],
            fluid_drag: Vec::new(),
            fluid_density: Vec::new(),
            radius: Vec::new(),
            volume: Vec::new(),
            restitution: Vec::new(),
            mu_s: Vec::new(),
            mu_k: Vec::new(),
            failed: vec![0; worlds.len()],
            steps_run: 0,
            layout: Layout::default(),
            first_push: vec![0],
            push_particle: Vec::new(),
            push_force: Vec::new(),
            floor: floor_of(first).map_err(|e| format!("world 0: {e}"))?,
            terrain: 0,
            terrain_param: Vec::new(),
            terrain_height: Vec::new(),
            g,
            gravity,
            integrator,
            dt,
            first_pair: vec![0],
            pair_a: Vec::new(),
            pair_b: Vec::new(),
            pair_stiffness: Vec::new(),
            pair_damping: Vec::new(),
            first_rod: vec![0],
            rod_a: Vec::new(),
            rod_b: Vec::new(),
            rod_drag: Vec::new(),
            fluid_current: Vec::new(),
            rod_current: Vec::new(),
            first_plane: vec![0],
            plane_param: Vec::new(),
            plane_first_particle: vec![0],
            plane_particle: Vec::new(),
            first_excluded: vec![0],
            excluded: Vec::new(),
            contact_param: Vec::new(),
            first_slot: vec![0],
            contact_slot: Vec::new(),
            first_nbody: vec![0],
            nbody_param: Vec::new(),
            nbody_first_body: vec![0],
            nbody_body: Vec::new(),
            nbody_first_range: vec![0],
            nbody_range: Vec::new(),
            clock: Vec::new(),
            implicit: Vec::new(),
            solver: first.solver(),
            ev: crate::scenes::Rules::default(),
        };
        if let Some(f) = &b.floor {
            (b.terrain, b.terrain_param, b.terrain_height) = terrain_arrays(&f.terrain);
        }
        for (k, w) in worlds.iter().enumerate() {
            supported(w).map_err(|what| format!("world {k}: {what}"))?;
            let same_gravity = w.forces().gravity().is_some() == gravity
                && w.forces().g().to_array().map(f64::to_bits) == g.to_array().map(f64::to_bits);
            let floor = floor_of(w).map_err(|e| format!("world {k}: {e}"))?;
            if floor != b.floor {
                return Err(format!(
                    "world {k}: a batch shares one floor; world 0 has {:?}, this one {floor:?}",
                    b.floor
                ));
            }
            if integrator == IntegratorKind::Implicit && w.solver() != b.solver {
                return Err(format!(
                    "world {k}: a batch shares one implicit solver; world 0 has {:?}, this one {:?}",
                    b.solver,
                    w.solver()
                ));
            }
            if !same_gravity || w.integrator() != integrator {
                return Err(format!(
                    "world {k}: a batch shares one gravity and one integrator; world 0 has g = {g} and {integrator:?}, this one g = {} and {:?}",
                    w.forces().g(),
                    w.integrator()
                ));
            }
            let n = w.len();
            if n > i32::MAX as usize {
                return Err(format!(
                    "world {k}: {n} particles are more than a batch indexes"
                ));
            }
            let props = w.particles();
            b.inv_mass.extend_from_slice(&props.inv_mass);
            b.mass.extend_from_slice(&props.mass);
            for p in &w.state().pos {
                b.pos.extend(p.to_array());
            }
            for v in &w.state().vel {
                b.vel.extend(v.to_array());
            }
            for s in w.forces().springs.iter() {
                let (a, c) = s.ends();
                b.spring_a.push(a.index() as i32);
                b.spring_b.push(c.index() as i32);
                b.stiffness.push(s.stiffness);
                b.damping.push(s.damping);
                b.rest_length.push(s.rest_length);
            }
            for jt in w.forces().angle_joints.iter() {
                let (a, j, e) = jt.particles();
                b.joint_a.push(a.index() as i32);
                b.joint_j.push(j.index() as i32);
                b.joint_b.push(e.index() as i32);
                b.joint_stiffness.push(jt.stiffness);
                b.joint_damping.push(jt.damping);
                b.joint_rest.push(jt.rest_angle);
            }
            for m in w.forces().torque_joints.iter() {
                let (e, j) = m.particles();
                b.motor_end.push(e.index() as i32);
                b.motor_joint.push(j.index() as i32);
                b.motor_axis.extend(m.axis().to_array());
                b.motor_torque.push(m.torque);
            }
            for cf in w.forces().constant_forces.iter() {
                for p in cf.particles() {
                    b.push_particle.push(p.index() as i32);
                    b.push_force.extend(cf.force.to_array());
                }
            }
            for fl in w.forces().fluids() {
                // As FluidMedium::apply forms it.
                b.fluid_drag
                    .push(-0.5 * fl.drag_coefficient * fl.density * std::f64::consts::PI);
                b.fluid_density.push(fl.density);
                b.fluid_current.extend(current(&fl.current));
            }
            for g in w.forces().nbody() {
                // As NBodyGravity::apply forms them.
                b.nbody_param.extend([g.g, g.softening * g.softening]);
                let first = b.nbody_body.len();
                g.targets().for_each(n, |i| b.nbody_body.push(i as i32));
                b.nbody_first_body.push(b.nbody_body.len() as i64);
                let ranges = NBodyGravity::row_ranges(b.nbody_body.len() - first);
                b.nbody_range
                    .extend(ranges[..ranges.len() - 1].iter().map(|&r| r as i64));
                b.nbody_first_range.push(b.nbody_range.len() as i64);
            }
            for sc in w
                .forces()
                .user()
                .filter_map(|u| u.as_any()?.downcast_ref::<SoftContact>())
            {
                for &(a, e) in sc.pair_list() {
                    b.pair_a.push(a as i32);
                    b.pair_b.push(e as i32);
                    b.pair_stiffness.push(sc.stiffness);
                    b.pair_damping.push(sc.damping);
                }
            }
            for rd in w
                .forces()
                .user()
                .filter_map(|u| u.as_any()?.downcast_ref::<RodDrag>())
            {
                // As RodDrag::apply forms it.
                let drag = -0.5 * rd.drag_coefficient * rd.density * rd.diameter;
                for &(a, e) in rd.rods() {
                    b.rod_a.push(a as i32);
                    b.rod_b.push(e as i32);
                    b.rod_drag.push(drag);
                    b.rod_current.extend(current(&rd.current));
                }
            }
            // Planes, in the order of the world's events, each marked
            // where it is handled before the floor's collisions.
            let mut floor_seen = false;
            for e in w.events() {
                floor_seen |= e.as_any().is::<FloorCollision>();
                if let Some(pc) = e.as_any().downcast_ref::<PlaneConstraint>() {
                    b.plane_param.extend(pc.point().to_array());
                    b.plane_param.extend(pc.normal().to_array());
                    b.plane_param.push(if floor_seen { 0.0 } else { 1.0 });
                    b.plane_particle
                        .extend(pc.particles().iter().map(|p| p.index() as i32));
                    b.plane_first_particle.push(b.plane_particle.len() as i64);
                }
            }
            b.radius.extend_from_slice(&props.radius);
            b.volume.extend_from_slice(&props.volume);
            b.restitution.extend_from_slice(&props.restitution);
            b.mu_s.extend_from_slice(&props.mu_s);
            b.mu_k.extend_from_slice(&props.mu_k);
            b.first_particle.push(b.mass.len() as i64);
            b.first_spring.push(b.stiffness.len() as i64);
            b.first_joint.push(b.joint_a.len() as i64);
            b.first_motor.push(b.motor_end.len() as i64);
            b.first_fluid.push(b.fluid_drag.len() as i64);
            b.first_push.push(b.push_particle.len() as i64);
            b.first_pair.push(b.pair_a.len() as i64);
            b.first_rod.push(b.rod_a.len() as i64);
            b.first_nbody.push(b.nbody_param.len() as i64 / 2);
            b.clock.extend([w.time(), w.time_carry()]);
            b.first_plane.push(b.plane_first_particle.len() as i64 - 1);
            // Sphere contact ([`supported`]: one, after the floor, every
            // particle, no sleeping).
            let n = props.radius.len();
            let contact = w
                .events()
                .iter()
                .find_map(|e| e.as_any().downcast_ref::<SphereContact>());
            match contact.map(SphereContact::def) {
                Some(d) => {
                    let mut keys: Vec<i64> = d
                        .excluded
                        .iter()
                        .map(|(a, e)| {
                            let (lo, hi) = (a.index().min(e.index()), a.index().max(e.index()));
                            ((lo as i64) << 32) | hi as i64
                        })
                        .collect();
                    keys.sort_unstable();
                    keys.dedup();
                    b.excluded.extend(keys);
                    b.contact_param.extend([
                        1.0,
                        d.envelope,
                        d.rest_speed,
                        d.restitution.unwrap_or(f64::NAN),
                    ]);
                    b.contact_slot.resize(
                        b.contact_slot.len() + 4 * n + n * n.saturating_sub(1) / 2,
                        0,
                    );
                }
                None => b.contact_param.extend([0.0; 4]),
            }
            b.first_excluded.push(b.excluded.len() as i64);
            b.first_slot.push(b.contact_slot.len() as i64);
            b.ev.fixed.extend(props.fixed.iter().map(|&f| i32::from(f)));
        }
        b.scratch = vec![0.0; SCRATCH * b.mass.len()];
        if integrator == IntegratorKind::Implicit {
            let [per_particle, per_spring, per_joint] = IMPLICIT;
            b.implicit = vec![
                0.0;
                per_particle * b.mass.len()
                    + per_spring * b.rest_length.len()
                    + per_joint * b.joint_a.len()
            ];
        }
        b.ev.no_rules(worlds.len());
        Ok(b)
    }

    /// Whether the batch's floor has a shape (`[terrain]`).
    pub fn on_terrain(&self) -> bool {
        self.terrain != 0
    }

    /// Whether the batch steps with implicit Euler.
    pub fn implicit(&self) -> bool {
        self.integrator == IntegratorKind::Implicit
    }

    /// The batch's integrator as the C numbers them (`AN_RK4` and its
    /// kin, `kernel/step.h`).
    pub(crate) fn integrator_code(&self) -> c_int {
        match self.integrator {
            IntegratorKind::Euler => 0,
            IntegratorKind::Midpoint => 1,
            IntegratorKind::Rk4 => 2,
            IntegratorKind::Implicit => 4,
            _ => 3,
        }
    }

    /// The parts of the step no creature of the batch has, as the bits of
    /// `AN_ABSENT` (`kernel/step.h`, `AN_P_*`, in their order: eight kinds
    /// of force and event, seven of controller, a reef's waves): a kernel compiled without
    /// them runs the same arithmetic on this batch, each of their loops
    /// having had nothing to do.
    pub(crate) fn absent(&self) -> u32 {
        let parts = [
            self.joint_a.is_empty(),
            self.motor_end.is_empty(),
            self.push_particle.is_empty(),
            self.fluid_drag.is_empty(),
            self.nbody_param.is_empty(),
            self.pair_a.is_empty(),
            self.rod_a.is_empty(),
            self.plane_param.is_empty(),
        ];
        let kinds = (self.ev.ctrl_kind.iter())
            .filter(|&&k| (0..CONTROL_KINDS).contains(&k))
            .fold(0u32, |seen, &k| seen | 1 << k);
        let controls = (0..CONTROL_KINDS).map(|k| kinds & 1 << k == 0);
        // A reef's current is marked by a number in its slot 3 (a uniform
        // current's is NaN: `current`).
        let reef = |c: &[f64]| c.chunks_exact(CURRENT).any(|c| !c[3].is_nan());
        let no_reef = !reef(&self.fluid_current) && !reef(&self.rod_current);
        parts
            .into_iter()
            .chain(controls)
            .chain([no_reef])
            .enumerate()
            .fold(0, |bits, (i, none)| bits | (u32::from(none) << i))
    }

    /// Whether a creature of the batch has sphere contact (the event).
    pub fn sphere_contact(&self) -> bool {
        self.contact_param.chunks(4).any(|p| p[0] != 0.0)
    }

    /// Creatures in the batch.
    pub fn creatures(&self) -> usize {
        self.first_particle.len() - 1
    }

    /// Creature `c`'s particle `i`: its position and velocity (`None` for
    /// a creature or particle the batch does not have).
    pub fn state(&self, c: usize, i: usize) -> Option<(DVec3, DVec3)> {
        let (first, end) = (
            *self.first_particle.get(c)?,
            *self.first_particle.get(c + 1)?,
        );
        let p = first as usize + i;
        if p >= end as usize {
            return None;
        }
        let k = 3 * p;
        Some((
            DVec3::from_slice(&self.pos[k..k + 3]),
            DVec3::from_slice(&self.vel[k..k + 3]),
        ))
    }

    /// Steps every creature `steps` times with the C step compiled for this
    /// CPU, on the threads of the current rayon pool (creatures are
    /// independent: the same bits on any number of threads).
    pub fn run_cpu(&mut self, steps: u64) {
        use rayon::prelude::*;
        let shared = Shared(self.raw());
        let steps = steps.min(i64::MAX as u64) as c_longlong;
        let local = self.layout.flag();
        let n = self.creatures();
        (0..n.div_ceil(CHUNK)).into_par_iter().for_each(|k| {
            let (first, last) = (k * CHUNK, ((k + 1) * CHUNK).min(n));
            // SAFETY: `shared` points into this batch's vectors, which
            // live until the loop ends; the C reads and writes within the
            // bounds the offsets give (every spring's and joint's ends lie
            // within its creature, as packed), and creatures first..last
            // are this task's alone.
            unsafe {
                animats_step_range(
                    shared.get(),
                    first as c_longlong,
                    last as c_longlong,
                    steps,
                    local,
                )
            };
        });
        self.steps_run = self.steps_run.saturating_add(steps as u64);
    }

    /// Where the threads that step this batch keep each creature's state
    /// (on the CPU and on a GPU): [`Layout::Local`] unless set.
    pub fn set_layout(&mut self, layout: Layout) {
        self.layout = layout;
    }

    /// Where the threads keep each creature's state.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    pub(crate) fn raw(&mut self) -> Raw {
        let addresses: Vec<u64> = Array::ALL.iter().map(|&a| self.host_address(a)).collect();
        self.raw_with(|a| addresses[a as usize])
    }

    /// The address of array `a` in this process.
    fn host_address(&mut self, a: Array) -> u64 {
        match a {
            Array::Pos => self.pos.as_mut_ptr() as u64,
            Array::Vel => self.vel.as_mut_ptr() as u64,
            Array::Scratch => self.scratch.as_mut_ptr() as u64,
            Array::Failed => self.failed.as_mut_ptr() as u64,
            Array::RestLength => self.rest_length.as_mut_ptr() as u64,
            Array::JointRest => self.joint_rest.as_mut_ptr() as u64,
            Array::MotorTorque => self.motor_torque.as_mut_ptr() as u64,
            Array::PushForce => self.push_force.as_mut_ptr() as u64,
            Array::MuscleLevel => self.ev.muscle_level.as_mut_ptr() as u64,
            Array::Result => self.ev.result.as_mut_ptr() as u64,
            Array::Ended => self.ev.ended.as_mut_ptr() as u64,
            Array::MeasureSum => self.ev.measure_sum.as_mut_ptr() as u64,
            Array::MeasureStart => self.ev.measure_start.as_mut_ptr() as u64,
            Array::SensorLevel => self.ev.sensor_level.as_mut_ptr() as u64,
            Array::NetScratch => self.ev.net_scratch.as_mut_ptr() as u64,
            Array::NeuronState => self.ev.neuron_state.as_mut_ptr() as u64,
            Array::MuscleWork => self.ev.muscle_work.as_mut_ptr() as u64,
            Array::ContactSlot => self.contact_slot.as_mut_ptr() as u64,
            Array::Clock => self.clock.as_mut_ptr() as u64,
            Array::Implicit => self.implicit.as_mut_ptr() as u64,
            other => match self.array(other) {
                Slice::F64(v) => v.as_ptr() as u64,
                Slice::I32(v) => v.as_ptr() as u64,
                Slice::I64(v) => v.as_ptr() as u64,
            },
        }
    }

    /// Array `a`.
    pub(crate) fn array(&self, a: Array) -> Slice<'_> {
        use Slice::{F64, I32, I64};
        match a {
            Array::FirstParticle => I64(&self.first_particle),
            Array::FirstSpring => I64(&self.first_spring),
            Array::InvMass => F64(&self.inv_mass),
            Array::Mass => F64(&self.mass),
            Array::Pos => F64(&self.pos),
            Array::Vel => F64(&self.vel),
            Array::SpringA => I32(&self.spring_a),
            Array::SpringB => I32(&self.spring_b),
            Array::Stiffness => F64(&self.stiffness),
            Array::Damping => F64(&self.damping),
            Array::RestLength => F64(&self.rest_length),
            Array::Scratch => F64(&self.scratch),
            Array::FirstJoint => I64(&self.first_joint),
            Array::JointA => I32(&self.joint_a),
            Array::JointJ => I32(&self.joint_j),
            Array::JointB => I32(&self.joint_b),
            Array::JointStiffness => F64(&self.joint_stiffness),
            Array::JointDamping => F64(&self.joint_damping),
            Array::JointRest => F64(&self.joint_rest),
            Array::FirstMotor => I64(&self.first_motor),
            Array::MotorEnd => I32(&self.motor_end),
            Array::MotorJoint => I32(&self.motor_joint),
            Array::MotorAxis => F64(&self.motor_axis),
            Array::MotorTorque => F64(&self.motor_torque),
            Array::FirstFluid => I64(&self.first_fluid),
            Array::FluidDrag => F64(&self.fluid_drag),
            Array::FluidDensity => F64(&self.fluid_density),
            Array::Radius => F64(&self.radius),
            Array::Volume => F64(&self.volume),
            Array::Restitution => F64(&self.restitution),
            Array::MuS => F64(&self.mu_s),
            Array::MuK => F64(&self.mu_k),
            Array::Failed => I64(&self.failed),
            Array::FirstPush => I64(&self.first_push),
            Array::PushParticle => I32(&self.push_particle),
            Array::PushForce => F64(&self.push_force),
            Array::FirstPair => I64(&self.first_pair),
            Array::PairA => I32(&self.pair_a),
            Array::PairB => I32(&self.pair_b),
            Array::PairStiffness => F64(&self.pair_stiffness),
            Array::PairDamping => F64(&self.pair_damping),
            Array::FirstMuscle => I64(&self.ev.first_muscle),
            Array::MuscleSpring => I32(&self.ev.muscle_spring),
            Array::MuscleParam => F64(&self.ev.muscle_param),
            Array::MuscleLevel => F64(&self.ev.muscle_level),
            Array::FirstOsc => I64(&self.ev.first_osc),
            Array::OscFrequency => F64(&self.ev.osc_frequency),
            Array::FirstOutput => I64(&self.ev.first_output),
            Array::OutputMuscle => I32(&self.ev.output_muscle),
            Array::OutputGene => F64(&self.ev.output_gene),
            Array::FirstCentre => I64(&self.ev.first_centre),
            Array::CentreParticle => I32(&self.ev.centre_particle),
            Array::FirstTouch => I64(&self.ev.first_touch),
            Array::TouchParticle => I32(&self.ev.touch_particle),
            Array::FirstStretch => I64(&self.ev.first_stretch),
            Array::StretchPair => I32(&self.ev.stretch_pair),
            Array::StretchLength => F64(&self.ev.stretch_length),
            Array::Fixed => I32(&self.ev.fixed),
            Array::EvalParam => F64(&self.ev.eval_param),
            Array::EvalCount => I64(&self.ev.eval_count),
            Array::Result => F64(&self.ev.result),
            Array::Ended => I64(&self.ev.ended),
            Array::FirstMeasure => I64(&self.ev.first_measure),
            Array::MeasureKind => I32(&self.ev.measure_kind),
            Array::MeasureFirstId => I64(&self.ev.measure_first_id),
            Array::MeasureId => I32(&self.ev.measure_id),
            Array::MeasureAxis => F64(&self.ev.measure_axis),
            Array::MeasureFixed => F64(&self.ev.measure_fixed),
            Array::MeasureWeight => F64(&self.ev.measure_weight),
            Array::MeasureSum => F64(&self.ev.measure_sum),
            Array::MeasureStart => F64(&self.ev.measure_start),
            Array::FirstSensor => I64(&self.ev.first_sensor),
            Array::SensorKind => I32(&self.ev.sensor_kind),
            Array::SensorParticle => I32(&self.ev.sensor_particle),
            Array::SensorParam => F64(&self.ev.sensor_param),
            Array::SensorLevel => F64(&self.ev.sensor_level),
            Array::FirstCtrl => I64(&self.ev.first_ctrl),
            Array::CtrlKind => I32(&self.ev.ctrl_kind),
            Array::CtrlIndex => I32(&self.ev.ctrl_index),
            Array::NetFirstLayer => I64(&self.ev.net_first_layer),
            Array::LayerSize => I32(&self.ev.layer_size),
            Array::NetFirstWeight => I64(&self.ev.net_first_weight),
            Array::NetWeight => F64(&self.ev.net_weight),
            Array::NetClock => F64(&self.ev.net_clock),
            Array::NetFirstInput => I64(&self.ev.net_first_input),
            Array::NetInput => I32(&self.ev.net_input),
            Array::NetFirstOutput => I64(&self.ev.net_first_output),
            Array::NetOutputMuscle => I32(&self.ev.net_output_muscle),
            Array::NetOutputShift => F64(&self.ev.net_output_shift),
            Array::NetFirstScratch => I64(&self.ev.net_first_scratch),
            Array::NetScratch => F64(&self.ev.net_scratch),
            Array::NetFirstNeuron => I64(&self.ev.net_first_neuron),
            Array::NeuronParam => F64(&self.ev.neuron_param),
            Array::NeuronState => F64(&self.ev.neuron_state),
            Array::MuscleWork => F64(&self.ev.muscle_work),
            Array::MuscleKind => I32(&self.ev.muscle_kind),
            Array::MuscleBase => F64(&self.ev.muscle_base),
            Array::MusclePush => I32(&self.ev.muscle_push),
            Array::MuscleGate => F64(&self.ev.muscle_gate),
            Array::FirstRod => I64(&self.first_rod),
            Array::RodA => I32(&self.rod_a),
            Array::RodB => I32(&self.rod_b),
            Array::RodDrag => F64(&self.rod_drag),
            Array::FluidCurrent => F64(&self.fluid_current),
            Array::RodCurrent => F64(&self.rod_current),
            Array::FirstPlane => I64(&self.first_plane),
            Array::PlaneParam => F64(&self.plane_param),
            Array::PlaneFirstParticle => I64(&self.plane_first_particle),
            Array::PlaneParticle => I32(&self.plane_particle),
            Array::TerrainParam => F64(&self.terrain_param),
            Array::TerrainHeight => F64(&self.terrain_height),
            Array::FirstExcluded => I64(&self.first_excluded),
            Array::Excluded => I64(&self.excluded),
            Array::ContactParam => F64(&self.contact_param),
            Array::FirstSlot => I64(&self.first_slot),
            Array::ContactSlot => I64(&self.contact_slot),
            Array::FirstNbody => I64(&self.first_nbody),
            Array::NbodyParam => F64(&self.nbody_param),
            Array::NbodyFirstBody => I64(&self.nbody_first_body),
            Array::NbodyBody => I32(&self.nbody_body),
            Array::NbodyFirstRange => I64(&self.nbody_first_range),
            Array::NbodyRange => I64(&self.nbody_range),
            Array::Clock => F64(&self.clock),
            Array::Implicit => F64(&self.implicit),
        }
    }

    /// Positions, velocities and failures written back (from a GPU).
    pub(crate) fn set_state(&mut self, pos: &[f64], vel: &[f64], failed: &[i64], clock: &[f64]) {
        let n = self.pos.len();
        self.pos.copy_from_slice(&pos[..n]);
        self.vel.copy_from_slice(&vel[..n]);
        let c = self.failed.len();
        self.failed.copy_from_slice(&failed[..c]);
        let k = self.clock.len();
        self.clock.copy_from_slice(&clock[..k]);
    }

    /// Counts `steps` more taken (by a GPU run).
    pub(crate) fn ran(&mut self, steps: u64) {
        self.steps_run = self.steps_run.saturating_add(steps);
    }

    /// The step (1-based, counted over every run) at which creature `c`'s
    /// state stopped being finite, where the engine's step returns
    /// `SimError::NonFinite`; it is not stepped further.
    pub fn failed(&self, c: usize) -> Option<u64> {
        self.failed
            .get(c)
            .and_then(|&s| (s > 0).then_some(s as u64))
    }

    /// The C's struct with array `a` at address `at(a)`.
    pub(crate) fn raw_with(&self, at: impl Fn(Array) -> u64) -> Raw {
        let c = |a| at(a) as *const c_double;
        let m = |a| at(a) as *mut c_double;
        let i = |a| at(a) as *const c_int;
        let l = |a| at(a) as *const c_longlong;
        Raw {
            first_particle: l(Array::FirstParticle),
            first_spring: l(Array::FirstSpring),
            inv_mass: c(Array::InvMass),
            mass: c(Array::Mass),
            pos: m(Array::Pos),
            vel: m(Array::Vel),
            spring_a: i(Array::SpringA),
            spring_b: i(Array::SpringB),
            stiffness: c(Array::Stiffness),
            damping: c(Array::Damping),
            rest_length: m(Array::RestLength),
            scratch: m(Array::Scratch),
            first_joint: l(Array::FirstJoint),
            joint_a: i(Array::JointA),
            joint_j: i(Array::JointJ),
            joint_b: i(Array::JointB),
            joint_stiffness: c(Array::JointStiffness),
            joint_damping: c(Array::JointDamping),
            joint_rest: m(Array::JointRest),
            first_motor: l(Array::FirstMotor),
            motor_end: i(Array::MotorEnd),
            motor_joint: i(Array::MotorJoint),
            motor_axis: c(Array::MotorAxis),
            motor_torque: m(Array::MotorTorque),
            first_fluid: l(Array::FirstFluid),
            fluid_drag: c(Array::FluidDrag),
            fluid_density: c(Array::FluidDensity),
            radius: c(Array::Radius),
            volume: c(Array::Volume),
            restitution: c(Array::Restitution),
            mu_s: c(Array::MuS),
            mu_k: c(Array::MuK),
            failed: at(Array::Failed) as *mut c_longlong,
            steps_before: self.steps_run.min(i64::MAX as u64) as c_longlong,
            first_push: l(Array::FirstPush),
            push_particle: i(Array::PushParticle),
            push_force: m(Array::PushForce),
            gx: self.g.x,
            gy: self.g.y,
            gz: self.g.z,
            gravity: c_int::from(self.gravity),
            integrator: self.integrator_code(),
            dt: self.dt,
            floor: c_int::from(self.floor.is_some()),
            floor_contact: c_int::from(self.floor.as_ref().is_some_and(|f| f.contact.is_some())),
            envelope: self.floor.as_ref().map_or(0.0, |f| f.envelope),
            rest_speed: self.floor.as_ref().map_or(0.0, |f| f.rest_speed),
            static_speed: self
                .floor
                .as_ref()
                .and_then(|f| f.contact)
                .map_or(0.0, |c| c.0),
            contact_tolerance: self
                .floor
                .as_ref()
                .and_then(|f| f.contact)
                .map_or(0.0, |c| c.1),
            flight_shift: self.integrator.free_flight_shift(),
            first_pair: l(Array::FirstPair),
            pair_a: i(Array::PairA),
            pair_b: i(Array::PairB),
            pair_stiffness: c(Array::PairStiffness),
            pair_damping: c(Array::PairDamping),
            first_muscle: l(Array::FirstMuscle),
            muscle_spring: i(Array::MuscleSpring),
            muscle_param: c(Array::MuscleParam),
            muscle_level: m(Array::MuscleLevel),
            first_osc: l(Array::FirstOsc),
            osc_frequency: c(Array::OscFrequency),
            first_output: l(Array::FirstOutput),
            output_muscle: i(Array::OutputMuscle),
            output_gene: c(Array::OutputGene),
            first_centre: l(Array::FirstCentre),
            centre_particle: i(Array::CentreParticle),
            first_touch: l(Array::FirstTouch),
            touch_particle: i(Array::TouchParticle),
            first_stretch: l(Array::FirstStretch),
            stretch_pair: i(Array::StretchPair),
            stretch_length: c(Array::StretchLength),
            fixed: i(Array::Fixed),
            eval_param: c(Array::EvalParam),
            eval_count: l(Array::EvalCount),
            result: m(Array::Result),
            ended: at(Array::Ended) as *mut c_longlong,
            first_measure: l(Array::FirstMeasure),
            measure_kind: i(Array::MeasureKind),
            measure_first_id: l(Array::MeasureFirstId),
            measure_id: i(Array::MeasureId),
            measure_axis: c(Array::MeasureAxis),
            measure_fixed: c(Array::MeasureFixed),
            measure_weight: c(Array::MeasureWeight),
            measure_sum: m(Array::MeasureSum),
            measure_start: m(Array::MeasureStart),
            first_sensor: l(Array::FirstSensor),
            sensor_kind: i(Array::SensorKind),
            sensor_particle: i(Array::SensorParticle),
            sensor_param: c(Array::SensorParam),
            sensor_level: m(Array::SensorLevel),
            first_ctrl: l(Array::FirstCtrl),
            ctrl_kind: i(Array::CtrlKind),
            ctrl_index: i(Array::CtrlIndex),
            net_first_layer: l(Array::NetFirstLayer),
            layer_size: i(Array::LayerSize),
            net_first_weight: l(Array::NetFirstWeight),
            net_weight: c(Array::NetWeight),
            net_clock: c(Array::NetClock),
            net_first_input: l(Array::NetFirstInput),
            net_input: i(Array::NetInput),
            net_first_output: l(Array::NetFirstOutput),
            net_output_muscle: i(Array::NetOutputMuscle),
            net_output_shift: c(Array::NetOutputShift),
            net_first_scratch: l(Array::NetFirstScratch),
            net_scratch: m(Array::NetScratch),
            net_first_neuron: l(Array::NetFirstNeuron),
            neuron_param: c(Array::NeuronParam),
            neuron_state: m(Array::NeuronState),
            muscle_work: m(Array::MuscleWork),
            muscle_kind: i(Array::MuscleKind),
            muscle_base: c(Array::MuscleBase),
            muscle_push: i(Array::MusclePush),
            muscle_gate: c(Array::MuscleGate),
            first_rod: l(Array::FirstRod),
            rod_a: i(Array::RodA),
            rod_b: i(Array::RodB),
            rod_drag: c(Array::RodDrag),
            fluid_current: c(Array::FluidCurrent),
            rod_current: c(Array::RodCurrent),
            first_plane: l(Array::FirstPlane),
            plane_param: c(Array::PlaneParam),
            plane_first_particle: l(Array::PlaneFirstParticle),
            plane_particle: i(Array::PlaneParticle),
            terrain_param: c(Array::TerrainParam),
            terrain_height: c(Array::TerrainHeight),
            terrain: self.terrain,
            first_excluded: l(Array::FirstExcluded),
            excluded: l(Array::Excluded),
            contact_param: c(Array::ContactParam),
            first_slot: l(Array::FirstSlot),
            contact_slot: at(Array::ContactSlot) as *mut c_longlong,
            first_nbody: l(Array::FirstNbody),
            nbody_param: c(Array::NbodyParam),
            nbody_first_body: l(Array::NbodyFirstBody),
            nbody_body: i(Array::NbodyBody),
            nbody_first_range: l(Array::NbodyFirstRange),
            nbody_range: l(Array::NbodyRange),
            clock: m(Array::Clock),
            implicit: m(Array::Implicit),
            solver_tolerance: self.solver.tolerance,
            solver_iterations: c_longlong::from(self.solver.max_iterations),
            absent: self.absent(),
        }
    }
}

/// The most particles a world with sphere contact may hold for the C (each
/// creature's room for the pairs a check finds: `n (n − 1) / 2` numbers,
/// 16 MiB at this size).
const MAX_SPHERES: usize = 2048;

/// The most plane constraints a world may hold for the C (it notes which
/// of them a trial leaves, before handling any event, in one 64-bit word).
const MAX_PLANES: usize = 64;

/// Whether the C steps world `w` as the engine does: `Err` names the first
/// thing it holds that the C does not step.
fn supported(w: &World) -> Result<(), String> {
    use animats_engine::Targets;
    let f = w.forces();
    let refuse = |what: &str| Err(format!("{what} is not in the GPU step yet"));
    match w.integrator() {
        IntegratorKind::Euler
        | IntegratorKind::Midpoint
        | IntegratorKind::Rk4
        | IntegratorKind::Symplectic
        | IntegratorKind::Implicit => {}
    }
    let mut planes = 0;
    let mut floors = 0;
    let mut contacts = 0;
    for e in w.events() {
        let any = e.as_any();
        planes += usize::from(any.is::<PlaneConstraint>());
        floors += usize::from(any.is::<FloorCollision>());
        if let Some(c) = any.downcast_ref::<SphereContact>() {
            contacts += 1;
            let d = c.def();
            if d.sleep_speed > 0.0 {
                return refuse("sphere contact with sleeping (`sleep_speed` > 0)");
            }
            if d.targets != Targets::All {
                return refuse("sphere contact among some particles only");
            }
            if floors == 0 && w.events().iter().any(|e| e.as_any().is::<FloorCollision>()) {
                return refuse("sphere contact before the floor among the world's events");
            }
        } else if !any.is::<FloorCollision>() && !any.is::<PlaneConstraint>() {
            return refuse(&format!("the event `{}`", e.name()));
        }
    }
    if contacts > 1 {
        return refuse("a second sphere contact");
    }
    // (Its room for pairs grows as the square of the particles.)
    if contacts > 0 && w.len() > MAX_SPHERES {
        return refuse(&format!(
            "sphere contact among more than {MAX_SPHERES} particles"
        ));
    }
    if contacts > 0 && planes > 0 {
        return refuse("sphere contact with plane constraints");
    }
    if contacts > 0 && w.terrain().is_some_and(|t| !t.is_flat()) {
        return refuse("sphere contact on terrain");
    }
    if floors > 1 {
        return refuse("a second floor");
    }
    if planes > MAX_PLANES {
        return refuse(&format!("more than {MAX_PLANES} plane constraints"));
    }
    if planes > 0 && w.terrain().is_some_and(|t| !t.is_flat()) {
        return refuse("a plane constraint on terrain");
    }
    if f.gravity().is_some_and(|g| g.targets != Targets::All) {
        return refuse("gravity on some particles only");
    }
    for fl in f.fluids() {
        if fl.targets != Targets::All {
            return refuse("a fluid about some particles only");
        }
    }
    // Soft contact and drag across springs are the user forces the C
    // steps (body-stage forces, after the fluids, as the engine orders
    // them): every soft contact, then every rod drag.
    let mut rods_seen = false;
    for u in f.user() {
        let any = u.as_any();
        let soft = any.is_some_and(|a| a.is::<SoftContact>());
        let rods = any.is_some_and(|a| a.is::<RodDrag>());
        if !(soft || rods) || u.stage() != animats_engine::Stage::Body || (soft && rods_seen) {
            return refuse(&format!("the user force `{}`", u.name()));
        }
        rods_seen |= rods;
    }
    Ok(())
}

/// A fluid's current as the C reads it (`kernel/step.h`, `an_current`):
/// its uniform velocity (0 in still water), then NaN; or a reef's drift,
/// then its surface, `amplitude × ω`, `k`, `ω` and its direction
/// normalised (forces/current.rs, `ReefWater::velocity`, which forms each
/// of them so).
fn current(c: &animats_engine::Current) -> [f64; CURRENT] {
    use animats_engine::Current;
    use std::f64::consts::TAU;
    let uniform = |u: DVec3| [u.x, u.y, u.z, f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    match c {
        Current::Still => uniform(DVec3::ZERO),
        Current::Uniform(v) => uniform(*v),
        Current::Reef(r) => {
            let k = TAU / r.wavelength;
            let omega = TAU / r.period;
            let dir = DVec3::new(r.direction.x, 0.0, r.direction.z).normalize_or_zero();
            [
                r.drift.x,
                r.drift.y,
                r.drift.z,
                1.0,
                r.surface,
                r.amplitude * omega,
                k,
                omega,
                dir.x,
                dir.y,
                dir.z,
            ]
        }
    }
}

/// One of a batch's arrays, borrowed.
pub(crate) enum Slice<'a> {
    F64(&'a [f64]),
    I32(&'a [i32]),
    I64(&'a [i64]),
}

/// The arrays of a batch, in the order of the C's struct.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Array {
    FirstParticle,
    FirstSpring,
    InvMass,
    Mass,
    Pos,
    Vel,
    SpringA,
    SpringB,
    Stiffness,
    Damping,
    RestLength,
    Scratch,
    FirstJoint,
    JointA,
    JointJ,
    JointB,
    JointStiffness,
    JointDamping,
    JointRest,
    FirstMotor,
    MotorEnd,
    MotorJoint,
    MotorAxis,
    MotorTorque,
    FirstFluid,
    FluidDrag,
    FluidDensity,
    Radius,
    Volume,
    Restitution,
    MuS,
    MuK,
    Failed,
    FirstPush,
    PushParticle,
    PushForce,
    FirstPair,
    PairA,
    PairB,
    PairStiffness,
    PairDamping,
    FirstMuscle,
    MuscleSpring,
    MuscleParam,
    MuscleLevel,
    FirstOsc,
    OscFrequency,
    FirstOutput,
    OutputMuscle,
    OutputGene,
    FirstCentre,
    CentreParticle,
    FirstTouch,
    TouchParticle,
    FirstStretch,
    StretchPair,
    StretchLength,
    Fixed,
    EvalParam,
    EvalCount,
    Result,
    Ended,
    FirstMeasure,
    MeasureKind,
    MeasureFirstId,
    MeasureId,
    MeasureAxis,
    MeasureFixed,
    MeasureWeight,
    MeasureSum,
    MeasureStart,
    FirstSensor,
    SensorKind,
    SensorParticle,
    SensorParam,
    SensorLevel,
    FirstCtrl,
    CtrlKind,
    CtrlIndex,
    NetFirstLayer,
    LayerSize,
    NetFirstWeight,
    NetWeight,
    NetClock,
    NetFirstInput,
    NetInput,
    NetFirstOutput,
    NetOutputMuscle,
    NetOutputShift,
    NetFirstScratch,
    NetScratch,
    NetFirstNeuron,
    NeuronParam,
    NeuronState,
    MuscleWork,
    MuscleKind,
    MuscleBase,
    MusclePush,
    MuscleGate,
    FirstRod,
    RodA,
    RodB,
    RodDrag,
    FluidCurrent,
    RodCurrent,
    FirstPlane,
    PlaneParam,
    PlaneFirstParticle,
    PlaneParticle,
    TerrainParam,
    TerrainHeight,
    FirstExcluded,
    Excluded,
    ContactParam,
    FirstSlot,
    ContactSlot,
    FirstNbody,
    NbodyParam,
    NbodyFirstBody,
    NbodyBody,
    NbodyFirstRange,
    NbodyRange,
    Clock,
    Implicit,
}

impl Array {
    /// Every array, each at its own index (`a as usize`).
    pub(crate) const ALL: [Array; 124] = [
        Array::FirstParticle,
        Array::FirstSpring,
        Array::InvMass,
        Array::Mass,
        Array::Pos,
        Array::Vel,
        Array::SpringA,
        Array::SpringB,
        Array::Stiffness,
        Array::Damping,
        Array::RestLength,
        Array::Scratch,
        Array::FirstJoint,
        Array::JointA,
        Array::JointJ,
        Array::JointB,
        Array::JointStiffness,
        Array::JointDamping,
        Array::JointRest,
        Array::FirstMotor,
        Array::MotorEnd,
        Array::MotorJoint,
        Array::MotorAxis,
        Array::MotorTorque,
        Array::FirstFluid,
        Array::FluidDrag,
        Array::FluidDensity,
        Array::Radius,
        Array::Volume,
        Array::Restitution,
        Array::MuS,
        Array::MuK,
        Array::Failed,
        Array::FirstPush,
        Array::PushParticle,
        Array::PushForce,
        Array::FirstPair,
        Array::PairA,
        Array::PairB,
        Array::PairStiffness,
        Array::PairDamping,
        Array::FirstMuscle,
        Array::MuscleSpring,
        Array::MuscleParam,
        Array::MuscleLevel,
        Array::FirstOsc,
        Array::OscFrequency,
        Array::FirstOutput,
        Array::OutputMuscle,
        Array::OutputGene,
        Array::FirstCentre,
        Array::CentreParticle,
        Array::FirstTouch,
        Array::TouchParticle,
        Array::FirstStretch,
        Array::StretchPair,
        Array::StretchLength,
        Array::Fixed,
        Array::EvalParam,
        Array::EvalCount,
        Array::Result,
        Array::Ended,
        Array::FirstMeasure,
        Array::MeasureKind,
        Array::MeasureFirstId,
        Array::MeasureId,
        Array::MeasureAxis,
        Array::MeasureFixed,
        Array::MeasureWeight,
        Array::MeasureSum,
        Array::MeasureStart,
        Array::FirstSensor,
        Array::SensorKind,
        Array::SensorParticle,
        Array::SensorParam,
        Array::SensorLevel,
        Array::FirstCtrl,
        Array::CtrlKind,
        Array::CtrlIndex,
        Array::NetFirstLayer,
        Array::LayerSize,
        Array::NetFirstWeight,
        Array::NetWeight,
        Array::NetClock,
        Array::NetFirstInput,
        Array::NetInput,
        Array::NetFirstOutput,
        Array::NetOutputMuscle,
        Array::NetOutputShift,
        Array::NetFirstScratch,
        Array::NetScratch,
        Array::NetFirstNeuron,
        Array::NeuronParam,
        Array::NeuronState,
        Array::MuscleWork,
        Array::MuscleKind,
        Array::MuscleBase,
        Array::MusclePush,
        Array::MuscleGate,
        Array::FirstRod,
        Array::RodA,
        Array::RodB,
        Array::RodDrag,
        Array::FluidCurrent,
        Array::RodCurrent,
        Array::FirstPlane,
        Array::PlaneParam,
        Array::PlaneFirstParticle,
        Array::PlaneParticle,
        Array::TerrainParam,
        Array::TerrainHeight,
        Array::FirstExcluded,
        Array::Excluded,
        Array::ContactParam,
        Array::FirstSlot,
        Array::ContactSlot,
        Array::FirstNbody,
        Array::NbodyParam,
        Array::NbodyFirstBody,
        Array::NbodyBody,
        Array::NbodyFirstRange,
        Array::NbodyRange,
        Array::Clock,
        Array::Implicit,
    ];
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_array_is_listed_once_at_its_own_index() {
        for (k, a) in super::Array::ALL.iter().enumerate() {
            assert_eq!(*a as usize, k);
        }
    }
}

/// A batch's floor, under every particle: the plane y = 0 or terrain.
#[derive(Clone)]
struct Floor {
    envelope: f64,
    rest_speed: f64,
    /// The contact force's static speed and contact tolerance, if it has one.
    contact: Option<(f64, f64)>,
    /// The ground's shape.
    terrain: Arc<Terrain>,
}

impl PartialEq for Floor {
    fn eq(&self, other: &Floor) -> bool {
        (self.envelope, self.rest_speed, self.contact)
            == (other.envelope, other.rest_speed, other.contact)
            && (Arc::ptr_eq(&self.terrain, &other.terrain) || self.terrain == other.terrain)
    }
}

impl std::fmt::Debug for Floor {
    /// Its numbers and the ground's kind (not a heightfield's heights).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ground = match &*self.terrain {
            Terrain::Flat => "flat".to_string(),
            Terrain::Slope(s) => format!("a slope of {} rad", s.angle),
            Terrain::Steps(s) => format!("{} steps", s.count),
            Terrain::Heightfield(h) => format!("a {} x {} heightfield", h.nx, h.nz),
        };
        write!(
            f,
            "envelope {}, rest speed {}, contact {:?}, ground {ground}",
            self.envelope, self.rest_speed, self.contact
        )
    }
}

/// The C's terrain (`kernel/terrain.h`): its kind, its numbers and a
/// heightfield's heights, each number as the engine computes it.
fn terrain_arrays(t: &Terrain) -> (c_int, Vec<f64>, Vec<f64>) {
    match t {
        Terrain::Flat => (0, Vec::new(), Vec::new()),
        Terrain::Slope(s) => (1, s.normal().to_array().to_vec(), Vec::new()),
        Terrain::Steps(s) => {
            let mut p = s.direction.to_array().to_vec();
            p.extend([s.start, s.height, s.depth, f64::from(s.count)]);
            (2, p, Vec::new())
        }
        Terrain::Heightfield(h) => (
            3,
            vec![
                h.origin.x,
                h.origin.y,
                h.cell,
                h.steepest_cos(),
                h.nx as f64,
                h.nz as f64,
            ],
            h.heights.clone(),
        ),
    }
}

/// World `w`'s floor, if it has one the C steps (under every particle);
/// `Err` names what it does not.
fn floor_of(w: &World) -> Result<Option<Floor>, String> {
    use animats_engine::Targets;
    let collision = w
        .events()
        .iter()
        .find_map(|e| e.as_any().downcast_ref::<FloorCollision>());
    let contact = w.forces().floor();
    let Some(collision) = collision else {
        return match contact {
            None => Ok(None),
            Some(_) => Err(
                "a floor contact force without its collisions is not in the GPU step yet".into(),
            ),
        };
    };
    if contact.is_some_and(|c| *c.terrain != *collision.terrain()) {
        return Err("a floor whose contact force and collisions meet different ground is not in the GPU step yet".into());
    }
    if collision.targets != Targets::All || contact.is_some_and(|c| c.targets != Targets::All) {
        return Err("a floor under some particles only is not in the GPU step yet".into());
    }
    if contact.is_some_and(|c| c.rest_speed.to_bits() != collision.rest_speed.to_bits()) {
        return Err("a floor whose contact and collisions rest at different speeds is not in the GPU step yet".into());
    }
    Ok(Some(Floor {
        envelope: collision.envelope,
        rest_speed: collision.rest_speed,
        contact: contact.map(|c| (c.static_speed, c.contact_tolerance)),
        terrain: Arc::clone(collision.shared_terrain()),
    }))
}
