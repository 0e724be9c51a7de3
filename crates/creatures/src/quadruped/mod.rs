//! The (attempted) quadrupeds (thesis §3.2.3, §4.2.5): three models with a
//! flat rectangular torso of four masses fully connected by six springs, and
//! four legs of three designs. None of them walks; each fails the way the
//! thesis reports, for the reasons it gives:
//!
//! - **Model 1**, two-segment legs: the upper segment points up and out from
//!   the torso, the lower down and out to the floor, an angle joint holds the
//!   knee, and a 2-DOF hip joint holds the upper segment (here two angle
//!   joints against the torso's two edges at that corner). Nothing resists a
//!   knee swinging round the line from hip to foot: the knees twist, the legs
//!   lean over and the torso sinks to the floor.
//! - **Model 2**, single-segment legs each held by two angle joints (against
//!   the torso's front–back and left–right springs). It stands. Its actuators
//!   are eight torque joints and the four leg springs; a torque joint reacts
//!   only with a force on the torso, not a torque, so raising a pair of feet
//!   with them pours angular momentum into the whole body, which rises and
//!   turns over onto its back.
//! - **Model 3**, the angle joints replaced by pairs of springs from each foot
//!   to the neighbouring torso corners. It stands, but three springs act on
//!   every foot: changing one rest length to move a foot stretches the other
//!   two, and the foot goes somewhere else than intended.
//!
//! The thesis gives no dimensions; ours are a dog-sized frame (docs/SEAWORLD.md).

use crate::controller::{Actor, Status};
use animats_engine::math;
use animats_engine::{
    AngleJointDef, DVec3, ModelError, ParticleDef, ParticleId, SpringDef, SpringId, TorqueJointDef,
    TorqueJointId, World,
};

/// Which of the thesis's three designs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    /// Two-segment legs with angle-jointed knees (§3.2.3, Figure 14).
    TwoSegment,
    /// Single-segment legs held by angle joints (Figure 15).
    AngleJointed,
    /// Single-segment legs held by springs (Figure 16).
    Sprung,
}

impl Model {
    /// The thesis's number, 1 to 3.
    pub fn from_number(n: u32) -> Option<Model> {
        match n {
            1 => Some(Model::TwoSegment),
            2 => Some(Model::AngleJointed),
            3 => Some(Model::Sprung),
            _ => None,
        }
    }
    /// 1, 2 or 3.
    pub fn number(self) -> u32 {
        match self {
            Model::TwoSegment => 1,
            Model::AngleJointed => 2,
            Model::Sprung => 3,
        }
    }
}

/// Dimensions and constants (ours: the thesis gives none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadrupedConstants {
    /// Torso length (front to back) and width, m.
    pub torso: (f64, f64),
    /// Height of the torso above the floor, m.
    pub height: f64,
    /// Mass of each torso corner, kg.
    pub corner_mass: f64,
    /// Mass of each foot (and knee), kg.
    pub foot_mass: f64,
    /// How far out from its corner a foot stands, m.
    pub splay: f64,
    /// Torso springs: stiffness N/m, damping N s/m.
    pub torso_spring: (f64, f64),
    /// Leg springs (and support springs of model 3).
    pub leg_spring: (f64, f64),
    /// Angle joints: stiffness N m/rad, damping N m s/rad.
    pub joint: (f64, f64),
}

impl Default for QuadrupedConstants {
    fn default() -> Self {
        QuadrupedConstants {
            torso: (0.4, 0.2),
            height: 0.3,
            corner_mass: 0.5,
            foot_mass: 0.1,
            splay: 0.05,
            torso_spring: (2000.0, 5.0),
            leg_spring: (1000.0, 3.0),
            joint: (20.0, 0.2),
        }
    }
}

/// One leg's parts.
#[derive(Clone, Debug, PartialEq)]
pub struct Leg {
    /// The torso corner it hangs from.
    pub corner: ParticleId,
    /// The knee (model 1 only).
    pub knee: Option<ParticleId>,
    /// The foot.
    pub foot: ParticleId,
    /// The leg spring (corner–foot, or knee–foot for model 1).
    pub spring: SpringId,
    /// Torque joints swinging the foot forward/back and in/out (model 2).
    pub swing: Option<(TorqueJointId, TorqueJointId)>,
    /// Support springs to the front–back and left–right neighbours (model 3).
    pub supports: Option<(SpringId, SpringId)>,
}

/// A quadruped in a world.
#[derive(Clone, Debug)]
pub struct Quadruped {
    /// A name for reports.
    pub name: String,
    /// Which design.
    pub model: Model,
    /// Torso corners: front-left, front-right, back-right, back-left.
    pub corners: [ParticleId; 4],
    /// Legs, in the order of the corners.
    pub legs: Vec<Leg>,
    /// Forward direction at build time.
    pub forward: DVec3,
    /// The thesis's failing experiment, if this quadruped runs it.
    pub demo: Option<Demo>,
    performed: bool,
}

