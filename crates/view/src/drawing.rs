//! What is drawn, decided once for both pictures: each particle's ball,
//! each spring's rod, each jellyfish's bell, the floor's checker and
//! whether the world is under water. The live view's page draws what the
//! server sends it ([`Drawing`] with the scene, [`BellShape`]s with every
//! frame) and the software renderer what it is given; neither computes a
//! shape of its own.
// std's transcendental functions: this code draws or benchmarks, off the step path
#![allow(clippy::disallowed_methods)]

use crate::model::CreatureState;
use animats_engine::DVec3;
use animats_scene::{PartKind, Scene};
use serde::Serialize;

/// How a ball's surface looks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Look {
    /// Opaque.
    Solid,
    /// Opaque and glowing (food).
    Glow,
    /// See-through and glossy (a bubble).
    Clear,
    /// A little see-through (a jellyfish's flesh).
    Soft,
}

/// A particle, drawn as a ball.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Ball {
    /// m (at least 1 mm, so that it shows).
    pub radius: f64,
    /// 0xRRGGBB.
    pub colour: u32,
    /// Its surface.
    pub look: Look,
    /// Whether it casts a shadow.
    pub shadow: bool,
}

/// A spring, drawn as a rod between its ends.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Rod {
    /// One end (a particle's index).
    pub a: usize,
    /// The other.
    pub b: usize,
    /// m: 0.3 of the thinner end's radius, within [1.5 mm, 12 mm].
    pub radius: f64,
    /// 0xRRGGBB: its first end's colour, darkened (a muscle's colour at
    /// each instant is [`muscle_colour`] of its actuator's level).
    pub colour: u32,
    /// The actuator that drives its rest length (a muscle), by its index
    /// among the scene's actuators; `None` for a passive spring.
    pub muscle: Option<usize>,
}

/// A joint, drawn as an axle through its joint particle: square to the
/// plane of an angle joint's three particles (along z while they are in
/// line), along a torque joint's axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Axle {
    /// The joint particle (a particle's index).
    pub joint: usize,
    /// An angle joint's two ends, whose plane the axle is square to.
    pub ends: Option<(usize, usize)>,
    /// A torque joint's unit axis.
    pub axis: Option<[f64; 3]>,
    /// Half its length, m: 1.6 times the joint particle's radius.
    pub half: f64,
    /// m: 0.3 of the joint particle's radius, at least 2 mm.
    pub radius: f64,
    /// 0xRRGGBB: steel (a joint's motor's colour at each instant is
    /// [`muscle_colour`] of its actuator's level).
    pub colour: u32,
    /// The actuator that drives it (an angle joint's rest angle, a torque
    /// joint's torque), by its index among the scene's actuators.
    pub motor: Option<usize>,
}

/// A joint's axle's colour when no actuator drives it.
const STEEL: u32 = 0x8a_90_9a;

/// A muscle's colour at `level` (its actuator's level: 0 at the shortest
/// rest length, 1 at the longest): red when contracted, purple when
/// relaxed, through pale grey at the middle.
pub fn muscle_colour(level: f64) -> u32 {
    let l = if level.is_finite() {
        level.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let (red, mid, purple) = ([0xd7, 0x30, 0x27], [0xe8, 0xe4, 0xdc], [0x7b, 0x32, 0x94]);
    let mix = |a: [u32; 3], b: [u32; 3], t: f64| {
        let ch =
            |k: usize| (f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * t).round() as u32;
        (ch(0) << 16) | (ch(1) << 8) | ch(2)
    };
    if l < 0.5 {
        mix(red, mid, 2.0 * l)
    } else {
        mix(mid, purple, 2.0 * l - 1.0)
    }
}

/// A jellyfish's bell: which masses it wraps.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BellPlan {
    /// The jellyfish (its state carries the pulse's phase).
    pub name: String,
    /// Indices of the dome masses.
    pub dome: Vec<usize>,
    /// Indices of the tentacle masses (the bell opens towards them).
    pub tentacles: Vec<usize>,
    /// The dome masses' mean radius, m.
    pub size: f64,
    /// 0xRRGGBB.
    pub colour: u32,
}

/// A bell now: a half-ellipsoid whose rim is a circle of `radius` around
/// `centre` square to `axis`, its crown `height` along the axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BellShape {
    /// Centre of the rim, m.
    pub centre: [f64; 3],
    /// Unit vector from the rim to the crown.
    pub axis: [f64; 3],
    /// Rim radius, m.
    pub radius: f64,
    /// Crown height, m.
    pub height: f64,
}

