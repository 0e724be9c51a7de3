//! The roobot's body (thesis §3.2.1.1, Figure 8): a hip and a foot joined by
//! a telescoping leg spring, a head on a neck spring, a two-segment tail,
//! angle joints holding neck and tail to the leg, and motors at hip and ankle.
//!
//! The thesis gives only the hip (0.4 kg) and foot (0.1 kg) masses. The other
//! constants are ours, chosen for a small, springy, planar hopper (about the
//! size of a rabbit) that stays stable with RK4 at the thesis's 8 ms step:
//! the stiffest mode (foot on the leg spring) has ωh ≈ 0.6, far inside RK4's
//! stability limit of 2.8. Leg stiffness and damping, motor strengths and
//! tail mass were chosen by a search over body designs (docs/ROOBOT.md) for
//! the one that behaves as the thesis's did: Appendix B's initial parameters
//! hop and fall within a few landings, and the thesis's evolver finds stable
//! hopping within 100 generations in most lanes. Every constant is in
//! [`BodyConstants::STANDARD`].

use animats_engine::math;
use animats_engine::{
    AngleJointDef, DVec3, ModelError, ParticleDef, ParticleId, PlaneConstraint, SpringDef,
    SpringId, TorqueJointDef, TorqueJointId, World,
};

/// A sphere of the body: mass (kg), radius (m), and its offset from the hip
/// in the body's plane (forward, up), m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Part {
    /// kg.
    pub mass: f64,
    /// m.
    pub radius: f64,
    /// (forward, up) from the hip, m; ignored for hip and foot.
    pub offset: (f64, f64),
}

/// A damped spring's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringConstants {
    /// N/m.
    pub stiffness: f64,
    /// N s/m.
    pub damping: f64,
}

/// An angle joint's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointConstants {
    /// N m/rad.
    pub stiffness: f64,
    /// N m s/rad.
    pub damping: f64,
}

/// Everything that defines the body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyConstants {
    /// The hip (thesis: 0.4 kg).
    pub hip: Part,
    /// The foot (thesis: 0.1 kg).
    pub foot: Part,
    /// The head.
    pub head: Part,
    /// First tail segment.
    pub tail1: Part,
    /// Tail tip.
    pub tail2: Part,
    /// Leg spring.
    pub leg: SpringConstants,
    /// Leg rest length at actuator level 0 and 1, m.
    pub leg_range: (f64, f64),
    /// Leg actuator level at rest (the standing leg).
    pub leg_initial_level: f64,
    /// Leg length beyond which an evaluation stops, m (thesis: 1.0).
    pub leg_limit: f64,
    /// Neck spring (hip–head).
    pub neck: SpringConstants,
    /// Tail springs (hip–tail1, tail1–tail2).
    pub tail: SpringConstants,
    /// Angle joint foot–hip–head.
    pub neck_joint: JointConstants,
    /// Angle joint foot–hip–tail1.
    pub tail_joint: JointConstants,
    /// Angle joint hip–tail1–tail2.
    pub tail_tip_joint: JointConstants,
    /// Hip motor torque at levels 0 and 1 (level 0.5 is no torque), N m.
    pub hip_torque: f64,
    /// Ankle motor torque magnitude at levels 0 and 1, N m.
    pub ankle_torque: f64,
    /// Foot friction (static, kinetic) and restitution.
    pub foot_contact: (f64, f64, f64),
    /// Leg-angle sensor gain: level = 0.5 + gain × angle (rad). We use the
    /// evident intent of Appendix B, 1/(2π) (see `sensors/tilt.rs`).
    pub leg_angle_gain: f64,
    /// Friction and restitution of every other part.
    pub body_contact: (f64, f64, f64),
}

impl BodyConstants {
    /// The roobot used throughout animats (docs/ROOBOT.md).
    pub const STANDARD: BodyConstants = BodyConstants {
        hip: Part {
            mass: 0.4,
            radius: 0.05,
            offset: (0.0, 0.0),
        },
        foot: Part {
            mass: 0.1,
            radius: 0.03,
            offset: (0.0, 0.0),
        },
        head: Part {
            mass: 0.08,
            radius: 0.04,
            offset: (0.12, 0.12),
        },
        tail1: Part {
            mass: 0.06,
            radius: 0.025,
            offset: (-0.15, 0.02),
        },
        tail2: Part {
            mass: 0.045,
            radius: 0.02,
            offset: (-0.3, -0.02),
        },
        leg: SpringConstants {
            stiffness: 600.0,
            damping: 6.0,
        },
        leg_range: (0.2, 0.6),
        leg_initial_level: 0.5,
        leg_limit: 1.0,
        neck: SpringConstants {
            stiffness: 200.0,
            damping: 0.5,
        },
        tail: SpringConstants {
            stiffness: 150.0,
            damping: 0.3,
        },
        neck_joint: JointConstants {
            stiffness: 3.0,
            damping: 0.05,
        },
        tail_joint: JointConstants {
            stiffness: 3.0,
            damping: 0.05,
        },
        tail_tip_joint: JointConstants {
            stiffness: 0.5,
            damping: 0.01,
        },
        hip_torque: 1.0,
        ankle_torque: 2.0,
        foot_contact: (1.0, 0.8, 0.0),
        leg_angle_gain: 1.0 / std::f64::consts::TAU,
        body_contact: (0.5, 0.3, 0.3),
    };