/// The experiment that shows a model's failure, started at `at` seconds:
/// model 2 raises its front feet (its front swing motors at 4 N m for
/// 0.4 s); model 3 tries to step its front-left foot 8 cm forward; model 1
/// needs no help to fail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Demo {
    /// When to start, s.
    pub at: f64,
}

/// How long model 2's demo drives its motors, s.
pub const RAISE_SECONDS: f64 = 0.4;

impl Quadruped {
    /// Builds a quadruped of `model` with its torso centred above `base`
    /// facing `heading` (radians from +x, counter-clockwise seen from above).
    pub fn build(
        world: &mut World,
        name: &str,
        model: Model,
        c: &QuadrupedConstants,
        base: DVec3,
        heading: f64,
    ) -> Result<Quadruped, ModelError> {
        let f = DVec3::new(math::cos(heading), 0.0, -math::sin(heading));
        let side = f.cross(DVec3::Y); // to the right
        let (l, w) = (c.torso.0 / 2.0, c.torso.1 / 2.0);
        let centre = DVec3::new(base.x, c.height, base.z);
        // front-left, front-right, back-right, back-left
        let offsets = [
            f * l - side * w,
            f * l + side * w,
            -f * l + side * w,
            -f * l - side * w,
        ];
        let corner = |o: DVec3| {
            ParticleDef::new(c.corner_mass)
                .with_radius(0.03)
                .at(centre + o)
        };
        let mut corners = [ParticleId::from_index(0); 4];
        for (i, o) in offsets.iter().enumerate() {
            corners[i] = world.add_particle(corner(*o))?;
        }
        for i in 0..4 {
            for j in i + 1..4 {
                world.add_spring(SpringDef::new(
                    corners[i],
                    corners[j],
                    c.torso_spring.0,
                    c.torso_spring.1,
                ))?;
            }
        }
        let mut legs = Vec::with_capacity(4);
        for (i, o) in offsets.iter().enumerate() {
            let out = DVec3::new(o.x, 0.0, o.z).normalize();
            let at = LegAt {
                corners,
                i,
                out,
                forward: f,
                side,
            };
            legs.push(match model {
                Model::TwoSegment => at.two_segments(world, c)?,
                Model::AngleJointed | Model::Sprung => at.one_segment(world, c, model)?,
            });
        }
        Ok(Quadruped {
            name: name.to_string(),
            model,
            corners,
            legs,
            forward: f,
            demo: None,
            performed: false,
        })
    }

    /// Centre of the torso.
    pub fn torso_centre(&self, world: &World) -> DVec3 {
        self.corners
            .iter()
            .map(|p| world.position(*p))
            .sum::<DVec3>()
            / 4.0
    }

    /// Unit normal of the torso (up when upright): from its diagonals.
    pub fn torso_normal(&self, world: &World) -> DVec3 {
        let p = |i: usize| world.position(self.corners[i]);
        // the diagonals front-right → back-left and front-left → back-right
        (p(3) - p(1)).cross(p(2) - p(0)).normalize_or_zero()
    }

    /// Model 2: turns the swing motors of the front pair to raise those feet
    /// forward (N m each; 0 stops).
    pub fn raise_front_feet(&self, world: &mut World, torque: f64) {
        for leg in &self.legs[..2] {
            if let Some((forward_back, _)) = leg.swing {
                world
                    .forces_mut()
                    .torque_joints
                    .set_torque(forward_back, torque);
            }
        }
    }

    /// Model 3: tries to step the front-left foot forward by `distance` m the
    /// way a designer would: lift it by shortening its leg spring and swing
    /// it by lengthening its spring to the back corner and shortening the
    /// other. Returns the intended displacement of the foot.
    pub fn step_front_left(&self, world: &mut World, distance: f64) -> DVec3 {
        let leg = &self.legs[0];
        if let Some((to_back, to_side)) = leg.supports {
            let springs = &mut world.forces_mut().springs;
            let lift = springs.get(leg.spring).rest_length;
            springs.set_rest_length(leg.spring, lift - 0.3 * distance);
            let back = springs.get(to_back).rest_length;
            springs.set_rest_length(to_back, back + distance);
            let side = springs.get(to_side).rest_length;
            springs.set_rest_length(to_side, side);
        }
        self.forward * distance
    }
}

/// Where leg `i` of a quadruped hangs: its corner among `corners`, the
/// horizontal direction `out` from the torso's centre, and the body's
/// forward and right-hand directions.
struct LegAt {
    corners: [ParticleId; 4],
    i: usize,
    out: DVec3,
    forward: DVec3,
    side: DVec3,
}

impl LegAt {
    /// The corners next to this one: (front–back, left–right).
    fn neighbours(&self) -> (ParticleId, ParticleId) {
        let (fb, lr) = match self.i {
            0 => (3, 1),
            1 => (2, 0),
            2 => (1, 3),
            _ => (0, 2),
        };
        (self.corners[fb], self.corners[lr])
    }