/// Everything that is drawn, but for where it is.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Drawing {
    /// One per particle, by index.
    pub balls: Vec<Ball>,
    /// One per spring.
    pub rods: Vec<Rod>,
    /// One per jellyfish.
    pub bells: Vec<BellPlan>,
    /// One per joint: the angle joints, then the torque joints.
    pub axles: Vec<Axle>,
    /// The floor's checker square, m, if there is a floor.
    pub floor: Option<f64>,
    /// The floor's triangles when it has a terrain (not the plane y = 0).
    pub ground: Option<crate::GroundMesh>,
    /// The floor's terrain when it is not the plane y = 0 (the renderer
    /// asks it for heights; the page gets `ground`).
    #[serde(skip)]
    pub terrain: Option<animats_engine::Terrain>,
    /// Under water (tinted and fogged), not in air.
    pub water: bool,
}

/// Fluids denser than this are water to the eye, kg/m³.
const WATER_DENSITY: f64 = 500.0;

/// 0xRRGGBB times `f` per channel.
fn dim(c: u32, f: f64) -> u32 {
    let ch = |shift: u32| ((f64::from((c >> shift) & 0xff) * f).round() as u32).min(255) << shift;
    ch(16) | ch(8) | ch(0)
}

impl Drawing {
    /// The drawing of `scene`, framed from `distance` m (a far camera
    /// gets a coarser checker).
    pub fn of(scene: &Scene, distance: f64) -> Drawing {
        let w = &scene.world;
        let radius = &w.particles().radius;
        let colour = |i: usize| crate::palette::colour_of(scene.kinds[i].name());
        let balls = (0..w.len())
            .map(|i| {
                let kind = scene.kinds[i];
                Ball {
                    radius: radius[i].max(0.001),
                    colour: colour(i),
                    look: match kind {
                        PartKind::Food => Look::Glow,
                        PartKind::Bubble => Look::Clear,
                        PartKind::Dome | PartKind::Tentacle => Look::Soft,
                        _ => Look::Solid,
                    },
                    shadow: kind != PartKind::Bubble,
                }
            })
            .collect();
        // Which actuator, if any, drives each spring's rest length.
        let mut muscles = vec![None; w.forces().springs.len()];
        for (k, (_, a)) in scene.nervous.actuators.iter().enumerate() {
            if let animats_creatures::actuators::AnyActuator::Spring(a) = a {
                if let Some(m) = muscles.get_mut(a.target().0.index()) {
                    *m = Some(k);
                }
            }
        }
        let rods = w
            .forces()
            .springs
            .iter()
            .zip(muscles)
            .map(|(s, muscle)| {
                let (a, b) = s.ends();
                let (a, b) = (a.index(), b.index());
                let thin = (0.3 * radius[a].min(radius[b])).clamp(0.0015, 0.012);
                Rod {
                    a,
                    b,
                    // A muscle is drawn thicker than a passive spring.
                    radius: if muscle.is_some() { 1.6 * thin } else { thin },
                    colour: dim(colour(a), 0.8),
                    muscle,
                }
            })
            .collect();
        // Joints as axles; which actuator, if any, drives each.
        let forces = w.forces();
        let (mut angle_motors, mut torque_motors) = (
            vec![None; forces.angle_joints.len()],
            vec![None; forces.torque_joints.len()],
        );
        for (k, (_, a)) in scene.nervous.actuators.iter().enumerate() {
            use animats_creatures::actuators::AnyActuator;
            let slot = match a {
                AnyActuator::AngleJoint(a) => angle_motors.get_mut(a.target().0.index()),
                AnyActuator::TorqueJoint(a) => torque_motors.get_mut(a.target().0.index()),
                _ => None,
            };
            if let Some(m) = slot {
                *m = Some(k);
            }
        }
        let axle = |joint: usize, ends, axis, motor| Axle {
            joint,
            ends,
            axis,
            half: 1.6 * radius[joint].max(0.001),
            radius: (0.3 * radius[joint]).max(0.002),
            colour: STEEL,
            motor,
        };
        let axles = forces
            .angle_joints
            .iter()
            .zip(angle_motors)
            .map(|(j, motor)| {
                let (a, joint, b) = j.particles();
                axle(joint.index(), Some((a.index(), b.index())), None, motor)
            })
            .chain(
                forces
                    .torque_joints
                    .iter()
                    .zip(torque_motors)
                    .map(|(j, motor)| {
                        let (_, joint) = j.particles();
                        axle(joint.index(), None, Some(j.axis().to_array()), motor)
                    }),
            )
            .collect();
        let bells = scene
            .creatures
            .iter()
            .filter_map(|c| {
                let bell = c.bell.as_ref()?;
                let size = bell.dome.iter().map(|&i| radius[i]).sum::<f64>()
                    / bell.dome.len().max(1) as f64;
                Some(BellPlan {
                    name: c.name.clone(),
                    dome: bell.dome.clone(),
                    tentacles: bell.tentacles.clone(),
                    size,
                    colour: crate::palette::colour_of("bell"),
                })
            })
            .collect();
        let floor = w.event::<animats_engine::FloorCollision>().is_some();
        let terrain = w.terrain().filter(|t| !t.is_flat()).cloned();
        Drawing {
            ground: terrain.as_ref().and_then(crate::ground::mesh),
            terrain,
            balls,
            rods,
            bells,
            axles,
            floor: floor.then_some(if distance < 4.0 { 0.1 } else { 0.5 }),
            water: w
                .forces()
                .fluids()
                .first()
                .is_some_and(|f| f.density > WATER_DENSITY),
        }
    }