    /// Rest length of the leg at actuator level `level`, m.
    pub fn leg_length(&self, level: f64) -> f64 {
        self.leg_range.0 + level * (self.leg_range.1 - self.leg_range.0)
    }
}

/// Handles to the parts of one roobot in a world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Hip (the body's centre).
    pub hip: ParticleId,
    /// Foot.
    pub foot: ParticleId,
    /// Head.
    pub head: ParticleId,
    /// Tail, first segment.
    pub tail1: ParticleId,
    /// Tail tip.
    pub tail2: ParticleId,
    /// The telescoping leg.
    pub leg: SpringId,
    /// Hip motor: turns the foot about the hip.
    pub hip_motor: TorqueJointId,
    /// Ankle motor: turns the hip about the foot.
    pub ankle_motor: TorqueJointId,
    /// Unit horizontal forward direction.
    pub forward: DVec3,
    /// The constants it was built with.
    pub constants: BodyConstants,
}

impl Body {
    /// The five particles, hip first.
    pub fn particles(&self) -> [ParticleId; 5] {
        [self.hip, self.foot, self.head, self.tail1, self.tail2]
    }

    /// Current leg length, m.
    pub fn leg_length(&self, world: &World) -> f64 {
        (world.position(self.hip) - world.position(self.foot)).length()
    }
}

/// Horizontal unit vector at `heading` radians from +x, turning towards -z
/// (counter-clockwise seen from above, the usual sense about +y).
pub fn forward(heading: f64) -> DVec3 {
    DVec3::new(math::cos(heading), 0.0, -math::sin(heading))
}

/// Builds a roobot standing upright with its foot on the floor at `base`
/// (y is ignored: the foot rests on y = 0), facing `heading`.
///
/// Motors turn about the body's horizontal axis `-(forward × up)`, so that a
/// positive torque leans the hip forward over the foot (ankle) and swings the
/// foot backward under the hip (hip), which is the sense of Appendix B's
/// levels above 0.5.
pub fn build(
    world: &mut World,
    c: &BodyConstants,
    base: DVec3,
    heading: f64,
) -> Result<Body, ModelError> {
    let f = forward(heading);
    let up = DVec3::Y;
    let foot_at = DVec3::new(base.x, c.foot.radius, base.z);
    let hip_at = foot_at + up * c.leg_length(c.leg_initial_level);
    let at = |p: &Part| hip_at + f * p.offset.0 + up * p.offset.1;
    let particle = |p: &Part, x: DVec3, contact: (f64, f64, f64)| {
        ParticleDef::new(p.mass)
            .with_radius(p.radius)
            .at(x)
            .with_friction(contact.0, contact.1)
            .with_restitution(contact.2)
    };
    let hip = world.add_particle(particle(&c.hip, hip_at, c.body_contact))?;
    let foot = world.add_particle(particle(&c.foot, foot_at, c.foot_contact))?;
    let head = world.add_particle(particle(&c.head, at(&c.head), c.body_contact))?;
    let tail1 = world.add_particle(particle(&c.tail1, at(&c.tail1), c.body_contact))?;
    let tail2 = world.add_particle(particle(&c.tail2, at(&c.tail2), c.body_contact))?;

    let leg = world.add_spring(SpringDef::new(hip, foot, c.leg.stiffness, c.leg.damping))?;
    world.add_spring(SpringDef::new(hip, head, c.neck.stiffness, c.neck.damping))?;
    world.add_spring(SpringDef::new(hip, tail1, c.tail.stiffness, c.tail.damping))?;
    world.add_spring(SpringDef::new(
        tail1,
        tail2,
        c.tail.stiffness,
        c.tail.damping,
    ))?;
    let joint = |a, j, b, k: &JointConstants| AngleJointDef::new(a, j, b, k.stiffness, k.damping);
    world.add_angle_joint(joint(foot, hip, head, &c.neck_joint))?;
    world.add_angle_joint(joint(foot, hip, tail1, &c.tail_joint))?;
    world.add_angle_joint(joint(hip, tail1, tail2, &c.tail_tip_joint))?;

    // Planar motion (thesis §3.2.1.1): the body lives in the vertical plane
    // through its foot along `forward`.
    world.add_event(Box::new(PlaneConstraint::new(
        foot_at,
        f.cross(up),
        vec![hip, foot, head, tail1, tail2],
    )));
    let axis = -f.cross(up);
    let hip_motor = world.add_torque_joint(TorqueJointDef {
        end: foot,
        joint: hip,
        axis,
        torque: 0.0,
    })?;
    let ankle_motor = world.add_torque_joint(TorqueJointDef {
        end: hip,
        joint: foot,
        axis,
        torque: 0.0,
    })?;
    Ok(Body {
        hip,
        foot,
        head,
        tail1,
        tail2,
        leg,
        hip_motor,
        ankle_motor,
        forward: f,
        constants: *c,
    })
}