    fn foot(c: &QuadrupedConstants, x: DVec3) -> ParticleDef {
        ParticleDef::new(c.foot_mass)
            .with_radius(0.02)
            .at(x)
            .with_friction(1.0, 0.8)
            .with_restitution(0.1)
    }

    fn joint(c: &QuadrupedConstants, a: ParticleId, j: ParticleId, b: ParticleId) -> AngleJointDef {
        AngleJointDef::new(a, j, b, c.joint.0, c.joint.1)
    }

    /// Model 1's leg: a knee between hip and foot, the upper segment held
    /// against both torso edges by angle joints (a 2-DOF hip).
    fn two_segments(&self, world: &mut World, c: &QuadrupedConstants) -> Result<Leg, ModelError> {
        let corner = self.corners[self.i];
        let (fb, lr) = self.neighbours();
        let top = world.position(corner);
        let knee_at = top + self.out * 0.1 + DVec3::Y * 0.1;
        let foot_at = DVec3::new(knee_at.x, 0.02, knee_at.z) + self.out * 0.1;
        let knee = world.add_particle(Self::foot(c, knee_at).with_radius(0.02))?;
        let foot = world.add_particle(Self::foot(c, foot_at))?;
        world.add_spring(SpringDef::new(corner, knee, c.leg_spring.0, c.leg_spring.1))?;
        let spring =
            world.add_spring(SpringDef::new(knee, foot, c.leg_spring.0, c.leg_spring.1))?;
        // The 2-DOF hip: the upper segment held against both edges.
        world.add_angle_joint(Self::joint(c, knee, corner, fb))?;
        world.add_angle_joint(Self::joint(c, knee, corner, lr))?;
        // The knee.
        world.add_angle_joint(Self::joint(c, corner, knee, foot))?;
        Ok(Leg {
            corner,
            knee: Some(knee),
            foot,
            spring,
            swing: None,
            supports: None,
        })
    }

    /// Models 2 and 3's leg: one sprung segment, swung by two motors held
    /// by angle joints (model 2) or held by two more springs (model 3).
    fn one_segment(
        &self,
        world: &mut World,
        c: &QuadrupedConstants,
        model: Model,
    ) -> Result<Leg, ModelError> {
        let corner = self.corners[self.i];
        let (fb, lr) = self.neighbours();
        let top = world.position(corner);
        let foot_at = DVec3::new(top.x, 0.02, top.z) + self.out * c.splay;
        let foot = world.add_particle(Self::foot(c, foot_at))?;
        let spring =
            world.add_spring(SpringDef::new(corner, foot, c.leg_spring.0, c.leg_spring.1))?;
        let (swing, supports) = if model == Model::AngleJointed {
            world.add_angle_joint(Self::joint(c, foot, corner, fb))?;
            world.add_angle_joint(Self::joint(c, foot, corner, lr))?;
            let motor = |axis| TorqueJointDef {
                end: foot,
                joint: corner,
                axis,
                torque: 0.0,
            };
            let swing = (
                world.add_torque_joint(motor(self.side))?,
                world.add_torque_joint(motor(self.forward))?,
            );
            (Some(swing), None)
        } else {
            let s = |n: ParticleId| SpringDef::new(foot, n, c.leg_spring.0, c.leg_spring.1);
            (
                None,
                Some((world.add_spring(s(fb))?, world.add_spring(s(lr))?)),
            )
        };
        Ok(Leg {
            corner,
            knee: None,
            foot,
            spring,
            swing,
            supports,
        })
    }
}

impl Actor for Quadruped {
    /// Whether its experiment has begun.
    fn save_state(&self) -> Option<crate::kept::Kept> {
        Some(crate::kept::Kept::new(self.performed))
    }

    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        self.performed = *crate::kept::required::<bool>(kept, &self.name)?;
        Ok(())
    }

    fn act(&mut self, world: &mut World, _dt: f64) {
        let Some(demo) = self.demo else { return };
        let t = world.time();
        if self.model == Model::AngleJointed && self.performed && t >= demo.at + RAISE_SECONDS {
            self.raise_front_feet(world, 0.0);
        }
        if self.performed || t < demo.at {
            return;
        }
        self.performed = true;
        match self.model {
            Model::TwoSegment => {} // it fails standing still
            Model::AngleJointed => self.raise_front_feet(world, 4.0),
            Model::Sprung => {
                self.step_front_left(world, 0.08);
            }
        }
    }

    fn status(&self) -> Option<Status> {
        Some(Status {
            name: self.name.clone(),
            state: match (self.demo, self.performed) {
                (Some(_), true) => "acting",
                _ => "standing",
            },
            energy: None,
            phase: None,
        })
    }

    fn acts(&self) -> bool {
        self.demo.is_some()
    }
}
