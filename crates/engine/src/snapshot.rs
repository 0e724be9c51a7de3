//! Saving and restoring a world's state (serde), for checkpoints, for
//! branching a run, and for the Python API's `snapshot` / `restore`.
//!
//! A snapshot holds everything that changes while a world runs: the clock,
//! every particle's position, velocity, mass, volume and radius, and the parameters
//! that actuators and users drive (spring, angle-joint and torque-joint
//! parameters, constant forces, gravity). It does not hold the world's
//! structure (which particles, which forces join them, the integrator): it
//! is restored into the world it came from, or into one built the same way
//! (from the same scene file), and a restored world continues bit for bit as
//! the original did. It holds sphere contact's sleep too (`sleep_speed`:
//! which spheres sleep, where, and what each was doing), so a pile whose
//! rocks had fallen asleep goes on asleep. Fluid currents and user forces
//! and events keep their own state. Formats must round-trip `f64` exactly
//! (serde_json with `float_roundtrip`, bincode, ...).

use crate::error::ModelError;
use crate::events::sphere_contact::{SleepState, SphereContact};
use crate::forces::{angle_joint::AngleJointId, constant_force::ConstantForceId};
use crate::forces::{spring::SpringId, torque_joint::TorqueJointId};
use crate::particle::sphere_radius;
use crate::world::{Stats, World};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The state of a world at one instant; see the module documentation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Simulated time, s.
    pub time: f64,
    /// The clock's rounding carry (Kahan summation), s.
    pub time_carry: f64,
    /// Totals since the world was created.
    pub stats: Stats,
    /// Positions, m.
    pub positions: Vec<[f64; 3]>,
    /// Velocities, m/s.
    pub velocities: Vec<[f64; 3]>,
    /// Masses, kg.
    pub masses: Vec<f64>,
    /// Volumes, m³.
    pub volumes: Vec<f64>,
    /// Radii, m, as they were: a radius given with a particle is not the
    /// cube root of its volume to the last bit. (Absent from snapshots
    /// written before it was held: then each radius follows its volume.)
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub radii: Vec<f64>,
    /// Each spring's (stiffness, damping, rest length).
    pub springs: Vec<[f64; 3]>,
    /// Each angle joint's (stiffness, damping, rest angle).
    pub angle_joints: Vec<[f64; 3]>,
    /// Each torque joint's torque, then its axis.
    pub torque_joints: Vec<[f64; 4]>,
    /// Each constant force's vector, N.
    pub constant_forces: Vec<[f64; 3]>,
    /// The gravitational acceleration, if the world has gravity.
    pub gravity: Option<[f64; 3]>,
    /// Sphere contact's sleep, when its spheres may sleep and the world
    /// has stepped (absent from snapshots of other worlds, and from those
    /// written before it was held).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sleep: Option<SleepState>,
}

fn mismatch(field: &'static str, got: usize, want: usize) -> ModelError {
    ModelError::new(
        field,
        format!("the snapshot has {got} {field}, this world {want}: it is of another world"),
    )
}

fn finite(field: &'static str, xs: &[f64]) -> Result<(), ModelError> {
    match xs.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(ModelError::new(field, format!("not finite: {x}"))),
        None => Ok(()),
    }
}

impl World {
    /// The world's state now (see [`Snapshot`]).
    pub fn snapshot(&self) -> Snapshot {
        let f = &self.forces;
        Snapshot {
            time: self.time,
            time_carry: self.time_carry,
            stats: self.stats,
            positions: self.state.pos.iter().map(|x| x.to_array()).collect(),
            velocities: self.state.vel.iter().map(|v| v.to_array()).collect(),
            masses: self.particles.mass.clone(),
            volumes: self.particles.volume.clone(),
            radii: self.particles.radius.clone(),
            springs: f
                .springs
                .iter()
                .map(|s| [s.stiffness, s.damping, s.rest_length])
                .collect(),
            angle_joints: f
                .angle_joints
                .iter()
                .map(|j| [j.stiffness, j.damping, j.rest_angle])
                .collect(),
            torque_joints: f
                .torque_joints
                .iter()
                .map(|j| {
                    let a = j.axis();
                    [j.torque, a.x, a.y, a.z]
                })
                .collect(),
            constant_forces: f
                .constant_forces
                .iter()
                .map(|c| c.force.to_array())
                .collect(),
            gravity: f.gravity.as_ref().map(|g| g.g.to_array()),
            sleep: self
                .event::<SphereContact>()
                .and_then(SphereContact::sleep_state),
        }
    }

    /// Puts the world back in the state `s`, which must come from this world
    /// or one built the same way. Checks everything before changing anything:
    /// on an error the world is as it was.
    pub fn restore(&mut self, s: &Snapshot) -> Result<(), ModelError> {
        self.check_snapshot(s)?;
        // Everything checked: apply.
        self.apply_snapshot(s);
        Ok(())
    }