    /// Each rod's colour with the actuators at `levels` (scene order): a
    /// muscle's from its level, a passive spring's its own.
    pub fn rod_colours(&self, levels: &[f64]) -> Vec<u32> {
        self.rods
            .iter()
            .map(|r| match r.muscle.and_then(|k| levels.get(k)) {
                Some(&l) => muscle_colour(l),
                None => r.colour,
            })
            .collect()
    }

    /// Each axle's two ends with the particles at `positions`.
    pub fn axle_ends(&self, positions: &[DVec3]) -> Vec<[[f64; 3]; 2]> {
        let at = |i: usize| positions.get(i).copied().unwrap_or(DVec3::ZERO);
        self.axles
            .iter()
            .map(|x| {
                let c = at(x.joint);
                let dir = match (x.ends, x.axis) {
                    (Some((a, b)), _) => (at(a) - c).cross(at(b) - c).normalize_or_zero(),
                    (None, Some(axis)) => DVec3::from_array(axis),
                    (None, None) => DVec3::ZERO,
                };
                let dir = if dir == DVec3::ZERO { DVec3::Z } else { dir };
                [(c - x.half * dir).to_array(), (c + x.half * dir).to_array()]
            })
            .collect()
    }

    /// Each axle's colour with the actuators at `levels` (scene order): a
    /// motor's from its level, an undriven joint's steel.
    pub fn axle_colours(&self, levels: &[f64]) -> Vec<u32> {
        self.axles
            .iter()
            .map(|x| match x.motor.and_then(|k| levels.get(k)) {
                Some(&l) => muscle_colour(l),
                None => x.colour,
            })
            .collect()
    }

    /// Every bell's shape with the particles at `positions` and the
    /// creatures in `states` (`None` for a bell whose dome is degenerate).
    pub fn bell_shapes(
        &self,
        positions: &[DVec3],
        states: &[CreatureState],
    ) -> Vec<Option<BellShape>> {
        self.bells
            .iter()
            .map(|b| {
                // Contraction follows the pulse: full at the top of the power
                // stroke, none while idle.
                let squeeze = states
                    .iter()
                    .find(|c| c.name == b.name)
                    .and_then(|c| c.phase.filter(|_| c.state != "idle"))
                    .map_or(0.0, |phase| phase.sin().max(0.0));
                bell_shape(b, positions, squeeze)
            })
            .collect()
    }
}

/// The bell over a dome: wrapping the dome masses, opening towards the
/// tentacles, narrower and taller as it contracts (`squeeze` in [0, 1]).
fn bell_shape(b: &BellPlan, positions: &[DVec3], squeeze: f64) -> Option<BellShape> {
    let at = |i: usize| positions.get(i).copied().unwrap_or(DVec3::ZERO);
    if b.dome.len() < 3 {
        return None;
    }
    let p: Vec<DVec3> = b.dome.iter().map(|&i| at(i)).collect();
    let centre = p.iter().sum::<DVec3>() / p.len() as f64;
    let mut axis = (p[0] - p[1]).cross(p[2] - p[0]).try_normalize()?;
    if !b.tentacles.is_empty() {
        let t = b.tentacles.iter().map(|&i| at(i)).sum::<DVec3>() / b.tentacles.len() as f64;
        if axis.dot(centre - t) < 0.0 {
            axis = -axis;
        }
    }
    let radius = p.iter().map(|x| x.distance(centre)).sum::<f64>() / p.len() as f64 + b.size;
    let s = squeeze.clamp(0.0, 1.0);
    Some(BellShape {
        centre: (centre - axis * (0.5 * b.size)).to_array(),
        axis: axis.to_array(),
        radius: radius * (1.08 - 0.28 * s),
        height: radius * (0.75 + 0.45 * s),
    })
}