    /// Whether `s` fits this world: the same particles, forces and sleep,
    /// every value usable; the error names the field.
    fn check_snapshot(&self, s: &Snapshot) -> Result<(), ModelError> {
        let n = self.len();
        let f = &self.forces;
        for (field, got, want) in [
            ("positions", s.positions.len(), n),
            ("velocities", s.velocities.len(), n),
            ("masses", s.masses.len(), n),
            ("volumes", s.volumes.len(), n),
            ("springs", s.springs.len(), f.springs.len()),
            ("angle_joints", s.angle_joints.len(), f.angle_joints.len()),
            (
                "torque_joints",
                s.torque_joints.len(),
                f.torque_joints.len(),
            ),
            (
                "constant_forces",
                s.constant_forces.len(),
                f.constant_forces.len(),
            ),
        ] {
            if got != want {
                return Err(mismatch(field, got, want));
            }
        }
        if s.gravity.is_some() != f.gravity.is_some() {
            return Err(ModelError::new(
                "gravity",
                "the snapshot and this world differ in having gravity",
            ));
        }
        finite("time", &[s.time, s.time_carry])?;
        finite("positions", s.positions.as_flattened())?;
        finite("velocities", s.velocities.as_flattened())?;
        finite("springs", s.springs.as_flattened())?;
        finite("angle_joints", s.angle_joints.as_flattened())?;
        finite("torque_joints", s.torque_joints.as_flattened())?;
        finite("constant_forces", s.constant_forces.as_flattened())?;
        finite("gravity", s.gravity.as_ref().map_or(&[], |g| &g[..]))?;
        if let Some(x) = s.masses.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
            return Err(ModelError::new("masses", format!("must be > 0, got {x}")));
        }
        if let Some(x) = s.volumes.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
            return Err(ModelError::new("volumes", format!("must be >= 0, got {x}")));
        }
        if !s.radii.is_empty() && s.radii.len() != n {
            return Err(mismatch("radii", s.radii.len(), n));
        }
        if let Some(x) = s.radii.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
            return Err(ModelError::new("radii", format!("must be >= 0, got {x}")));
        }
        if let Some(k) = s
            .springs
            .iter()
            .position(|p| p[0] < 0.0 || p[1] < 0.0 || p[2] <= 0.0)
        {
            return Err(ModelError::new(
                "springs",
                format!("spring #{k} has a negative parameter or a rest length <= 0"),
            ));
        }

        if let Some(sleep) = &s.sleep {
            let why = match self.event::<SphereContact>() {
                None => Some("this world has no sphere contact"),
                Some(c) if c.def().sleep_speed <= 0.0 => {
                    Some("this world's spheres never sleep (sleep_speed 0)")
                }
                Some(_) => None,
            };
            if let Some(why) = why {
                return Err(ModelError::new(
                    "sleep",
                    format!("the snapshot has sleeping spheres, {why}: it is of another world"),
                ));
            }
            sleep.check(n)?;
        }
        Ok(())
    }

    /// Puts a checked snapshot's values in place.
    fn apply_snapshot(&mut self, s: &Snapshot) {
        let n = self.len();
        if let Some(contact) = self.event_mut::<SphereContact>() {
            contact.restore_sleep(s.sleep.as_ref());
        }
        self.time = s.time;
        self.time_carry = s.time_carry;
        self.stats = s.stats;
        let p = &mut self.particles;
        for i in 0..n {
            self.state.pos[i] = DVec3::from_array(s.positions[i]);
            self.state.vel[i] = if p.fixed[i] {
                DVec3::ZERO
            } else {
                DVec3::from_array(s.velocities[i])
            };
            p.mass[i] = s.masses[i];
            p.set_inv_mass(i, if p.fixed[i] { 0.0 } else { 1.0 / s.masses[i] });
            p.volume[i] = s.volumes[i];
            p.radius[i] = s
                .radii
                .get(i)
                .copied()
                .unwrap_or_else(|| sphere_radius(s.volumes[i]));
        }
        let f = &mut self.forces;
        for (k, q) in s.springs.iter().enumerate() {
            let id = SpringId(k as u32);
            f.springs.set_stiffness(id, q[0]);
            f.springs.set_damping(id, q[1]);
            f.springs.set_rest_length(id, q[2]);
        }
        for (k, q) in s.angle_joints.iter().enumerate() {
            let joint = f.angle_joints.get_mut(AngleJointId(k as u32));
            (joint.stiffness, joint.damping, joint.rest_angle) = (q[0], q[1], q[2]);
        }
        for (k, q) in s.torque_joints.iter().enumerate() {
            let joint = f.torque_joints.get_mut(TorqueJointId(k as u32));
            joint.torque = q[0];
            // As saved: it was normalised when set.
            joint.axis = DVec3::new(q[1], q[2], q[3]);
        }
        for (k, c) in s.constant_forces.iter().enumerate() {
            f.constant_forces
                .set(ConstantForceId(k as u32), DVec3::from_array(*c));
        }
        if let (Some(g), Some(gravity)) = (s.gravity, &mut f.gravity) {
            gravity.g = DVec3::from_array(g);
        }
    }
}
